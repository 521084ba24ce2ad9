//! Physical parameters, validated once, and the presets of the paper's robots.
//!
//! Every field carries its unit in its name. Values labelled *estimate* in the docs are
//! engineering estimates standing in for the paper's missing parameter table (see
//! `docs/model.md`); they are parameters, never hidden constants.

mod actuator;
mod drivetrain;
mod robot;
mod spin;
mod wip;

pub use actuator::ActuatorParams;
pub use drivetrain::{DrivetrainParams, WHEEL_COUNT};
pub use robot::{BallbotParams, PlanarRobotParams};
pub use spin::SpinParams;
pub use wip::WipParams;
