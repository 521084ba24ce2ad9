//! # ballbot-sim
//!
//! Simulation and experiments around [`ballbot_core`]: the multi-rate planar simulator, the
//! rapier3d ballbot world with friction-cone omniwheel contacts, trajectory optimisation with
//! clarabel, MCAP logging, and the `ballbot` command line.

pub mod cli;
pub mod experiments;
pub mod log;
pub mod planar;
pub mod plot;
pub mod rig;
pub mod scenario;
pub mod trajopt;
pub mod world;
