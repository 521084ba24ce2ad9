//! Minimum braking time in the 3D world (the paper's Sec. V, MiaPURE with 60 kg): the robot
//! accelerates slowly to the cruise speed along a heading, cruises, then follows the optimal
//! braking trajectory to rest in `T` ([`crate::trajopt`], the MiaPURE plane with the
//! actuator, traction and tilt limits) through the core's [`Command::Trajectory`]; the
//! paper's protocol starts at `T = 5 s` and cuts 0.5 s per success until failure
//! ([`braking_study`]), and a bisection refines the limit beyond the paper.
//!
//! A run succeeds when the world reports no failure (tilt, chassis on the floor, sustained
//! slip, lift-off: [`crate::world::failure`]) and the robot is **at rest** from
//! `rest_within_s` after `T` on for `rest_hold_s`: horizontal ball speed at most
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

use super::WorldError;
use super::closed_loop::CoreLoop;
use super::failure::{Failure, tilt_from_vertical_rad};
use super::params::WorldParams;
use super::telemetry::StepTelemetry;
use crate::trajopt::{
    BrakingProblem, BrakingSolution, Drive, InitialGuess, Limits, Method, SolveOptions,
    SolveStatus, Trajectory, TrajoptError,
};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{
    AxisLimits, Command, JerkLimiter, Trajectory as CommandTrajectory, VelocityCommand,
};
use ballbot_core::{BallbotParams, WipParams, WipState};
use nalgebra::{Rotation3, Vector3};

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

fn invalid(field: &'static str, requirement: &'static str) -> BrakingError {
    BrakingError::InvalidParameter { field, requirement }
}

/// What the trajectory command feeds forward (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
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
    pub settle_s: f64,
    /// Cruising at the cruise speed before braking (s). Default 2.5 (the LQR-PI's slowest
    /// closed-loop pole, -2.06 rad/s, has decayed to below 1 %).
    pub cruise_s: f64,
    /// The robot must be at rest from this long after the braking time on (s). Default 0.5.
    pub rest_within_s: f64,
    /// ... and stay at rest for this long (s). Default 1.0.
    pub rest_hold_s: f64,
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
    pub sample_every_s: f64,
    /// What the trajectory command feeds forward. Default [`TrajectoryFeedforward::Full`].
    pub feedforward: TrajectoryFeedforward,
}

impl Default for BrakingParams {
    fn default() -> Self {
        Self {
            cruise_speed_m_per_s: 1.4,
            approach_accel_m_per_s2: 0.5,
            approach_jerk_m_per_s3: 2.0,
            settle_s: 0.5,
            cruise_s: 2.5,
            rest_within_s: 0.5,
            rest_hold_s: 1.0,
            rest_speed_m_per_s: 0.1,
            rest_tilt_rad: 3.0_f64.to_radians(),
            trajectory_tilt_limit_rad: 15.0_f64.to_radians(),
            intervals: 100,
            sample_every_s: 0.01,
            feedforward: TrajectoryFeedforward::Full,
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
        non_negative(self.settle_s, "settle_s")?;
        non_negative(self.cruise_s, "cruise_s")?;
        non_negative(self.rest_within_s, "rest_within_s")?;
        positive(self.rest_hold_s, "rest_hold_s")?;
        positive(self.rest_speed_m_per_s, "rest_speed_m_per_s")?;
        positive(self.rest_tilt_rad, "rest_tilt_rad")?;
        positive(self.trajectory_tilt_limit_rad, "trajectory_tilt_limit_rad")?;
        positive(self.sample_every_s, "sample_every_s")?;
        if self.intervals < 2 {
            return Err(invalid("intervals", "must be >= 2"));
        }
        Ok(())
    }

    /// Duration of the jerk-limited approach ramp from rest to the cruise speed (s).
    ///
    /// ```
    /// use ballbot_sim::world::braking::BrakingParams;
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
    let mut config = BallbotControllerConfig::design(robot)?;
    config.shaping.translation.max_rate_per_s = 20.0;
    config.shaping.translation.max_jerk_per_s2 = 500.0;
    config.shaping.max_tilt_command_rad = 0.5;
    config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
    Ok(config)
}

/// The plane model for travel at `heading_rad`: the sagittal plane for headings nearer the
/// body x axis, the frontal one otherwise (identical for MiaPURE).
fn plane_for_heading(robot: &BallbotParams<f64>, heading_rad: f64) -> WipParams<f64> {
    if heading_rad.cos().abs() >= heading_rad.sin().abs() {
        robot.sagittal
    } else {
        robot.frontal
    }
}

/// The braking problem of a run: `robot`'s plane along `heading_deg` from the cruise speed to
/// rest in `duration_s`, Hermite-Simpson, torques pinned to 0 at both ends (a command that
/// starts and ends without a step), with the actuator limits of all three omniwheels, their
/// traction cones (`mu N`) and the tilt bound.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_sim::world::braking::{BrakingParams, braking_problem};
/// let robot = BallbotParams::miapure_60kg();
/// let problem = braking_problem(&robot, &BrakingParams::default(), 180.0, 2.0);
/// let plan = problem.solve()?;
/// assert!(plan.is_solved());
/// // Non-minimum phase: the body leans back (about 6.8 deg) and the ball first speeds up.
/// assert!((plan.peak_tilt_rad().to_degrees() - 6.8).abs() < 0.2);
/// # Ok::<(), ballbot_sim::trajopt::TrajoptError>(())
/// ```
pub fn braking_problem(
    robot: &BallbotParams<f64>,
    params: &BrakingParams,
    heading_deg: f64,
    duration_s: f64,
) -> BrakingProblem {
    let heading_rad = heading_deg.to_radians();
    BrakingProblem {
        plane: plane_for_heading(robot, heading_rad),
        initial_speed_m_per_s: params.cruise_speed_m_per_s,
        duration_secs: duration_s,
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
            ..Limits::none()
        },
    }
}

/// A failed run goes on for this long after the failure (s): its samples show what followed;
/// its peaks and outcome are those at the failure.
pub const AFTER_FAILURE_S: f64 = 0.25;

/// One sample of a braking run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrakingSample {
    /// Time since the start of the run (s).
    pub time_s: f64,
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
#[derive(Clone, Copy, Debug, PartialEq, Default)]
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
    pub slip_s: f64,
}

/// How a braking run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BrakingOutcome {
    /// At rest within the tolerance from `rest_within_s` after `T` on, no failure.
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
    pub duration_s: f64,
    /// How it ended.
    pub outcome: BrakingOutcome,
    /// Time braking started, since the start of the run (s).
    pub brake_start_s: f64,
    /// The braking trajectory flown (`None` if none was found).
    pub plan: Option<Trajectory>,
    /// The planned trajectory's peak tilt (rad); `None` without a trajectory.
    pub plan_peak_tilt_rad: Option<f64>,
    /// The planned trajectory's cost `integral tau^2 dt` (N^2 m^2 s) when solved by
    /// [`braking_run`].
    pub plan_cost_n2m2s: Option<f64>,
    /// Extremes of the braking phase.
    pub peaks: BrakingPeaks,
    /// Samples every `sample_every_s` (empty without a trajectory).
    pub samples: Vec<BrakingSample>,
    /// FNV-1a hash of every step's telemetry (bit-identical runs have equal hashes).
    pub telemetry_hash: u64,
}

/// Solves the braking trajectory of a run (warm-started from `warm` if given).
pub fn plan_braking(
    robot: &BallbotParams<f64>,
    params: &BrakingParams,
    heading_deg: f64,
    duration_s: f64,
    warm: Option<&Trajectory>,
) -> Result<BrakingSolution, BrakingError> {
    let problem = braking_problem(robot, params, heading_deg, duration_s);
    let options = SolveOptions {
        initial_guess: warm.map_or(InitialGuess::LinearQuadratic, |t| {
            InitialGuess::Trajectory(t.clone())
        }),
        ..SolveOptions::default()
    };
    Ok(crate::trajopt::solve(&problem, &options)?)
}

/// `samples` (period `period_s`) linearly interpolated at `t_s`, held after the end.
fn sample_linear(samples: &[WipState<f64>], period_s: f64, t_s: f64) -> WipState<f64> {
    let x = (t_s / period_s).max(0.0);
    let k = x.floor() as usize;
    match (samples.get(k), samples.get(k + 1)) {
        (Some(a), Some(b)) => a + (b - a) * (x - k as f64),
        (Some(a), None) => *a,
        _ => samples.last().copied().unwrap_or_else(WipState::zeros),
    }
}

/// Ball speed along `dir` in the body's yaw frame, signed tilt in the plane of `heading`.
fn along_heading(tel: &StepTelemetry, cos_h: f64, sin_h: f64) -> (f64, f64) {
    let (_, _, yaw) = tel.body_orientation.euler_angles();
    let v_body = Rotation3::from_axis_angle(&Vector3::z_axis(), -yaw) * tel.ball_velocity_m_per_s;
    let speed = v_body.x * cos_h + v_body.y * sin_h;
    // The command maps a planar tilt to the sagittal plane as cos(h) and to the frontal plane
    // as -sin(h); project back the same way.
    let tilt = cos_h * tel.tilt_rad[1] - sin_h * tel.tilt_rad[0];
    (speed, tilt)
}

fn actuator_utilisation(world_params: &WorldParams, tel: &StepTelemetry) -> [f64; 3] {
    let actuator = world_params.robot.drivetrain.actuator;
    tel.wheels.map(|w| {
        let (lo, hi) = actuator.torque_bounds_nm(w.speed_rad_per_s);
        let bound = if w.motor_torque_nm >= 0.0 { hi } else { lo };
        if bound.abs() > 1e-12 {
            (w.motor_torque_nm / bound).abs()
        } else if w.motor_torque_nm == 0.0 {
            0.0
        } else {
            1.0
        }
    })
}

/// Runs one braking experiment: settle, jerk-limited ramp to the cruise speed along
/// `heading_deg`, cruise, then the optimal braking trajectory to rest in `duration_s`
/// (solved here, warm-started from `warm`), followed until the end of the rest window.
pub fn braking_run(
    world_params: WorldParams,
    params: &BrakingParams,
    heading_deg: f64,
    duration_s: f64,
    warm: Option<&Trajectory>,
) -> Result<BrakingRun, BrakingError> {
    params.validate()?;
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(invalid("duration_s", "must be finite and > 0"));
    }
    if !heading_deg.is_finite() {
        return Err(invalid("heading_deg", "must be finite"));
    }
    let plan = plan_braking(&world_params.robot, params, heading_deg, duration_s, warm)?;
    if !plan.is_solved() {
        let config = braking_controller_config(&world_params.robot)?;
        return Ok(BrakingRun {
            heading_deg,
            duration_s,
            outcome: BrakingOutcome::NoTrajectory {
                status: plan.status,
            },
            brake_start_s: brake_start_step(&world_params, params, &config) as f64
                * world_params.dt_secs,
            plan: None,
            plan_peak_tilt_rad: None,
            plan_cost_n2m2s: None,
            peaks: BrakingPeaks::default(),
            samples: Vec::new(),
            telemetry_hash: super::telemetry::FNV_OFFSET_BASIS,
        });
    }
    let mut run = fly_braking(
        world_params,
        params,
        heading_deg,
        &plan.trajectory,
        &mut |_, _| {},
    )?;
    run.plan_cost_n2m2s = Some(plan.cost_n2m2s);
    Ok(run)
}

/// The physics step at which braking starts: after settle, approach and cruise, rounded up to
/// an outer-loop step, so the outer loop samples the trajectory exactly at its sample times.
fn brake_start_step(
    world_params: &WorldParams,
    params: &BrakingParams,
    config: &BallbotControllerConfig<f64>,
) -> u64 {
    let dt = world_params.dt_secs;
    let steps_per_outer = (config.outer_dt_secs / dt).round().max(1.0) as u64;
    let before_brake_s = params.settle_s + params.approach_secs() + params.cruise_s;
    (before_brake_s / dt / steps_per_outer as f64).ceil() as u64 * steps_per_outer
}

/// Flies one braking run with a given braking trajectory `plan` (its duration is the braking
/// time), calling `observe` after every physics step with the loop and, before braking, the
/// velocity command of that step (e.g. to write an MCAP log with
/// [`crate::log::WorldLogger`]). The run is the same with or without an observer, and
/// [`braking_run`] is this with the plan it solves, so replaying a run's
/// [`BrakingRun::plan`] reproduces it bit for bit.
pub fn fly_braking(
    world_params: WorldParams,
    params: &BrakingParams,
    heading_deg: f64,
    plan: &Trajectory,
    observe: &mut dyn FnMut(&CoreLoop, Option<&VelocityCommand<f64>>),
) -> Result<BrakingRun, BrakingError> {
    params.validate()?;
    if !heading_deg.is_finite() {
        return Err(invalid("heading_deg", "must be finite"));
    }
    let duration_s = plan.duration_secs();
    let config = braking_controller_config(&world_params.robot)?;
    let dt = world_params.dt_secs;
    let brake_step = brake_start_step(&world_params, params, &config);
    let heading_rad = heading_deg.to_radians();
    let plane = plane_for_heading(&world_params.robot, heading_rad);
    let mut run = BrakingRun {
        heading_deg,
        duration_s,
        outcome: BrakingOutcome::NoTrajectory {
            status: SolveStatus::Solved,
        },
        brake_start_s: brake_step as f64 * dt,
        plan: Some(plan.clone()),
        plan_peak_tilt_rad: Some(
            plan.knot_states()
                .iter()
                .fold(0.0, |m: f64, s| m.max(s[0].abs())),
        ),
        plan_cost_n2m2s: None,
        peaks: BrakingPeaks::default(),
        samples: Vec::new(),
        telemetry_hash: super::telemetry::FNV_OFFSET_BASIS,
    };
    let radius = plane.ball_radius_m;
    let period = config.outer_dt_secs;
    let physical: Vec<WipState<f64>> = plan.sample(period).into_iter().map(|(_, s, _)| s).collect();
    let mut states = physical.clone();
    if params.feedforward == TrajectoryFeedforward::Core {
        // The core shifts the commanded tilt theta_c by c(theta_c) theta_ddot* / k1
        // (theta_ddot*: slope of the tilt rate on the interval starting at the sample); the
        // sample's tilt theta_c solves theta_c + c(theta_c) theta_ddot* / k1 = theta* (a few
        // fixed-point steps: the shift is a contraction, |dc/dtheta theta_ddot* / k1| << 1).
        let (lqr, robot_plane) = if heading_rad.cos().abs() >= heading_rad.sin().abs() {
            (config.sagittal.lqr, config.robot.sagittal)
        } else {
            (config.frontal.lqr, config.robot.frontal)
        };
        let mrl = robot_plane.body_mass_kg * robot_plane.ball_radius_m * robot_plane.com_height_m;
        let coupling = |tilt: f64| mrl * tilt.cos() - robot_plane.wheel_inertia_kg_m2;
        let k1 = lqr.tilt_nm_per_rad;
        if k1.is_finite() && k1 != 0.0 {
            for (k, s) in states.iter_mut().enumerate() {
                let next = physical.get(k + 1).unwrap_or(&physical[k]);
                let tilt_accel = (next[2] - physical[k][2]) / period;
                let planned = physical[k][0];
                for _ in 0..4 {
                    s[0] = planned - coupling(s[0]) * tilt_accel / k1;
                }
            }
        }
    }
    let command_trajectory = CommandTrajectory::new(&states, period, heading_rad)
        .map_err(|e| BrakingError::World(WorldError::Robot(e)))?;

    let mut sim = CoreLoop::with_config(world_params, config)?;
    let (sin_h, cos_h) = heading_rad.sin_cos();
    let ramp_limits = AxisLimits {
        max_value: params.cruise_speed_m_per_s,
        max_rate_per_s: params.approach_accel_m_per_s2,
        max_jerk_per_s2: params.approach_jerk_m_per_s3,
    };
    let mut ramp = JerkLimiter::at(0.0);
    let settle_steps = (params.settle_s / dt).round() as u64;
    let rest_from_step = brake_step + ((duration_s + params.rest_within_s) / dt).round() as u64;
    let end_step = rest_from_step + (params.rest_hold_s / dt).round() as u64;
    let every = (params.sample_every_s / dt).round().max(1.0) as u64;
    let after_failure_steps = (AFTER_FAILURE_S / dt).round() as u64;
    let mut failed_at: Option<u64> = None;
    let mut peaks = BrakingPeaks {
        min_normal_force_n: [f64::INFINITY; 3],
        ..BrakingPeaks::default()
    };
    let slip_threshold = world_params.failure.slip_speed_threshold_m_per_s;
    let (mut rest_speed, mut rest_tilt) = (0.0_f64, 0.0_f64);
    run.samples
        .reserve((end_step / every + 1).min(1 << 20) as usize);
    for k in 0..end_step {
        let (command, command_speed, command_tilt) = if k < brake_step {
            let v = if k >= settle_steps {
                ramp.step(params.cruise_speed_m_per_s, &ramp_limits, dt)
            } else {
                0.0
            };
            let cmd = VelocityCommand {
                vx_m_per_s: v * cos_h,
                vy_m_per_s: v * sin_h,
                yaw_rate_rad_per_s: 0.0,
            };
            (Command::Velocity(cmd), v, 0.0)
        } else {
            let t = (k - brake_step) as f64 * dt;
            let s = sample_linear(&physical, period, t);
            let cmd = Command::Trajectory {
                trajectory: command_trajectory,
                time_secs: t,
            };
            (cmd, s[3] * radius, s[0])
        };
        let tel = *sim.step(command);
        match command {
            Command::Velocity(v) => observe(&sim, Some(&v)),
            _ => observe(&sim, None),
        }
        tel.hash_into(&mut run.telemetry_hash);
        let (speed, tilt) = along_heading(&tel, cos_h, sin_h);
        let braking = k >= brake_step;
        let utilisation = if braking || k % every == 0 {
            actuator_utilisation(&world_params, &tel)
        } else {
            [0.0; 3]
        };
        let failed = failed_at.is_some();
        if braking && !failed {
            let p = &mut peaks;
            for (i, w) in tel.wheels.iter().enumerate() {
                p.cone_utilisation[i] = p.cone_utilisation[i].max(w.cone_utilisation);
                p.min_normal_force_n[i] = p.min_normal_force_n[i].min(w.normal_force_n);
                p.actuator_utilisation[i] = p.actuator_utilisation[i].max(utilisation[i]);
            }
            if tel
                .wheels
                .iter()
                .any(|w| w.slipping && w.slip_speed_m_per_s.abs() > slip_threshold)
            {
                p.slip_s += dt;
            }
            p.tilt_rad = p.tilt_rad.max(tilt_from_vertical_rad(&tel));
            p.speed_error_m_per_s = p.speed_error_m_per_s.max((command_speed - speed).abs());
        }
        if k % every == 0 {
            run.samples.push(BrakingSample {
                time_s: tel.time_s,
                command_m_per_s: command_speed,
                speed_m_per_s: speed,
                command_tilt_rad: command_tilt,
                tilt_rad: tilt,
                cone_utilisation: tel.wheels.map(|w| w.cone_utilisation),
                normal_force_n: tel.wheels.map(|w| w.normal_force_n),
                actuator_utilisation: utilisation,
            });
        }
        if k >= rest_from_step && !failed {
            let v = &tel.ball_velocity_m_per_s;
            rest_speed = rest_speed.max(v.x.hypot(v.y));
            rest_tilt = rest_tilt.max(tilt_from_vertical_rad(&tel));
        }
        match (failed_at, sim.world().failure()) {
            (None, Some(failure)) => {
                run.outcome = BrakingOutcome::Failed(failure);
                failed_at = Some(k);
            }
            (Some(at), _) if k >= at + after_failure_steps => break,
            _ => {}
        }
    }
    if !matches!(run.outcome, BrakingOutcome::Failed(_)) {
        run.outcome =
            if rest_speed <= params.rest_speed_m_per_s && rest_tilt <= params.rest_tilt_rad {
                BrakingOutcome::Stopped {
                    rest_speed_m_per_s: rest_speed,
                }
            } else {
                BrakingOutcome::NotAtRest {
                    rest_speed_m_per_s: rest_speed,
                    rest_tilt_rad: rest_tilt,
                }
            };
    }
    // Never braked (failed before): no normal-force extreme to report.
    for n in &mut peaks.min_normal_force_n {
        if !n.is_finite() {
            *n = 0.0;
        }
    }
    run.peaks = peaks;
    Ok(run)
}

/// The paper's protocol and the refinement beyond it.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingStudyParams {
    /// Braking times of the descent, tried in order until one fails (s).
    pub durations_s: Vec<f64>,
    /// Bisect between the shortest success and the first failure down to this bracket (s);
    /// `None` skips the bisection.
    pub bisection_resolution_s: Option<f64>,
}

impl BrakingStudyParams {
    /// The paper's descent, `T = 5, 4.5, ..., 0.5 s`, and a bisection to 0.05 s.
    pub fn paper() -> Self {
        Self {
            durations_s: (0..10).map(|k| 5.0 - 0.5 * f64::from(k)).collect(),
            bisection_resolution_s: Some(0.05),
        }
    }
}

/// The result of [`braking_study`] at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingStudy {
    /// Heading of travel (deg).
    pub heading_deg: f64,
    /// The descending runs of the paper's protocol, in order (the last one failed unless the
    /// descent ran out of durations).
    pub descent: Vec<BrakingRun>,
    /// The bisection's runs, in order.
    pub bisection: Vec<BrakingRun>,
    /// Shortest successful `T` of the descent (s), the paper's figure; `None` if the first
    /// already failed.
    pub shortest_success_s: Option<f64>,
    /// First failing `T` of the descent (s); `None` if none failed.
    pub first_failure_s: Option<f64>,
    /// Shortest successful `T` after the bisection (s).
    pub limit_s: Option<f64>,
    /// Longest failing `T` after the bisection (s).
    pub limit_failure_s: Option<f64>,
}

impl BrakingStudy {
    /// The run of the descent at its shortest success.
    pub fn shortest_success(&self) -> Option<&BrakingRun> {
        let t = self.shortest_success_s?;
        self.descent.iter().find(|r| r.duration_s == t)
    }

    /// The descent's first failing run.
    pub fn first_failure(&self) -> Option<&BrakingRun> {
        let t = self.first_failure_s?;
        self.descent.iter().find(|r| r.duration_s == t)
    }
}

/// The paper's protocol at one heading: the durations of `study` in order (the paper: 5 s,
/// then 0.5 s shorter per success) until a run fails; then, beyond the paper, bisection
/// between the shortest success and the first failure. Each trajectory is warm-started from
/// the last solved one. Assumes success is monotone in `T` within the bracket (each
/// bisection run is reported, so a non-monotone outcome is visible). `on_run` sees every run
/// as it finishes.
pub fn braking_study(
    world_params: WorldParams,
    params: &BrakingParams,
    study: &BrakingStudyParams,
    heading_deg: f64,
    on_run: &mut dyn FnMut(&BrakingRun),
) -> Result<BrakingStudy, BrakingError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if study.durations_s.is_empty() || !study.durations_s.iter().all(|&t| ok(t)) {
        return Err(invalid(
            "study.durations_s",
            "must be non-empty, every duration finite and > 0",
        ));
    }
    if study.bisection_resolution_s.is_some_and(|r| !ok(r)) {
        return Err(invalid(
            "study.bisection_resolution_s",
            "must be finite and > 0",
        ));
    }
    let mut out = BrakingStudy {
        heading_deg,
        descent: Vec::new(),
        bisection: Vec::new(),
        shortest_success_s: None,
        first_failure_s: None,
        limit_s: None,
        limit_failure_s: None,
    };
    let mut warm: Option<Trajectory> = None;
    for &t in &study.durations_s {
        let run = braking_run(world_params, params, heading_deg, t, warm.as_ref())?;
        on_run(&run);
        if run.plan.is_some() {
            warm.clone_from(&run.plan);
        }
        let success = run.outcome.is_success();
        out.descent.push(run);
        if success {
            out.shortest_success_s = Some(t);
        } else {
            out.first_failure_s = Some(t);
            break;
        }
    }
    out.limit_s = out.shortest_success_s;
    out.limit_failure_s = out.first_failure_s;
    if let (Some(resolution), Some(mut lo), Some(mut hi)) = (
        study.bisection_resolution_s,
        out.first_failure_s,
        out.shortest_success_s,
    ) {
        while (hi - lo).abs() > resolution + 1e-9 && lo < hi {
            let mid = 0.5 * (lo + hi);
            let run = braking_run(world_params, params, heading_deg, mid, warm.as_ref())?;
            on_run(&run);
            if run.plan.is_some() {
                warm.clone_from(&run.plan);
            }
            if run.outcome.is_success() {
                hi = mid;
            } else {
                lo = mid;
            }
            out.bisection.push(run);
        }
        out.limit_s = Some(hi);
        out.limit_failure_s = Some(lo);
    }
    Ok(out)
}
