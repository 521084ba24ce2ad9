//! Minimum braking time in the 3D world (the paper's Sec. V, MiaPURE with 60 kg): the robot
//! accelerates slowly to the cruise speed along a heading, cruises, then follows the optimal
//! braking trajectory to rest in `T` ([`ballbot_trajopt`], the MiaPURE plane with the
//! actuator, traction and tilt limits) through the core's [`Command::Trajectory`]; the
//! paper's protocol starts at `T = 5 s` and cuts 0.5 s per success until failure
//! ([`braking_study`]), and a bisection refines the limit beyond the paper. The protocol is a
//! [`BrakingExperiment`] on the experiment driver ([`crate::studies::driver`]); every run
//! solves its trajectory from a cold start, so a run of the study at `T` is the run
//! [`braking_run`] gives at `T` without a warm start.
//!
//! A run succeeds when the world reports no failure (tilt, body touched the floor, sustained
//! slip, lift-off: [`ballbot_world::world::failure`]) and the robot is **at rest** from
//! `rest_within_secs` after `T` on for `rest_hold_secs`: horizontal ball speed at most
//! `rest_speed_m_per_s` and tilt from the vertical at most `rest_tilt_rad` at every physics
//! step of that window ([`BrakingParams`]).
//!
//! The controller is the core's cascaded LQR-PI designed from the robot, with the command
//! shaper's translation acceleration and jerk caps and its tilt command caps raised
//! ([`braking_controller_config`]): the trajectory, not the shaper, sets the deceleration.
//! The approach ramp is jerk-limited by its own profile, so the raised caps never bite there.
//!
//! **Tilt-acceleration feedforward.** A braking trajectory is not at equilibrium: its onset
//! tips the body back (`theta_ddot* < 0`), and its torque is the second row of the WIP
//! equations, `tau* = c(theta*) theta_ddot* + b phi_ddot*`, `c = m_U r l cos(theta) - I_W`
//! (4.25 against `b = 1.07` kg m^2 on MiaPURE). The core's controller feeds forward exactly
//! that for a [`Command::Trajectory`] (its tilt command is shifted by `tau* / k1`, with the
//! slopes of the interpolated rates), so the experiment sends the plan as it is
//! ([`TrajectoryFeedforward::Full`], the default). The ablation
//! [`TrajectoryFeedforward::Core`] removes the `c theta_ddot*` part (the core fed forward
//! only the equilibrium-lean torque `b phi_ddot*` before): the controller then asks about
//! 40 N m instead of the planned 8 N m in the first 10 ms of a 2 s braking from 1.4 m/s, and
//! the ball's forward kick lifts OW1 off at 180 deg. The samples in
//! [`BrakingSample::command_tilt_rad`] are the physical, unshifted tilt.

mod experiment;
mod fly;
mod study;

pub use experiment::{BrakingExperiment, braking_study};
pub use fly::{braking_run, braking_run_observed, fly_braking};
pub use study::{BrakingStudy, BrakingStudyParams};

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{
    AxisLimits, Command, JerkLimiter, Trajectory as CommandTrajectory, VelocityCommand,
};
use ballbot_core::{BallbotParams, WipParams, WipState};
use ballbot_trajopt::{
    BrakingProblem, BrakingSolution, Drive, InitialGuess, Limits, Method, SolveOptions,
    SolveStatus, Trajectory, TrajoptError,
};
use ballbot_world::rig::Happened;
use ballbot_world::world::failure::Failure;
use ballbot_world::world::params::WorldParams;
use ballbot_world::world::{StopRules, WorldError};

/// What can go wrong setting up a braking experiment (the outcome of a run is a
/// [`BrakingOutcome`], not an error).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BrakingError {
    /// The world or the controller rejected its parameters.
    #[error(transparent)]
    World(#[from] WorldError),
    /// The braking problem was malformed.
    #[error(transparent)]
    Trajopt(#[from] TrajoptError),
    /// An experiment parameter is out of range.
    #[error("invalid braking parameter `{field}`: {requirement}")]
    InvalidParameter {
        /// The field's name.
        field: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
    },
}

pub(crate) fn invalid(field: &'static str, requirement: &'static str) -> BrakingError {
    BrakingError::InvalidParameter { field, requirement }
}

/// What the trajectory command feeds forward (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, schemars::JsonSchema)]
#[schemars(rename_all = "snake_case")]
pub enum TrajectoryFeedforward {
    /// Ablation: the equilibrium-lean torque `b phi_ddot*` alone (what the core fed forward
    /// before it had the tilt-acceleration term): each sample's tilt is shifted so that the
    /// core's `c(theta) theta_ddot* / k1` shift cancels.
    Core,
    /// The trajectory's full torque `c(theta*) theta_ddot* + b phi_ddot*`: the plan as it is,
    /// the core feeds forward both terms.
    #[default]
    Full,
}

impl TrajectoryFeedforward {
    /// `core` or `full`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Core => "core",
            Self::Full => "full",
        }
    }
}

/// One braking run's protocol and success criterion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrakingParams {
    /// Cruise speed before braking (m/s). Default 1.4 (the paper).
    pub cruise_speed_m_per_s: f64,
    /// Acceleration of the approach ramp (m/s^2). Default 0.5 ("slow": half the core
    /// shaper's default cap; the paper's PIPTB protocol also ramps at 0.5 m/s^2).
    pub approach_accel_m_per_s2: f64,
    /// Jerk of the approach ramp (m/s^3). Default 2 (the core shaper's default).
    pub approach_jerk_m_per_s3: f64,
    /// Standing still before the ramp starts (s). Default 0.5.
    pub settle_secs: f64,
    /// Cruising at the cruise speed before braking (s). Default 2.5 (the LQR-PI's slowest
    /// closed-loop pole, -2.06 rad/s, has decayed to below 1 %).
    pub cruise_secs: f64,
    /// The robot must be at rest from this long after the braking time on (s). Default 0.5.
    pub rest_within_secs: f64,
    /// ... and stay at rest for this long (s). Default 1.0.
    pub rest_hold_secs: f64,
    /// At rest: horizontal ball speed at most this (m/s). Default 0.1.
    pub rest_speed_m_per_s: f64,
    /// At rest: tilt from the vertical at most this (rad). Default 3 deg.
    pub rest_tilt_rad: f64,
    /// Tilt bound of the braking trajectory (rad). Default 15 deg: 5 deg clear of the core
    /// safety supervisor's 20 deg tilt limit.
    pub trajectory_tilt_limit_rad: f64,
    /// Collocation intervals of the braking trajectory. Default 100 (Hermite-Simpson).
    pub intervals: usize,
    /// Sample period of the returned series (s). Default 0.01.
    pub sample_every_secs: f64,
    /// What the trajectory command feeds forward. Default [`TrajectoryFeedforward::Full`].
    pub feedforward: TrajectoryFeedforward,
    /// Normal-force margin of the trajectory's traction cones (N): the plan keeps
    /// `|F_i| <= mu (N_i - margin)` at every knot ([`Limits::normal_force_margin_n`]), so
    /// every planned normal force is at least the margin. Default 0 (the plain cone).
    pub normal_force_margin_n: f64,
    /// The world's stop rules during the run. Default all on, the protocol as it always ran;
    /// `world_braking.lift_off_rule_relaxed` runs the study with the lift-off rule off.
    pub stop_rules: StopRules,
}

impl Default for BrakingParams {
    fn default() -> Self {
        Self {
            cruise_speed_m_per_s: 1.4,
            approach_accel_m_per_s2: 0.5,
            approach_jerk_m_per_s3: 2.0,
            settle_secs: 0.5,
            cruise_secs: 2.5,
            rest_within_secs: 0.5,
            rest_hold_secs: 1.0,
            rest_speed_m_per_s: 0.1,
            rest_tilt_rad: 3.0_f64.to_radians(),
            trajectory_tilt_limit_rad: 15.0_f64.to_radians(),
            intervals: 100,
            sample_every_secs: 0.01,
            feedforward: TrajectoryFeedforward::Full,
            normal_force_margin_n: 0.0,
            stop_rules: StopRules::all(),
        }
    }
}

impl BrakingParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), BrakingError> {
        let positive = |v: f64, field| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(invalid(field, "must be finite and > 0"))
            }
        };
        let non_negative = |v: f64, field| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(invalid(field, "must be finite and >= 0"))
            }
        };
        positive(self.cruise_speed_m_per_s, "cruise_speed_m_per_s")?;
        positive(self.approach_accel_m_per_s2, "approach_accel_m_per_s2")?;
        positive(self.approach_jerk_m_per_s3, "approach_jerk_m_per_s3")?;
        non_negative(self.settle_secs, "settle_secs")?;
        non_negative(self.cruise_secs, "cruise_secs")?;
        non_negative(self.rest_within_secs, "rest_within_secs")?;
        positive(self.rest_hold_secs, "rest_hold_secs")?;
        positive(self.rest_speed_m_per_s, "rest_speed_m_per_s")?;
        positive(self.rest_tilt_rad, "rest_tilt_rad")?;
        positive(self.trajectory_tilt_limit_rad, "trajectory_tilt_limit_rad")?;
        positive(self.sample_every_secs, "sample_every_secs")?;
        non_negative(self.normal_force_margin_n, "normal_force_margin_n")?;
        if self.intervals < 2 {
            return Err(invalid("intervals", "must be >= 2"));
        }
        Ok(())
    }

    /// Duration of the jerk-limited approach ramp from rest to the cruise speed (s).
    ///
    /// ```
    /// use ballbot_studies::studies::world_braking::BrakingParams;
    /// // 1.4 m/s at 0.5 m/s^2 with a 2 m/s^3 jerk: 1.4 / 0.5 + 0.5 / 2 = 3.05 s.
    /// approx::assert_relative_eq!(BrakingParams::default().approach_secs(), 3.05);
    /// ```
    pub fn approach_secs(&self) -> f64 {
        let (v, a, j) = (
            self.cruise_speed_m_per_s,
            self.approach_accel_m_per_s2,
            self.approach_jerk_m_per_s3,
        );
        if v >= a * a / j {
            v / a + a / j
        } else {
            2.0 * (v / j).sqrt()
        }
    }
}

/// The controller used for braking: the core's design for `robot`, with the command shaper's
/// translation acceleration cap raised to 20 m/s^2, its jerk cap to 500 m/s^3, the tilt
/// command cap to 0.5 rad and the tilt-rate command cap to 5 rad/s, so that a braking
/// trajectory passes the shaper unchanged (its own limits come from the trajectory
/// optimisation). The speed cap (2 m/s) and everything else stay the core's defaults.
pub fn braking_controller_config(
    robot: &BallbotParams<f64>,
) -> Result<BallbotControllerConfig<f64>, WorldError> {
    let mut config = BallbotControllerConfig::paper(robot)?;
    config.shaping.translation.max_rate_per_s = 20.0;
    config.shaping.translation.max_jerk_per_s2 = 500.0;
    config.shaping.max_tilt_command_rad = 0.5;
    config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
    Ok(config)
}

/// The plane model for travel at `heading_rad`: the sagittal plane for headings nearer the
/// body x axis, the frontal one otherwise (identical for MiaPURE).
pub(crate) fn plane_for_heading(robot: &BallbotParams<f64>, heading_rad: f64) -> WipParams<f64> {
    if heading_rad.cos().abs() >= heading_rad.sin().abs() {
        robot.sagittal
    } else {
        robot.frontal
    }
}

/// The braking problem of a run: `robot`'s plane along `heading_deg` from the cruise speed to
/// rest in `duration_secs`, Hermite-Simpson, torques pinned to 0 at both ends (a command that
/// starts and ends without a step), with the actuator limits of all three omniwheels, their
/// traction cones (`mu N`, or `mu (N - margin)` with [`BrakingParams::normal_force_margin_n`])
/// and the tilt bound.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_studies::studies::world_braking::{BrakingParams, braking_problem};
/// let robot = BallbotParams::miapure_60kg();
/// let problem = braking_problem(&robot, &BrakingParams::default(), 180.0, 2.0);
/// let plan = problem.solve()?;
/// assert!(plan.is_solved());
/// // Non-minimum phase: the body leans back (about 6.8 deg) and the ball first speeds up.
/// assert!((plan.peak_tilt_rad().to_degrees() - 6.8).abs() < 0.2);
/// # Ok::<(), ballbot_trajopt::TrajoptError>(())
/// ```
pub fn braking_problem(
    robot: &BallbotParams<f64>,
    params: &BrakingParams,
    heading_deg: f64,
    duration_secs: f64,
) -> BrakingProblem {
    let heading_rad = heading_deg.to_radians();
    BrakingProblem {
        plane: plane_for_heading(robot, heading_rad),
        initial_speed_m_per_s: params.cruise_speed_m_per_s,
        duration_secs,
        intervals: params.intervals,
        method: Method::HermiteSimpson,
        zero_end_torques: true,
        limits: Limits {
            tilt_rad: Some(params.trajectory_tilt_limit_rad),
            drive: Some(Drive::Omniwheels {
                params: robot.drivetrain,
                heading_rad,
            }),
            traction: true,
            normal_force_margin_n: params.normal_force_margin_n,
            ..Limits::none()
        },
    }
}

/// A failed run goes on for this long after the failure (s): its samples show what followed;
/// its peaks and outcome are those at the failure.
pub const AFTER_FAILURE_SECS: f64 = 0.25;

/// One sample of a braking run.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, schemars::JsonSchema)]
pub struct BrakingSample {
    /// Time since the start of the run (s).
    pub time_secs: f64,
    /// Commanded speed along the heading (m/s): the approach ramp, the cruise speed, then the
    /// trajectory's `r phi_dot`.
    pub command_m_per_s: f64,
    /// Ball speed along the heading, in the body's yaw frame (m/s).
    pub speed_m_per_s: f64,
    /// Commanded tilt in the plane of travel (rad; negative leans back).
    pub command_tilt_rad: f64,
    /// Body tilt in the plane of travel (rad; negative leans back against the heading).
    pub tilt_rad: f64,
    /// Friction-cone utilisation `|F_i| / (mu N_i)` of each omniwheel.
    pub cone_utilisation: [f64; 3],
    /// Normal force of each omniwheel (N).
    pub normal_force_n: [f64; 3],
    /// Torque of each actuator over its bound at the present wheel speed, in the direction of
    /// the torque (1: saturated).
    pub actuator_utilisation: [f64; 3],
}

/// Extremes of the braking phase (from the start of braking to the end of the run).
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, schemars::JsonSchema)]
pub struct BrakingPeaks {
    /// Largest friction-cone utilisation of each omniwheel.
    pub cone_utilisation: [f64; 3],
    /// Smallest normal force of each omniwheel (N).
    pub min_normal_force_n: [f64; 3],
    /// Largest actuator utilisation of each omniwheel (see
    /// [`BrakingSample::actuator_utilisation`]).
    pub actuator_utilisation: [f64; 3],
    /// Largest tilt from the vertical (rad).
    pub tilt_rad: f64,
    /// Largest difference between the commanded and the actual speed along the heading (m/s).
    pub speed_error_m_per_s: f64,
    /// Time any wheel spent slipping faster than the failure threshold (s).
    pub slip_secs: f64,
}

/// How a braking run ended.
#[derive(Clone, Copy, Debug, PartialEq, schemars::JsonSchema)]
#[schemars(rename_all = "snake_case")]
pub enum BrakingOutcome {
    /// At rest within the tolerance from `rest_within_secs` after `T` on, no failure.
    Stopped {
        /// Largest horizontal ball speed in the rest window (m/s).
        rest_speed_m_per_s: f64,
    },
    /// The trajectory optimisation found no braking trajectory for `T` under the limits:
    /// the plan, not the world, failed.
    NoTrajectory {
        /// How the solve ended.
        status: SolveStatus,
    },
    /// The world detected a failure (tilt, floor contact, sustained slip, lift-off).
    Failed(Failure),
    /// No failure, but not at rest in the rest window.
    NotAtRest {
        /// Largest horizontal ball speed in the rest window (m/s).
        rest_speed_m_per_s: f64,
        /// Largest tilt from the vertical in the rest window (rad).
        rest_tilt_rad: f64,
    },
}

impl BrakingOutcome {
    /// Whether the run succeeded.
    pub fn is_success(&self) -> bool {
        matches!(self, Self::Stopped { .. })
    }

    /// A short label: `stopped`, `no_trajectory`, `failed`, `not_at_rest`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Stopped { .. } => "stopped",
            Self::NoTrajectory { .. } => "no_trajectory",
            Self::Failed(_) => "failed",
            Self::NotAtRest { .. } => "not_at_rest",
        }
    }
}

/// One braking run.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingRun {
    /// Heading of travel in the body frame (deg; 0 towards OW1).
    pub heading_deg: f64,
    /// Braking time `T` commanded (s).
    pub duration_secs: f64,
    /// How it ended.
    pub outcome: BrakingOutcome,
    /// Time braking started, since the start of the run (s).
    pub brake_start_secs: f64,
    /// The braking trajectory flown (`None` if none was found).
    pub plan: Option<Trajectory>,
    /// The planned trajectory's peak tilt (rad); `None` without a trajectory.
    pub plan_peak_tilt_rad: Option<f64>,
    /// The planned trajectory's cost `integral tau^2 dt` (N^2 m^2 s) when solved by
    /// [`braking_run`].
    pub plan_cost_n2m2s: Option<f64>,
    /// Extremes of the braking phase.
    pub peaks: BrakingPeaks,
    /// Samples every `sample_every_secs` (empty without a trajectory).
    pub samples: Vec<BrakingSample>,
    /// FNV-1a hash of every step's telemetry (bit-identical runs have equal hashes).
    pub telemetry_hash: u64,
    /// How the flown run ended (fell, ended by a stop rule, at rest...) and its contact
    /// events, whatever the stop rules; `None` when no trajectory was flown.
    pub happened: Option<Happened>,
}

/// Solves the braking trajectory of a run (warm-started from `warm` if given).
pub fn plan_braking(
    robot: &BallbotParams<f64>,
    params: &BrakingParams,
    heading_deg: f64,
    duration_secs: f64,
    warm: Option<&Trajectory>,
) -> Result<BrakingSolution, BrakingError> {
    let problem = braking_problem(robot, params, heading_deg, duration_secs);
    let options = SolveOptions {
        initial_guess: warm.map_or(InitialGuess::LinearQuadratic, |t| {
            InitialGuess::Trajectory(t.clone())
        }),
        ..SolveOptions::default()
    };
    Ok(ballbot_trajopt::solve(&problem, &options)?)
}
