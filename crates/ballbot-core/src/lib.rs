//! # ballbot-core
//!
//! Models and controllers of a ballbot drivetrain (ball-balancing robot), written to run inside
//! a robot's firmware loop: `#![no_std]`, no allocation, no panics, bounded time, generic over
//! `f32` and `f64`.
//!
//! It implements "Design and Control of a Ballbot Drivetrain with High Agility, Minimal
//! Footprint, and High Payload" (MiaPURE, PIPTB): the planar wheeled-inverted-pendulum and spin
//! models, the omniwheel kinematics, LQR synthesis, and the LQR, cascaded PI-PD and cascaded
//! LQR-PI controllers.
//!
//! ```
//! use ballbot_core::{Wip, WipParams};
//! let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
//! // Open-loop poles 0, 0, +-8.04 rad/s for MiaPURE with 60 kg.
//! approx::assert_relative_eq!(wip.upright_unstable_pole_rad_per_s(), 8.04, epsilon = 0.01);
//! # Ok::<(), ballbot_core::Error>(())
//! ```
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
