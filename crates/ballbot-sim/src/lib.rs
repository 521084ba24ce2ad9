//! # ballbot-sim
//!
//! Simulation and experiments around `ballbot-core` in one dependency: this crate re-exports
//! the layer crates under the module paths the project has always used (see `ARCHITECTURE.md`):
//!
//! - physics ([`ballbot_world`]): [`world`] (the rapier3d ballbot world with friction-cone
//!   omniwheel contacts), [`planar`] (the multi-rate planar simulator), [`rig`] (the shipped
//!   robot loop on the simulated devices) and [`export`] (the world's robot as MJCF and URDF);
//! - [`trajopt`] ([`ballbot_trajopt`]): braking trajectories, clarabel;
//! - [`log`] ([`ballbot_log`]): MCAP logging and reading, the live view (feature `live`);
//! - [`gym`] ([`ballbot_gym`]): the reinforcement-learning environments;
//! - [`studies`], [`report`] and [`params_file`] ([`ballbot_studies`]): the paper's
//!   experiments on that physics with one experiment driver, their JSON, tables and figures
//!   (figures behind the `plot` feature), and every parameter file's schema, checks, presets
//!   and differences (`ballbot params`).
//!
//! A program that needs only one layer depends on its crate (a controller study on the world
//! needs `ballbot-world` alone). The `ballbot` command line is the `ballbot-cli` crate.

pub use ballbot_gym as gym;
pub use ballbot_log as log;
pub use ballbot_studies::{params_file, report, studies};
pub use ballbot_trajopt as trajopt;
pub use ballbot_world::{export, planar, rig, world};
