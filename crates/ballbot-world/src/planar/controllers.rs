//! The core's planar controllers behind [`PlanarController`], driven as on the PIPTB (paper
//! Sec. IV-B): the LQR and the cascaded PI-PD compute a torque on the main controller at
//! 400 Hz and the drive applies it (open-loop torque control); the cascaded LQR-PI computes
//! `(tau_r, phi_dot_r)` at 400 Hz and the drive's speed PI runs at 8 kHz.
//!
//! **The drive's speed loop measures the motor, not the ball.** A motor encoder sees the joint
//! rate `phi_dot - theta_dot`, so the outer loop maps its ball-rate reference to a joint-rate
//! reference with the tilt rate it measured, `psi_dot_r = phi_dot_r - theta_dot` (MODEL.md
//! section 4 does the same per omniwheel), and the drive tracks that with its own encoder. The
//! speed PI's gains place the joint-rate error at a critically damped double pole at the
//! chosen bandwidth, with the joint's acceleration per torque
//! [`super::PlanarPlant::joint_gain`] upright as plant gain. Its anti-windup sees the torque
//! range the actuator really has at the measured speed (torque-speed line).

use super::{
    DriveMeasurement, DriveSetpoint, OuterMeasurement, PlanarCommand, PlanarController, PlanarError,
};
use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, LqrPiOuterOutput, PiPdController,
    PiPdGains, PlaneController, PlaneOutput, SpeedCommand, SpeedPi, SpeedPiGains, SpeedPiOutput,
    StepStatus, Terms,
};
use ballbot_core::lqr::WipLqrWeights;
use ballbot_core::{ActuatorParams, PlanarRobotParams, Wip, WipState};

/// Which of the paper's three controllers.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum ControllerKind {
    /// LQR torque control at the outer rate.
    Lqr,
    /// Cascaded PI-PD torque control at the outer rate.
    PiPd,
    /// Cascaded LQR-PI: LQR and reference model at the outer rate, speed PI in the drive.
    LqrPi,
}

impl ControllerKind {
    /// All three, in the paper's order.
    pub const ALL: [Self; 3] = [Self::Lqr, Self::PiPd, Self::LqrPi];

    /// The key used in summaries and logs: `lqr`, `pi_pd`, `lqr_pi`.
    pub fn key(self) -> &'static str {
        match self {
            Self::Lqr => "lqr",
            Self::PiPd => "pi_pd",
            Self::LqrPi => "lqr_pi",
        }
    }

    /// The paper's name: `LQR`, `PI-PD`, `LQR-PI`.
    pub fn label(self) -> &'static str {
        match self {
            Self::Lqr => "LQR",
            Self::PiPd => "PI-PD",
            Self::LqrPi => "LQR-PI",
        }
    }
}

/// How to build a controller for a robot: the kind and its design settings. Every gain is
/// designed from the model unless given explicitly.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct ControllerSettings {
    /// Which controller.
    pub kind: ControllerKind,
    /// LQR state weights on `[theta, theta_dot, phi_dot]` (LQR and LQR-PI). Default MODEL.md's
    /// `[100, 10, 1]`.
    #[serde(default = "default_q")]
    pub lqr_q_diag: [f64; 3],
    /// LQR torque weight (LQR and LQR-PI). Default 0.1.
    #[serde(default = "default_r")]
    pub lqr_r: f64,
    /// Explicit LQR gains `[k1, k2, k3]` in the paper's form `tau = k (s_c - s)`; overrides
    /// the design when given.
    #[serde(default)]
    pub lqr_gains: Option<[f64; 3]>,
    /// Bandwidth of the drive's speed PI (LQR-PI), rad/s. Default 60.
    #[serde(default = "default_inner_bandwidth")]
    pub inner_bandwidth_rad_per_s: f64,
    /// Closed-loop poles of the PI-PD design as multiples of the open-loop unstable pole;
    /// default the core's [`ballbot_core::control::PI_PD_DEFAULT_POLES_PER_P0`].
    #[serde(default = "default_pi_pd_poles")]
    pub pi_pd_poles_per_p0: [f64; 4],
    /// Reference-tilt limit of the PI-PD (rad). Default the core's 0.2 rad.
    #[serde(default = "default_pi_pd_max_tilt")]
    pub pi_pd_max_tilt_rad: f64,
}

fn default_q() -> [f64; 3] {
    [100.0, 10.0, 1.0]
}
fn default_r() -> f64 {
    0.1
}
fn default_inner_bandwidth() -> f64 {
    60.0
}
fn default_pi_pd_poles() -> [f64; 4] {
    ballbot_core::control::PI_PD_DEFAULT_POLES_PER_P0
}
fn default_pi_pd_max_tilt() -> f64 {
    ballbot_core::control::PI_PD_DEFAULT_MAX_TILT_RAD
}

impl ControllerSettings {
    /// The documented defaults for `kind`.
    pub fn new(kind: ControllerKind) -> Self {
        Self {
            kind,
            lqr_q_diag: default_q(),
            lqr_r: default_r(),
            lqr_gains: None,
            inner_bandwidth_rad_per_s: default_inner_bandwidth(),
            pi_pd_poles_per_p0: default_pi_pd_poles(),
            pi_pd_max_tilt_rad: default_pi_pd_max_tilt(),
        }
    }

    /// The LQR gains these settings give for `robot` (designed or explicit), limited to the
    /// actuator's peak torque.
    pub fn lqr_gains_for(
        &self,
        robot: &PlanarRobotParams<f64>,
    ) -> Result<LqrGains<f64>, PlanarError> {
        let peak = robot.actuator.peak_torque_nm;
        let gains = match self.lqr_gains {
            Some(k) => {
                let g = LqrGains::from_reduced(k, peak);
                g.validate()
                    .map_err(|e| controller_error("controller.lqr_gains", e))?;
                g
            }
            None => {
                let wip = Wip::new(robot.plane)?;
                let weights = WipLqrWeights::diagonal(self.lqr_q_diag, self.lqr_r);
                LqrGains::design(&wip, &weights, peak)
                    .map_err(|e| controller_error("controller.lqr_q_diag / controller.lqr_r", e))?
            }
        };
        Ok(gains)
    }

    /// Builds the controller for `robot`. `joint_gain` is the joint's acceleration per torque
    /// upright ([`super::PlanarPlant::joint_gain`]), the speed PI's plant gain.
    pub fn build(
        &self,
        robot: &PlanarRobotParams<f64>,
        joint_gain: f64,
    ) -> Result<Box<dyn PlanarController + Send>, PlanarError> {
        let peak = robot.actuator.peak_torque_nm;
        let wip = Wip::new(robot.plane)?;
        Ok(match self.kind {
            ControllerKind::Lqr => Box::new(LqrTorque::new(self.lqr_gains_for(robot)?)?),
            ControllerKind::PiPd => {
                let p0 = wip.upright_unstable_pole_rad_per_s();
                let poles = self.pi_pd_poles_per_p0.map(|m| m * p0);
                let gains = PiPdGains::design(&wip, poles, self.pi_pd_max_tilt_rad, peak)
                    .map_err(|e| controller_error("controller.pi_pd_poles_per_p0", e))?;
                Box::new(PiPdTorque::new(gains)?)
            }
            ControllerKind::LqrPi => {
                let inner =
                    SpeedPiGains::from_bandwidth(joint_gain, self.inner_bandwidth_rad_per_s, peak)
                        .map_err(|e| controller_error("controller.inner_bandwidth_rad_per_s", e))?;
                let config = LqrPiOuterConfig::new(self.lqr_gains_for(robot)?, &inner)?;
                Box::new(LqrPiCascade::new(wip, config, inner, robot.actuator)?)
            }
        })
    }
}

fn controller_error(key: &str, e: ballbot_core::Error) -> PlanarError {
    PlanarError::invalid(key, e.to_string())
}

/// The measured state `[theta, phi, theta_dot, phi_dot]`.
fn measured_state(m: &OuterMeasurement) -> WipState<f64> {
    WipState::new(
        m.tilt_rad,
        m.ball_angle_rad,
        m.tilt_rate_rad_per_s,
        m.ball_rate_rad_per_s,
    )
}

/// The command state `s_c = [theta_c, 0, theta_dot_c, phi_dot_c]` (phi is not fed back).
fn command_state(c: &PlanarCommand) -> WipState<f64> {
    WipState::new(
        c.tilt_rad,
        0.0,
        c.tilt_rate_rad_per_s,
        c.ball_rate_rad_per_s,
    )
}

/// Appends `last`'s terms by [`Terms::for_each_term`] (zeros under [`Terms::TERM_NAMES`]
/// before the first step) and its step status as `("status", code)` ([`StepStatus::code`]).
fn push_terms<O: Terms<f64>>(
    last: Option<&O>,
    status: StepStatus,
    out: &mut Vec<(&'static str, f64)>,
) {
    match last {
        Some(o) => o.for_each_term(|name, value| out.push((name, value))),
        None => out.extend(O::TERM_NAMES.iter().map(|&name| (name, 0.0))),
    }
    out.push(("status", f64::from(status.code())));
}

/// A balancing-plane controller of the core in torque mode: its step's torque goes straight to
/// the drive ([`PlaneController`]). [`LqrTorque`] and [`PiPdTorque`] are the paper's two.
#[derive(Clone, Debug)]
pub struct TorqueMode<C: PlaneController<f64>> {
    name: &'static str,
    controller: C,
    last: Option<C::Output>,
}

/// The paper's LQR in torque mode.
pub type LqrTorque = TorqueMode<LqrController<f64>>;

/// The cascaded PI-PD in torque mode.
pub type PiPdTorque = TorqueMode<PiPdController<f64>>;

impl LqrTorque {
    /// An LQR torque controller with `gains`.
    pub fn new(gains: LqrGains<f64>) -> Result<Self, PlanarError> {
        Ok(TorqueMode::with_name("lqr", LqrController::new(gains)?))
    }
}

impl PiPdTorque {
    /// A PI-PD torque controller with `gains`.
    pub fn new(gains: PiPdGains<f64>) -> Result<Self, PlanarError> {
        Ok(TorqueMode::with_name("pi_pd", PiPdController::new(gains)?))
    }
}

impl<C: PlaneController<f64>> TorqueMode<C> {
    /// `controller` in torque mode, named `name` in logs and run summaries.
    pub fn with_name(name: &'static str, controller: C) -> Self {
        Self {
            name,
            controller,
            last: None,
        }
    }
}

impl<C: PlaneController<f64>> PlanarController for TorqueMode<C> {
    fn name(&self) -> &str {
        self.name
    }
    fn outer_step(&mut self, m: &OuterMeasurement, c: &PlanarCommand, dt: f64) -> DriveSetpoint {
        let out = self
            .controller
            .step(&measured_state(m), &command_state(c), dt);
        self.last = Some(out);
        DriveSetpoint {
            torque_nm: out.torque_nm(),
            joint_rate_rad_per_s: None,
        }
    }
    fn terms(&self, out: &mut Vec<(&'static str, f64)>) {
        let status = self.last.map_or(StepStatus::Nominal, |o| o.status());
        push_terms(self.last.as_ref(), status, out);
    }
    fn reset(&mut self) {
        self.controller.reset();
        self.last = None;
    }
}

/// The cascaded LQR-PI: [`LqrPiOuter`] on the main controller, [`SpeedPi`] in the drive on the
/// joint rate (see the module docs).
#[derive(Clone, Debug)]
pub struct LqrPiCascade {
    outer: LqrPiOuter<f64>,
    inner: SpeedPi<f64>,
    actuator: ActuatorParams<f64>,
    last_outer: Option<LqrPiOuterOutput<f64>>,
    last_inner: Option<SpeedPiOutput<f64>>,
}

impl LqrPiCascade {
    /// The cascade with reference model `model`, outer `config`, drive PI `inner`, and the
    /// actuator whose torque range the drive's anti-windup respects.
    pub fn new(
        model: Wip<f64>,
        config: LqrPiOuterConfig<f64>,
        inner: SpeedPiGains<f64>,
        actuator: ActuatorParams<f64>,
    ) -> Result<Self, PlanarError> {
        Ok(Self {
            outer: LqrPiOuter::new(model, config)?,
            inner: SpeedPi::new(inner)?,
            actuator,
            last_outer: None,
            last_inner: None,
        })
    }
}

impl PlanarController for LqrPiCascade {
    fn name(&self) -> &str {
        "lqr_pi"
    }
    fn outer_step(&mut self, m: &OuterMeasurement, c: &PlanarCommand, dt: f64) -> DriveSetpoint {
        let out = self.outer.step(&measured_state(m), &command_state(c), dt);
        self.last_outer = Some(out);
        DriveSetpoint {
            torque_nm: out.reference_torque_nm,
            joint_rate_rad_per_s: Some(out.reference_ball_rate_rad_per_s - m.tilt_rate_rad_per_s),
        }
    }
    fn drive_step(&mut self, m: &DriveMeasurement, sp: &DriveSetpoint, dt: f64) -> f64 {
        let Some(reference) = sp.joint_rate_rad_per_s else {
            // Before the first outer step: torque mode.
            return sp.torque_nm;
        };
        let (lo, hi) = self.actuator.torque_bounds_nm(m.joint_rate_rad_per_s);
        let command = SpeedCommand {
            speed_rad_per_s: reference,
            feedforward_torque_nm: sp.torque_nm,
        };
        let out = self
            .inner
            .step_within(m.joint_rate_rad_per_s, &command, dt, lo, hi);
        self.last_inner = Some(out);
        out.torque_nm
    }
    /// The log's historical column names, spelled here rather than taken from [`Terms`]: the
    /// outer and inner outputs share field names (`torque_nm`, `saturation_nm`), so their
    /// terms would need prefixes, and a prefixed `&'static str` cannot be built without
    /// allocating (or leaking) at every outer tick. The inner terms also have the log's
    /// names (`inner_p_term_nm` for `proportional_nm`) and a derived `tracking_torque_nm`.
    fn terms(&self, out: &mut Vec<(&'static str, f64)>) {
        let z = 0.0;
        let (tau_r, rate_r, accel_r, t1, t2, t3, sat_r) = match &self.last_outer {
            Some(o) => (
                o.reference_torque_nm,
                o.reference_ball_rate_rad_per_s,
                o.reference_ball_accel_rad_per_s2,
                o.tilt_term_nm,
                o.tilt_rate_term_nm,
                o.ball_rate_term_nm,
                o.saturation_nm,
            ),
            None => (z, z, z, z, z, z, z),
        };
        let (tau, p, i, sat, err) = match &self.last_inner {
            Some(o) => (
                o.torque_nm,
                o.proportional_nm,
                o.integral_nm,
                o.saturation_nm,
                o.speed_error_rad_per_s,
            ),
            None => (z, z, z, z, z),
        };
        out.extend([
            ("torque_nm", tau),
            ("reference_torque_nm", tau_r),
            ("reference_ball_rate_rad_per_s", rate_r),
            ("reference_ball_accel_rad_per_s2", accel_r),
            ("tilt_term_nm", t1),
            ("tilt_rate_term_nm", t2),
            ("ball_rate_term_nm", t3),
            ("reference_saturation_nm", sat_r),
            ("inner_p_term_nm", p),
            ("inner_i_term_nm", i),
            ("tracking_torque_nm", p + i),
            ("inner_saturation_nm", sat),
            ("joint_rate_error_rad_per_s", err),
        ]);
    }
    fn reset(&mut self) {
        self.outer.reset();
        self.inner.reset();
        self.last_outer = None;
        self.last_inner = None;
    }
}
