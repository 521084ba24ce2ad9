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
//! | `ImuStale` | no valid IMU sample newer than `imu_timeout_us` | unrecoverable |
//! | `ImuFrozen` | bit-identical IMU readings for `frozen_imu_timeout_us` | unrecoverable |
//! | `EncoderNonFinite`, `EncoderOutOfRange` | as for the IMU | recoverable (sample rejected) |
//! | `EncoderStale` | no valid encoder sample newer than `encoder_timeout_us` | unrecoverable |
//! | `TiltLimit` | roll or pitch beyond `tilt_limit_rad` | unrecoverable |
//! | `WheelSpeedLimit` | an omniwheel faster than `wheel_speed_limit_rad_per_s` | recoverable |
//! | `LoopOverrun` | more than `max_loop_period_us` since the previous step, or reported | recoverable |
//! | `ClockFault` | the clock went backwards | recoverable |
//! | `CommandLinkLost` | no command newer than `command_timeout_us` | recoverable |
//! | `CommandNonFinite` | the command holds a NaN/inf | recoverable |
//! | `StateNonFinite` | reported by the controller: its estimate or output went non-finite | unrecoverable |
//!
//! A single bad sample therefore starts a controlled stop on held data; if no good sample
//! follows within the timeout the data is stale and the motors are disabled.
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

use crate::check::{lit, positive};
use crate::estimation::{EncoderSample, ImuSample};
use crate::{ActuatorParams, Error};
use core::fmt;
use nalgebra::RealField;

/// The supervisor's mode.
///
/// ```
/// use ballbot_core::safety::{Mode, ModeRequest, SafetyParams, SafetySupervisor};
/// # use ballbot_core::estimation::{EncoderSample, ImuSample};
/// # use ballbot_core::safety::SafetyInput;
/// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
/// # let input = |t_us: u64, request| SafetyInput {
/// #     now_us: t_us,
/// #     imu: ImuSample::<f64>::upright(t_us),
/// #     encoders: EncoderSample::still(t_us),
/// #     command_timestamp_us: Some(t_us),
/// #     command_finite: true,
/// #     request,
/// # };
/// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
/// assert_eq!(sup.mode(), Mode::Idle);
/// assert_eq!(sup.step(&input(0, ModeRequest::Arm)).mode, Mode::Balancing);
/// assert_eq!(sup.step(&input(2500, ModeRequest::Stop)).mode, Mode::ControlledStop);
/// assert_eq!(sup.step(&input(5000, ModeRequest::Resume)).mode, Mode::Balancing);
/// assert_eq!(sup.step(&input(7500, ModeRequest::Disarm)).mode, Mode::Idle);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Motors off, waiting to be armed.
    Idle,
    /// Balancing and following the command.
    Balancing,
    /// Balancing, decelerating to rest and holding upright (after `Stop` or a recoverable
    /// fault).
    ControlledStop,
    /// Motors off after an unrecoverable fault.
    Fault,
}

impl Mode {
    /// Whether the motors are driven in this mode.
    ///
    /// ```
    /// use ballbot_core::safety::Mode;
    /// // A controlled stop keeps balancing: zero torque would drop the rider.
    /// assert!(Mode::ControlledStop.motors_enabled());
    /// assert!(!Mode::Fault.motors_enabled() && !Mode::Idle.motors_enabled());
    /// ```
    pub const fn motors_enabled(self) -> bool {
        matches!(self, Self::Balancing | Self::ControlledStop)
    }
}

/// What the operator (or the application) asks of the supervisor this step.
///
/// ```
/// use ballbot_core::safety::{Mode, ModeRequest, SafetyParams, SafetySupervisor};
/// # use ballbot_core::estimation::{EncoderSample, ImuSample};
/// # use ballbot_core::safety::SafetyInput;
/// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
/// # let input = |t_us: u64, request| SafetyInput {
/// #     now_us: t_us,
/// #     imu: ImuSample::<f64>::upright(t_us),
/// #     encoders: EncoderSample::still(t_us),
/// #     command_timestamp_us: Some(t_us),
/// #     command_finite: true,
/// #     request,
/// # };
/// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
/// // Arming is refused while the body leans 5 deg (the limit is 3 deg) ...
/// let mut leaning = input(0, ModeRequest::Arm);
/// leaning.imu.pitch_rad = 5f64.to_radians();
/// assert_eq!(sup.step(&leaning).mode, Mode::Idle);
/// // ... and accepted upright.
/// assert_eq!(sup.step(&input(2500, ModeRequest::Arm)).mode, Mode::Balancing);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ModeRequest {
    /// Nothing.
    #[default]
    None,
    /// Idle -> Balancing, if no fault is active and the body is upright and still.
    Arm,
    /// Balancing -> ControlledStop.
    Stop,
    /// ControlledStop -> Balancing, if no fault is active.
    Resume,
    /// Balancing or ControlledStop -> Idle: motors off. Only when the robot is supported.
    Disarm,
    /// Fault -> Idle (acknowledges the fault; the motors stay off).
    Reset,
}

/// Whether a fault can be handled while balancing.
///
/// ```
/// use ballbot_core::safety::{Fault, Severity};
/// // A lost command link is handled by a controlled stop; a stale IMU disables the motors.
/// assert_eq!(Fault::CommandLinkLost.severity(), Severity::Recoverable);
/// assert_eq!(Fault::ImuStale.severity(), Severity::Unrecoverable);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Severity {
    /// Handled by a controlled stop that keeps balancing.
    Recoverable,
    /// Balancing is no longer possible or safe: the motors are disabled.
    Unrecoverable,
}

/// A typed fault code. `code()` is stable (for logs and telemetry).
///
/// ```
/// use ballbot_core::safety::{Fault, Severity};
/// let fault = Fault::TiltLimit;
/// assert_eq!((fault.code(), fault.severity()), (7, Severity::Unrecoverable));
/// assert_eq!(format!("{fault}"), "fault 7: tilt beyond the recoverable limit");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Fault {
    /// The IMU sample holds a NaN or infinity.
    ImuNonFinite = 0,
    /// An IMU angle or rate is beyond its physical or sensor range.
    ImuOutOfRange = 1,
    /// No valid IMU sample within the timeout.
    ImuStale = 2,
    /// The IMU keeps returning bit-identical readings.
    ImuFrozen = 3,
    /// An encoder sample holds a NaN or infinity.
    EncoderNonFinite = 4,
    /// An encoder speed is beyond the sensor's range.
    EncoderOutOfRange = 5,
    /// No valid encoder sample within the timeout.
    EncoderStale = 6,
    /// Roll or pitch beyond the recoverable limit.
    TiltLimit = 7,
    /// An omniwheel speed beyond its limit.
    WheelSpeedLimit = 8,
    /// The control loop ran late.
    LoopOverrun = 9,
    /// The monotonic clock went backwards.
    ClockFault = 10,
    /// No fresh command within the timeout.
    CommandLinkLost = 11,
    /// The command holds a NaN or infinity.
    CommandNonFinite = 12,
    /// The controller's estimate or output went non-finite.
    StateNonFinite = 13,
}

impl Fault {
    /// Every fault, in code order.
    ///
    /// ```
    /// use ballbot_core::safety::Fault;
    /// // In code order, one entry per code.
    /// assert!(Fault::ALL.iter().enumerate().all(|(i, f)| usize::from(f.code()) == i));
    /// ```
    pub const ALL: [Self; 14] = [
        Self::ImuNonFinite,
        Self::ImuOutOfRange,
        Self::ImuStale,
        Self::ImuFrozen,
        Self::EncoderNonFinite,
        Self::EncoderOutOfRange,
        Self::EncoderStale,
        Self::TiltLimit,
        Self::WheelSpeedLimit,
        Self::LoopOverrun,
        Self::ClockFault,
        Self::CommandLinkLost,
        Self::CommandNonFinite,
        Self::StateNonFinite,
    ];

    /// The stable numeric code.
    ///
    /// ```
    /// assert_eq!(ballbot_core::safety::Fault::CommandLinkLost.code(), 11);
    /// ```
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// How the supervisor reacts (see the module docs' table).
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, Severity};
    /// // A single bad IMU sample is recoverable (held data); a frozen IMU is not.
    /// assert_eq!(Fault::ImuNonFinite.severity(), Severity::Recoverable);
    /// assert_eq!(Fault::ImuFrozen.severity(), Severity::Unrecoverable);
    /// ```
    pub const fn severity(self) -> Severity {
        match self {
            Self::ImuStale
            | Self::ImuFrozen
            | Self::EncoderStale
            | Self::TiltLimit
            | Self::StateNonFinite => Severity::Unrecoverable,
            Self::ImuNonFinite
            | Self::ImuOutOfRange
            | Self::EncoderNonFinite
            | Self::EncoderOutOfRange
            | Self::WheelSpeedLimit
            | Self::LoopOverrun
            | Self::ClockFault
            | Self::CommandLinkLost
            | Self::CommandNonFinite => Severity::Recoverable,
        }
    }

    /// A short description.
    ///
    /// ```
    /// use ballbot_core::safety::Fault;
    /// assert_eq!(Fault::LoopOverrun.description(), "control loop overrun");
    /// ```
    pub const fn description(self) -> &'static str {
        match self {
            Self::ImuNonFinite => "IMU sample is not finite",
            Self::ImuOutOfRange => "IMU sample out of range",
            Self::ImuStale => "IMU data stale",
            Self::ImuFrozen => "IMU readings frozen",
            Self::EncoderNonFinite => "encoder sample is not finite",
            Self::EncoderOutOfRange => "encoder sample out of range",
            Self::EncoderStale => "encoder data stale",
            Self::TiltLimit => "tilt beyond the recoverable limit",
            Self::WheelSpeedLimit => "omniwheel speed beyond its limit",
            Self::LoopOverrun => "control loop overrun",
            Self::ClockFault => "clock went backwards",
            Self::CommandLinkLost => "command link lost",
            Self::CommandNonFinite => "command is not finite",
            Self::StateNonFinite => "controller state is not finite",
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "fault {}: {}", self.code(), self.description())
    }
}

/// A set of [`Fault`]s (a bit set; `Copy`, no allocation).
///
/// ```
/// use ballbot_core::safety::{Fault, FaultSet, Severity};
/// let mut faults = FaultSet::empty();
/// faults.insert(Fault::CommandLinkLost);
/// faults.insert(Fault::LoopOverrun);
/// assert!(faults.any(Severity::Recoverable) && !faults.any(Severity::Unrecoverable));
/// assert_eq!(faults.bits(), (1 << 9) | (1 << 11));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FaultSet(u16);

impl FaultSet {
    /// No fault.
    ///
    /// ```
    /// use ballbot_core::safety::FaultSet;
    /// assert!(FaultSet::empty().is_empty() && FaultSet::empty() == FaultSet::default());
    /// ```
    pub const fn empty() -> Self {
        Self(0)
    }

    /// The set as bits, bit `code()` per fault (for telemetry).
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let mut faults = FaultSet::empty();
    /// faults.insert(Fault::ImuStale); // code 2
    /// assert_eq!(faults.bits(), 0b100);
    /// ```
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Adds `fault`.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let mut faults = FaultSet::empty();
    /// faults.insert(Fault::ClockFault);
    /// faults.insert(Fault::ClockFault); // a set: inserting twice changes nothing
    /// assert_eq!(faults.iter().count(), 1);
    /// ```
    pub fn insert(&mut self, fault: Fault) {
        self.0 |= 1 << fault.code();
    }

    /// Whether `fault` is in the set.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let mut faults = FaultSet::empty();
    /// faults.insert(Fault::EncoderStale);
    /// assert!(faults.contains(Fault::EncoderStale) && !faults.contains(Fault::ImuStale));
    /// ```
    pub const fn contains(self, fault: Fault) -> bool {
        self.0 & (1 << fault.code()) != 0
    }

    /// Whether the set is empty.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let mut faults = FaultSet::empty();
    /// assert!(faults.is_empty());
    /// faults.insert(Fault::TiltLimit);
    /// assert!(!faults.is_empty());
    /// ```
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The union of two sets.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let (mut a, mut b) = (FaultSet::empty(), FaultSet::empty());
    /// a.insert(Fault::ImuStale);
    /// b.insert(Fault::EncoderStale);
    /// let both = a.union(b);
    /// assert!(both.contains(Fault::ImuStale) && both.contains(Fault::EncoderStale));
    /// ```
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// Whether any fault of `severity` is in the set.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet, Severity};
    /// let mut faults = FaultSet::empty();
    /// faults.insert(Fault::WheelSpeedLimit);
    /// assert!(faults.any(Severity::Recoverable));
    /// assert!(!faults.any(Severity::Unrecoverable));
    /// ```
    pub const fn any(self, severity: Severity) -> bool {
        let mask = match severity {
            Severity::Unrecoverable => Self::UNRECOVERABLE,
            Severity::Recoverable => Self::RECOVERABLE,
        };
        self.0 & mask != 0
    }

    const UNRECOVERABLE: u16 = Self::mask_of(Severity::Unrecoverable);
    const RECOVERABLE: u16 = Self::mask_of(Severity::Recoverable);

    const fn mask_of(severity: Severity) -> u16 {
        let mut mask = 0;
        let mut i = 0;
        while i < Fault::ALL.len() {
            let f = Fault::ALL[i];
            if matches!(
                (f.severity(), severity),
                (Severity::Unrecoverable, Severity::Unrecoverable)
                    | (Severity::Recoverable, Severity::Recoverable)
            ) {
                mask |= 1 << f.code();
            }
            i += 1;
        }
        mask
    }

    /// The faults in the set, in code order.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, FaultSet};
    /// let mut faults = FaultSet::empty();
    /// faults.insert(Fault::StateNonFinite);
    /// faults.insert(Fault::ImuNonFinite);
    /// let mut it = faults.iter();
    /// assert_eq!(it.next(), Some(Fault::ImuNonFinite)); // code 0 first
    /// assert_eq!(it.next(), Some(Fault::StateNonFinite)); // code 13
    /// assert_eq!(it.next(), None);
    /// ```
    pub fn iter(self) -> impl Iterator<Item = Fault> {
        Fault::ALL.into_iter().filter(move |f| self.contains(*f))
    }
}

/// Thresholds and timeouts of the [`SafetySupervisor`]. Times in microseconds of the robot's
/// monotonic clock.
///
/// ```
/// use ballbot_core::safety::{SafetyParams, SafetySupervisor};
/// // MiaPURE's defaults, without a remote control (no command-link supervision).
/// let params = SafetyParams::<f64> { command_timeout_us: None, ..SafetyParams::miapure() };
/// let sup = SafetySupervisor::new(params)?;
/// assert_eq!(sup.params().command_timeout_us, None);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyParams<T> {
    /// Longest age of the newest valid IMU sample (us).
    pub imu_timeout_us: u64,
    /// Longest age of the newest valid encoder sample (us).
    pub encoder_timeout_us: u64,
    /// How long bit-identical IMU readings may last before the IMU counts as frozen (us);
    /// `None` disables the check (needed for noiseless simulated sensors at rest).
    pub frozen_imu_timeout_us: Option<u64>,
    /// Longest age of the newest command (us); `None` disables link supervision (a robot
    /// without a remote).
    pub command_timeout_us: Option<u64>,
    /// Longest time between two supervisor steps (us).
    pub max_loop_period_us: u64,
    /// Largest roll or pitch from which balancing is still attempted (rad).
    pub tilt_limit_rad: T,
    /// Largest roll or pitch at which arming is allowed (rad).
    pub arm_tilt_limit_rad: T,
    /// Largest body rate (each gyro axis) at which arming is allowed (rad/s).
    pub arm_rate_limit_rad_per_s: T,
    /// Gyro measurement range: beyond it a reading is out of range (rad/s).
    pub gyro_range_rad_per_s: T,
    /// Omniwheel speed beyond which a controlled stop starts (rad/s, at the omniwheel).
    pub wheel_speed_limit_rad_per_s: T,
    /// Encoder measurement range: beyond it a reading is out of range (rad/s).
    pub encoder_range_rad_per_s: T,
}

impl<T: RealField + Copy> SafetyParams<T> {
    /// Defaults for MiaPURE at a 400 Hz outer loop (engineering choices, not from the paper):
    /// IMU and encoder timeouts 20 ms (8 periods), frozen IMU 100 ms, command link 250 ms, loop
    /// period 5 ms (2 periods), tilt limit 20 deg, arming within 3 deg and 0.2 rad/s, gyro range
    /// 2000 deg/s, wheel-speed limit 90 % of the 62 rad/s no-load speed, encoder range twice
    /// the no-load speed.
    ///
    /// ```
    /// use ballbot_core::safety::SafetyParams;
    /// let p = SafetyParams::<f64>::miapure();
    /// approx::assert_relative_eq!(p.tilt_limit_rad.to_degrees(), 20.0, epsilon = 1e-9);
    /// // 90 % of the actuator's 62 rad/s no-load speed.
    /// approx::assert_relative_eq!(p.wheel_speed_limit_rad_per_s, 55.8, epsilon = 1e-9);
    /// assert_eq!(p.imu_timeout_us, 20_000); // 8 periods at 400 Hz
    /// ```
    pub fn miapure() -> Self {
        Self::for_actuator(&ActuatorParams::miapure())
    }

    /// The [`Self::miapure`] thresholds with the wheel-speed limits taken from `actuator`.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::safety::SafetyParams;
    /// // A faster gearing: 100 rad/s no-load at the omniwheel.
    /// let actuator = ActuatorParams {
    ///     no_load_speed_rad_per_s: 100.0,
    ///     ..ActuatorParams::<f64>::miapure()
    /// };
    /// let p = SafetyParams::for_actuator(&actuator);
    /// approx::assert_relative_eq!(p.wheel_speed_limit_rad_per_s, 90.0, epsilon = 1e-9);
    /// approx::assert_relative_eq!(p.encoder_range_rad_per_s, 200.0, epsilon = 1e-9);
    /// ```
    pub fn for_actuator(actuator: &ActuatorParams<T>) -> Self {
        let deg = T::pi() / lit(180.0);
        Self {
            imu_timeout_us: 20_000,
            encoder_timeout_us: 20_000,
            frozen_imu_timeout_us: Some(100_000),
            command_timeout_us: Some(250_000),
            max_loop_period_us: 5_000,
            tilt_limit_rad: lit::<T>(20.0) * deg,
            arm_tilt_limit_rad: lit::<T>(3.0) * deg,
            arm_rate_limit_rad_per_s: lit(0.2),
            gyro_range_rad_per_s: lit::<T>(2000.0) * deg,
            wheel_speed_limit_rad_per_s: lit::<T>(0.9) * actuator.no_load_speed_rad_per_s,
            encoder_range_rad_per_s: lit::<T>(2.0) * actuator.no_load_speed_rad_per_s,
        }
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::safety::SafetyParams;
    /// let p = SafetyParams::<f64>::miapure();
    /// assert!(p.validate().is_ok());
    /// // Arming must not be allowed beyond the tilt at which balancing is given up.
    /// let bad = SafetyParams { arm_tilt_limit_rad: 0.5, ..p };
    /// assert!(matches!(
    ///     bad.validate(),
    ///     Err(Error::InvalidParameter { field: "arm_tilt_limit_rad", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let nonzero = |v: u64, field| {
            if v > 0 {
                Ok(())
            } else {
                Err(Error::invalid(field, "must be > 0"))
            }
        };
        nonzero(self.imu_timeout_us, "imu_timeout_us")?;
        nonzero(self.encoder_timeout_us, "encoder_timeout_us")?;
        if let Some(v) = self.frozen_imu_timeout_us {
            nonzero(v, "frozen_imu_timeout_us")?;
        }
        if let Some(v) = self.command_timeout_us {
            nonzero(v, "command_timeout_us")?;
        }
        nonzero(self.max_loop_period_us, "max_loop_period_us")?;
        positive(self.tilt_limit_rad, "tilt_limit_rad")?;
        positive(self.arm_tilt_limit_rad, "arm_tilt_limit_rad")?;
        if self.arm_tilt_limit_rad > self.tilt_limit_rad {
            return Err(Error::invalid(
                "arm_tilt_limit_rad",
                "must not exceed tilt_limit_rad",
            ));
        }
        positive(self.arm_rate_limit_rad_per_s, "arm_rate_limit_rad_per_s")?;
        positive(self.gyro_range_rad_per_s, "gyro_range_rad_per_s")?;
        positive(
            self.wheel_speed_limit_rad_per_s,
            "wheel_speed_limit_rad_per_s",
        )?;
        positive(self.encoder_range_rad_per_s, "encoder_range_rad_per_s")?;
        if self.wheel_speed_limit_rad_per_s > self.encoder_range_rad_per_s {
            return Err(Error::invalid(
                "wheel_speed_limit_rad_per_s",
                "must not exceed encoder_range_rad_per_s",
            ));
        }
        Ok(())
    }
}

/// What the supervisor looks at in one step.
///
/// ```
/// use ballbot_core::estimation::{EncoderSample, ImuSample};
/// use ballbot_core::safety::{Mode, ModeRequest, SafetyInput, SafetyParams, SafetySupervisor};
/// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
/// let input = SafetyInput {
///     now_us: 10_000,
///     imu: ImuSample::<f64>::upright(9_900),
///     encoders: EncoderSample::still(9_950),
///     command_timestamp_us: Some(8_000),
///     command_finite: true,
///     request: ModeRequest::Arm,
/// };
/// assert_eq!(sup.step(&input).mode, Mode::Balancing);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyInput<T: nalgebra::Scalar> {
    /// The time of this step on the robot's monotonic clock (us).
    pub now_us: u64,
    /// The latest IMU sample.
    pub imu: ImuSample<T>,
    /// The latest encoder sample.
    pub encoders: EncoderSample<T>,
    /// When the latest command was received (us); `None` if none ever was.
    pub command_timestamp_us: Option<u64>,
    /// Whether the latest command is finite.
    pub command_finite: bool,
    /// The operator's request.
    pub request: ModeRequest,
}

/// The supervisor's verdict for one step.
///
/// ```
/// use ballbot_core::safety::{Fault, Mode, ModeRequest, SafetyParams, SafetySupervisor};
/// # use ballbot_core::estimation::{EncoderSample, ImuSample};
/// # use ballbot_core::safety::SafetyInput;
/// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
/// # let input = |t_us: u64, request| SafetyInput {
/// #     now_us: t_us,
/// #     imu: ImuSample::<f64>::upright(t_us),
/// #     encoders: EncoderSample::still(t_us),
/// #     command_timestamp_us: Some(t_us),
/// #     command_finite: true,
/// #     request,
/// # };
/// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
/// sup.step(&input(0, ModeRequest::Arm));
/// // An encoder reads 80 rad/s: beyond the 55.8 rad/s wheel-speed limit, within its range.
/// let mut fast = input(2500, ModeRequest::None);
/// fast.encoders.wheel_speeds_rad_per_s[0] = 80.0;
/// let status = sup.step(&fast);
/// assert!(status.faults.contains(Fault::WheelSpeedLimit) && status.encoders_valid);
/// assert_eq!((status.previous_mode, status.mode), (Mode::Balancing, Mode::ControlledStop));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SafetyStatus {
    /// The mode after this step.
    pub mode: Mode,
    /// The mode before it (a transition happened when they differ).
    pub previous_mode: Mode,
    /// The faults detected in this step.
    pub faults: FaultSet,
    /// Whether this step's IMU sample is valid (finite and in range) and may be used.
    pub imu_valid: bool,
    /// Whether this step's encoder sample is valid and may be used.
    pub encoders_valid: bool,
}

impl SafetyStatus {
    /// Whether the mode changed in this step.
    ///
    /// ```
    /// use ballbot_core::safety::{ModeRequest, SafetyParams, SafetySupervisor};
    /// # use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// # use ballbot_core::safety::SafetyInput;
    /// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
    /// # let input = |t_us: u64, request| SafetyInput {
    /// #     now_us: t_us,
    /// #     imu: ImuSample::<f64>::upright(t_us),
    /// #     encoders: EncoderSample::still(t_us),
    /// #     command_timestamp_us: Some(t_us),
    /// #     command_finite: true,
    /// #     request,
    /// # };
    /// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
    /// assert!(sup.step(&input(0, ModeRequest::Arm)).transitioned());
    /// assert!(!sup.step(&input(2500, ModeRequest::None)).transitioned());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn transitioned(&self) -> bool {
        self.mode != self.previous_mode
    }
}

/// The safety supervisor: checks samples, timing and the command link every outer step and
/// runs the [`Mode`] state machine. O(1), allocation-free, panic-free.
///
/// ```
/// use ballbot_core::safety::{Fault, Mode, ModeRequest, SafetyParams, SafetySupervisor};
/// # use ballbot_core::estimation::{EncoderSample, ImuSample};
/// # use ballbot_core::safety::SafetyInput;
/// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
/// # let input = |t_us: u64, request| SafetyInput {
/// #     now_us: t_us,
/// #     imu: ImuSample::<f64>::upright(t_us),
/// #     encoders: EncoderSample::still(t_us),
/// #     command_timestamp_us: Some(t_us),
/// #     command_finite: true,
/// #     request,
/// # };
/// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
/// sup.step(&input(0, ModeRequest::Arm));
/// // The body tips past 20 deg: balancing is given up, the motors are disabled ...
/// let mut fallen = input(2500, ModeRequest::None);
/// fallen.imu.pitch_rad = 25f64.to_radians();
/// let status = sup.step(&fallen);
/// assert!(status.faults.contains(Fault::TiltLimit));
/// assert_eq!(status.mode, Mode::Fault);
/// // ... until the operator acknowledges the fault, which leaves the motors off.
/// assert_eq!(sup.step(&input(5000, ModeRequest::Reset)).mode, Mode::Idle);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetySupervisor<T: nalgebra::Scalar> {
    params: SafetyParams<T>,
    mode: Mode,
    latched: FaultSet,
    reported: FaultSet,
    last_step_us: Option<u64>,
    last_valid_imu_us: Option<u64>,
    last_valid_encoder_us: Option<u64>,
    /// The last valid IMU reading (roll, pitch, yaw, rates) and since when it is unchanged.
    last_imu_values: Option<[T; 6]>,
    imu_unchanged_since_us: u64,
}

impl<T: RealField + Copy> SafetySupervisor<T> {
    /// Validates `params`; starts in [`Mode::Idle`].
    ///
    /// ```
    /// use ballbot_core::safety::{Mode, SafetyParams, SafetySupervisor};
    /// let sup = SafetySupervisor::new(SafetyParams::<f64>::miapure())?;
    /// assert_eq!(sup.mode(), Mode::Idle);
    /// let no_timeout = SafetyParams { imu_timeout_us: 0, ..SafetyParams::<f64>::miapure() };
    /// assert!(SafetySupervisor::new(no_timeout).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: SafetyParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self {
            params,
            mode: Mode::Idle,
            latched: FaultSet::empty(),
            reported: FaultSet::empty(),
            last_step_us: None,
            last_valid_imu_us: None,
            last_valid_encoder_us: None,
            last_imu_values: None,
            imu_unchanged_since_us: 0,
        })
    }

    /// The thresholds.
    ///
    /// ```
    /// use ballbot_core::safety::{SafetyParams, SafetySupervisor};
    /// let sup = SafetySupervisor::new(SafetyParams::<f64>::miapure())?;
    /// assert_eq!(sup.params().max_loop_period_us, 5_000);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &SafetyParams<T> {
        &self.params
    }

    /// The current mode.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, Mode, ModeRequest, SafetyParams, SafetySupervisor};
    /// # use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// # use ballbot_core::safety::SafetyInput;
    /// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
    /// # let input = |t_us: u64, request| SafetyInput {
    /// #     now_us: t_us,
    /// #     imu: ImuSample::<f64>::upright(t_us),
    /// #     encoders: EncoderSample::still(t_us),
    /// #     command_timestamp_us: Some(t_us),
    /// #     command_finite: true,
    /// #     request,
    /// # };
    /// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
    /// sup.step(&input(0, ModeRequest::Arm));
    /// assert_eq!(sup.mode(), Mode::Balancing);
    /// sup.report(Fault::LoopOverrun);
    /// assert_eq!(sup.mode(), Mode::ControlledStop);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Every fault seen since the last arm, resume or reset, including those of the step that
    /// made it (for diagnostics).
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, ModeRequest, SafetyParams, SafetySupervisor};
    /// # use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// # use ballbot_core::safety::SafetyInput;
    /// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
    /// # let input = |t_us: u64, request| SafetyInput {
    /// #     now_us: t_us,
    /// #     imu: ImuSample::<f64>::upright(t_us),
    /// #     encoders: EncoderSample::still(t_us),
    /// #     command_timestamp_us: Some(t_us),
    /// #     command_finite: true,
    /// #     request,
    /// # };
    /// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
    /// sup.step(&input(0, ModeRequest::Arm));
    /// let mut nan = input(2500, ModeRequest::None);
    /// nan.command_finite = false;
    /// sup.step(&nan);
    /// // The fault is gone in the next step but stays latched for diagnostics ...
    /// assert!(sup.step(&input(5000, ModeRequest::None)).faults.is_empty());
    /// assert!(sup.latched_faults().contains(Fault::CommandNonFinite));
    /// // ... until the operator resumes.
    /// sup.step(&input(7500, ModeRequest::Resume));
    /// assert!(sup.latched_faults().is_empty());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn latched_faults(&self) -> FaultSet {
        self.latched
    }

    /// Reports a fault found outside the supervisor (e.g. [`Fault::StateNonFinite`] by the
    /// controller, or [`Fault::LoopOverrun`] measured by the application). It takes effect at
    /// once: an unrecoverable fault while the motors are on enters [`Mode::Fault`], a
    /// recoverable one while balancing enters [`Mode::ControlledStop`]. It is also listed in
    /// the next step's faults. Returns the mode.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, Mode, ModeRequest, SafetyParams, SafetySupervisor};
    /// # use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// # use ballbot_core::safety::SafetyInput;
    /// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
    /// # let input = |t_us: u64, request| SafetyInput {
    /// #     now_us: t_us,
    /// #     imu: ImuSample::<f64>::upright(t_us),
    /// #     encoders: EncoderSample::still(t_us),
    /// #     command_timestamp_us: Some(t_us),
    /// #     command_finite: true,
    /// #     request,
    /// # };
    /// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
    /// sup.step(&input(0, ModeRequest::Arm));
    /// // The controller's estimate went NaN: motors off at once, not at the next step.
    /// assert_eq!(sup.report(Fault::StateNonFinite), Mode::Fault);
    /// // The next step lists it.
    /// assert!(sup.step(&input(2500, ModeRequest::None)).faults.contains(Fault::StateNonFinite));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn report(&mut self, fault: Fault) -> Mode {
        self.reported.insert(fault);
        self.latched.insert(fault);
        if self.mode.motors_enabled() {
            match fault.severity() {
                Severity::Unrecoverable => self.mode = Mode::Fault,
                Severity::Recoverable => {
                    if self.mode == Mode::Balancing {
                        self.mode = Mode::ControlledStop;
                    }
                }
            }
        }
        self.mode
    }

    /// Checks the samples and timing of one step and applies the operator's request.
    ///
    /// ```
    /// use ballbot_core::safety::{Fault, Mode, ModeRequest, SafetyParams, SafetySupervisor};
    /// # use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// # use ballbot_core::safety::SafetyInput;
    /// // `input(t_us, request)`: fresh, upright and still samples at `t_us` (see `SafetyInput`).
    /// # let input = |t_us: u64, request| SafetyInput {
    /// #     now_us: t_us,
    /// #     imu: ImuSample::<f64>::upright(t_us),
    /// #     encoders: EncoderSample::still(t_us),
    /// #     command_timestamp_us: Some(t_us),
    /// #     command_finite: true,
    /// #     request,
    /// # };
    /// let mut sup = SafetySupervisor::new(SafetyParams::miapure())?;
    /// sup.step(&input(0, ModeRequest::Arm));
    /// // One non-finite IMU sample: rejected (the last good one is held), a controlled stop
    /// // starts.
    /// let mut glitch = input(2500, ModeRequest::None);
    /// glitch.imu.pitch_rad = f64::NAN;
    /// let status = sup.step(&glitch);
    /// assert!(!status.imu_valid && status.faults.contains(Fault::ImuNonFinite));
    /// assert_eq!(status.mode, Mode::ControlledStop);
    /// // If no valid sample follows within 20 ms the IMU data is stale: the motors are disabled.
    /// let mut t = 2500;
    /// while sup.mode() == Mode::ControlledStop && t < 100_000 {
    ///     t += 2500;
    ///     glitch.now_us = t;
    ///     sup.step(&glitch);
    /// }
    /// assert_eq!(sup.mode(), Mode::Fault);
    /// assert!(sup.latched_faults().contains(Fault::ImuStale));
    /// assert!(t > 20_000 && t <= 25_000);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(&mut self, input: &SafetyInput<T>) -> SafetyStatus {
        let p = &self.params;
        let now = input.now_us;
        let mut faults = core::mem::take(&mut self.reported);

        // Loop timing.
        if let Some(last) = self.last_step_us {
            if now < last {
                faults.insert(Fault::ClockFault);
            } else if now - last > p.max_loop_period_us {
                faults.insert(Fault::LoopOverrun);
            }
        }
        self.last_step_us = Some(now);

        // IMU.
        let imu = &input.imu;
        let imu_valid = if !imu.is_finite() {
            faults.insert(Fault::ImuNonFinite);
            false
        } else if !self.imu_in_range(imu) {
            faults.insert(Fault::ImuOutOfRange);
            false
        } else {
            true
        };
        if imu_valid {
            self.last_valid_imu_us = Some(
                self.last_valid_imu_us
                    .map_or(imu.timestamp_us, |t| t.max(imu.timestamp_us)),
            );
            if imu.roll_rad.abs() > p.tilt_limit_rad || imu.pitch_rad.abs() > p.tilt_limit_rad {
                faults.insert(Fault::TiltLimit);
            }
            let w = imu.angular_velocity_rad_per_s;
            let values = [imu.roll_rad, imu.pitch_rad, imu.yaw_rad, w[0], w[1], w[2]];
            if self.last_imu_values != Some(values) {
                self.last_imu_values = Some(values);
                self.imu_unchanged_since_us = now;
            }
            if let Some(limit) = p.frozen_imu_timeout_us
                && now.saturating_sub(self.imu_unchanged_since_us) > limit
            {
                faults.insert(Fault::ImuFrozen);
            }
        }
        if is_stale(self.last_valid_imu_us, now, p.imu_timeout_us) {
            faults.insert(Fault::ImuStale);
        }

        // Encoders.
        let enc = &input.encoders;
        let speeds = enc.wheel_speeds_rad_per_s;
        let encoders_valid = if !enc.is_finite() {
            faults.insert(Fault::EncoderNonFinite);
            false
        } else if speeds.iter().any(|s| s.abs() > p.encoder_range_rad_per_s) {
            faults.insert(Fault::EncoderOutOfRange);
            false
        } else {
            true
        };
        if encoders_valid {
            self.last_valid_encoder_us = Some(
                self.last_valid_encoder_us
                    .map_or(enc.timestamp_us, |t| t.max(enc.timestamp_us)),
            );
            if speeds
                .iter()
                .any(|s| s.abs() > p.wheel_speed_limit_rad_per_s)
            {
                faults.insert(Fault::WheelSpeedLimit);
            }
        }
        if is_stale(self.last_valid_encoder_us, now, p.encoder_timeout_us) {
            faults.insert(Fault::EncoderStale);
        }

        // Command link.
        if !input.command_finite {
            faults.insert(Fault::CommandNonFinite);
        }
        if let Some(timeout) = p.command_timeout_us
            && is_stale(input.command_timestamp_us, now, timeout)
        {
            faults.insert(Fault::CommandLinkLost);
        }

        let previous_mode = self.mode;
        self.transition(input, faults, imu_valid);
        self.latched = self.latched.union(faults);
        SafetyStatus {
            mode: self.mode,
            previous_mode,
            faults,
            imu_valid,
            encoders_valid,
        }
    }

    fn imu_in_range(&self, imu: &ImuSample<T>) -> bool {
        let pi = T::pi();
        let slack: T = lit(1e-3);
        imu.roll_rad.abs() <= pi + slack
            && imu.pitch_rad.abs() <= T::frac_pi_2() + slack
            && imu.yaw_rad.abs() <= T::two_pi() + slack
            && imu
                .angular_velocity_rad_per_s
                .iter()
                .all(|w| w.abs() <= self.params.gyro_range_rad_per_s)
    }

    fn transition(&mut self, input: &SafetyInput<T>, faults: FaultSet, imu_valid: bool) {
        let request = input.request;
        match self.mode {
            Mode::Idle => {
                if request == ModeRequest::Arm && faults.is_empty() && imu_valid {
                    let p = &self.params;
                    let imu = &input.imu;
                    let upright = imu.roll_rad.abs() <= p.arm_tilt_limit_rad
                        && imu.pitch_rad.abs() <= p.arm_tilt_limit_rad;
                    let still = imu
                        .angular_velocity_rad_per_s
                        .iter()
                        .all(|w| w.abs() <= p.arm_rate_limit_rad_per_s);
                    if upright && still {
                        self.mode = Mode::Balancing;
                        self.latched = FaultSet::empty();
                    }
                }
            }
            Mode::Balancing | Mode::ControlledStop => {
                if faults.any(Severity::Unrecoverable) {
                    self.mode = Mode::Fault;
                } else if request == ModeRequest::Disarm {
                    self.mode = Mode::Idle;
                } else if faults.any(Severity::Recoverable) || request == ModeRequest::Stop {
                    self.mode = Mode::ControlledStop;
                } else if self.mode == Mode::ControlledStop && request == ModeRequest::Resume {
                    self.mode = Mode::Balancing;
                    self.latched = FaultSet::empty();
                }
            }
            Mode::Fault => {
                if request == ModeRequest::Reset {
                    self.mode = Mode::Idle;
                    self.latched = FaultSet::empty();
                }
            }
        }
    }
}

/// Whether the newest valid data at `last_us` is older than `timeout_us` at `now_us` (no data
/// at all is stale; data stamped in the future is fresh).
fn is_stale(last_us: Option<u64>, now_us: u64, timeout_us: u64) -> bool {
    match last_us {
        Some(t) => now_us.saturating_sub(t) > timeout_us,
        None => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    const PERIOD_US: u64 = 2500;

    /// A healthy robot at time `t`, with a little sensor noise so the IMU is not frozen.
    fn healthy(t: u64) -> SafetyInput<f64> {
        let noise = (t as f64 * 1e-3).sin() * 1e-4;
        let mut imu = ImuSample::upright(t);
        imu.roll_rad = noise;
        SafetyInput {
            now_us: t,
            imu,
            encoders: EncoderSample::still(t),
            command_timestamp_us: Some(t),
            command_finite: true,
            request: ModeRequest::None,
        }
    }

    fn supervisor() -> SafetySupervisor<f64> {
        SafetySupervisor::new(SafetyParams::miapure()).unwrap()
    }

    /// Steps a healthy robot from `*t`, then arms it.
    fn armed(t: &mut u64) -> SafetySupervisor<f64> {
        let mut sup = supervisor();
        sup.step(&healthy(*t));
        *t += PERIOD_US;
        let status = sup.step(&SafetyInput {
            request: ModeRequest::Arm,
            ..healthy(*t)
        });
        assert_eq!(status.mode, Mode::Balancing);
        assert!(status.transitioned());
        *t += PERIOD_US;
        sup
    }

    #[test]
    fn fault_codes_are_stable_and_sets_behave() {
        for (i, f) in Fault::ALL.iter().enumerate() {
            assert_eq!(f.code() as usize, i);
        }
        let mut set = FaultSet::empty();
        assert!(set.is_empty());
        set.insert(Fault::TiltLimit);
        set.insert(Fault::LoopOverrun);
        assert!(set.contains(Fault::TiltLimit) && !set.contains(Fault::ImuStale));
        assert!(set.any(Severity::Unrecoverable) && set.any(Severity::Recoverable));
        let listed: [Option<Fault>; 3] = {
            let mut it = set.iter();
            [it.next(), it.next(), it.next()]
        };
        assert_eq!(
            listed,
            [Some(Fault::TiltLimit), Some(Fault::LoopOverrun), None]
        );
        assert_eq!(set.bits(), (1 << 7) | (1 << 9));
    }

    #[test]
    fn arming_needs_healthy_upright_still_robot() {
        let mut sup = supervisor();
        // Never seen a sample: stale everything, so no arming.
        let mut first = healthy(0);
        first.request = ModeRequest::Arm;
        first.command_timestamp_us = None;
        let status = sup.step(&first);
        assert_eq!(status.mode, Mode::Idle);
        assert!(status.faults.contains(Fault::CommandLinkLost));
        // Tilted beyond the arming limit (but within the tilt limit): refused.
        let mut tilted = healthy(PERIOD_US);
        tilted.request = ModeRequest::Arm;
        tilted.imu.pitch_rad = 0.1;
        assert_eq!(sup.step(&tilted).mode, Mode::Idle);
        // Moving: refused.
        let mut moving = healthy(2 * PERIOD_US);
        moving.request = ModeRequest::Arm;
        moving.imu.angular_velocity_rad_per_s = Vector3::new(0.0, 0.5, 0.0);
        assert_eq!(sup.step(&moving).mode, Mode::Idle);
        // Upright and still: armed.
        let mut good = healthy(3 * PERIOD_US);
        good.request = ModeRequest::Arm;
        assert_eq!(sup.step(&good).mode, Mode::Balancing);
    }

    #[test]
    fn idle_reports_faults_but_never_enters_fault_mode() {
        let mut sup = supervisor();
        let mut lying = healthy(0);
        lying.imu.pitch_rad = 1.2;
        let status = sup.step(&lying);
        assert!(status.faults.contains(Fault::TiltLimit));
        assert_eq!(status.mode, Mode::Idle);
    }

    #[test]
    fn stop_resume_and_disarm() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let mut input = healthy(t);
        input.request = ModeRequest::Stop;
        assert_eq!(sup.step(&input).mode, Mode::ControlledStop);
        t += PERIOD_US;
        assert_eq!(sup.step(&healthy(t)).mode, Mode::ControlledStop, "holds");
        t += PERIOD_US;
        let mut input = healthy(t);
        input.request = ModeRequest::Resume;
        assert_eq!(sup.step(&input).mode, Mode::Balancing);
        t += PERIOD_US;
        let mut input = healthy(t);
        input.request = ModeRequest::Disarm;
        let status = sup.step(&input);
        assert_eq!(status.mode, Mode::Idle);
        assert!(!status.mode.motors_enabled());
    }

    #[test]
    fn lost_command_link_stops_under_control_and_resume_waits_for_it() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let last_command = t;
        let mut status = sup.step(&healthy(t));
        while t < last_command + 300_000 {
            t += PERIOD_US;
            let mut input = healthy(t);
            input.command_timestamp_us = Some(last_command);
            input.request = ModeRequest::Resume; // refused while the link is down
            status = sup.step(&input);
        }
        assert_eq!(status.mode, Mode::ControlledStop);
        assert!(status.faults.contains(Fault::CommandLinkLost));
        assert!(status.mode.motors_enabled());
        // Link back: still holding until resumed.
        t += PERIOD_US;
        assert_eq!(sup.step(&healthy(t)).mode, Mode::ControlledStop);
        assert!(sup.latched_faults().contains(Fault::CommandLinkLost));
        t += PERIOD_US;
        let mut input = healthy(t);
        input.request = ModeRequest::Resume;
        assert_eq!(sup.step(&input).mode, Mode::Balancing);
        assert!(sup.latched_faults().is_empty());
    }

    #[test]
    fn a_single_bad_imu_sample_stops_and_a_persistent_one_disables() {
        for bad in [f64::NAN, f64::INFINITY, 10.0] {
            let mut t = 0;
            let mut sup = armed(&mut t);
            let mut input = healthy(t);
            input.imu.angular_velocity_rad_per_s[1] = bad * 1e3;
            let status = sup.step(&input);
            assert!(!status.imu_valid);
            let expected = if bad.is_finite() {
                Fault::ImuOutOfRange
            } else {
                Fault::ImuNonFinite
            };
            assert!(status.faults.contains(expected));
            assert_eq!(status.mode, Mode::ControlledStop);
            // It persists: after the timeout the data is stale.
            let start = t;
            while t <= start + 20_000 + PERIOD_US {
                t += PERIOD_US;
                let mut input = healthy(t);
                input.imu.pitch_rad = bad;
                input.imu.pitch_rad *= 1e3;
                sup.step(&input);
            }
            assert_eq!(sup.mode(), Mode::Fault);
            assert!(sup.latched_faults().contains(Fault::ImuStale));
        }
    }

    #[test]
    fn stale_encoders_disable_the_motors() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let frozen_stamp = t;
        let mut status = sup.step(&healthy(t));
        for _ in 0..9 {
            t += PERIOD_US;
            let mut input = healthy(t);
            input.encoders.timestamp_us = frozen_stamp;
            status = sup.step(&input);
        }
        assert_eq!(status.mode, Mode::Fault);
        assert!(status.faults.contains(Fault::EncoderStale));
        // Reset acknowledges; the motors stay off.
        t += PERIOD_US;
        let mut input = healthy(t);
        input.request = ModeRequest::Reset;
        assert_eq!(sup.step(&input).mode, Mode::Idle);
    }

    #[test]
    fn frozen_imu_is_detected_only_when_enabled() {
        for enabled in [true, false] {
            let mut params = SafetyParams::miapure();
            if !enabled {
                params.frozen_imu_timeout_us = None;
            }
            let mut sup = SafetySupervisor::new(params).unwrap();
            let mut t = 0;
            let mut input = healthy(t);
            input.request = ModeRequest::Arm;
            sup.step(&input);
            let frozen = healthy(t).imu;
            for _ in 0..60 {
                t += PERIOD_US;
                let mut input = healthy(t);
                input.imu = ImuSample {
                    timestamp_us: t,
                    ..frozen
                };
                sup.step(&input);
            }
            let expected = if enabled {
                Mode::Fault
            } else {
                Mode::Balancing
            };
            assert_eq!(sup.mode(), expected);
        }
    }

    #[test]
    fn tilt_beyond_limit_disables_and_wheel_speed_stops() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let mut input = healthy(t);
        input.encoders.wheel_speeds_rad_per_s[2] = 60.0;
        let status = sup.step(&input);
        assert!(status.faults.contains(Fault::WheelSpeedLimit));
        assert_eq!(status.mode, Mode::ControlledStop);
        t += PERIOD_US;
        let mut input = healthy(t);
        input.imu.roll_rad = -0.4;
        let status = sup.step(&input);
        assert!(status.faults.contains(Fault::TiltLimit));
        assert_eq!(status.mode, Mode::Fault);
    }

    #[test]
    fn loop_overrun_and_clock_faults_are_recoverable() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        t += 10_000;
        let status = sup.step(&healthy(t));
        assert!(status.faults.contains(Fault::LoopOverrun));
        assert_eq!(status.mode, Mode::ControlledStop);
        let mut input = healthy(t - 1);
        input.request = ModeRequest::Resume;
        let status = sup.step(&input);
        assert!(status.faults.contains(Fault::ClockFault));
        assert_eq!(status.mode, Mode::ControlledStop, "resume refused");
    }

    #[test]
    fn reported_faults_act_at_once() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        assert_eq!(sup.report(Fault::LoopOverrun), Mode::ControlledStop);
        assert!(sup.step(&healthy(t)).faults.contains(Fault::LoopOverrun));
        assert_eq!(sup.report(Fault::StateNonFinite), Mode::Fault);
        // In Idle a report changes nothing.
        let mut idle = supervisor();
        assert_eq!(idle.report(Fault::StateNonFinite), Mode::Idle);
    }

    #[test]
    fn non_finite_command_stops() {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let mut input = healthy(t);
        input.command_finite = false;
        let status = sup.step(&input);
        assert!(status.faults.contains(Fault::CommandNonFinite));
        assert_eq!(status.mode, Mode::ControlledStop);
    }

    #[test]
    fn params_validation_names_the_field() {
        let mut p = SafetyParams::<f64>::miapure();
        p.arm_tilt_limit_rad = 1.0;
        assert_eq!(
            p.validate(),
            Err(Error::invalid(
                "arm_tilt_limit_rad",
                "must not exceed tilt_limit_rad"
            ))
        );
        let mut p = SafetyParams::<f64>::miapure();
        p.imu_timeout_us = 0;
        assert!(SafetySupervisor::new(p).is_err());
    }
}
