//! [`BallbotEnv`]: one environment, with the Gymnasium protocol's `reset` and `step`.

use super::config::{EnvConfig, Task};
use super::error::GymError;
use super::observe::{observation_high, observation_len, observe};
use super::plant::{DelayLine, Plant};
use super::randomize::{EpisodeDraw, Randomization};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_world::rig::{Event, EventLog};
use ballbot_world::world::{Failure, FailureKind, StepTelemetry, WorldParams};
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_distr::{Distribution, Uniform};

/// Per-reset choices (Gymnasium's `reset(options=...)`): they hold for this episode only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ResetOptions {
    /// Ranges replacing the environment's for this episode.
    pub randomization: Option<Randomization>,
    /// The initial tilt `[about x, about y]` (rad), instead of a drawn one.
    pub initial_tilt_rad: Option<[f64; 2]>,
    /// A fixed velocity command for the whole episode (`Velocity` task).
    pub command: Option<[f64; 3]>,
}

/// What a reset reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResetInfo {
    /// The episode's drawn values, its seed among them.
    pub draw: EpisodeDraw,
    /// The world the episode runs (the nominal one with the draw applied).
    pub params: WorldParams,
}

/// Why an episode ended `terminated`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Termination {
    /// The chassis touched the floor: a fall (whatever the stop rules).
    Fell,
    /// A stop rule in force ([`EnvConfig::stop_rules`]) ended the episode: the failure it
    /// called. [`FailureKind::Tilt`] is a fall called before the chassis reaches the floor.
    StopRule(FailureKind),
    /// The controller underneath (`Velocity` with the residual) switched the motors off.
    ControllerOff,
}

impl Termination {
    /// The canonical name: `fell`, the stop rule's failure ([`FailureKind::as_str`]: `tilt`,
    /// `sustained_slip`, `lift_off`, `driver_trip`), or `controller_off`.
    ///
    /// ```
    /// use ballbot_gym::Termination;
    /// use ballbot_world::world::FailureKind;
    /// assert_eq!(Termination::Fell.as_str(), "fell");
    /// assert_eq!(Termination::StopRule(FailureKind::LiftOff { wheel: 0 }).as_str(), "lift_off");
    /// ```
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Fell => "fell",
            Self::StopRule(kind) => kind.as_str(),
            Self::ControllerOff => "controller_off",
        }
    }

    /// Whether the robot fell: the chassis on the floor, or the tilt rule.
    pub fn is_fall(&self) -> bool {
        matches!(self, Self::Fell | Self::StopRule(FailureKind::Tilt { .. }))
    }

    /// The termination of a step that ended with the world's latched `failure` (the world
    /// latches only what its stop rules end a run on) and the controller `controller_off`.
    fn judge(failure: Option<Failure>, controller_off: bool) -> Option<Self> {
        match failure.map(|f| f.kind) {
            Some(FailureKind::BodyTouchedFloor) => Some(Self::Fell),
            Some(kind) => Some(Self::StopRule(kind)),
            None if controller_off => Some(Self::ControllerOff),
            None => None,
        }
    }
}

/// What a step reports besides observation and reward. The contact events (slips, lift-offs,
/// driver trips; controller faults and traction limits with the controller underneath) are on
/// the environment: [`BallbotEnv::step_events`] for this step's, [`BallbotEnv::events`] for the
/// episode's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInfo {
    /// Simulated time at the end of the step (s).
    pub time_secs: f64,
    /// Why the episode ended, when it ended `terminated`.
    pub termination: Option<Termination>,
    /// The world's failure that ended the episode, if any (only the stop rules in force and
    /// the chassis on the floor are latched).
    pub failure: Option<Failure>,
    /// `true` when the controller (`Velocity` task with the residual) switched the motors off.
    pub controller_off: bool,
    /// The push applied at the start of this step (N s, world x and y), if any.
    pub push_ns: Option<[f64; 2]>,
    /// The velocity command of this step.
    pub command: [f64; 3],
}

/// One step's outcome.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutcome {
    /// The reward ([`super::RewardWeights`]).
    pub reward: f64,
    /// The episode ended: the chassis touched the floor, a stop rule in force called a
    /// failure ([`EnvConfig::stop_rules`]: by default tilt or a driver trip, not slip or
    /// lift-off), or the controller switched the motors off ([`StepInfo::termination`]).
    pub terminated: bool,
    /// The time limit was reached.
    pub truncated: bool,
    /// Details.
    pub info: StepInfo,
}

struct Episode {
    plant: Plant,
    rng: ChaCha8Rng,
    command: [f64; 3],
    fixed_command: bool,
    next_command_step: u64,
    next_push_step: Option<u64>,
    steps: u64,
    max_steps: u64,
    last_action: [f64; 3],
    delay: DelayLine,
    done: bool,
    ranges: Randomization,
    /// The events in progress during the last step.
    step_events: StepEvents,
}

/// A ballbot environment: the Gymnasium protocol on the rapier3d world, in Rust.
///
/// Seeding: `reset(Some(s))` starts the episode seeded `s`; `reset(None)` draws the next
/// episode's seed (63 bits) from the stream the last explicit seed started (seed 0 if there
/// was none).
/// An episode's seed (in [`ResetInfo`]) replays it: `reset(Some(seed))` with the same options.
///
/// ```
/// use ballbot_gym::{BallbotEnv, EnvConfig, Task};
/// let mut env = BallbotEnv::new(EnvConfig::new(Task::Velocity))?;
/// let mut obs = vec![0.0_f32; env.observation_len()];
/// let info = env.reset(Some(3), None, &mut obs)?;
/// assert_eq!(info.draw.seed, 3);
/// let mut steps = 0;
/// loop {
///     // No residual: the core's LQR-PI tracks the commands alone.
///     let out = env.step([0.0; 3], &mut obs)?;
///     steps += 1;
///     if out.terminated || out.truncated || steps == 400 {
///         assert!(!out.terminated, "the LQR-PI keeps the robot up");
///         break;
///     }
/// }
/// # Ok::<(), ballbot_gym::GymError>(())
/// ```
pub struct BallbotEnv {
    config: EnvConfig,
    steps_per_action: u32,
    high: Vec<f32>,
    controller: BallbotControllerConfig<f64>,
    stream: ChaCha8Rng,
    episode: Option<Episode>,
}

impl BallbotEnv {
    /// The environment, its configuration validated (an error names the field and the bound).
    pub fn new(config: EnvConfig) -> Result<Self, GymError> {
        config.validate()?;
        let controller = BallbotControllerConfig::design(&config.world.robot)
            .map_err(|e| GymError::World(e.into()))?;
        check_arming(&config, &controller, &config.randomization)?;
        Ok(Self {
            steps_per_action: config.steps_per_action()?,
            high: observation_high(&config),
            controller,
            config,
            stream: ChaCha8Rng::seed_from_u64(0),
            episode: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &EnvConfig {
        &self.config
    }

    /// Length of an observation.
    pub fn observation_len(&self) -> usize {
        observation_len(&self.config)
    }

    /// The observation box's upper bounds (the lower ones are their negatives).
    pub fn observation_high(&self) -> &[f32] {
        &self.high
    }

    /// Physics steps per agent step.
    pub fn steps_per_action(&self) -> u32 {
        self.steps_per_action
    }

    /// The world's last step record, once reset.
    pub fn telemetry(&self) -> Option<&StepTelemetry> {
        self.episode.as_ref().map(|e| e.plant.world().telemetry())
    }

    /// Whether the episode has ended (terminated or truncated): `None` before the first reset.
    pub fn episode_ended(&self) -> Option<bool> {
        self.episode.as_ref().map(|e| e.done)
    }

    /// Simulated time of the episode (s), once reset.
    pub fn time_secs(&self) -> Option<f64> {
        self.episode.as_ref().map(|e| e.plant.world().time_secs())
    }

    /// The episode's events so far, once reset: per wheel its slips (faster than
    /// `failure.slip_speed_threshold_m_per_s`), lift-offs (normal force below
    /// `failure.lift_off_force_n`) and a driver trip, every physics step; with the controller
    /// underneath, its faults and traction limits too, every outer step. Each has its onset,
    /// duration and peak ([`EventLog`]: at most [`EventLog::MAX_EVENTS`] kept, the rest
    /// counted). Recorded whatever the stop rules.
    pub fn events(&self) -> Option<&EventLog> {
        self.episode.as_ref().map(|e| e.plant.events())
    }

    /// The events in progress at any time during the last step, in order of onset: the ones
    /// still going on from before it and the ones that began in it ([`Event::ongoing`] tells
    /// whether each was still going on at the step's end). Nothing before the first step of an
    /// episode. At most one event per condition (slip, lift-off, trip per wheel; each fault;
    /// the traction limit) comes from before the step.
    ///
    /// ```
    /// use ballbot_gym::{BallbotEnv, EnvConfig, ResetOptions, Task};
    /// let mut env = BallbotEnv::new(EnvConfig::new(Task::Balance))?;
    /// let mut obs = vec![0.0_f32; env.observation_len()];
    /// let upright = ResetOptions { initial_tilt_rad: Some([0.0; 2]), ..ResetOptions::default() };
    /// env.reset(Some(0), Some(&upright), &mut obs)?;
    /// // Opposite torques on OW1 and OW2 lift a wheel off the ball for longer than 20 ms: an
    /// // event, not the end of the episode.
    /// let mut longest_lift_off_secs = 0.0_f64;
    /// for _ in 0..20 {
    ///     let out = env.step([0.5, -0.5, 0.0], &mut obs)?;
    ///     assert!(!out.terminated);
    ///     for e in env.step_events().filter(|e| e.kind.as_str() == "lift_off") {
    ///         longest_lift_off_secs = longest_lift_off_secs.max(e.duration_secs);
    ///     }
    /// }
    /// assert!(longest_lift_off_secs > 0.02);
    /// # Ok::<(), ballbot_gym::GymError>(())
    /// ```
    pub fn step_events(&self) -> impl Iterator<Item = &Event> {
        self.episode.iter().flat_map(|ep| {
            let events = ep.plant.events().events();
            ep.step_events.indices.iter().filter_map(|&i| events.get(i))
        })
    }

    /// Starts an episode (see the type's docs for the seeding) and writes its first
    /// observation into `obs` (length [`Self::observation_len`]).
    pub fn reset(
        &mut self,
        seed: Option<u64>,
        options: Option<&ResetOptions>,
        obs: &mut [f32],
    ) -> Result<ResetInfo, GymError> {
        self.check_len(obs)?;
        let options = options.copied().unwrap_or_default();
        let ranges = match options.randomization {
            Some(o) => {
                let merged = self.config.randomization.merged(&o);
                merged.validate(&self.config.world)?;
                check_arming(&self.config, &self.controller, &merged)?;
                merged
            }
            None => self.config.randomization,
        };
        if let Some(t) = options.initial_tilt_rad {
            let max = match self.config.task {
                Task::Velocity if self.config.residual => arm_tilt_limit_rad(&self.controller),
                _ => self.config.world.failure.max_tilt_rad,
            };
            if !(t.iter().all(|x| x.is_finite()) && t[0].hypot(t[1]) < max) {
                return Err(GymError::invalid(
                    "initial_tilt_rad",
                    "must be finite and below the failure tilt (with the controller \
                     underneath: below its arming tilt)",
                    format!("{t:?}"),
                ));
            }
        }
        if let Some(c) = options.command
            && !c.iter().all(|x| x.is_finite())
        {
            return Err(GymError::invalid(
                "command",
                "must be finite",
                format!("{c:?}"),
            ));
        }
        let seed = match seed {
            Some(s) => {
                self.stream = ChaCha8Rng::seed_from_u64(s);
                s
            }
            // 63 bits: a seed fits a signed 64-bit integer (numpy's int64 info arrays).
            None => self.stream.next_u64() >> 1,
        };
        let mut draw = EpisodeDraw::sample(seed, &ranges);
        if let Some(t) = options.initial_tilt_rad {
            draw.initial_tilt_rad = t;
        }
        let params = draw.apply(&self.config.world);
        let dt = params.dt_secs;
        let delay_steps = (draw.sensor_delay_secs / dt).round() as usize;
        let mut plant = match (self.config.task, self.config.residual) {
            (Task::Velocity, true) => {
                let delay_us = (delay_steps as f64 * dt * 1e6).round() as u64;
                Plant::controlled(params, self.controller, delay_us)?
            }
            _ => Plant::torque(params)?,
        };
        plant.world_mut().set_stop_rules(self.config.stop_rules);
        if draw.initial_tilt_rad != [0.0; 2] {
            plant.world_mut().tilt_body(draw.initial_tilt_rad);
        }
        // Its own stream for commands and pushes, apart from the draws and the sensors.
        let rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let m = plant.world_mut().measure();
        let max_steps = (self.config.max_episode_secs * self.config.control_hz).ceil() as u64;
        let mut episode = Episode {
            plant,
            rng,
            command: options.command.unwrap_or([0.0; 3]),
            fixed_command: options.command.is_some() || self.config.task == Task::Balance,
            next_command_step: 0,
            next_push_step: None,
            steps: 0,
            max_steps: max_steps.max(1),
            last_action: [0.0; 3],
            delay: DelayLine::new(delay_steps, m),
            done: false,
            ranges,
            step_events: StepEvents::default(),
        };
        self.update_command(&mut episode);
        episode.next_push_step = self.next_push(&mut episode);
        observe(obs, &self.high, &m, episode.command, episode.last_action);
        self.episode = Some(episode);
        Ok(ResetInfo { draw, params })
    }

    /// One agent step with `action` (three numbers, clipped to [-1, 1]): the action is held
    /// for [`Self::steps_per_action`] physics steps (fewer if the episode ends). Writes the
    /// next observation into `obs`.
    pub fn step(&mut self, action: [f64; 3], obs: &mut [f32]) -> Result<StepOutcome, GymError> {
        if !action.iter().all(|a| a.is_finite()) {
            return Err(GymError::NonFiniteAction(action));
        }
        self.check_len(obs)?;
        let mut episode = self
            .episode
            .take()
            .ok_or(GymError::NeedsReset("before the first reset"))?;
        let result = self.step_episode(&mut episode, action, obs);
        self.episode = Some(episode);
        result
    }

    fn step_episode(
        &self,
        ep: &mut Episode,
        action: [f64; 3],
        obs: &mut [f32],
    ) -> Result<StepOutcome, GymError> {
        if ep.done {
            return Err(GymError::NeedsReset("after the episode ended"));
        }
        let a = action.map(|x| x.clamp(-1.0, 1.0));
        self.update_command(ep);
        let mut push_ns = None;
        if ep.next_push_step == Some(ep.steps) {
            let range = ep.ranges.push_impulse_ns.unwrap_or((0.0, 0.0).into());
            let magnitude = range.sample(&mut ep.rng);
            let heading =
                Uniform::new(0.0, core::f64::consts::TAU).map_or(0.0, |u| u.sample(&mut ep.rng));
            let j = [magnitude * heading.cos(), magnitude * heading.sin()];
            ep.plant
                .world_mut()
                .push_body(Vector3::new(j[0], j[1], 0.0));
            push_ns = Some(j);
            ep.next_push_step = self.next_push(ep);
        }
        let peak = self.config.world.robot.drivetrain.actuator.peak_torque_nm;
        let scale = match ep.plant {
            Plant::Controlled(..) => peak * self.config.residual_fraction,
            Plant::Torque(..) => peak,
        };
        let torque = a.map(|x| x * scale);
        ep.step_events.begin(ep.plant.events());
        for _ in 0..self.steps_per_action {
            ep.plant.step(torque, ep.command);
            if ep.delay.delays() {
                let m = ep.plant.world_mut().measure();
                ep.delay.push(m);
            }
            if ep.plant.world().failure().is_some() {
                break;
            }
        }
        ep.steps += 1;
        ep.last_action = a;
        ep.step_events.end(ep.plant.events());
        let m = match ep.delay.oldest() {
            Some(m) if ep.delay.delays() => *m,
            _ => ep.plant.world_mut().measure(),
        };
        observe(obs, &self.high, &m, ep.command, a);
        let world = ep.plant.world();
        let failure = world.failure();
        let controller_off = ep.plant.mode().is_some_and(|m| !m.motors_enabled());
        let termination = Termination::judge(failure, controller_off);
        let terminated = termination.is_some();
        let truncated = !terminated && ep.steps >= ep.max_steps;
        ep.done = terminated || truncated;
        let reward = self.reward(world.telemetry(), ep.command, a, terminated);
        Ok(StepOutcome {
            reward,
            terminated,
            truncated,
            info: StepInfo {
                time_secs: world.time_secs(),
                termination,
                failure,
                controller_off,
                push_ns,
                command: ep.command,
            },
        })
    }

    /// The observation buffer must fit one observation exactly.
    fn check_len(&self, obs: &[f32]) -> Result<(), GymError> {
        if obs.len() == self.high.len() {
            Ok(())
        } else {
            Err(GymError::invalid(
                "obs",
                "the buffer must have observation_len() entries",
                obs.len(),
            ))
        }
    }

    /// A new velocity command when one is due (`Velocity` task, no fixed command).
    fn update_command(&self, ep: &mut Episode) {
        if ep.fixed_command || ep.steps != ep.next_command_step {
            return;
        }
        let c = &self.config.commands;
        let mut uniform =
            |lo: f64, hi: f64| Uniform::new_inclusive(lo, hi).map_or(lo, |u| u.sample(&mut ep.rng));
        let speed = uniform(0.0, c.max_speed_m_per_s);
        let heading = uniform(0.0, core::f64::consts::TAU);
        let yaw = uniform(-c.max_yaw_rate_rad_per_s, c.max_yaw_rate_rad_per_s);
        ep.command = [speed * heading.cos(), speed * heading.sin(), yaw];
        let period = (c.period_secs * self.config.control_hz).round().max(1.0) as u64;
        ep.next_command_step = ep.steps + period;
    }

    /// The step of the next push, if pushes are on.
    fn next_push(&self, ep: &mut Episode) -> Option<u64> {
        let (Some(_), Some(interval)) = (ep.ranges.push_impulse_ns, ep.ranges.push_interval_secs)
        else {
            return None;
        };
        let secs = interval.sample(&mut ep.rng);
        let steps = (secs * self.config.control_hz).round().max(1.0) as u64;
        Some(ep.steps + steps)
    }

    /// The reward of [`super::RewardWeights`] at the state `t`.
    fn reward(&self, t: &StepTelemetry, command: [f64; 3], a: [f64; 3], fell: bool) -> f64 {
        let w = &self.config.reward;
        let tilt2 = t.tilt_rad[0].powi(2) + t.tilt_rad[1].powi(2);
        let rate2 = t.body_rate_rad_per_s.x.powi(2) + t.body_rate_rad_per_s.y.powi(2);
        let (_, _, yaw) = t.body_orientation.euler_angles();
        let (s, c) = yaw.sin_cos();
        let v = &t.ball_velocity_m_per_s;
        let v_heading = [c * v.x + s * v.y, -s * v.x + c * v.y];
        let verr2 = (v_heading[0] - command[0]).powi(2) + (v_heading[1] - command[1]).powi(2);
        // The yaw rate in the world frame: the body's rate about the vertical.
        let yaw_rate = (t.body_orientation * t.body_rate_rad_per_s).z;
        let yerr2 = (yaw_rate - command[2]).powi(2);
        let action2 = a.iter().map(|x| x * x).sum::<f64>() / 3.0;
        let alive = if fell { 0.0 } else { w.alive };
        alive
            - w.tilt * tilt2 / 0.1_f64.powi(2)
            - w.body_rate * rate2
            - w.velocity_error * verr2 / 0.5_f64.powi(2)
            - w.yaw_rate_error * yerr2 / 0.5_f64.powi(2)
            - w.action * action2
    }
}

/// The largest initial tilt allowed with the controller underneath: 90 % of its supervisor's
/// arming limit, so that the IMU's noise cannot keep it from arming.
fn arm_tilt_limit_rad(controller: &BallbotControllerConfig<f64>) -> f64 {
    0.9 * controller.safety.arm_tilt_limit_rad
}

/// With the controller underneath, the initial tilt must let it arm.
fn check_arming(
    config: &EnvConfig,
    controller: &BallbotControllerConfig<f64>,
    ranges: &Randomization,
) -> Result<(), GymError> {
    let limit = arm_tilt_limit_rad(controller);
    match ranges.initial_tilt_rad {
        Some(r) if config.task == Task::Velocity && config.residual && r.hi >= limit => {
            Err(GymError::invalid(
                "randomization.initial_tilt_rad",
                "must stay below 90 % of the controller's arming tilt \
                 (safety.arm_tilt_limit_rad, 3 deg) with the LQR-PI underneath",
                r.hi,
            ))
        }
        _ => Ok(()),
    }
}

/// Which events of an episode's [`EventLog`] were in progress during a step, as indices into
/// its events (which are in order of onset and never removed).
#[derive(Debug, Default)]
struct StepEvents {
    indices: Vec<usize>,
    count_before: usize,
}

impl StepEvents {
    /// Before a step: keeps the events still going on (each began before the step and may
    /// end during it) and notes where the step's new events will start.
    fn begin(&mut self, log: &EventLog) {
        let events = log.events();
        self.indices
            .retain(|&i| events.get(i).is_some_and(|e| e.ongoing));
        self.count_before = events.len();
    }

    /// After a step: adds the events that began during it.
    fn end(&mut self, log: &EventLog) {
        self.indices.extend(self.count_before..log.events().len());
    }
}
