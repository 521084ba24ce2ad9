// The crate documentation is the crate's README (crates.io shows the same text), so its first
// example is compiled and run as a doctest and cannot rot.
#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

pub mod ballbot;
mod check;
pub mod command;
pub mod control;
mod error;
pub mod estimation;
pub mod hal;
pub mod integrate;
pub mod kinematics;
pub mod linalg;
pub mod lqr;
mod names;
mod num;
pub mod params;
pub mod rates;
pub mod safety;
pub mod spin;
pub mod traction;
pub mod wip;

pub use error::Error;
pub use integrate::rk4_step;
pub use kinematics::{
    ContactForces, OmniKinematics, TorqueInterval, TorqueSaturation, WheelContact, WheelGeometry,
};
pub use names::ParseNameError;
pub use params::{
    ActuatorParams, BallbotParams, DrivetrainParams, PlanarRobotParams, SpinParams, WHEEL_COUNT,
    WipParams,
};
pub use spin::{Spin, SpinState};
pub use wip::{Wip, WipLinearization, WipReducedState, WipState};

/// The Rust examples of the repository's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
