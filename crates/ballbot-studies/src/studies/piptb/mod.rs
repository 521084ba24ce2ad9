//! The PIPTB controller comparison (paper Sec. IV-C, MODEL.md section 7): a study on the
//! planar physics; its JSON, tables and figures are in [`crate::report::piptb`].
//!
//! Command `phi_dot_c = (v / T_a) t / r` for `T_a = 2 s` (0 to 1 m/s), hold `v / r` for 2 s,
//! then track the braking reference (state `s_c = s*(t)`) to rest in 1.4 s, then hold rest for
//! a settling second. Every controller runs the same seeded trials (trial `k` uses seed
//! `base_seed + k` for all three: the same noise samples, a paired comparison).
//!
//! Metrics, all from the true (simulated) state and the torque the actuator delivered:
//!
//! - `j_p`: braking effort `integral_{t2}^{t3} tau^2 dt` over the braking phase
//!   (N^2 m^2 s; times 1e6 for the paper's N^2 mm^2 s), integrated at the plant rate;
//! - `stopped`: `|r phi_dot(t3)| <= stop_speed` (default 0.05 m/s) at the end of the braking
//!   phase, and the run did not fall;
//!
//! Two readings of `t3` (the end of "the measured braking phase"): the fixed `t2 + 1.4 s`
//! ([`run`]'s report, the summary's `piptb`) and "until stopped" ([`stop`], the summary's
//! `piptb_until_stopped`): when the speed has settled in the stop band, so that a controller
//! that brakes late is charged for the torque it spends after 1.4 s.
//!
//! - `speed_rmse`: RMS of `r (phi_dot - phi_dot_c)` over the braking phase, sampled at the
//!   main controller's ticks (m/s);
//! - `torque_jitter_nm`: RMS of the change of the delivered torque between successive ticks of
//!   the main controller over the braking phase (N m): zero for a smooth torque, large for a
//!   torque that chatters (stick-slip limit cycles, noise amplification).

pub mod stop;
mod trial;

pub use stop::{StopCriterion, stop_time};
pub use trial::{ControllerResult, TrialResult, TrialSeries, run_trial};

use super::planar_braking::BrakingTrajectory;
use ballbot_core::PlanarRobotParams;
use ballbot_core::wip::{BALL_RATE, TILT, TILT_RATE};
use ballbot_log::LogError;
use ballbot_trajopt::BrakingProblem;
use ballbot_world::planar::{
    CommandProfile, ControllerKind, ControllerSettings, PlanarCommand, PlanarError, SensorParams,
    SimConfig, TransmissionFriction,
};
use std::path::Path;

/// What the paper reports for one controller (Sec. IV-C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperResult {
    /// The controller.
    pub kind: ControllerKind,
    /// Braking effort, N^2 mm^2 s (mean, std), where the paper gives one.
    pub j_p_n2mm2s: Option<(f64, f64)>,
    /// Whether it stopped within 1.4 s.
    pub stopped: Option<bool>,
}

/// The paper's results. It gives no number for the LQR: it braked in time but jittered.
pub const PAPER: [PaperResult; 3] = [
    PaperResult {
        kind: ControllerKind::Lqr,
        j_p_n2mm2s: None,
        stopped: Some(true),
    },
    PaperResult {
        kind: ControllerKind::PiPd,
        j_p_n2mm2s: Some((1.2e6, 0.3e6)),
        stopped: Some(false),
    },
    PaperResult {
        kind: ControllerKind::LqrPi,
        j_p_n2mm2s: Some((8.2e5, 0.2e5)),
        stopped: Some(true),
    },
];

/// Errors of an experiment.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// The simulator's inputs are invalid.
    #[error(transparent)]
    Planar(#[from] PlanarError),
    /// Writing a log failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// No braking reference could be computed.
    #[error("braking reference: {0}")]
    Braking(String),
}

/// Settings of the PIPTB experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct PiptbSettings {
    /// The robot.
    pub robot: PlanarRobotParams<f64>,
    /// Its transmission friction.
    pub friction: TransmissionFriction,
    /// Its sensors.
    pub sensors: SensorParams,
    /// Rates and delay.
    pub sim: SimConfig,
    /// Cruise speed `v` (m/s). Paper: 1.
    pub cruise_speed_m_per_s: f64,
    /// Acceleration ramp `T_a` (s). Paper: 2.
    pub accel_secs: f64,
    /// Cruise hold (s). Paper: 2.
    pub hold_secs: f64,
    /// Braking time (s). Paper: 1.4.
    pub brake_secs: f64,
    /// Rest held after braking (s), to see whether the robot stays stopped.
    pub settle_secs: f64,
    /// Trials per controller. Paper: 3.
    pub trials: usize,
    /// Seed of trial 0; trial `k` uses `base_seed + k`.
    pub base_seed: u64,
    /// Speed below which the robot counts as stopped (m/s).
    pub stop_speed_m_per_s: f64,
    /// Until-stopped reading: the speed must stay below `stop_speed_m_per_s` this long (s).
    /// Default [`StopCriterion::DEFAULT_HOLD_SECS`] (0.2 s, see [`stop`]).
    pub stop_hold_secs: f64,
}

impl PiptbSettings {
    /// The paper's protocol on the PIPTB preset with its transmission stiction and sensors
    /// ([`TransmissionFriction::piptb`], [`SensorParams::piptb`]), 3 trials.
    pub fn paper() -> Self {
        Self {
            robot: PlanarRobotParams::piptb(),
            friction: TransmissionFriction::piptb(),
            sensors: SensorParams::piptb(),
            sim: SimConfig::default(),
            cruise_speed_m_per_s: 1.0,
            accel_secs: 2.0,
            hold_secs: 2.0,
            brake_secs: 1.4,
            settle_secs: 1.0,
            trials: 3,
            base_seed: 1,
            stop_speed_m_per_s: 0.05,
            stop_hold_secs: StopCriterion::DEFAULT_HOLD_SECS,
        }
    }

    /// The CI variant: the same protocol, one trial per controller, a shorter hold (1 s) and
    /// settle (0.3 s).
    pub fn quick() -> Self {
        Self {
            hold_secs: 1.0,
            settle_secs: 0.3,
            trials: 1,
            ..Self::paper()
        }
    }

    /// Start of the braking phase `t2` (s).
    pub fn brake_start_secs(&self) -> f64 {
        self.accel_secs + self.hold_secs
    }

    /// End of the braking phase `t3` (s).
    pub fn brake_end_secs(&self) -> f64 {
        self.brake_start_secs() + self.brake_secs
    }

    /// The until-stopped reading's criterion: `stop_speed_m_per_s` held `stop_hold_secs`.
    pub fn stop_criterion(&self) -> StopCriterion {
        StopCriterion {
            speed_band_m_per_s: self.stop_speed_m_per_s,
            hold_secs: self.stop_hold_secs,
        }
    }

    /// Total simulated time per trial (s).
    pub fn duration_secs(&self) -> f64 {
        self.brake_end_secs() + self.settle_secs
    }
}

/// The command of the experiment as a function of time.
#[derive(Clone, Debug)]
pub struct PiptbProfile {
    radius_m: f64,
    speed_m_per_s: f64,
    accel_secs: f64,
    brake_start_secs: f64,
    brake: BrakingTrajectory,
}

impl PiptbProfile {
    /// The profile of `settings`, braking along `brake`.
    pub fn new(settings: &PiptbSettings, brake: BrakingTrajectory) -> Self {
        Self {
            radius_m: settings.robot.plane.ball_radius_m,
            speed_m_per_s: settings.cruise_speed_m_per_s,
            accel_secs: settings.accel_secs,
            brake_start_secs: settings.brake_start_secs(),
            brake,
        }
    }
}

impl CommandProfile for PiptbProfile {
    fn command(&self, t: f64) -> PlanarCommand {
        let cruise_rate = self.speed_m_per_s / self.radius_m;
        if t < self.accel_secs {
            PlanarCommand {
                ball_rate_rad_per_s: cruise_rate * t / self.accel_secs,
                ..PlanarCommand::default()
            }
        } else if t < self.brake_start_secs {
            PlanarCommand {
                ball_rate_rad_per_s: cruise_rate,
                ..PlanarCommand::default()
            }
        } else if t < self.brake_start_secs + self.brake.duration_secs() {
            let s = self.brake.state_at(t - self.brake_start_secs);
            PlanarCommand {
                tilt_rad: s[TILT],
                tilt_rate_rad_per_s: s[TILT_RATE],
                ball_rate_rad_per_s: s[BALL_RATE],
            }
        } else {
            PlanarCommand::default()
        }
    }
}

/// The braking reference as the summary reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ReferenceSummary {
    /// How it was computed (`nonlinear_optimum` or `linear_quadratic`).
    pub source: super::planar_braking::BrakingSource,
    /// Its own effort `integral tau^2` (N^2 m^2 s): the lower bound a perfect tracker of a
    /// frictionless plant would reach.
    pub effort_n2m2s: f64,
    /// Its largest tilt (rad).
    pub peak_tilt_rad: f64,
    /// Braking time (s).
    pub duration_secs: f64,
}

/// The whole experiment's result.
#[derive(Clone, Debug, PartialEq)]
pub struct PiptbReport {
    /// Per controller, in the order LQR, PI-PD, LQR-PI.
    pub controllers: Vec<ControllerResult>,
    /// The braking reference.
    pub reference: ReferenceSummary,
    /// The settings used.
    pub settings: PiptbSettings,
    /// `None`: the fixed window `[t2, t2 + brake_secs]`; the criterion of the until-stopped
    /// reading ([`PiptbReport::until_stopped`]) otherwise.
    pub stop: Option<StopCriterion>,
}

/// Runs the experiment: every controller of `kinds` (with its default settings) on
/// `settings.trials` seeded trials tracking `brake`. With `log_dir`, each trial writes
/// `log_dir/piptb_<controller>_trial<k>.mcap`. `progress` is called after every trial.
pub fn run(
    settings: &PiptbSettings,
    brake: BrakingTrajectory,
    kinds: &[ControllerKind],
    log_dir: Option<&Path>,
    progress: &mut dyn FnMut(ControllerKind, &TrialResult),
) -> Result<PiptbReport, ExperimentError> {
    let reference = ReferenceSummary {
        source: brake.source(),
        effort_n2m2s: brake.effort_n2m2s(),
        peak_tilt_rad: brake.peak_tilt_rad(),
        duration_secs: brake.duration_secs(),
    };
    let profile = PiptbProfile::new(settings, brake);
    let mut controllers = Vec::new();
    for &kind in kinds {
        let controller = ControllerSettings::new(kind);
        let mut trials = Vec::new();
        for k in 0..settings.trials {
            let seed = settings.base_seed.wrapping_add(k as u64);
            let path = log_dir.map(|d| d.join(format!("piptb_{}_trial{}.mcap", kind.key(), k)));
            let trial = run_trial(settings, &profile, &controller, seed, path.as_deref())?;
            progress(kind, &trial);
            trials.push(trial);
        }
        controllers.push(ControllerResult::new(kind, trials));
    }
    Ok(PiptbReport {
        controllers,
        reference,
        settings: settings.clone(),
        stop: None,
    })
}

/// The braking reference for `settings`: the nonlinear minimum-effort optimum of the
/// trajectory optimiser ([`ballbot_trajopt::BrakingProblem`], Hermite-Simpson, 100 intervals,
/// free end torques, no path limits: the PIPTB needs under 2 N m of its 43.2), sampled every
/// millisecond. Should the solve not converge, the linear-quadratic optimum of the upright
/// linearisation stands in, and the summary's `reference.source` says so.
pub fn braking_reference(settings: &PiptbSettings) -> Result<BrakingTrajectory, ExperimentError> {
    let problem = BrakingProblem {
        plane: settings.robot.plane,
        initial_speed_m_per_s: settings.cruise_speed_m_per_s,
        duration_secs: settings.brake_secs,
        ..BrakingProblem::piptb()
    };
    if let Ok(solution) = problem.solve()
        && solution.is_solved()
        && let Some(t) = BrakingTrajectory::from_optimum(&solution.trajectory, 1e-3)
    {
        return Ok(t);
    }
    let wip = ballbot_core::Wip::new(settings.robot.plane).map_err(PlanarError::from)?;
    BrakingTrajectory::linear_quadratic(
        &wip,
        settings.cruise_speed_m_per_s,
        settings.brake_secs,
        1e-3,
    )
    .ok_or_else(|| ExperimentError::Braking("the linear-quadratic problem is singular".into()))
}

/// One variant of the ablation: the paper's settings with some imperfections switched off.
#[derive(Clone, Debug, PartialEq)]
pub struct AblationVariant {
    /// Short name: `ideal`, `noise_only`, `friction_only`, `friction_and_noise`.
    pub name: &'static str,
    /// The result.
    pub report: PiptbReport,
}

/// Runs the experiment (no logs) four times, to separate the effects of transmission friction
/// and sensor noise: ideal sensors without friction, noise only, friction only, and both
/// (`settings` as given). Same seeds and reference throughout.
pub fn ablation(
    settings: &PiptbSettings,
    brake: &BrakingTrajectory,
) -> Result<Vec<AblationVariant>, ExperimentError> {
    let ideal = SensorParams::ideal();
    let none = TransmissionFriction::none();
    let variants = [
        ("ideal", none, ideal),
        ("noise_only", none, settings.sensors),
        ("friction_only", settings.friction, ideal),
        ("friction_and_noise", settings.friction, settings.sensors),
    ];
    variants
        .into_iter()
        .map(|(name, friction, sensors)| {
            let s = PiptbSettings {
                friction,
                sensors,
                ..settings.clone()
            };
            let report = run(
                &s,
                brake.clone(),
                &ControllerKind::ALL,
                None,
                &mut |_, _| {},
            )?;
            Ok(AblationVariant { name, report })
        })
        .collect()
}
