//! The 3D ballbot world on rapier3d (f64): floor, rubber ball, body, and three omniwheels
//! whose contacts carry compliant normal forces and friction-cone-bounded traction along
//! their rolling directions only.
//!
//! Layer rule: this is physics; it imports the core and nothing from `ballbot_studies::studies`,
//! `ballbot_studies::report` or the command line (the experiments run in it live in
//! `ballbot_studies::studies`).
//!
//! * [`sim`]: the world ([`BallbotWorld`]): rapier3d integrates ball and body.
//! * [`floor`]: the floor as a height map (a plane, its slope, bumps and steps) and the ball
//!   coating's compliant contact on it, with friction in a cone, rolling resistance and a
//!   torsional spin friction.
//! * [`contact`]: the omniwheel contact law and its step-size needs; [`rollers`] (roller
//!   gaps), [`axle_loss`] (roller losses along the axle) and [`rubber`] (stiffness and damping
//!   of the ball's coating) are its realistic mechanisms (on in the default world,
//!   [`WorldParams::realistic`]; off in [`WorldParams::ideal`]).
//! * [`disturbance`]: a payload that shifts, a bump or a step on the floor ([`FloorBump`],
//!   [`FloorStep`]).
//! * [`driver`]: the motor driver between torque command and motor (ideal line or ODrive);
//!   [`transmission`]: the drivetrain between motor and wheel (gearbox stiction, elastomeric
//!   coupling, backlash; rigid in [`WorldParams::ideal`]).
//! * [`sensors`], [`failure`], [`telemetry`]: IMU and encoders, failure detection, per-step
//!   records; [`imu`]: the IMU's attitude filter, bias and delay (on in the default world).
//!
//! MCAP logs of world runs (telemetry, controller, a Foxglove 3D scene) are written by
//! `ballbot_log::WorldLogger` (`ballbot_log::world`).
//!
//! Why `rapier3d-f64`: the contact deflections are a fraction of a millimetre (0.17 mm under the
//! static load) and are computed from positions of ball and body that travel metres; in `f32`
//! at 10 m the position resolution (about 1 um) is already 1 % of the deflection and the normal
//! forces would become noisy. The core runs in `f64` too, so no conversions are needed.

pub mod axle_loss;
mod check;
pub mod contact;
pub mod disturbance;
pub mod driver;
pub mod failure;
pub mod floor;
pub mod imu;
pub(crate) mod num;
pub mod params;
mod rigid;
pub mod rollers;
pub mod rubber;
pub mod sensors;
pub mod sim;
pub mod telemetry;
pub mod transmission;

pub use axle_loss::AxleLossParams;
pub use driver::{DriverLimit, DriverModel, DriverParams};
pub use failure::{Failure, FailureKind, StopRules, wheel_name};
pub use floor::{FloorBump, FloorParams, FloorStep};
pub use imu::{ImuModel, ImuParams};
pub use params::{
    ContactNormalLaw, ContactParams, DEFAULT_RIGID_STEP_RATIO, FailureParams,
    MAX_BALL_CONTACT_PHASE_RAD, MAX_RIGID_STEP_RATIO, SensorParams, WorldParams,
};
pub use rollers::{RollerParams, RollerProfile};
pub use rubber::RubberLayer;
pub use sensors::Measurement;
pub use sim::BallbotWorld;
pub use telemetry::{StepTelemetry, WheelTelemetry};
pub use transmission::{GearboxMode, TransmissionParams};

/// What can go wrong building the world.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WorldError {
    /// A robot parameter from the core is out of range.
    #[error("robot parameters: {0}")]
    Robot(#[from] ballbot_core::Error),
    /// A world parameter is out of range.
    #[error("invalid parameter `{field}`: {requirement}")]
    InvalidParameter {
        /// The field's name.
        field: &'static str,
        /// The bound it violates.
        requirement: &'static str,
    },
}
