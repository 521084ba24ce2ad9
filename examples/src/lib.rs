//! # ballbot-examples
//!
//! Embedding the ballbot controller in a robot binary. This library is `#![no_std]`: it runs
//! the shipped robot loop ([`ballbot_runtime::RobotLoop`], linked by the workspace's no_std
//! check `nostd-check/`) on a PC against the simulated devices of [`sim`].
//!
//! - [`sim`]: the core's hardware traits ([`ballbot_core::hal`]) implemented by a simulated
//!   MiaPURE (decoupled planar plants coupled through the omniwheel kinematics).
//! - [`demo`]: the scripted demonstration (arming, driving, a lost command link, shutdown).
//!
//! Runnable examples (`examples/examples/`): `robot_loop` (the loop on the simulated robot:
//! arming, driving, a lost command link, shutdown) and `gains` (the controller gains for a
//! parameter file). See `docs/embedding.md`.
//!
//! ```
//! use ballbot_core::BallbotParams;
//! use ballbot_core::ballbot::BallbotControllerConfig;
//! use ballbot_core::command::Command;
//! use ballbot_core::safety::{Mode, ModeRequest};
//! use ballbot_runtime::{LoopConfig, OperatorInput, RobotLoop};
//! use ballbot_examples::sim::{SimPlant, devices};
//! use core::cell::RefCell;
//!
//! let robot = BallbotParams::miapure_60kg();
//! let plant = RefCell::new(SimPlant::new(&robot)?);
//! let (imu, encoders, motors, clock) = devices(&plant);
//! let config = BallbotControllerConfig::design(&robot)?;
//! let mut robot_loop = RobotLoop::new(config, LoopConfig::miapure(), imu, encoders, motors, clock)?;
//! // Half a second: 0.25 s upright and still, then armed and balancing.
//! for tick in 0..4000u64 {
//!     if tick % 20 == 0 {
//!         let now_us = plant.borrow().now_us;
//!         robot_loop.outer_task(&OperatorInput {
//!             command: Command::Stop,
//!             command_timestamp_us: Some(now_us),
//!             request: ModeRequest::None,
//!         });
//!     }
//!     robot_loop.inner_task();
//!     plant.borrow_mut().advance(125);
//! }
//! assert_eq!(robot_loop.mode(), Mode::Balancing);
//! # Ok::<(), ballbot_core::Error>(())
//! ```
#![cfg_attr(not(test), no_std)]

pub mod demo;
pub mod sim;
