//! Reinforcement-learning environments on the rapier3d world, in Rust: the engine behind the
//! Python package's Gymnasium environments (`ballbot.gym`).
//!
//! - [`BallbotEnv`]: one environment with Gymnasium's `reset` / `step` protocol, seeded,
//!   `terminated` on a fall by default ([`EnvConfig::stop_rules`], [`Termination`]), its
//!   contact events recorded ([`BallbotEnv::step_events`], [`BallbotEnv::events`]);
//! - [`VecEnv`]: N of them stepped in one call on a thread pool, with next-step autoreset;
//! - [`EnvConfig`]: the task ([`Task::Balance`]: wheel torques; [`Task::Velocity`]: track
//!   velocity commands, by default as a residual on top of the core's LQR-PI), the world, the
//!   control rate, the observation ([`observation_len`], bounds in [`observe`]) and the reward
//!   ([`RewardWeights`]);
//! - [`Randomization`] and [`EpisodeDraw`]: domain randomisation per episode, seeded.

pub mod config;
pub mod env;
pub mod error;
pub mod observe;
mod plant;
pub mod randomize;
pub mod vector;

pub use config::{CommandRanges, EnvConfig, RewardWeights, Task};
pub use env::{BallbotEnv, ResetInfo, ResetOptions, StepInfo, StepOutcome, Termination};
pub use error::GymError;
pub use observe::{GYRO_RANGE_RAD_PER_S, observation_high, observation_len};
pub use randomize::{EpisodeDraw, MAX_SENSOR_DELAY_SECS, Randomization, Range};
pub use vector::{VecEnv, VecInfo, VecStep};
