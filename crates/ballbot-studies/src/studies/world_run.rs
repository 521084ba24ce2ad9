//! One run of the 3D world with the core's controller in the loop, written to an MCAP log
//! ([`WorldLogger`]): a velocity ramp towards a heading after a [`SETTLE_SECS`] hold, optionally a
//! push of the body; reduced to a [`WorldOutcome`]. What `ballbot world` runs; [`run_world`] is the
//! same run without a log (`ballbot world --no-log`).

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_log::{LogError, LogSink, McapLogger, WorldLogOptions, WorldLogger};
use ballbot_world::rig::{Event, Outcome, OutcomeTracker, WorldRobot};
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::{Failure, StepTelemetry, StopRules, WorldError, WorldParams};
use nalgebra::{Rotation3, Vector3};
use std::path::{Path, PathBuf};

/// Hold before the ramp starts (s).
pub const SETTLE_SECS: f64 = 0.5;

/// The command and the push of a run (checked by the caller: finite, ramp acceleration > 0,
/// the rest >= 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldRunSettings {
    /// Heading of travel in the body frame (deg; 0 is towards OW1).
    pub heading_deg: f64,
    /// Acceleration of the commanded velocity ramp (m/s^2).
    pub accel_m_per_s2: f64,
    /// Top commanded speed (m/s); the ramp holds it.
    pub top_speed_m_per_s: f64,
    /// Simulated time (s).
    pub duration_secs: f64,
    /// Horizontal impulse applied to the body at its centre of mass (N s); 0: no push.
    pub push_ns: f64,
    /// When the push is applied (s).
    pub push_at_secs: f64,
    /// Direction of the push in the body frame (deg).
    pub push_heading_deg: f64,
    /// Simulated time kept running after a failure (s).
    pub after_failure_secs: f64,
    /// Which failures end the run early ([`StopRules`]; all, as before, by default). With
    /// none, it ends at its end or when the body touches the floor.
    pub stop_rules: StopRules,
}

/// What can go wrong in a logged world run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorldRunError {
    /// The world or its controller rejected the parameters.
    #[error("cannot build the world: {0}")]
    World(#[from] WorldError),
    /// The log could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Log {
        /// The log.
        path: PathBuf,
        /// What went wrong.
        source: LogError,
    },
    /// The log's folder could not be created or the log read back.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
}

/// The outcome of a logged world run (`ballbot world`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WorldOutcome {
    /// How the run ended: fell, ended by a stop rule, stopped, at rest, recovered or
    /// unsettled ([`Outcome`]).
    pub outcome: Outcome,
    /// What happened, whatever the stop rules: slips, lift-offs, driver trips, controller
    /// faults, traction limits, each with its onset, duration and peak.
    pub events: Vec<Event>,
    /// Events beyond [`ballbot_world::rig::EventLog::MAX_EVENTS`], not kept.
    pub events_dropped: u64,
    /// The stop rules the run had, e.g. `tilt,slip,lift-off,driver-trip` or `none`.
    pub stop_rules: String,
    /// The failure that ended the run, e.g. `sustained_slip`; `None` if it ran to the end.
    pub failure: Option<String>,
    /// The wheel concerned by the failure, 1-based (OW1 is 1), if any.
    pub failure_wheel: Option<usize>,
    /// When the failure was detected (s).
    pub failure_time_secs: Option<f64>,
    /// Highest ball speed along the heading before any failure (m/s).
    pub max_speed_m_per_s: f64,
    /// Highest friction-cone utilisation of any wheel before any failure.
    pub peak_cone_utilisation: f64,
    /// The wheel with the highest utilisation, 1-based.
    pub peak_cone_wheel: usize,
    /// Smallest wheel normal force before any failure (N).
    pub min_normal_force_n: f64,
    /// Largest tilt from the vertical before any failure (deg).
    pub max_tilt_deg: f64,
    /// Simulated time reached (s).
    pub end_time_secs: f64,
    /// The MCAP log.
    pub log: String,
    /// Size of the log (bytes).
    pub log_bytes: u64,
}

/// Runs the world with `config` in the loop as `args` say, writes the log `out` with
/// `options` (its folder is created) and returns the outcome.
pub fn run_logged_world(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
    out: &Path,
    options: WorldLogOptions,
) -> Result<WorldOutcome, WorldRunError> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| WorldRunError::Io {
            path: dir.to_owned(),
            source,
        })?;
    }
    let file =
        McapLogger::create(out, options.logger.clone()).map_err(|source| WorldRunError::Log {
            path: out.to_owned(),
            source,
        })?;
    let sink = LogSink::file(file);
    run_world_with_sink(params, config, args, sink, options, |_| {})
}

/// [`run_logged_world`] (with `Some((out, options))`) or [`run_world`] (with `None`), showing
/// every step's telemetry to `observe` (e.g. to render a video): the same run, step for step.
pub fn run_world_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
    log: Option<(&Path, WorldLogOptions)>,
    observe: &mut dyn FnMut(&StepTelemetry),
) -> Result<WorldOutcome, WorldRunError> {
    let Some((out, options)) = log else {
        let sim = robot(params, config, args)?;
        return drive(sim, args, None, observe).map_err(|source| WorldRunError::Log {
            path: PathBuf::from("no log"),
            source,
        });
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| WorldRunError::Io {
            path: dir.to_owned(),
            source,
        })?;
    }
    let file =
        McapLogger::create(out, options.logger.clone()).map_err(|source| WorldRunError::Log {
            path: out.to_owned(),
            source,
        })?;
    run_sink(
        params,
        config,
        args,
        LogSink::file(file),
        options,
        |_| {},
        observe,
    )
}

/// Runs the world with `config` in the loop as `args` say, without a log, and returns the
/// outcome (`log` empty, `log_bytes` 0): the same run as [`run_logged_world`], step for step,
/// and the baseline of what a log costs (`ballbot world --no-log`).
pub fn run_world(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
) -> Result<WorldOutcome, WorldRunError> {
    let sim = robot(params, config, args)?;
    // Without a log nothing is written, so no log error can arise.
    drive(sim, args, None, &mut |_| {}).map_err(|source| WorldRunError::Log {
        path: PathBuf::from("no log"),
        source,
    })
}

/// Runs the world with `config` in the loop as `args` say, writing to `sink` (an MCAP file, a
/// live Foxglove view that paces the run, or both) with `options`, and returns the outcome
/// (`log` is empty and `log_bytes` 0 without a file).
///
/// `before_first_step` is called once the run's channels are registered, before the first
/// step: the place to wait for a live client (`LogSink::wait_for_client`) and its subscription
/// (`LogSink::wait_for_subscriber`). A client that connects after the channels exist is sent
/// all of them before the server reads its first request; one connected earlier can race a
/// channel's advertisement with its subscription and be refused ("Unknown channel ID").
pub fn run_world_with_sink(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
    sink: LogSink,
    options: WorldLogOptions,
    before_first_step: impl FnOnce(&LogSink),
) -> Result<WorldOutcome, WorldRunError> {
    run_sink(
        params,
        config,
        args,
        sink,
        options,
        before_first_step,
        &mut |_| {},
    )
}

/// [`run_world_with_sink`] showing every step to `observe`.
fn run_sink(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
    sink: LogSink,
    options: WorldLogOptions,
    before_first_step: impl FnOnce(&LogSink),
    observe: &mut dyn FnMut(&StepTelemetry),
) -> Result<WorldOutcome, WorldRunError> {
    let out = sink
        .path()
        .map_or_else(|| PathBuf::from("live view"), Path::to_owned);
    let has_file = sink.path().is_some();
    let sim = robot(params, config, args)?;
    let log_error = |source| WorldRunError::Log {
        path: out.clone(),
        source,
    };
    let mut log = WorldLogger::with_sink(sink, &params, options).map_err(log_error)?;
    before_first_step(log.sink_mut());
    let mut outcome = drive(sim, args, Some(&mut log), observe).map_err(log_error)?;
    log.finish().map_err(log_error)?;
    if has_file {
        outcome.log = out.display().to_string();
        outcome.log_bytes = std::fs::metadata(&out)
            .map_err(|source| WorldRunError::Io {
                path: out.clone(),
                source,
            })?
            .len();
    }
    Ok(outcome)
}

/// The robot of a run: the world built from `params` with `config` in the loop and the run's
/// stop rules.
fn robot(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    args: &WorldRunSettings,
) -> Result<WorldRobot, WorldError> {
    let mut sim = WorldRobot::with_config(params, config)?;
    sim.world_mut().set_stop_rules(args.stop_rules);
    Ok(sim)
}

/// Runs `sim` through the ramp and push of `args`, recording each step to `log` if there is
/// one and showing it to `observe`, and returns the outcome without its log fields. The log
/// and the observer only observe: the run is the same with or without them.
fn drive(
    mut sim: WorldRobot,
    args: &WorldRunSettings,
    mut log: Option<&mut WorldLogger>,
    observe: &mut dyn FnMut(&StepTelemetry),
) -> Result<WorldOutcome, LogError> {
    let dt = sim.world().params().dt_secs;
    let (sin_h, cos_h) = args.heading_deg.to_radians().sin_cos();
    let heading = Vector3::new(cos_h, sin_h, 0.0);
    let steps = (args.duration_secs / dt).ceil() as u64;
    let mut pushed = args.push_ns <= 0.0;
    let mut failure: Option<Failure> = None;
    let mut judge = OutcomeTracker::default();
    let mut outcome = WorldOutcome::start(args);
    for k in 0..steps {
        let t = k as f64 * dt;
        if failure.is_some_and(|f| t > f.time_secs + args.after_failure_secs) {
            break;
        }
        let v = ((t - SETTLE_SECS).max(0.0) * args.accel_m_per_s2).min(args.top_speed_m_per_s);
        let command = VelocityCommand {
            vx_m_per_s: v * cos_h,
            vy_m_per_s: v * sin_h,
            yaw_rate_rad_per_s: 0.0,
        };
        if !pushed && t + 0.5 * dt >= args.push_at_secs {
            pushed = true;
            push(&mut sim, args, t, log.as_deref_mut())?;
        }
        if let Some(log) = log.as_deref_mut() {
            log.record_command(t, &command)?;
        }
        let telemetry = *sim.step(Command::Velocity(command));
        if let Some(log) = log.as_deref_mut() {
            log.record_robot(&sim)?;
        }
        observe(&telemetry);
        outcome.end_time_secs = telemetry.time_secs;
        if failure.is_some() {
            continue;
        }
        // Ball velocity in the body's yaw frame.
        let v_yaw = telemetry.ball_velocity_yaw_frame_m_per_s();
        judge.update(
            &sim,
            [v_yaw.x, v_yaw.y],
            [command.vx_m_per_s, command.vy_m_per_s],
        );
        failure = sim.world().failure();
        if failure.is_none() {
            outcome.track(&telemetry, v_yaw.dot(&heading));
        }
    }
    outcome.finish(&sim, judge.outcome(failure), failure);
    Ok(outcome)
}

/// Pushes the body as `args` say at `t` (the direction in the body's yaw frame) and records
/// the push as an event.
fn push(
    sim: &mut WorldRobot,
    args: &WorldRunSettings,
    t: f64,
    log: Option<&mut WorldLogger>,
) -> Result<(), LogError> {
    let telemetry = sim.world().telemetry();
    let (_, _, yaw) = telemetry.body_orientation.euler_angles();
    let direction = Rotation3::from_axis_angle(&Vector3::z_axis(), yaw)
        * Vector3::new(
            args.push_heading_deg.to_radians().cos(),
            args.push_heading_deg.to_radians().sin(),
            0.0,
        );
    let tilt = tilt_from_vertical_rad(telemetry);
    sim.world_mut().push_body(direction * args.push_ns);
    let Some(log) = log else {
        return Ok(());
    };
    let description = format!(
        "push of {} N s towards {} deg (body frame)",
        args.push_ns, args.push_heading_deg
    );
    log.record_event(t, "push", &description, tilt)
}

impl WorldOutcome {
    /// The outcome before the first step of a run with `args`.
    fn start(args: &WorldRunSettings) -> Self {
        Self {
            outcome: Outcome::Unsettled,
            events: Vec::new(),
            events_dropped: 0,
            stop_rules: args.stop_rules.to_string(),
            failure: None,
            failure_wheel: None,
            failure_time_secs: None,
            max_speed_m_per_s: 0.0,
            peak_cone_utilisation: 0.0,
            peak_cone_wheel: 1,
            min_normal_force_n: f64::INFINITY,
            max_tilt_deg: 0.0,
            end_time_secs: 0.0,
            log: String::new(),
            log_bytes: 0,
        }
    }

    /// Updates the peaks with a step before any failure, whose ball speed along the heading
    /// is `speed_m_per_s`.
    fn track(&mut self, telemetry: &StepTelemetry, speed_m_per_s: f64) {
        self.max_speed_m_per_s = self.max_speed_m_per_s.max(speed_m_per_s);
        for (i, w) in telemetry.wheels.iter().enumerate() {
            if w.cone_utilisation > self.peak_cone_utilisation {
                self.peak_cone_utilisation = w.cone_utilisation;
                self.peak_cone_wheel = i + 1;
            }
            self.min_normal_force_n = self.min_normal_force_n.min(w.normal_force_n);
        }
        self.max_tilt_deg = self
            .max_tilt_deg
            .max(tilt_from_vertical_rad(telemetry).to_degrees());
    }

    /// Fills in how the run of `sim` ended and its events.
    fn finish(&mut self, sim: &WorldRobot, outcome: Outcome, failure: Option<Failure>) {
        self.outcome = outcome;
        self.events = sim.events().events().to_vec();
        self.events_dropped = sim.events().dropped();
        if let Some(f) = failure {
            self.failure = Some(f.kind.as_str().to_owned());
            self.failure_wheel = f.kind.wheel().map(|w| w + 1);
            self.failure_time_secs = Some(f.time_secs);
        }
    }
}
