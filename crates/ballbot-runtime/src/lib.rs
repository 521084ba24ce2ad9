//! # ballbot-runtime
//!
//! The robot's control loop on the core's hardware traits ([`ballbot_core::hal`]): the code a
//! firmware calls from its timer interrupts, and the same code every 3D closed-loop experiment
//! of the project runs (the rapier3d world implements the traits in `ballbot-sim`, the
//! decoupled demo plant in `ballbot-examples`). The planar research controllers (PIPTB, the
//! Python planar rollouts) run on the planar simulator's scheduler instead.
//!
//! - [`RobotLoop::outer_task`] at 400 Hz: sensors, supervisor, estimation, command shaping,
//!   LQR-PI planes, kinematics; references for the inner loop.
//! - [`RobotLoop::inner_task`] at 8 kHz: encoders, the three motor speed PIs, torques (or
//!   motors off).
//! - Start-up (arming after the body is upright and still), faults, and shutdown (a controlled
//!   stop, then disarm at rest).
//!
//! `#![no_std]`, no allocation, no panics: the workspace's no_std check (`nostd-check/`) links
//! it with a panic handler and no allocator.
//!
//! ```
//! use ballbot_core::BallbotParams;
//! use ballbot_core::ballbot::BallbotControllerConfig;
//! use ballbot_core::command::Command;
//! use ballbot_core::estimation::{EncoderSample, ImuSample};
//! use ballbot_core::hal::{Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders};
//! use ballbot_core::safety::{Mode, ModeRequest};
//! use ballbot_runtime::{LoopConfig, OperatorInput, Phase, RobotLoop};
//! use core::convert::Infallible;
//! use nalgebra::Vector3;
//!
//! // A robot standing still on a stand: upright IMU, still wheels, a stopped clock.
//! struct StillImu(u64);
//! impl Imu<f64> for StillImu {
//!     type Error = Infallible;
//!     fn read(&mut self) -> Result<ImuSample<f64>, Infallible> {
//!         self.0 += 2500;
//!         // A real IMU never repeats a reading bit for bit (the frozen-IMU check).
//!         let mut s = ImuSample::upright(self.0);
//!         s.angular_velocity_rad_per_s.x = 1e-6 * (self.0 % 7) as f64;
//!         Ok(s)
//!     }
//! }
//! struct StillWheels(u64);
//! impl WheelEncoders<f64> for StillWheels {
//!     type Error = Infallible;
//!     fn read(&mut self) -> Result<EncoderSample<f64>, Infallible> {
//!         self.0 += 125;
//!         Ok(EncoderSample::still(self.0))
//!     }
//! }
//! struct Motors(Vector3<f64>);
//! impl MotorTorques<f64> for Motors {
//!     type Error = Infallible;
//!     fn apply(&mut self, torque_nm: &Vector3<f64>) -> Result<[MotorFeedback<f64>; 3], Infallible> {
//!         // Drivers that deliver what they are told, at 45 V, the wheels still.
//!         let feedback = [0, 1, 2].map(|i| MotorFeedback::healthy(self.0[i], 0.0, 45.0));
//!         self.0 = *torque_nm;
//!         Ok(feedback)
//!     }
//!     fn disable(&mut self) -> Result<(), Infallible> {
//!         self.0 = Vector3::zeros();
//!         Ok(())
//!     }
//! }
//! struct Clock(u64);
//! impl MonotonicClock for Clock {
//!     fn now_us(&mut self) -> u64 {
//!         self.0
//!     }
//! }
//!
//! let config = BallbotControllerConfig::design(&BallbotParams::miapure_60kg())?;
//! let mut robot = RobotLoop::new(
//!     config,
//!     LoopConfig::miapure(),
//!     StillImu(0),
//!     StillWheels(0),
//!     Motors(Vector3::zeros()),
//!     Clock(0),
//! )?;
//! let operator = OperatorInput { command: Command::Stop, command_timestamp_us: None, request: ModeRequest::None };
//! assert_eq!(robot.outer_task(&operator).phase, Phase::StartingUp);
//! assert_eq!(robot.mode(), Mode::Idle);
//! # Ok::<(), ballbot_core::Error>(())
//! ```
#![no_std]
#![forbid(unsafe_code)]

mod robot_loop;

pub use robot_loop::{
    DeviceErrorCounts, InnerReport, LoopConfig, OperatorInput, OuterReport, Phase, RobotLoop,
};
