//! # ballbot-world
//!
//! The physics around [`ballbot_core`], and the robot loop on it (see `ARCHITECTURE.md`):
//!
//! - [`world`]: the rapier3d ballbot world with friction-cone omniwheel contacts, the
//!   drivetrain, the sensors and the floor;
//! - [`planar`]: the multi-rate planar simulator (the PIPTB testbed's physics);
//! - [`rig`]: the shipped robot loop (`ballbot_runtime::RobotLoop`) driving the world through
//!   the HAL traits, fault injection, and what happened in a run;
//! - [`export`]: the world's robot as MJCF and URDF;
//! - [`runner`]: the one job runner (independent jobs on every core, results in job order).
//!
//! Layer rule: this crate imports the core and the runtime, never logs, studies, reports or
//! the command line (`python3 scripts/check-layers.py` checks the crate graph).

pub mod export;
pub mod planar;
pub mod rig;
pub mod runner;
pub mod world;
