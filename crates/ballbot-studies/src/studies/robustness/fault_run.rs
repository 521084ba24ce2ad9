//! One cell of the fault-injection matrix: the robot reaches its condition, the fault strikes,
//! and the run records what the controller did, how fast, and whether the robot stayed up.

use super::faults::{Condition, FaultClass, FaultMagnitudes, SafeState};
use super::injector::FaultInjector;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::{Fault, Mode};
use ballbot_log::{LogError, McapLog, WorldLogOptions, WorldLogger};
use ballbot_world::rig::{Happened, OutcomeTracker, WorldRobot};
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::{FloorBump, StopRules, WorldError, WorldParams};
use nalgebra::Vector3;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The protocol of every cell.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CellProtocol {
    /// Cruise speed of the cruising and braking conditions (m/s). 1.4, the paper's.
    pub cruise_m_per_s: f64,
    /// Standing still before the command starts (s).
    pub settle_secs: f64,
    /// When the fault strikes while standing (s).
    pub standing_inject_secs: f64,
    /// When the fault strikes while cruising or braking (s): the command has long arrived.
    pub moving_inject_secs: f64,
    /// Run time after the fault (s).
    pub observe_secs: f64,
    /// A controlled stop has ended at rest when the ball is slower than this (m/s).
    pub rest_speed_m_per_s: f64,
    /// Telemetry in the cell's log every this many physics steps (the controller's output
    /// goes in at 50 Hz, the 3D scene at 5 Hz and its frames at 25 Hz).
    pub log_telemetry_every_steps: u32,
    /// Balancing counts as following the command when the ball's final speed is within this
    /// of the command's (m/s); else the robot is drifting ([`SafeState::Drifting`]).
    pub max_command_error_m_per_s: f64,
}

impl CellProtocol {
    /// The full fault-injection matrix's protocol: 1.4 m/s, faults at 1 s standing and 4 s
    /// moving, 6 s after ([`FaultMatrixSettings::quick`](super::FaultMatrixSettings::quick)
    /// shortens the last two).
    pub fn fault_matrix() -> Self {
        Self {
            cruise_m_per_s: 1.4,
            settle_secs: 0.5,
            standing_inject_secs: 1.0,
            moving_inject_secs: 4.0,
            observe_secs: 6.0,
            rest_speed_m_per_s: 0.1,
            log_telemetry_every_steps: 160,
            max_command_error_m_per_s: 0.2,
        }
    }

    /// The full fault-injection matrix's protocol under its old name.
    #[deprecated(note = "renamed to `CellProtocol::fault_matrix`")]
    // check-no-issue-numbers: allow (the deprecated alias keeps its old name for one release)
    pub fn issue15() -> Self {
        Self::fault_matrix()
    }

    /// When the fault strikes in `condition` (s).
    pub fn inject_secs(&self, condition: Condition) -> f64 {
        match condition {
            Condition::Standing => self.standing_inject_secs,
            Condition::Cruising | Condition::Braking => self.moving_inject_secs,
        }
    }
}

/// Which controller a cell runs: the core's, designed for the world's robot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ControllerVariant {
    /// [`BallbotControllerConfig::paper`]: the paper's configuration, traction-aware control
    /// and balance-point estimation off (the default before they were turned on).
    Paper,
    /// [`BallbotControllerConfig::design`]: what an engineer gets by default (traction-aware
    /// control and balance-point estimation on).
    Design,
}

impl ControllerVariant {
    /// Both variants.
    pub const ALL: [Self; 2] = [Self::Paper, Self::Design];

    /// The canonical name.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::ControllerVariant;
    /// assert_eq!(ControllerVariant::Paper.as_str(), "paper");
    /// ```
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Design => "design",
        }
    }

    /// The variant's configuration for `world`'s robot.
    pub fn config(self, world: &WorldParams) -> Result<BallbotControllerConfig<f64>, WorldError> {
        Ok(match self {
            Self::Paper => BallbotControllerConfig::paper(&world.robot)?,
            Self::Design => BallbotControllerConfig::design(&world.robot)?,
        })
    }
}

/// What to run: one fault in one condition at one heading, with one controller.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Cell {
    /// The controller.
    pub controller: ControllerVariant,
    /// The fault.
    pub class: FaultClass,
    /// Where the robot is when it strikes.
    pub condition: Condition,
    /// Direction of travel (deg from world x; OW1 lies at 0).
    pub heading_deg: f64,
    /// Seed of the world's sensor noise.
    pub seed: u64,
}

/// The cell's MCAP log, read back.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellLog {
    /// The file.
    pub path: PathBuf,
    /// Messages written.
    pub messages: u64,
    /// Whether it read back whole: complete, with every message written.
    pub read_back_whole: bool,
}

/// What happened in one cell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellResult {
    /// The cell.
    #[serde(flatten)]
    pub cell: Cell,
    /// The safe state the class should end in ([`FaultClass::expected`]).
    pub expected: SafeState,
    /// The one it ended in.
    pub observed: SafeState,
    /// Whether `observed == expected`.
    pub as_expected: bool,
    /// Whether the body passed the world's fall limit (25 deg from the vertical).
    pub fell: bool,
    /// The controller's mode at the end.
    pub final_mode: &'static str,
    /// Faults the supervisor raised after the injection, in the order first raised.
    pub detected: Vec<&'static str>,
    /// From the injection to the first fault raised (ms); `None`: nothing detected.
    pub time_to_detect_ms: Option<f64>,
    /// Path length of the ball from the injection to the end or the fall (m).
    pub distance_m: f64,
    /// Largest tilt from the vertical after the injection (deg).
    pub peak_tilt_deg: f64,
    /// Ball speed when the fault struck (m/s).
    pub speed_at_injection_m_per_s: f64,
    /// Ball speed at the end (m/s).
    pub final_speed_m_per_s: f64,
    /// How far the final ball velocity is from the command's (m/s).
    pub final_command_error_m_per_s: f64,
    /// Faults raised before the injection (a healthy run raises none).
    pub faults_before_injection: Vec<&'static str>,
    /// Whether the fault could act: a floor bump ahead of a robot that stands still is never
    /// reached.
    pub exercised: bool,
    /// The log, when one was written.
    pub log: Option<CellLog>,
    /// How the run ended and its contact events (JSON: `outcome`, `events`,
    /// `events_dropped` in the cell's record). The world's only stop rule here is the tilt
    /// rule, the cell's own fall limit, so `ended_by_stop_rule` (tilt) is a fall; the cell
    /// still runs 0.5 s past it.
    #[serde(flatten)]
    pub happened: Happened,
}

impl CellResult {
    /// The cell's short mark in tables and figures: `n/a` (the fault never acted), `ok` (the
    /// expected state), else the observed state's initials (`kb`, `cs`, `ps`, `dr`), or
    /// `FELL` for an undetected fall.
    pub fn mark(&self) -> &'static str {
        if !self.exercised {
            return "n/a";
        }
        if self.as_expected {
            return "ok";
        }
        match self.observed {
            SafeState::KeepsBalancing => "kb",
            SafeState::ControlledStop => "cs",
            SafeState::ProtectiveStop => "ps",
            SafeState::Drifting => "dr",
            SafeState::Unsafe if self.fell => "FELL",
            SafeState::Unsafe => "bad",
        }
    }
}

/// Why a cell could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CellError {
    /// The world or the controller rejected its parameters.
    #[error(transparent)]
    World(#[from] WorldError),
    /// The log could not be written or read back.
    #[error("{}: {source}", path.display())]
    Log {
        /// The log's path.
        path: PathBuf,
        /// What went wrong.
        source: LogError,
    },
}

/// Runs `cell` on `world` (its sensor seed replaced by the cell's) with the cell's controller
/// designed for it; writes the MCAP log `log` when given.
pub fn run_cell(
    world: &WorldParams,
    protocol: &CellProtocol,
    magnitudes: &FaultMagnitudes,
    cell: Cell,
    log: Option<&Path>,
) -> Result<CellResult, CellError> {
    run_cell_observed(world, protocol, magnitudes, cell, log, &mut |_| {})
}

/// [`run_cell`] calling `observe` after every physics step (the run is the same with or
/// without it).
pub fn run_cell_observed(
    world: &WorldParams,
    protocol: &CellProtocol,
    magnitudes: &FaultMagnitudes,
    cell: Cell,
    log: Option<&Path>,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<CellResult, CellError> {
    let mut params = *world;
    params.sensors.seed = cell.seed;
    let config = cell.controller.config(&params)?;
    let mut sim = WorldRobot::with_config(params, config)?;
    // The cell's fall limit is the world's tilt limit: the only rule that records a failure.
    sim.world_mut().set_stop_rules(CELL_STOP_RULES);
    let mut judge = OutcomeTracker::default();
    let mut logger = match log {
        Some(path) => Some(
            WorldLogger::with_options(
                path,
                &params,
                WorldLogOptions {
                    telemetry_every_steps: protocol.log_telemetry_every_steps,
                    transform_interval_secs: 0.04,
                    scene_interval_secs: 0.2,
                    controller_interval_secs: 0.02,
                    ..WorldLogOptions::default()
                },
            )
            .map_err(|source| log_error(path, source))?,
        ),
        None => None,
    };
    let mut run = CellRun::new(protocol, magnitudes, cell, &params);
    let mut log_result = Ok(());
    let total_steps = ((run.inject_secs + protocol.observe_secs) / params.dt_secs).round() as u64;
    for _ in 0..total_steps {
        let command = run.command(sim.world().time_secs());
        if let Some(what) = run.strike_if_due(&mut sim)?
            && let Some(l) = logger.as_mut()
            && log_result.is_ok()
        {
            let t = sim.world().telemetry();
            log_result = l.record_event(t.time_secs, "fault", &what, tilt_from_vertical_rad(t));
        }
        sim.step_injected(Command::Velocity(command), &mut run.injector);
        observe(&sim);
        if let Some(l) = logger.as_mut()
            && log_result.is_ok()
        {
            log_result = l
                .record_robot(&sim)
                .and_then(|()| l.record_command(sim.world().time_secs(), &command));
        }
        run.update_patch(&mut sim)?;
        run.observe(&sim, params.dt_secs);
        if sim.world().failure().is_none() {
            let v = sim.world().telemetry().ball_velocity_yaw_frame_m_per_s();
            judge.update(&sim, [v.x, v.y], [command.vx_m_per_s, command.vy_m_per_s]);
        }
        if run.fallen_for_secs(sim.world().time_secs()) > 0.5 {
            break;
        }
    }
    let cell_log = match (logger, log) {
        (Some(l), Some(path)) => {
            log_result.map_err(|e| log_error(path, e))?;
            Some(finish_and_read_back(l, path)?)
        }
        _ => None,
    };
    Ok(run.result(&sim, cell_log, Happened::of(&sim, &judge)))
}

/// The stop rules of a cell's world: tilt only (the cell's fall limit); slips, lift-offs and
/// driver trips are events, and the fault classes make them on purpose.
const CELL_STOP_RULES: StopRules = StopRules {
    tilt: true,
    ..StopRules::none()
};

fn log_error(path: &Path, source: LogError) -> CellError {
    CellError::Log {
        path: path.to_owned(),
        source,
    }
}

/// Finishes `log` and reads it back: complete, with every message written.
fn finish_and_read_back(log: WorldLogger, path: &Path) -> Result<CellLog, CellError> {
    let channels = log.finish().map_err(|e| log_error(path, e))?;
    let written: u64 = channels.iter().map(|c| c.message_count).sum();
    let reader = McapLog::open(path).map_err(|e| log_error(path, e))?;
    Ok(CellLog {
        path: path.to_owned(),
        messages: written,
        read_back_whole: reader.is_complete() && reader.message_count() == written,
    })
}

/// The state of one cell's run.
struct CellRun {
    protocol: CellProtocol,
    magnitudes: FaultMagnitudes,
    cell: Cell,
    inject_secs: f64,
    fall_tilt_rad: f64,
    direction: Vector3<f64>,
    injector: FaultInjector,
    struck: bool,
    /// The low-friction patch along the path (m, from the origin along `direction`).
    patch_m: Option<(f64, f64)>,
    on_patch: bool,
    nominal_floor_friction: f64,
    /// Where the ball is along the path at the injection (m).
    start_along_m: f64,
    furthest_along_m: f64,
    speed_at_injection_m_per_s: f64,
    detected: Vec<Fault>,
    first_detect_secs: Option<f64>,
    before: Vec<Fault>,
    distance_m: f64,
    peak_tilt_rad: f64,
    fell_at_secs: Option<f64>,
    /// Whether the motors were switched off by a fault other than the tilt limit before the
    /// body passed the fall limit.
    protective_stop_before_fall: bool,
}

impl CellRun {
    fn new(
        protocol: &CellProtocol,
        magnitudes: &FaultMagnitudes,
        cell: Cell,
        params: &WorldParams,
    ) -> Self {
        let inject_secs = protocol.inject_secs(cell.condition);
        let h = cell.heading_deg.to_radians();
        Self {
            protocol: *protocol,
            magnitudes: *magnitudes,
            cell,
            inject_secs,
            fall_tilt_rad: params.failure.max_tilt_rad,
            direction: Vector3::new(h.cos(), h.sin(), 0.0),
            injector: FaultInjector::new(
                cell.class,
                *magnitudes,
                (inject_secs * 1e6).round() as u64,
                params.robot.drivetrain.actuator,
            ),
            struck: false,
            patch_m: None,
            on_patch: false,
            nominal_floor_friction: params.robot.drivetrain.ball_floor_friction,
            start_along_m: 0.0,
            furthest_along_m: 0.0,
            speed_at_injection_m_per_s: 0.0,
            detected: Vec::new(),
            first_detect_secs: None,
            before: Vec::new(),
            distance_m: 0.0,
            peak_tilt_rad: 0.0,
            fell_at_secs: None,
            protective_stop_before_fall: false,
        }
    }

    /// The velocity command at `t_secs`.
    fn command(&self, t_secs: f64) -> VelocityCommand<f64> {
        let p = &self.protocol;
        let moving = self.cell.condition != Condition::Standing;
        let mut speed = if moving && t_secs >= p.settle_secs {
            p.cruise_m_per_s
        } else {
            0.0
        };
        if self.cell.condition == Condition::Braking && t_secs >= self.inject_secs {
            speed = 0.0;
        }
        if self.cell.class == FaultClass::CommandJump && t_secs >= self.inject_secs {
            speed = -p.cruise_m_per_s;
        }
        VelocityCommand {
            vx_m_per_s: speed * self.direction.x,
            vy_m_per_s: speed * self.direction.y,
            yaw_rate_rad_per_s: 0.0,
        }
    }

    /// Applies the world's side of the fault when it is due; returns its description once.
    fn strike_if_due(&mut self, sim: &mut WorldRobot) -> Result<Option<String>, WorldError> {
        if self.struck || sim.world().time_secs() + 1e-9 < self.inject_secs {
            return Ok(None);
        }
        self.struck = true;
        let tel = sim.world().telemetry();
        let ball = tel.ball_position_m;
        let along = ball.dot(&self.direction);
        self.start_along_m = along;
        self.furthest_along_m = along;
        self.speed_at_injection_m_per_s = tel.ball_velocity_m_per_s.xy().norm();
        let m = &self.magnitudes;
        match self.cell.class {
            FaultClass::LowFrictionPatch => {
                // Standing, the ball stands in the middle of the patch; moving, it starts
                // `obstacle_ahead_m` ahead.
                self.patch_m = Some(if self.cell.condition == Condition::Standing {
                    (
                        along - 0.5 * m.patch_length_m,
                        along + 0.5 * m.patch_length_m,
                    )
                } else {
                    let start = along + m.obstacle_ahead_m;
                    (start, start + m.patch_length_m)
                });
            }
            FaultClass::FloorBump => {
                let at = ball + self.direction * m.obstacle_ahead_m;
                sim.world_mut().add_floor_bump(FloorBump {
                    centre_m: [at.x, at.y],
                    heading_deg: self.cell.heading_deg,
                    height_m: m.bump_height_m,
                    width_m: m.bump_width_m,
                    length_m: 2.0,
                })?;
            }
            FaultClass::PayloadShift => {
                sim.world_mut()
                    .shift_payload_m(self.direction * m.payload_shift_m)?;
            }
            _ => {}
        }
        Ok(Some(format!(
            "{} while {} at {:.0} deg",
            self.cell.class.as_str(),
            self.cell.condition.as_str(),
            self.cell.heading_deg
        )))
    }

    /// Updates the floor patch under the ball.
    fn update_patch(&mut self, sim: &mut WorldRobot) -> Result<(), WorldError> {
        let Some((from, to)) = self.patch_m else {
            return Ok(());
        };
        let along = sim.world().telemetry().ball_position_m.dot(&self.direction);
        let on = (from..=to).contains(&along);
        if on != self.on_patch {
            self.on_patch = on;
            let friction = if on {
                self.magnitudes.patch_floor_friction
            } else {
                self.nominal_floor_friction
            };
            sim.world_mut().set_floor_friction(friction)?;
        }
        Ok(())
    }

    /// Records the step just taken.
    fn observe(&mut self, sim: &WorldRobot, dt_secs: f64) {
        let tel = sim.world().telemetry();
        let t = tel.time_secs;
        let Some(out) = sim.last_outer() else { return };
        // The motor-health faults are raised in the 8 kHz task and take effect at once: seen in
        // the supervisor's latched set at the step they are raised, not at the next outer step.
        let mut raised = out.safety.faults;
        for f in sim
            .robot()
            .controller()
            .supervisor()
            .latched_faults()
            .iter()
        {
            if matches!(
                f,
                Fault::MotorDead | Fault::MotorStuck | Fault::MotorTripped
            ) {
                raised.insert(f);
            }
        }
        if !self.struck {
            for f in raised.iter() {
                if !self.before.contains(&f) {
                    self.before.push(f);
                }
            }
            return;
        }
        if self.fell_at_secs.is_some() {
            return;
        }
        for f in raised.iter() {
            if !self.detected.contains(&f) {
                self.detected.push(f);
            }
        }
        if self.first_detect_secs.is_none() && !raised.is_empty() {
            self.first_detect_secs = Some(t);
        }
        if (out.safety.mode == Mode::Fault || sim.mode() == Mode::Fault)
            && self.detected.first() != Some(&Fault::TiltLimit)
        {
            self.protective_stop_before_fall = true;
        }
        self.distance_m += tel.ball_velocity_m_per_s.xy().norm() * dt_secs;
        let along = tel.ball_position_m.dot(&self.direction);
        self.furthest_along_m = self.furthest_along_m.max(along);
        let tilt = tilt_from_vertical_rad(tel);
        self.peak_tilt_rad = self.peak_tilt_rad.max(tilt);
        if tilt > self.fall_tilt_rad {
            self.fell_at_secs = Some(t);
        }
    }

    /// How long ago the body passed the fall limit (s); 0 while it has not.
    fn fallen_for_secs(&self, t_secs: f64) -> f64 {
        self.fell_at_secs.map_or(0.0, |f| t_secs - f)
    }

    fn result(&self, sim: &WorldRobot, log: Option<CellLog>, happened: Happened) -> CellResult {
        let tel = sim.world().telemetry();
        let mode = sim.mode();
        let fell = self.fell_at_secs.is_some();
        let final_speed = tel.ball_velocity_m_per_s.xy().norm();
        let command = self.command(tel.time_secs);
        let command_error = (tel.ball_velocity_m_per_s.xy()
            - nalgebra::Vector2::new(command.vx_m_per_s, command.vy_m_per_s))
        .norm();
        let observed = if fell {
            if self.protective_stop_before_fall {
                SafeState::ProtectiveStop
            } else {
                SafeState::Unsafe
            }
        } else {
            match mode {
                Mode::Balancing if command_error <= self.protocol.max_command_error_m_per_s => {
                    SafeState::KeepsBalancing
                }
                Mode::Balancing => SafeState::Drifting,
                Mode::ControlledStop if final_speed <= self.protocol.rest_speed_m_per_s => {
                    SafeState::ControlledStop
                }
                Mode::Fault if self.protective_stop_before_fall => SafeState::ProtectiveStop,
                _ => SafeState::Unsafe,
            }
        };
        let expected = self.cell.class.expected();
        let exercised = match self.cell.class {
            // The bar lies ahead: reached only if the ball touched it (the ball's centre is
            // sqrt(2 r h - h^2) short of the bar's near face when it does).
            FaultClass::FloorBump => {
                let m = &self.magnitudes;
                let r = sim.world().params().robot.ball_radius_m();
                let h = m.bump_height_m.min(r);
                let touch =
                    m.obstacle_ahead_m - 0.5 * m.bump_width_m - (2.0 * r * h - h * h).sqrt();
                self.furthest_along_m >= self.start_along_m + touch
            }
            _ => true,
        };
        CellResult {
            cell: self.cell,
            expected,
            observed,
            as_expected: observed == expected,
            fell,
            final_mode: mode.as_str(),
            detected: self.detected.iter().map(|f| f.as_str()).collect(),
            time_to_detect_ms: self.first_detect_secs.map(|t| (t - self.inject_secs) * 1e3),
            distance_m: self.distance_m,
            peak_tilt_deg: self.peak_tilt_rad.to_degrees(),
            speed_at_injection_m_per_s: self.speed_at_injection_m_per_s,
            final_speed_m_per_s: final_speed,
            final_command_error_m_per_s: command_error,
            faults_before_injection: self.before.iter().map(|f| f.as_str()).collect(),
            exercised,
            log,
            happened,
        }
    }
}
