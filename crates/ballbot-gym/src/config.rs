//! [`EnvConfig`]: what an environment is (task, world, rates, observation, reward), and its
//! validation. Every field is checked at construction; an error names the field and the bound.

pub use super::error::GymError;
use super::randomize::Randomization;
use ballbot_world::world::{StopRules, WorldParams};
use serde::{Deserialize, Serialize};

/// What the agent does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Task {
    /// `ballbot/Balance-v0`: the action is the three wheel torques, normalised to [-1, 1] of
    /// the actuator's peak torque; the robot starts from a random tilt and should stand.
    Balance,
    /// `ballbot/Velocity-v0`: track random velocity commands. With
    /// [`EnvConfig::residual`] the core's cascaded LQR-PI runs underneath and the action adds
    /// a residual wheel torque (a fraction [`EnvConfig::residual_fraction`] of peak torque);
    /// without it the action is the torque, as in `Balance`.
    Velocity,
}

impl Task {
    /// The canonical name: `balance` or `velocity`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Balance => "balance",
            Self::Velocity => "velocity",
        }
    }
}

impl core::str::FromStr for Task {
    type Err = GymError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "balance" => Ok(Self::Balance),
            "velocity" => Ok(Self::Velocity),
            _ => Err(GymError::invalid(
                "task",
                "must be \"balance\" or \"velocity\"",
                s,
            )),
        }
    }
}

/// The velocity commands of the `Velocity` task: a new command every `period_secs`, its speed
/// uniform in `[0, max_speed_m_per_s]` at a uniform heading (body frame), its yaw rate uniform
/// in `+-max_yaw_rate_rad_per_s`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CommandRanges {
    /// Largest commanded speed (m/s). Default 1.0.
    pub max_speed_m_per_s: f64,
    /// Largest commanded yaw rate (rad/s). Default 0.5.
    pub max_yaw_rate_rad_per_s: f64,
    /// Time between command changes (s). Default 2.5.
    pub period_secs: f64,
}

impl Default for CommandRanges {
    fn default() -> Self {
        Self {
            max_speed_m_per_s: 1.0,
            max_yaw_rate_rad_per_s: 0.5,
            period_secs: 2.5,
        }
    }
}

/// The weights of the reward, one formula for both tasks (the `Balance` task's command is
/// zero):
///
/// `r = alive - tilt (|tilt| / 0.1 rad)^2 - body_rate (|w_xy| / 1 rad/s)^2
///      - velocity_error (|v_xy - v_cmd| / 0.5 m/s)^2 - yaw_rate_error ((w_z - w_cmd) / 0.5 rad/s)^2
///      - action |a|^2 / 3`
///
/// with the body's true tilt and rates, the ball's velocity in the heading frame and the
/// normalised action `a`. A termination ([`EnvConfig::stop_rules`]) ends the episode and
/// forfeits the alive reward of the steps it did not live.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RewardWeights {
    /// Reward per step for staying up. Default 1.
    pub alive: f64,
    /// Weight of the squared tilt. Default 0.5.
    pub tilt: f64,
    /// Weight of the squared horizontal body rate. Default 0.05.
    pub body_rate: f64,
    /// Weight of the squared velocity error. Default 0.2.
    pub velocity_error: f64,
    /// Weight of the squared yaw-rate error. Default 0.05.
    pub yaw_rate_error: f64,
    /// Weight of the squared normalised action. Default 0.01.
    pub action: f64,
}

impl Default for RewardWeights {
    fn default() -> Self {
        Self {
            alive: 1.0,
            tilt: 0.5,
            body_rate: 0.05,
            velocity_error: 0.2,
            yaw_rate_error: 0.05,
            action: 0.01,
        }
    }
}

/// Everything an environment needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvConfig {
    /// The task.
    pub task: Task,
    /// The nominal world; each episode applies its [`Randomization`] draw to it.
    pub world: WorldParams,
    /// Agent steps per second. Default 400 (the outer loop's rate); `1 / world.dt_secs` must be
    /// a whole multiple of it.
    pub control_hz: f64,
    /// The time limit (s): an episode that reaches it ends `truncated`. Default 10.
    pub max_episode_secs: f64,
    /// The observation ends with the last action (3 more entries). Default false.
    pub last_action_in_observation: bool,
    /// `Velocity` task: the action is a residual on top of the core's LQR-PI (default true).
    pub residual: bool,
    /// The residual's full scale as a fraction of peak torque. Default 0.2.
    pub residual_fraction: f64,
    /// The velocity commands of the `Velocity` task.
    pub commands: CommandRanges,
    /// The reward's weights.
    pub reward: RewardWeights,
    /// The domain randomisation of every episode (none by default).
    pub randomization: Randomization,
    /// Which world failures end an episode `terminated`, besides the chassis touching the
    /// floor (which always does). Default [`Self::DEFAULT_STOP_RULES`]: tilt beyond the failure
    /// tilt and a motor driver trip; a wheel's slip and lift-off are reported as events
    /// ([`super::BallbotEnv::step_events`]) and the episode goes on. [`StopRules::all()`] ends
    /// it at the first slip longer than `world.failure.max_slip_duration_secs` or lift-off
    /// longer than `max_lift_off_duration_secs` too, as every episode did before.
    pub stop_rules: StopRules,
}

impl EnvConfig {
    /// The stop rules of [`Self::new`]: [`StopRules::contact_rules_off`], the project's
    /// definition of a fall (the Monte Carlo's fall count, `world_push.rules_relaxed`).
    ///
    /// - The chassis on the floor always ends an episode: a fall, by geometry.
    /// - Tilt beyond `world.failure.max_tilt_rad` (25 deg) is on: a fall called before the
    ///   chassis reaches the floor. It is 5 deg past the tilt the core's supervisor gives up at
    ///   as unrecoverable (`SafetyParams::tilt_limit_rad`, 20 deg); running on would only add
    ///   the steps of the fall.
    /// - A driver trip is on: not a fall, but the end of the robot's balance. The driver stays
    ///   disarmed for the rest of the episode, so that wheel has no torque whatever the agent
    ///   does (and in `Velocity` the controller's motor-health monitor switches the motors off).
    /// - Slip and lift-off are off: contact events a robot can recover from (a push that lifts
    ///   a wheel for longer than 20 ms can be recovered: `world_push.rules_relaxed`,
    ///   docs/results.md). They are reported as events, and an agent can learn what they cost.
    ///
    /// ```
    /// use ballbot_gym::{EnvConfig, Task};
    /// assert_eq!(EnvConfig::DEFAULT_STOP_RULES.to_string(), "tilt,driver-trip");
    /// assert_eq!(EnvConfig::new(Task::Balance).stop_rules, EnvConfig::DEFAULT_STOP_RULES);
    /// ```
    pub const DEFAULT_STOP_RULES: StopRules = StopRules::contact_rules_off();

    /// The task's defaults on MiaPURE with 60 kg. `Balance` starts each episode from a tilt
    /// uniform in [0, 0.1] rad at a uniform direction; `Velocity` from upright.
    ///
    /// ```
    /// use ballbot_gym::{EnvConfig, Task};
    /// let config = EnvConfig::new(Task::Balance);
    /// assert_eq!(config.control_hz, 400.0);
    /// assert_eq!(config.steps_per_action()?, 20);
    /// # Ok::<(), ballbot_gym::GymError>(())
    /// ```
    pub fn new(task: Task) -> Self {
        let randomization = match task {
            Task::Balance => Randomization {
                initial_tilt_rad: Some((0.0, 0.1).into()),
                ..Randomization::default()
            },
            Task::Velocity => Randomization::default(),
        };
        Self {
            task,
            world: WorldParams::miapure_60kg(),
            control_hz: 400.0,
            max_episode_secs: 10.0,
            last_action_in_observation: false,
            residual: true,
            residual_fraction: 0.2,
            commands: CommandRanges::default(),
            reward: RewardWeights::default(),
            randomization,
            stop_rules: Self::DEFAULT_STOP_RULES,
        }
    }

    /// Physics steps per agent step (`1 / (world.dt_secs * control_hz)`), or the error naming
    /// the field.
    pub fn steps_per_action(&self) -> Result<u32, GymError> {
        let hz = self.control_hz;
        if !(hz.is_finite() && hz > 0.0) {
            return Err(GymError::invalid(
                "control_hz",
                "must be finite and > 0",
                hz,
            ));
        }
        let ratio = 1.0 / (self.world.dt_secs * hz);
        if !(ratio.is_finite() && ratio >= 1.0 && (ratio - ratio.round()).abs() < 1e-6) {
            return Err(GymError::invalid(
                "control_hz",
                "the physics rate 1 / world.dt_secs must be a whole multiple of it",
                hz,
            ));
        }
        Ok(ratio.round() as u32)
    }

    /// Checks every field (and the randomisation's extremes against the world's bounds).
    pub fn validate(&self) -> Result<(), GymError> {
        self.world.validate()?;
        self.steps_per_action()?;
        let positive = |field: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(GymError::invalid(field, "must be finite and > 0", x))
            }
        };
        let non_negative = |field: &str, x: f64| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err(GymError::invalid(field, "must be finite and >= 0", x))
            }
        };
        positive("max_episode_secs", self.max_episode_secs)?;
        if !(self.residual_fraction.is_finite()
            && self.residual_fraction > 0.0
            && self.residual_fraction <= 1.0)
        {
            return Err(GymError::invalid(
                "residual_fraction",
                "must be in (0, 1]",
                self.residual_fraction,
            ));
        }
        non_negative(
            "commands.max_speed_m_per_s",
            self.commands.max_speed_m_per_s,
        )?;
        non_negative(
            "commands.max_yaw_rate_rad_per_s",
            self.commands.max_yaw_rate_rad_per_s,
        )?;
        positive("commands.period_secs", self.commands.period_secs)?;
        let r = &self.reward;
        for (field, w) in [
            ("reward.alive", r.alive),
            ("reward.tilt", r.tilt),
            ("reward.body_rate", r.body_rate),
            ("reward.velocity_error", r.velocity_error),
            ("reward.yaw_rate_error", r.yaw_rate_error),
            ("reward.action", r.action),
        ] {
            if !w.is_finite() {
                return Err(GymError::invalid(field, "must be finite", w));
            }
        }
        self.randomization.validate(&self.world)
    }
}
