//! The multi-rate planar simulator: one WIP plane (or the PIPTB) with the things a real
//! drivetrain has and the controller's model does not.
//!
//! Layer rule: this is physics (with its multi-rate scheduler); it imports the core only, nothing from
//! `ballbot_log` (which records it: `ballbot_log::planar`), `ballbot_studies::studies`, `ballbot_studies::report` or the command line.
//!
//! - [`PlanarPlant`]: the core's nonlinear [`ballbot_core::Wip`], integrated with RK4 at a fixed
//!   rate (default 8 kHz), with [`TransmissionFriction`] (stiction, Coulomb, viscous; Karnopp
//!   stick-slip) on the motor joint and the actuator's peak torque and torque-speed line.
//! - [`Sensors`]: IMU tilt and rate with white noise and bias, a quantised motor encoder, a
//!   differenced and low-passed speed estimate; all noise from one seeded ChaCha8 stream.
//! - [`PlanarSim`]: runs a [`PlanarController`] with its main loop and its motor-drive loop at
//!   their own rates, with a one-period computation delay, and reports to an [`Observer`].

mod controller;
mod controllers;
mod error;
mod friction;
mod plant;
mod rollout;
mod sensors;
mod sim;

pub use controller::{
    CommandProfile, DriveMeasurement, DriveSetpoint, OuterMeasurement, PlanarCommand,
    PlanarController,
};
pub use controllers::{
    ControllerKind, ControllerSettings, LqrPiCascade, LqrTorque, PiPdTorque, TorqueMode,
};
pub use error::PlanarError;
pub use friction::{FrictionMode, TransmissionFriction};
pub use plant::{PlanarPlant, PlantStep};
pub use rollout::{Rollout, RolloutController, RolloutSettings, rollout};
pub use sensors::{ImuSample, SensorParams, Sensors, SpeedEstimator};
pub use sim::{Fault, FaultKind, Observer, OuterTick, PlanarSim, RunOutcome, SimConfig};
