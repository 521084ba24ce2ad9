//! Safety supervision: sensor and timing checks, typed fault codes, and the mode state machine.
//!
//! # Modes and transitions
//!
//! ```text
//!            Arm (no fault, upright, still)
//!   Idle ───────────────────────────────────▶ Balancing ◀──────────┐
//!    ▲ ▲                                         │                  │ Resume (no fault)
//!    │ │ Disarm                                  │ Stop, or a       │
//!    │ └─────────────── (Balancing or            ▼ recoverable fault│
//!    │                   ControlledStop)    ControlledStop ─────────┘
//!    │ Reset                                     │
//!    │                         unrecoverable     │ unrecoverable
//!  Fault ◀──────────────────── fault from ───────┘ fault
//!                              Balancing or ControlledStop
//! ```
//!
//! - **Idle**: motors off. Faults are reported but change nothing; arming is refused while any
//!   fault is active or the body is not upright and still.
//! - **Balancing**: following the operator's command.
//! - **ControlledStop**: still balancing (motors on), the command replaced by "come to rest and
//!   hold upright": for a rideable robot zero torque means a fall, so a recoverable fault
//!   never switches the motors off. It stays here, holding, until `Resume` (accepted once no
//!   fault is active) or `Disarm`.
//! - **Fault**: motors off, entered on an unrecoverable fault; left only by `Reset` (to Idle).
//!
//! Priority within one step: an unrecoverable fault, then `Disarm`, then a recoverable fault or
//! `Stop`, then `Resume`.
//!
//! # Faults
//!
//! Each [`Fault`] has a fixed [`Severity`]:
//!
//! | fault | detected when | severity |
//! |---|---|---|
//! | `ImuNonFinite`, `ImuOutOfRange` | the IMU sample has a NaN/inf, or an angle or rate beyond its range | recoverable: the sample is rejected, the last good one held |
//! | `ImuStale` | no valid IMU sample newer than `imu_timeout_us`, or none with a new timestamp for its ticks ([`SafetyParams::timeout_ticks`]) | unrecoverable |
//! | `ImuFrozen` | bit-identical IMU readings for `frozen_imu_timeout_us` (or its ticks) | unrecoverable |
//! | `EncoderNonFinite`, `EncoderOutOfRange` | as for the IMU | recoverable (sample rejected) |
//! | `EncoderStale` | no valid encoder sample newer than `encoder_timeout_us` (or its ticks); or reported by the runtime: the 8 kHz guard held a wheel for as long | unrecoverable |
//! | `TiltLimit` | the tilt from the vertical ([`tilt_from_vertical_rad`]) beyond `tilt_limit_rad` | unrecoverable |
//! | `WheelSpeedLimit` | an omniwheel faster than `wheel_speed_limit_rad_per_s` | recoverable |
//! | `LoopOverrun` | more than `max_loop_period_us` since the previous step, or reported | recoverable |
//! | `ClockFault` | the clock went backwards | recoverable |
//! | `CommandLinkLost` | no command newer than `command_timeout_us` (or its ticks) | recoverable |
//! | `CommandNonFinite` | the command holds a NaN/inf | recoverable |
//! | `StateNonFinite` | reported by the controller: its estimate or output went non-finite | unrecoverable |
//! | `WheelSlip` | reported by the controller: a wheel kept slipping despite the traction reaction ([`crate::traction`]) | recoverable |
//! | `ClockStalled` | the clock did not advance between two steps | recoverable (the tick watchdogs still run) |
//! | `EncoderImplausible` | reported by the runtime from the 8 kHz guard ([`crate::ballbot::SpeedGuard`]): a wheel's samples rejected for longer than the hold, without a continuous trajectory | recoverable (the guard holds the last plausible speed) |
//! | `MotorDead`, `MotorStuck`, `MotorTripped` | reported by the robot loop's 8 kHz task: a driver's feedback shows no torque, a torque that does not follow the command, or an error flag ([`MotorHealthMonitor`]) | unrecoverable |
//! | `MotorUnanswered` | reported by the robot loop's 8 kHz task: every write to the drivers failed for the health monitor's persistence ([`MotorHealthMonitor::unanswered`]) | unrecoverable |
//!
//! A single bad sample therefore starts a controlled stop on held data; if no good sample
//! follows within the timeout the data is stale and the motors are disabled. Each step is a
//! tick: staleness is counted in ticks as well as by the clock, so a clock that stalls or
//! steps back cannot keep held data fresh.
//!
//! ```
//! use ballbot_core::estimation::{EncoderSample, ImuSample};
//! use ballbot_core::safety::{Mode, ModeRequest, SafetyInput, SafetyParams, SafetySupervisor};
//! let mut params = SafetyParams::<f64>::miapure();
//! params.frozen_imu_timeout_us = None; // these made-up samples are noiseless
//! let mut sup = SafetySupervisor::new(params)?;
//! let input = |t_us: u64, request| SafetyInput {
//!     now_us: t_us,
//!     imu: ImuSample::upright(t_us),
//!     encoders: EncoderSample::still(t_us),
//!     command_timestamp_us: Some(t_us),
//!     command_finite: true,
//!     request,
//! };
//! assert_eq!(sup.step(&input(0, ModeRequest::None)).mode, Mode::Idle);
//! assert_eq!(sup.step(&input(2500, ModeRequest::Arm)).mode, Mode::Balancing);
//! // The command link goes quiet: a controlled stop, motors still on.
//! let mut quiet = input(600_000, ModeRequest::None);
//! quiet.command_timestamp_us = Some(2500);
//! for t in (5000..=600_000).step_by(2500) {
//!     quiet.now_us = t;
//!     quiet.imu.timestamp_us = t;
//!     quiet.encoders.timestamp_us = t;
//!     sup.step(&quiet);
//! }
//! assert_eq!(sup.mode(), Mode::ControlledStop);
//! assert!(sup.mode().motors_enabled());
//! # Ok::<(), ballbot_core::Error>(())
//! ```

mod fault;
mod mode;
pub mod motor_health;
mod params;
mod supervisor;
#[cfg(test)]
mod tests;

pub use fault::{Fault, FaultSet, Severity};
pub use mode::{Mode, ModeRequest};
pub use motor_health::{
    MIAPURE_NOMINAL_BUS_VOLTAGE_V, MotorHealthMonitor, MotorHealthParams, MotorVerdict,
    ODRIVE_CURRENT_BANDWIDTH_RAD_PER_S, ODRIVE_MAX_MODULATION,
};
pub use params::{SafetyParams, tilt_from_vertical_rad};
pub use supervisor::{SafetyInput, SafetyStatus, SafetySupervisor};
