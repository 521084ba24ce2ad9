//! The 3D ballbot controller: the paper's cascaded LQR-PI on MiaPURE (Sec. IV-D, Fig.
//! "PURE_control"), with command shaping and safety supervision.
//!
//! Two pieces, because on the robot they run on different processors:
//!
//! - [`BallbotController`], the **outer loop** (main controller, 400 Hz):
//!   1. [`SafetySupervisor`] checks the samples, timing and command link, runs the mode
//!      machine;
//!   2. [`Estimator`] builds the sagittal, frontal and spin states (inverse kinematics);
//!   3. [`CommandShaper`] turns the command (or, in a controlled stop, "come to rest") into
//!      jerk-limited planar command states;
//!   4. two [`LqrPiOuter`] planes (frontal x, sagittal y) and a [`SpinOuter`] give the reference
//!      planar torques `u_r = [tau_rx, tau_ry, tau_rz]` and reference rates
//!      `[phi_dot_rx, phi_dot_ry, theta_dot_rz]` (reference WIP and spin models);
//!   5. the kinematics ([`OmniKinematics`]) maps them to per-omniwheel feedforward torques
//!      `tau_r = J^-T S u_r` (scaled uniformly into the actuator limits) and reference
//!      omniwheel speeds `psi_dot_r = J [phi_dot_rx - theta_dot_x, phi_dot_ry - theta_dot_y,
//!      k . [phi_dot_rx, phi_dot_ry] - theta_dot_rz]` (measured tilt rates: the motor driver
//!      controls the relative rate). `k` ([`ball_body_z_rate_per_ball_rate`], 0 upright) is
//!      the rolling ball's rate about the leaning body's z axis when it does not spin about
//!      the vertical; without it the wheels turn a sideways lean at speed into a yaw rate
//!      (`-tan(roll) phi_dot_y`), which made the closed loop's yaw diverge above 2.6 m/s.
//!      The paper's upright mapping (`k = 0`, MODEL.md section 4) remains available as an
//!      ablation, [`WheelMapping::Upright`] ([`BallbotControllerConfig::with_paper_ablation`]).
//!
//!   Its output is a small [`MotorReferences`] value: what the main controller sends to the
//!   motor drivers.
//! - [`MotorSpeedLoop`], the **inner loop** (motor drivers, 8 kHz): one [`SpeedPi`] per
//!   omniwheel, `tau_i = sat(tau_ri + kp (psi_dot_ri - psi_dot_i) + I_i)` within the actuator's
//!   torque-speed limits ([`ActuatorParams::torque_bounds_nm`]), back-calculation anti-windup
//!   driven by the applied torque.
//!
//! **Guarantees**, whatever the input (tested with proptest): no panic, no allocation, bounded
//! time; every output finite; feedforward torques within the actuator peak, reference speeds
//! within the no-load speed, applied torques within the actuator's torque-speed limits; motors
//! disabled (zero torque, integrators cleared) outside [`Mode::Balancing`] and
//! [`Mode::ControlledStop`].
//!
//! **Per-motor PI gains** ([`motor_speed_pi_gains`]). With the reference model equal to the
//! plant, each plane's ball-rate error obeys `e_dot = -B4 tau_e`. The wheel error is
//! `J e` and a wheel PI `tau_w = kp e_w` gives the planar torque `S J^T kp J e`; for the
//! symmetric layout `J^T J = (r_S / r_W)^2 diag(3/2 cos^2 a, 3/2 cos^2 a, 3 sin^2 a)`, so in
//! translation the wheel loop acts like a planar PI on the plant `b_w = B4 (J^T J)_xx`.
//! Designing the wheel PI for `b_w` reproduces the planar PI of the paper exactly.
//!
//! ```
//! use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput};
//! use ballbot_core::command::{Command, VelocityCommand};
//! use ballbot_core::estimation::{EncoderSample, ImuSample};
//! use ballbot_core::safety::{Mode, ModeRequest};
//! use ballbot_core::BallbotParams;
//! let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
//! let mut outer = BallbotController::new(config)?;
//! let mut inner = MotorSpeedLoop::new(&config)?;
//! let input = OuterInput {
//!     now_us: 0,
//!     imu: ImuSample::upright(0),
//!     encoders: EncoderSample::still(0),
//!     command: Command::Velocity(VelocityCommand::zero()),
//!     command_timestamp_us: Some(0),
//!     request: ModeRequest::Arm,
//! };
//! let out = outer.step(&input);
//! assert_eq!(out.safety.mode, Mode::Balancing);
//! // 20 inner steps per outer step at 8 kHz.
//! inner.set_references(&out.motors);
//! let torques = inner.step(&input.encoders.wheel_speeds_rad_per_s, 1.25e-4);
//! assert!(torques.torque_nm.iter().all(|t| t.abs() <= 43.2));
//! # Ok::<(), ballbot_core::Error>(())
//! ```
//!
//! [`ball_body_z_rate_per_ball_rate`]: crate::estimation::ball_body_z_rate_per_ball_rate
//! [`SafetySupervisor`]: crate::safety::SafetySupervisor
//! [`Estimator`]: crate::estimation::Estimator
//! [`CommandShaper`]: crate::command::CommandShaper
//! [`LqrPiOuter`]: crate::control::LqrPiOuter
//! [`OmniKinematics`]: crate::OmniKinematics
//! [`SpeedPi`]: crate::control::SpeedPi
//! [`ActuatorParams::torque_bounds_nm`]: crate::ActuatorParams::torque_bounds_nm
//! [`Mode::Balancing`]: crate::safety::Mode::Balancing
//! [`Mode::ControlledStop`]: crate::safety::Mode::ControlledStop

mod balance;
mod balancing;
mod design;
mod feedforward;
mod guard;
mod imu_lean;
mod mapping;
mod motor;
mod outer;
mod outer_io;
mod spin;
#[cfg(test)]
mod tests;
mod trajectory_limits;

pub use balance::{BalancePoint, BalancePointParams, BalanceSample};
pub use design::{BalancingLaw, BallbotControllerConfig, BallbotDesign, motor_speed_pi_gains};
pub use guard::SpeedGuard;
pub use imu_lean::{ImuLean, ImuLeanParams};
pub use mapping::WheelMapping;
pub use motor::{InnerOutput, MotorSpeedLoop, MotorSpeedPi};
pub use outer::BallbotController;
pub use outer_io::{MotorReferences, OuterInput, OuterOutput};
pub use spin::{SpinGains, SpinOuter, SpinOuterConfig, SpinOuterOutput};
