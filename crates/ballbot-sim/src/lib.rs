//! # ballbot-sim
//!
//! Simulation and experiments around [`ballbot_core`], in layers (see `ARCHITECTURE.md`):
//!
//! - physics: [`world`] (the rapier3d ballbot world with friction-cone omniwheel contacts) and
//!   [`planar`] (the multi-rate planar simulator); [`trajopt`] (braking trajectories, clarabel);
//! - [`studies`]: the paper's experiments on that physics, with one shared job runner;
//! - [`report`]: their JSON, tables and figures (figures behind the `plot` feature);
//! - [`log`]: MCAP logging and reading; [`studies::scenario`]: scenario files; [`params_file`]: every
//!   parameter file's schema, checks, presets and differences (`ballbot params`);
//!   [`export`]: the world's robot as MJCF and URDF (`ballbot export`).
//!
//! The `ballbot` command line is the `ballbot-cli` crate.

pub mod export;
pub mod gym;
pub mod log;
pub mod params_file;
pub mod planar;
pub mod report;
pub mod rig;
pub mod studies;
pub mod trajopt;
pub mod world;
