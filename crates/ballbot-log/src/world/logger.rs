//! [`WorldLogger`]: one world run into one MCAP file.

use std::path::Path;

use ballbot_core::ballbot::OuterOutput;
use ballbot_core::command::VelocityCommand;
use ballbot_core::safety::Mode;

use super::grid::Grid;
use super::messages::{WorldCommandMsg, WorldControllerMsg, WorldEventMsg, WorldTelemetryMsg};
use super::options::WorldLogOptions;
use super::scene::WorldScene;
use crate::foxglove::{FrameTransforms, JointStates, Log, LogLevel, SceneUpdate, timestamp};
use crate::{ChannelInfo, LogError, LogSink, McapLogger, Protobuf, SinkChannel, topics};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::failure::{Failure, tilt_from_vertical_rad};
use ballbot_world::world::params::WorldParams;
use ballbot_world::world::sim::BallbotWorld;
use ballbot_world::world::telemetry::StepTelemetry;

/// Writes a world run into an MCAP file, a live Foxglove view, or both (see the module docs
/// for the channels).
///
/// Create it with the run's parameters ([`create`](Self::create) for a file,
/// [`with_sink`](Self::with_sink) for a [`LogSink`] that may serve a live view), call
/// [`record_robot`](Self::record_robot) (with a [`WorldRobot`]), [`record`](Self::record) (a
/// [`BallbotWorld`] and any controller output) or
/// [`record_telemetry`](Self::record_telemetry) after every physics step, and
/// [`finish`](Self::finish) at the end. A run that is killed leaves a file that
/// [`McapLog::open`](crate::McapLog::open) reads up to the last closed chunk (at most
/// one second of simulated time is lost with the default
/// [`LoggerOptions`](crate::LoggerOptions)).
#[derive(Debug)]
pub struct WorldLogger {
    log: LogSink,
    scene: WorldScene,
    options: WorldLogOptions,
    dt_secs: f64,
    steps_per_outer: u64,
    telemetry: SinkChannel<WorldTelemetryMsg>,
    controller: SinkChannel<WorldControllerMsg>,
    command: SinkChannel<WorldCommandMsg>,
    transforms: SinkChannel<FrameTransforms, Protobuf>,
    joints: SinkChannel<JointStates, Protobuf>,
    scene_channel: SinkChannel<SceneUpdate, Protobuf>,
    events: SinkChannel<WorldEventMsg>,
    text_log: SinkChannel<Log, Protobuf>,
    records: u64,
    transform_grid: Grid,
    scene_grid: Grid,
    command_grid: Grid,
    last_outer_index: Option<u64>,
    last_mode: Option<Mode>,
    failure_logged: bool,
}

impl WorldLogger {
    /// Creates (or truncates) the log at `path` for a run of the world built from `params`,
    /// with the default [`WorldLogOptions`].
    pub fn create(path: impl AsRef<Path>, params: &WorldParams) -> Result<Self, LogError> {
        Self::with_options(path, params, WorldLogOptions::default())
    }

    /// Creates (or truncates) the log at `path` with the given options.
    pub fn with_options(
        path: impl AsRef<Path>,
        params: &WorldParams,
        options: WorldLogOptions,
    ) -> Result<Self, LogError> {
        let path = path.as_ref();
        options.validate(path, params.dt_secs)?;
        let log = McapLogger::create(path, options.logger.clone())?;
        Self::with_sink(LogSink::file(log), params, options)
    }

    /// Writes the run to `sink`: an MCAP file, a live view, or both. The options' `logger`
    /// field is not used (the file, if any, is already open); the live view, if any, paces
    /// the run at every [`record_telemetry`](Self::record_telemetry).
    pub fn with_sink(
        mut log: LogSink,
        params: &WorldParams,
        options: WorldLogOptions,
    ) -> Result<Self, LogError> {
        let path = log
            .path()
            .map_or_else(|| Path::new("live view").to_owned(), Path::to_owned);
        options.validate(&path, params.dt_secs)?;
        let telemetry = log.channel::<WorldTelemetryMsg>(topics::WORLD_TELEMETRY)?;
        let controller = log.channel::<WorldControllerMsg>(topics::WORLD_CONTROLLER)?;
        let command = log.channel::<WorldCommandMsg>(topics::WORLD_COMMAND)?;
        let transforms = log.channel_with::<FrameTransforms, Protobuf>(topics::TRANSFORMS)?;
        let joints = log.channel_with::<JointStates, Protobuf>(topics::JOINT_STATES)?;
        let scene_channel = log.channel_with::<SceneUpdate, Protobuf>(topics::SCENE)?;
        let events = log.channel::<WorldEventMsg>(topics::FAULTS)?;
        let text_log = log.channel_with::<Log, Protobuf>(topics::LOG)?;
        // Validated above: a whole number >= 1.
        let steps_per_outer = (options.controller_interval_secs / params.dt_secs).round() as u64;
        Ok(Self {
            log,
            scene: WorldScene::new(params, options.metres_per_newton),
            dt_secs: params.dt_secs,
            steps_per_outer,
            telemetry,
            controller,
            command,
            transforms,
            joints,
            scene_channel,
            events,
            text_log,
            records: 0,
            transform_grid: Grid::new(options.transform_interval_secs),
            scene_grid: Grid::new(options.scene_interval_secs),
            command_grid: Grid::new(
                options.controller_interval_secs * f64::from(options.controller_every_outer_steps),
            ),
            last_outer_index: None,
            last_mode: None,
            failure_logged: false,
            options,
        })
    }

    /// The file being written, if the run goes to one.
    pub fn path(&self) -> Option<&Path> {
        self.log.path()
    }

    /// The options in use.
    pub fn options(&self) -> &WorldLogOptions {
        &self.options
    }

    /// The scene drawn (dimensions, frame names).
    pub fn scene(&self) -> &WorldScene {
        &self.scene
    }

    /// Where the run goes, e.g. to add channels of one's own
    /// ([`LogSink::channel`]).
    pub fn sink_mut(&mut self) -> &mut LogSink {
        &mut self.log
    }

    /// Records the step just taken by a [`WorldRobot`]: its world (telemetry, failure) and its
    /// controller's last outer-loop output.
    pub fn record_robot(&mut self, sim: &WorldRobot) -> Result<(), LogError> {
        self.record(sim.world(), sim.last_outer())
    }

    /// Records the step just taken by `world`, with the output of the controller's outer loop
    /// that drove it, if any (e.g. [`WorldRobot::last_outer`]).
    pub fn record(
        &mut self,
        world: &BallbotWorld,
        outer: Option<&OuterOutput<f64>>,
    ) -> Result<(), LogError> {
        self.record_telemetry(world.telemetry(), world.failure(), outer)
    }

    /// Records one step from its parts: the step's telemetry, the first failure detected so
    /// far, and the controller's latest outer-loop output.
    ///
    /// The outer output is written once per outer step (every `controller_interval_secs`;
    /// every `controller_every_outer_steps`-th), stamped with the time at which the controller
    /// computed it: the start of the physics step at which an outer step falls due, as in
    /// [`WorldRobot::step`].
    pub fn record_telemetry(
        &mut self,
        t: &StepTelemetry,
        failure: Option<Failure>,
        outer: Option<&OuterOutput<f64>>,
    ) -> Result<(), LogError> {
        if let Some(out) = outer {
            self.record_outer(t, out)?;
        }
        let every = u64::from(self.options.telemetry_every_steps);
        if self.records.is_multiple_of(every) {
            let msg = WorldTelemetryMsg::new(t, failure.is_some());
            self.log.write(&self.telemetry, t.time_secs, &msg)?;
        }
        self.records += 1;
        if self.transform_grid.due(t.time_secs) {
            let frames = self.scene.frames(t);
            self.log.write(&self.transforms, t.time_secs, &frames)?;
            let joints = self.scene.joints(t);
            self.log.write(&self.joints, t.time_secs, &joints)?;
        }
        if self.scene_grid.due(t.time_secs) {
            let update = self.scene.scene(t);
            self.log.write(&self.scene_channel, t.time_secs, &update)?;
        }
        if let (Some(f), false) = (failure, self.failure_logged) {
            self.failure_logged = true;
            let msg = WorldEventMsg::failure(&f, tilt_from_vertical_rad(t));
            self.write_event(f.time_secs.max(0.0), &msg, LogLevel::Error)?;
        }
        self.log.pace(t.time_secs);
        Ok(())
    }

    /// Writes an event on [`topics::FAULTS`] and, as text, on [`topics::LOG`].
    fn write_event(
        &mut self,
        time_secs: f64,
        msg: &WorldEventMsg,
        level: LogLevel,
    ) -> Result<(), LogError> {
        self.log.write(&self.events, time_secs, msg)?;
        let text = Log {
            timestamp: Some(timestamp(time_secs)),
            level: level as i32,
            message: format!("{}: {}", msg.kind, msg.description),
            name: "ballbot.world".to_owned(),
            file: String::new(),
            line: 0,
        };
        self.log.write(&self.text_log, time_secs, &text)
    }

    fn record_outer(&mut self, t: &StepTelemetry, out: &OuterOutput<f64>) -> Result<(), LogError> {
        // The physics step that has just ended started at `steps_done - 1`.
        let steps_done = (t.time_secs / self.dt_secs).round();
        if steps_done.is_nan() || steps_done < 1.0 {
            return Ok(());
        }
        let outer_index = (steps_done as u64 - 1) / self.steps_per_outer;
        if self.last_outer_index == Some(outer_index) {
            return Ok(());
        }
        self.last_outer_index = Some(outer_index);
        let computed_secs = (outer_index * self.steps_per_outer) as f64 * self.dt_secs;
        let every = u64::from(self.options.controller_every_outer_steps);
        if outer_index.is_multiple_of(every) {
            let msg = WorldControllerMsg::from(out);
            self.log.write(&self.controller, computed_secs, &msg)?;
        }
        let mode = out.safety.mode;
        if self.last_mode != Some(mode) {
            self.last_mode = Some(mode);
            let msg = WorldEventMsg {
                kind: "mode".to_owned(),
                description: format!("controller mode {}", mode.as_str()),
                wheel: None,
                tilt_rad: tilt_from_vertical_rad(t),
            };
            let level = match mode {
                Mode::Idle | Mode::Balancing => LogLevel::Info,
                Mode::ControlledStop => LogLevel::Warning,
                Mode::Fault => LogLevel::Error,
            };
            self.write_event(computed_secs, &msg, level)?;
        }
        Ok(())
    }

    /// Records the velocity command in force at `time_secs`, at most once per
    /// `controller_interval_secs` (call it every step; repeated calls in between are skipped).
    pub fn record_command(
        &mut self,
        time_secs: f64,
        command: &VelocityCommand<f64>,
    ) -> Result<(), LogError> {
        if self.command_grid.due(time_secs) {
            self.log
                .write(&self.command, time_secs, &WorldCommandMsg::from(command))?;
        }
        Ok(())
    }

    /// Records an event of the run on [`topics::FAULTS`], e.g. `kind = "push"` with a
    /// description of the impulse; `tilt_rad` is the tilt from the vertical at the event.
    pub fn record_event(
        &mut self,
        time_secs: f64,
        kind: &str,
        description: &str,
        tilt_rad: f64,
    ) -> Result<(), LogError> {
        let msg = WorldEventMsg {
            kind: kind.to_owned(),
            description: description.to_owned(),
            wheel: None,
            tilt_rad,
        };
        self.write_event(time_secs, &msg, LogLevel::Info)
    }

    /// The file's channels, with the number of messages written to each so far (empty
    /// without a file).
    pub fn channels(&self) -> Vec<ChannelInfo> {
        self.log.channels()
    }

    /// Writes the file's summary section and footer and returns its channels with their
    /// message counts (empty without a file).
    pub fn finish(self) -> Result<Vec<ChannelInfo>, LogError> {
        self.log.finish()
    }
}
