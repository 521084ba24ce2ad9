//! The closed-loop rig: presets, the controllers under test, the nonlinear WIP plant with joint
//! friction, and the simulation that records a trace.

use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedCommand,
    SpeedPi, SpeedPiGains,
};
use ballbot_core::{Wip, WipParams, WipState, rk4_step};
use nalgebra::Vector4;

pub(super) const OUTER_HZ: f64 = 400.0;
pub(super) const INNER_HZ: f64 = 8000.0;
/// Plant RK4 substeps per inner period: 1, the plant at 8 kHz with the torque held over each
/// inner period (as the motor driver holds it). Convergence check: 2 substeps (16 kHz) give
/// the same reported numbers to 3-4 significant digits, at twice the test time.
pub(super) const PLANT_SUBSTEPS: usize = 1;
pub(super) const INNER_PER_OUTER: usize = 20;
/// Bandwidth of the inner speed PI's error dynamics (rad/s).
pub(super) const INNER_BANDWIDTH_RAD_PER_S: f64 = 30.0;

pub(super) const TILT: usize = 0;
pub(super) const TILT_RATE: usize = 2;
pub(super) const BALL_RATE: usize = 3;

// ----------------------------------------------------------------------------------------
// Fixtures

/// A robot preset with the torque limit its planar controller must respect.
#[derive(Clone, Copy, Debug)]
pub(super) struct Preset {
    pub(super) name: &'static str,
    pub(super) params: WipParams<f64>,
    /// MiaPURE: the x-plane torque capacity of three 43.2 N m actuators (MODEL.md section 6,
    /// the smaller of the two planes); PIPTB: one actuator's peak.
    pub(super) max_torque_nm: f64,
}

pub(super) fn presets() -> [Preset; 3] {
    [
        Preset {
            name: "miapure_60kg",
            params: WipParams::miapure_60kg(),
            max_torque_nm: 83.9,
        },
        Preset {
            name: "miapure_unloaded",
            params: WipParams::miapure_unloaded(),
            max_torque_nm: 83.9,
        },
        Preset {
            name: "piptb",
            params: WipParams::piptb(),
            max_torque_nm: 43.2,
        },
    ]
}

pub(super) fn miapure() -> Preset {
    presets()[0]
}

/// LQR gains for a preset, designed by the core's synthesis (continuous LQR on the upright
/// linearisation, MODEL.md's weights Q = diag(100, 10, 1), R = 0.1).
pub(super) fn lqr_gains(preset: &Preset) -> LqrGains<f64> {
    LqrGains::for_wip(&wip(preset), preset.max_torque_nm).unwrap()
}

pub(super) fn wip(preset: &Preset) -> Wip<f64> {
    Wip::new(preset.params).unwrap()
}

pub(super) fn inner_gains(preset: &Preset) -> SpeedPiGains<f64> {
    SpeedPiGains::for_wip_ball_rate(
        &wip(preset),
        INNER_BANDWIDTH_RAD_PER_S,
        preset.max_torque_nm,
    )
    .unwrap()
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Kind {
    Lqr,
    PiPd,
    LqrPi,
}

/// A controller under test, driven at the inner rate.
pub(super) enum Controller {
    Lqr(LqrController<f64>),
    PiPd(PiPdController<f64>),
    LqrPi {
        outer: LqrPiOuter<f64>,
        inner: SpeedPi<f64>,
        command: SpeedCommand<f64>,
    },
}

impl Controller {
    pub(super) fn new(kind: Kind, preset: &Preset) -> Self {
        match kind {
            Kind::Lqr => Self::Lqr(LqrController::new(lqr_gains(preset)).unwrap()),
            Kind::PiPd => Self::PiPd(
                PiPdController::new(
                    PiPdGains::for_wip(&wip(preset), preset.max_torque_nm).unwrap(),
                )
                .unwrap(),
            ),
            Kind::LqrPi => {
                let inner = inner_gains(preset);
                let config = LqrPiOuterConfig::new(lqr_gains(preset), &inner).unwrap();
                Self::lqr_pi(preset, inner, config)
            }
        }
    }

    pub(super) fn lqr_pi(
        preset: &Preset,
        inner: SpeedPiGains<f64>,
        config: LqrPiOuterConfig<f64>,
    ) -> Self {
        Self::LqrPi {
            outer: LqrPiOuter::new(wip(preset), config).unwrap(),
            inner: SpeedPi::new(inner).unwrap(),
            command: SpeedCommand {
                speed_rad_per_s: 0.0,
                feedforward_torque_nm: 0.0,
            },
        }
    }

    /// The torque for the coming inner period. `outer_due` marks an outer-rate tick; the LQR
    /// and the PI-PD hold their torque between outer ticks.
    pub(super) fn tick(
        &mut self,
        s: &WipState<f64>,
        sc: &WipState<f64>,
        outer_due: bool,
        held: f64,
    ) -> f64 {
        let dt_outer = 1.0 / OUTER_HZ;
        match self {
            Self::Lqr(c) => {
                if outer_due {
                    c.step(s, sc, dt_outer).torque_nm
                } else {
                    held
                }
            }
            Self::PiPd(c) => {
                if outer_due {
                    c.step(s, sc, dt_outer).torque_nm
                } else {
                    held
                }
            }
            Self::LqrPi {
                outer,
                inner,
                command,
            } => {
                if outer_due {
                    let o = outer.step(s, sc, dt_outer);
                    *command = SpeedCommand {
                        speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                        feedforward_torque_nm: o.reference_torque_nm,
                    };
                }
                inner.step(s[BALL_RATE], command, 1.0 / INNER_HZ).torque_nm
            }
        }
    }
}

/// Friction on the relative (motor) joint, opposing `phi_dot - theta_dot`.
#[derive(Clone, Copy, Debug)]
pub(super) enum Friction {
    None,
    /// Smooth Coulomb friction `torque_nm tanh(w_rel / slip_rate_rad_per_s)`.
    Coulomb {
        torque_nm: f64,
        slip_rate_rad_per_s: f64,
    },
    /// Karnopp stick-slip: within `stick_rate_rad_per_s` of zero relative rate the joint sticks
    /// (friction cancels the net torque that would make it slip, up to `stiction_nm`); outside
    /// it slides against `coulomb_nm`.
    Karnopp {
        stiction_nm: f64,
        coulomb_nm: f64,
        stick_rate_rad_per_s: f64,
    },
}

pub(super) struct Plant {
    pub(super) wip: Wip<f64>,
    pub(super) friction: Friction,
    pub(super) state: WipState<f64>,
}

impl Plant {
    /// Friction torque on the relative joint with the motor applying `torque_nm`.
    pub(super) fn friction_nm(&self, s: &WipState<f64>, torque_nm: f64) -> f64 {
        match self.friction {
            Friction::None => 0.0,
            Friction::Coulomb {
                torque_nm,
                slip_rate_rad_per_s,
            } => torque_nm * ((s[BALL_RATE] - s[TILT_RATE]) / slip_rate_rad_per_s).tanh(),
            Friction::Karnopp {
                stiction_nm,
                coulomb_nm,
                stick_rate_rad_per_s,
            } => {
                let w_rel = s[BALL_RATE] - s[TILT_RATE];
                if w_rel.abs() > stick_rate_rad_per_s {
                    return coulomb_nm * w_rel.signum();
                }
                // The relative acceleration is affine in the net torque: find the friction
                // that holds it at zero, and stick if the joint can supply it.
                let rel_accel = |net: f64| {
                    let q = self.wip.accelerations(s, net);
                    q[1] - q[0]
                };
                let at_zero = rel_accel(0.0);
                let per_nm = rel_accel(1.0) - at_zero;
                let hold = torque_nm + at_zero / per_nm;
                hold.clamp(-stiction_nm, stiction_nm)
            }
        }
    }

    pub(super) fn step(&mut self, torque_nm: f64, dt_secs: f64) {
        let f = |x: &WipState<f64>| {
            self.wip
                .derivative(x, torque_nm - self.friction_nm(x, torque_nm))
        };
        self.state = rk4_step(f, &self.state, dt_secs);
    }
}

#[test]
pub(super) fn karnopp_friction_sticks_below_stiction_and_slips_above() {
    let preset = miapure();
    let plant = Plant {
        wip: wip(&preset),
        friction: Friction::Karnopp {
            stiction_nm: 6.0,
            coulomb_nm: 5.0,
            stick_rate_rad_per_s: 0.01,
        },
        state: Vector4::new(0.02, 0.0, 0.1, 0.1),
    };
    let rel_accel = |s: &WipState<f64>, tau: f64| {
        let d = plant.wip.derivative(s, tau - plant.friction_nm(s, tau));
        d[3] - d[2]
    };
    // Stuck (relative rate 0): a 2 N m motor torque does not make the joint slip.
    assert!(rel_accel(&plant.state, 2.0).abs() < 1e-9);
    // 20 N m exceeds the stiction: it slips.
    assert!(rel_accel(&plant.state, 20.0) > 1.0);
    // Sliding: the Coulomb level, against the motion.
    let sliding = Vector4::new(0.0, 0.0, 0.0, 1.0);
    assert_eq!(plant.friction_nm(&sliding, 0.0), 5.0);
}

/// One record per outer period.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sample {
    pub(super) t_secs: f64,
    pub(super) state: WipState<f64>,
    pub(super) command: WipState<f64>,
    pub(super) torque_nm: f64,
}

pub(super) struct Trace {
    pub(super) samples: Vec<Sample>,
    pub(super) ball_radius_m: f64,
    /// When the body passed 1.2 rad (the run stops there).
    pub(super) fell_at_secs: Option<f64>,
}

impl Trace {
    pub(super) fn speed_error_m_per_s(&self, s: &Sample) -> f64 {
        (s.state[BALL_RATE] - s.command[BALL_RATE]) * self.ball_radius_m
    }

    pub(super) fn between(&self, t0: f64, t1: f64) -> impl Iterator<Item = &Sample> {
        self.samples
            .iter()
            .filter(move |s| s.t_secs >= t0 && s.t_secs <= t1)
    }

    /// Mean speed error over `[t0, t1]` (m/s, signed).
    pub(super) fn mean_speed_error(&self, t0: f64, t1: f64) -> f64 {
        let (sum, n) = self.between(t0, t1).fold((0.0, 0), |(a, n), s| {
            (a + self.speed_error_m_per_s(s), n + 1)
        });
        sum / n as f64
    }

    /// Largest |speed error| over `[t0, t1]` (m/s).
    pub(super) fn max_speed_error(&self, t0: f64, t1: f64) -> f64 {
        self.between(t0, t1)
            .map(|s| self.speed_error_m_per_s(s).abs())
            .fold(0.0, f64::max)
    }

    /// Settle criterion: the time after which the robot stays within |theta| <= 0.5 deg,
    /// |theta_dot| <= 2 deg/s and |ball speed| <= 0.02 m/s (a regulation run to rest).
    /// `None` if it is outside the band at the end.
    pub(super) fn settle_time_secs(&self) -> Option<f64> {
        if self.fell_at_secs.is_some() {
            return None;
        }
        let deg = std::f64::consts::PI / 180.0;
        let inside = |s: &Sample| {
            s.state[TILT].abs() <= 0.5 * deg
                && s.state[TILT_RATE].abs() <= 2.0 * deg
                && (s.state[BALL_RATE] * self.ball_radius_m).abs() <= 0.02
        };
        let last_outside = self.samples.iter().rposition(|s| !inside(s));
        match last_outside {
            None => Some(0.0),
            Some(i) if i + 1 < self.samples.len() => Some(self.samples[i + 1].t_secs),
            Some(_) => None,
        }
    }

    pub(super) fn max_abs_tilt_rad(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.state[TILT].abs())
            .fold(0.0, f64::max)
    }

    pub(super) fn max_abs_torque_nm(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.torque_nm.abs())
            .fold(0.0, f64::max)
    }
}

/// Runs `controller` on the plant for `duration_secs` from `initial`, the command state
/// given by `command(t)`.
pub(super) fn simulate(
    preset: &Preset,
    controller: &mut Controller,
    friction: Friction,
    initial: WipState<f64>,
    command: impl Fn(f64) -> WipState<f64>,
    duration_secs: f64,
) -> Trace {
    let mut plant = Plant {
        wip: wip(preset),
        friction,
        state: initial,
    };
    let inner_dt = 1.0 / INNER_HZ;
    let plant_dt = inner_dt / PLANT_SUBSTEPS as f64;
    let steps = (duration_secs * INNER_HZ).round() as usize;
    let mut samples = Vec::with_capacity(steps / INNER_PER_OUTER + 1);
    let mut torque = 0.0;
    let mut sc = command(0.0);
    let mut fell_at_secs = None;
    for k in 0..steps {
        let t = k as f64 * inner_dt;
        let outer_due = k % INNER_PER_OUTER == 0;
        if outer_due {
            sc = command(t);
        }
        torque = controller.tick(&plant.state, &sc, outer_due, torque);
        assert!(torque.is_finite() && torque.abs() <= preset.max_torque_nm + 1e-9);
        if outer_due {
            samples.push(Sample {
                t_secs: t,
                state: plant.state,
                command: sc,
                torque_nm: torque,
            });
        }
        for _ in 0..PLANT_SUBSTEPS {
            plant.step(torque, plant_dt);
        }
        if plant.state[TILT].abs() > 1.2 || !plant.state[TILT].is_finite() {
            fell_at_secs = Some(t);
            break;
        }
    }
    Trace {
        samples,
        ball_radius_m: preset.params.ball_radius_m,
        fell_at_secs,
    }
}

/// A speed command: `speed_m_per_s(t)` as the ball rate, upright, no tilt rate.
pub(super) fn speed_command(
    r: f64,
    speed_m_per_s: impl Fn(f64) -> f64,
) -> impl Fn(f64) -> WipState<f64> {
    move |t| Vector4::new(0.0, 0.0, 0.0, speed_m_per_s(t) / r)
}

/// The paper's PIPTB profile without the braking phase: 0 -> 1 m/s in 2 s, hold.
pub(super) fn ramp_1m_per_s(t: f64) -> f64 {
    (t / 2.0).min(1.0)
}
