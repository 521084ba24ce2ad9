//! The simulated planar robot: the core's nonlinear WIP, transmission friction and the
//! actuator's limits, integrated with fixed-step RK4.

use super::{FrictionMode, PlanarError, TransmissionFriction};
use ballbot_core::wip::{BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{ActuatorParams, PlanarRobotParams, Wip, WipState};
use nalgebra::Vector2;

/// The WIP's constant inertia and force terms (the core's closed form, MODEL.md section 2).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Consts {
    /// `a = I_U + m_U l^2 + I_W`.
    a: f64,
    /// `b = I_S + (m_S + m_U) r^2 + I_W`.
    b: f64,
    /// `m_U r l`.
    mrl: f64,
    /// `m_U g l`.
    mgl: f64,
    /// `I_W`.
    iw: f64,
    /// `b_m`.
    bm: f64,
    /// `b_k`.
    bk: f64,
}

/// What happened during one plant step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantStep {
    /// Torque the drive asked the actuator for (N m).
    pub requested_torque_nm: f64,
    /// Torque the actuator delivered, after its current limit and torque-speed line (N m).
    pub applied_torque_nm: f64,
    /// `true` when the actuator limited the request.
    pub saturated: bool,
    /// Transmission friction torque at the start of the step (N m).
    pub friction_torque_nm: f64,
    /// The friction model's branch at the start of the step.
    pub friction_mode: FrictionMode,
}

/// The planar plant: one WIP plane (or the PIPTB) with its actuator and transmission friction.
///
/// The motor torque is held constant over a step (zero-order hold); friction is evaluated at
/// every RK4 stage. The actuator's limits are evaluated at the joint rate at the start of the
/// step: the current limit `peak_torque_nm` and the torque-speed line through the no-load
/// speed ([`ActuatorParams::clamp_torque_nm`]).
///
/// ```
/// use ballbot_core::PlanarRobotParams;
/// use ballbot_world::planar::{PlanarPlant, TransmissionFriction};
/// use nalgebra::Vector4;
/// let mut plant =
///     PlanarPlant::new(PlanarRobotParams::piptb(), TransmissionFriction::piptb(), 8000.0)?;
/// plant.set_state(Vector4::new(0.0, 0.0, 0.0, 0.0));
/// // 0.2 N m is below the 0.5 N m breakaway torque: the transmission stays stuck.
/// let step = plant.step(0.2);
/// assert_eq!(step.friction_mode, ballbot_world::planar::FrictionMode::Stuck);
/// # Ok::<(), ballbot_world::planar::PlanarError>(())
/// ```
#[derive(Clone, Debug)]
pub struct PlanarPlant {
    wip: Wip<f64>,
    consts: Consts,
    actuator: ActuatorParams<f64>,
    friction: TransmissionFriction,
    frictionless: bool,
    state: WipState<f64>,
    dt_secs: f64,
}

impl PlanarPlant {
    /// Builds the plant, integrated at `rate_hz` (RK4 steps per second).
    ///
    /// Fails when a parameter is invalid or the friction's stick window is too narrow for the
    /// step (see [`TransmissionFriction::min_stick_window_rad_per_s`]).
    pub fn new(
        robot: PlanarRobotParams<f64>,
        friction: TransmissionFriction,
        rate_hz: f64,
    ) -> Result<Self, PlanarError> {
        robot.validate()?;
        friction.validate()?;
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(PlanarError::invalid(
                "sim.plant_rate_hz",
                "must be finite and > 0",
            ));
        }
        let wip = Wip::new(robot.plane)?;
        let dt_secs = 1.0 / rate_hz;
        let p = &robot.plane;
        let (r, l) = (p.ball_radius_m, p.com_height_m);
        let consts = Consts {
            a: p.body_inertia_kg_m2 + p.body_mass_kg * l * l + p.wheel_inertia_kg_m2,
            b: p.ball_inertia_kg_m2
                + (p.ball_mass_kg + p.body_mass_kg) * r * r
                + p.wheel_inertia_kg_m2,
            mrl: p.body_mass_kg * r * l,
            mgl: p.body_mass_kg * p.gravity_m_per_s2 * l,
            iw: p.wheel_inertia_kg_m2,
            bm: p.drive_damping_nm_s_per_rad,
            bk: p.ball_damping_nm_s_per_rad,
        };
        let plant = Self {
            wip,
            consts,
            actuator: robot.actuator,
            friction,
            frictionless: friction.is_none(),
            state: WipState::zeros(),
            dt_secs,
        };
        if !plant.frictionless {
            let min = friction.min_stick_window_rad_per_s(plant.joint_gain(0.0), dt_secs);
            if friction.stick_window_rad_per_s < min {
                return Err(PlanarError::invalid(
                    "friction.stick_window_rad_per_s",
                    format!(
                        "must be >= {min:.3e} rad/s at this plant rate, or a stuck joint can \
                         jump across the window in one step"
                    ),
                ));
            }
            if friction.stick_settle_time_secs < dt_secs {
                return Err(PlanarError::invalid(
                    "friction.stick_settle_time_secs",
                    format!("must be >= one plant step ({dt_secs:.3e} s)"),
                ));
            }
        }
        Ok(plant)
    }

    /// The WIP model.
    pub fn wip(&self) -> &Wip<f64> {
        &self.wip
    }

    /// The actuator.
    pub fn actuator(&self) -> &ActuatorParams<f64> {
        &self.actuator
    }

    /// The transmission friction.
    pub fn friction(&self) -> &TransmissionFriction {
        &self.friction
    }

    /// The integration step (s).
    pub fn dt_secs(&self) -> f64 {
        self.dt_secs
    }

    /// The true state `[theta, phi, theta_dot, phi_dot]`.
    pub fn state(&self) -> &WipState<f64> {
        &self.state
    }

    /// Sets the true state.
    pub fn set_state(&mut self, state: WipState<f64>) {
        self.state = state;
    }

    /// The joint's rate `phi_dot - theta_dot` (rad/s): what the motor encoder sees.
    pub fn joint_rate_rad_per_s(&self) -> f64 {
        self.state[BALL_RATE] - self.state[TILT_RATE]
    }

    /// `M^-1 [-1, 1]^T`: the accelerations `[theta_ddot, phi_ddot]` per N m of joint torque.
    #[inline]
    fn torque_response(&self, tilt_rad: f64) -> Vector2<f64> {
        let m = self.wip.mass_matrix(tilt_rad);
        let (a, c, b) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
        let delta = a * b - c * c;
        Vector2::new(-(b + c) / delta, (a + c) / delta)
    }

    /// `k = [-1, 1] M^-1 [-1, 1]^T` (rad/s^2 per N m): how fast a joint torque accelerates the
    /// joint at tilt `tilt_rad`. Positive; largest upright.
    pub fn joint_gain(&self, tilt_rad: f64) -> f64 {
        let du = self.torque_response(tilt_rad);
        du[1] - du[0]
    }

    /// State derivative under motor torque `motor_torque_nm`, with the friction torque and
    /// branch it implies.
    #[inline]
    pub fn derivative(
        &self,
        s: &WipState<f64>,
        motor_torque_nm: f64,
    ) -> (WipState<f64>, f64, FrictionMode) {
        if self.frictionless {
            return (
                self.wip.derivative(s, motor_torque_nm),
                0.0,
                FrictionMode::Free,
            );
        }
        let v = s[BALL_RATE] - s[TILT_RATE];
        if !self.friction.in_window(v) {
            let (tau_f, mode) = self.friction.torque_nm(v, 0.0, 1.0);
            return (self.wip.derivative(s, motor_torque_nm + tau_f), tau_f, mode);
        }
        let q_ddot = self.wip.accelerations(s, motor_torque_nm);
        let du = self.torque_response(s[TILT]);
        let k = du[1] - du[0];
        let (tau_f, mode) = self.friction.torque_nm(v, q_ddot[1] - q_ddot[0], k);
        let q_ddot = q_ddot + du * tau_f;
        (
            WipState::new(s[TILT_RATE], s[BALL_RATE], q_ddot[0], q_ddot[1]),
            tau_f,
            mode,
        )
    }

    /// The torque the actuator delivers for `requested_torque_nm` at the present joint rate.
    pub fn actuator_torque_nm(&self, requested_torque_nm: f64) -> f64 {
        self.actuator
            .clamp_torque_nm(requested_torque_nm, self.joint_rate_rad_per_s())
    }

    /// Advances one step with `requested_torque_nm` asked of the actuator.
    ///
    /// The four RK4 stages evaluate the same equations as [`ballbot_core::Wip::derivative`]
    /// (tested to agree to rounding), with one `sin_cos` per step: the later stages, whose tilt
    /// differs from the step's start by `|d| < 0.01` rad, use `sin(t0 + d)`, `cos(t0 + d)` by
    /// the angle-addition formulas with `sin d`, `cos d` from their Taylor series (error below
    /// `d^7 / 5040 < 2e-18`); a larger `d` falls back to `sin_cos`.
    #[inline]
    pub fn step(&mut self, requested_torque_nm: f64) -> PlantStep {
        let applied = self.actuator_torque_nm(requested_torque_nm);
        let h = self.dt_secs;
        let s0 = self.state;
        let (sin0, cos0) = s0[TILT].sin_cos();
        let trig = |tilt: f64| {
            let d = tilt - s0[TILT];
            if d.abs() < 1e-2 {
                let d2 = d * d;
                let sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0));
                let cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
                (sin0 * cd + cos0 * sd, cos0 * cd - sin0 * sd)
            } else {
                tilt.sin_cos()
            }
        };
        let (k1, friction_torque_nm, friction_mode) = self.eval(&s0, sin0, cos0, applied);
        let s2 = s0 + k1 * (0.5 * h);
        let (sn, cs) = trig(s2[TILT]);
        let k2 = self.eval(&s2, sn, cs, applied).0;
        let s3 = s0 + k2 * (0.5 * h);
        let (sn, cs) = trig(s3[TILT]);
        let k3 = self.eval(&s3, sn, cs, applied).0;
        let s4 = s0 + k3 * h;
        let (sn, cs) = trig(s4[TILT]);
        let k4 = self.eval(&s4, sn, cs, applied).0;
        self.state = s0 + (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
        PlantStep {
            requested_torque_nm,
            applied_torque_nm: applied,
            // A non-finite request is clamped to 0, which counts as limited.
            saturated: applied != requested_torque_nm,
            friction_torque_nm,
            friction_mode,
        }
    }

    /// The state derivative at `s` with `sin`, `cos` of its tilt given: the core's closed
    /// form (see [`ballbot_core::wip`]) plus the friction torque on the joint.
    #[inline(always)]
    fn eval(
        &self,
        s: &WipState<f64>,
        sin: f64,
        cos: f64,
        motor_torque_nm: f64,
    ) -> (WipState<f64>, f64, FrictionMode) {
        let k = &self.consts;
        let c = k.mrl * cos - k.iw;
        let inv_delta = 1.0 / (k.a * k.b - c * c);
        let (tilt_rate, ball_rate) = (s[TILT_RATE], s[BALL_RATE]);
        let rel = ball_rate - tilt_rate;
        // Generalised forces without the joint torque; the joint torque u enters as
        // [-u, +u].
        let g1 = k.mgl * sin + k.bm * rel;
        let g2 = k.mrl * sin * tilt_rate * tilt_rate - k.bm * rel - k.bk * ball_rate;
        let (tau_f, mode) = if self.frictionless {
            (0.0, FrictionMode::Free)
        } else if !self.friction.in_window(rel) {
            self.friction.torque_nm(rel, 0.0, 1.0)
        } else {
            let u = motor_torque_nm;
            let th = (k.b * (g1 - u) - c * (g2 + u)) * inv_delta;
            let ph = (k.a * (g2 + u) - c * (g1 - u)) * inv_delta;
            let gain = (k.a + k.b + 2.0 * c) * inv_delta;
            self.friction.torque_nm(rel, ph - th, gain)
        };
        let u = motor_torque_nm + tau_f;
        let (f1, f2) = (g1 - u, g2 + u);
        (
            WipState::new(
                tilt_rate,
                ball_rate,
                (k.b * f1 - c * f2) * inv_delta,
                (k.a * f2 - c * f1) * inv_delta,
            ),
            tau_f,
            mode,
        )
    }
}
