//! Traction-aware control: every direction safe, not only the strong ones.
//!
//! The paper ends on omniwheel slip: accelerating towards OW1 (0 deg) unloads the two wheels
//! that drive, so the same acceleration that is safe towards 180 deg makes them slip towards
//! 0 deg, and the authors ask for mitigation "to ensure that all translational directions are
//! safe". This module gives the 3D controller what it needs for that, inside the outer step's
//! no-allocation, bounded-time budget:
//!
//! 1. [`TractionEnvelope`]: the largest acceleration in each direction that keeps every wheel
//!    inside a margin of its friction cone (`mu / safety factor`) and above a minimum normal
//!    force, from the core's contact model at the quasi-static accelerating equilibrium; a
//!    table over direction built at configuration time, plus the actuators' speed-dependent
//!    limit evaluated every step.
//! 2. The command shaper follows it ([`CommandShaper::step_within`]): velocity, lean-to-drive
//!    and trajectory commands accelerate at most at the envelope along their direction, the
//!    vector acceleration (not each axis) bounded; braking is never limited below
//!    [`TractionParams::min_braking_decel_m_per_s2`].
//! 3. [`SlipMonitor`]: slip of each wheel from the sensors' redundancy (two momentum observers
//!    and the ball's no-spin condition), imminent lift-off from the predicted normal forces,
//!    and the reaction of a traction control: less acceleration (reached within the shaper's
//!    jerk limit), the slip taken off the ball-rate estimate, balancing on, a controlled stop
//!    ([`Fault::WheelSlip`]) if the slip persists, and a friction estimate.
//!
//! `with_traction_control` also turns on the shaper's 0.3 s reference filter, without which
//! the ball overshoots the envelope where an acceleration ends. `docs/traction.md` has the
//! defaults with their sources and the measurements in the 3D world.
//!
//! Enable it with [`BallbotControllerConfig::with_traction_control`]; it is off in
//! [`BallbotControllerConfig::design`], which keeps the paper's controller.
//!
//! ```
//! use ballbot_core::BallbotParams;
//! use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
//! use ballbot_core::command::{Command, VelocityCommand};
//! use ballbot_core::estimation::{EncoderSample, ImuSample};
//! use ballbot_core::safety::ModeRequest;
//! let robot = BallbotParams::<f64>::miapure_60kg();
//! let mut config = BallbotControllerConfig::design(&robot)?.with_traction_control();
//! config.shaping.translation.max_rate_per_s = 3.0; // the user would allow 3 m/s^2
//! let mut outer = BallbotController::new(config)?;
//! let go = Command::Velocity(VelocityCommand { vx_m_per_s: 2.0, ..VelocityCommand::zero() });
//! let mut out = None;
//! for k in 0..400u64 {
//!     let now_us = k * 2500;
//!     // The pitch dithers by 0.1 mrad: a bit-identical IMU would be a frozen-IMU fault.
//!     let imu = ImuSample { pitch_rad: 1e-4 * (k % 2) as f64, ..ImuSample::upright(now_us) };
//!     out = Some(outer.step(&OuterInput {
//!         now_us,
//!         imu,
//!         encoders: EncoderSample::still(now_us),
//!         command: go,
//!         command_timestamp_us: Some(now_us),
//!         request: if k == 0 { ModeRequest::Arm } else { ModeRequest::None },
//!     }));
//! }
//! let traction = out.unwrap().traction.unwrap();
//! // Towards OW1 the envelope, not the user's 3 m/s^2, sets the acceleration.
//! let limit = traction.accel_limit_m_per_s2.unwrap();
//! assert!(traction.limited && limit < 1.5, "{limit}");
//! # Ok::<(), ballbot_core::Error>(())
//! ```
//!
//! [`CommandShaper::step_within`]: crate::command::CommandShaper::step_within
//! [`Fault::WheelSlip`]: crate::safety::Fault::WheelSlip
//! [`BallbotControllerConfig::with_traction_control`]: crate::ballbot::BallbotControllerConfig::with_traction_control
//! [`BallbotControllerConfig::design`]: crate::ballbot::BallbotControllerConfig::design

mod control;
mod envelope;
mod monitor;
mod params;

pub use control::{TractionControl, TractionStatus};
pub use envelope::{ENVELOPE_DIRECTIONS, TractionEnvelope};
pub(crate) use monitor::TiltTerms;
pub use monitor::{SlipMonitor, SlipStatus};
pub use params::TractionParams;
