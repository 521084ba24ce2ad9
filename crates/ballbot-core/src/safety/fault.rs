//! Typed fault codes: [`Fault`], its [`Severity`], and the set of active faults [`FaultSet`].

use crate::ParseNameError;
use crate::names::parse_name;
use core::fmt;
use core::str::FromStr;

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

/// A typed fault code. `code()` is stable (for telemetry bits), [`Fault::as_str`] is its one
/// name (for logs, `Display` and serde) and [`Fault::description`] a sentence for people.
///
/// ```
/// use ballbot_core::safety::{Fault, Severity};
/// let fault = Fault::TiltLimit;
/// assert_eq!((fault.code(), fault.severity()), (7, Severity::Unrecoverable));
/// assert_eq!(format!("{fault}"), "tilt_limit");
/// assert_eq!(fault.description(), "tilt beyond the recoverable limit");
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
    /// An omniwheel kept slipping on the ball despite the traction reaction
    /// ([`crate::traction::SlipMonitor`]).
    WheelSlip = 14,
    /// The monotonic clock did not advance between two outer steps.
    ClockStalled = 15,
    /// An encoder kept reading speeds no omniwheel can reach, without settling on a
    /// physically continuous trajectory (the 8 kHz guard, [`crate::ballbot::SpeedGuard`]).
    EncoderImplausible = 16,
    /// A motor driver delivers no torque while one is commanded
    /// ([`crate::safety::MotorHealthMonitor`]).
    MotorDead = 17,
    /// A motor driver's torque does not follow its command.
    MotorStuck = 18,
    /// A motor driver reports an error ([`crate::hal::DriverErrors`]).
    MotorTripped = 19,
    /// The motor drivers do not answer: every write failed for the motor health monitor's
    /// persistence ([`crate::safety::MotorHealthMonitor::unanswered`]), so nothing says the
    /// wheels deliver what is commanded.
    MotorUnanswered = 20,
}

// Every code fits a bit of `FaultSet`'s `u32`: the shifts below cannot overflow.
const _: () = assert!(Fault::ALL.len() <= 32);

impl Fault {
    /// Every fault, in code order.
    ///
    /// ```
    /// use ballbot_core::safety::Fault;
    /// // In code order, one entry per code.
    /// assert!(Fault::ALL.iter().enumerate().all(|(i, f)| usize::from(f.code()) == i));
    /// ```
    pub const ALL: [Self; 21] = [
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
        Self::WheelSlip,
        Self::ClockStalled,
        Self::EncoderImplausible,
        Self::MotorDead,
        Self::MotorStuck,
        Self::MotorTripped,
        Self::MotorUnanswered,
    ];

    /// The fault's canonical name (snake_case), the one string form used by `Display`,
    /// `FromStr` and serde.
    ///
    /// ```
    /// use ballbot_core::safety::Fault;
    /// assert_eq!(Fault::CommandLinkLost.as_str(), "command_link_lost");
    /// assert_eq!("imu_stale".parse(), Ok(Fault::ImuStale));
    /// ```
    pub const fn as_str(&self) -> &'static str {
        match self {
            Self::ImuNonFinite => "imu_non_finite",
            Self::ImuOutOfRange => "imu_out_of_range",
            Self::ImuStale => "imu_stale",
            Self::ImuFrozen => "imu_frozen",
            Self::EncoderNonFinite => "encoder_non_finite",
            Self::EncoderOutOfRange => "encoder_out_of_range",
            Self::EncoderStale => "encoder_stale",
            Self::TiltLimit => "tilt_limit",
            Self::WheelSpeedLimit => "wheel_speed_limit",
            Self::LoopOverrun => "loop_overrun",
            Self::ClockFault => "clock_fault",
            Self::CommandLinkLost => "command_link_lost",
            Self::CommandNonFinite => "command_non_finite",
            Self::StateNonFinite => "state_non_finite",
            Self::WheelSlip => "wheel_slip",
            Self::ClockStalled => "clock_stalled",
            Self::EncoderImplausible => "encoder_implausible",
            Self::MotorDead => "motor_dead",
            Self::MotorStuck => "motor_stuck",
            Self::MotorTripped => "motor_tripped",
            Self::MotorUnanswered => "motor_unanswered",
        }
    }

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
            | Self::StateNonFinite
            | Self::MotorDead
            | Self::MotorStuck
            | Self::MotorTripped
            | Self::MotorUnanswered => Severity::Unrecoverable,
            Self::ImuNonFinite
            | Self::ImuOutOfRange
            | Self::EncoderNonFinite
            | Self::EncoderOutOfRange
            | Self::WheelSpeedLimit
            | Self::LoopOverrun
            | Self::ClockFault
            | Self::CommandLinkLost
            | Self::CommandNonFinite
            | Self::WheelSlip
            | Self::ClockStalled
            | Self::EncoderImplausible => Severity::Recoverable,
        }
    }

    /// A short description for people (logs and telemetry use [`Fault::as_str`]).
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
            Self::WheelSlip => "omniwheel slip persisted",
            Self::ClockStalled => "clock stalled",
            Self::EncoderImplausible => "encoder readings implausible",
            Self::MotorDead => "motor driver delivers no torque",
            Self::MotorStuck => "motor torque does not follow its command",
            Self::MotorTripped => "motor driver reports an error",
            Self::MotorUnanswered => "motor drivers do not answer",
        }
    }
}

impl fmt::Display for Fault {
    /// Writes [`Fault::as_str`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Fault {
    type Err = ParseNameError;

    /// The fault named `s` ([`Fault::as_str`]).
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        parse_name(s, &Self::ALL, Self::as_str, "fault")
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Fault {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Fault {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        crate::names::serde_name::deserialize(deserializer, "fault")
    }
}

/// A set of [`Fault`]s (a bit set; `Copy`, no allocation).
///
/// Its string form lists the faults' names ([`Fault::as_str`]) in code order, separated by
/// commas without spaces (`""` for the empty set), for `Display` and `FromStr`; with serde it
/// is a sequence of fault names.
///
/// ```
/// use ballbot_core::safety::{Fault, FaultSet, Severity};
/// let mut faults = FaultSet::empty();
/// faults.insert(Fault::CommandLinkLost);
/// faults.insert(Fault::LoopOverrun);
/// assert!(faults.any(Severity::Recoverable) && !faults.any(Severity::Unrecoverable));
/// assert_eq!(faults.bits(), (1 << 9) | (1 << 11));
/// assert_eq!(faults.to_string(), "loop_overrun,command_link_lost");
/// assert_eq!("command_link_lost,loop_overrun".parse(), Ok(faults));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FaultSet(u32);

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
    pub const fn bits(self) -> u32 {
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

    const UNRECOVERABLE: u32 = Self::mask_of(Severity::Unrecoverable);
    const RECOVERABLE: u32 = Self::mask_of(Severity::Recoverable);

    const fn mask_of(severity: Severity) -> u32 {
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

impl fmt::Display for FaultSet {
    /// Writes the faults' names in code order, separated by `,` (nothing for the empty set).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, fault) in self.iter().enumerate() {
            if i > 0 {
                f.write_str(",")?;
            }
            f.write_str(fault.as_str())?;
        }
        Ok(())
    }
}

impl FromStr for FaultSet {
    type Err = ParseNameError;

    /// The set of the faults named in `s`, separated by `,` (`""`: the empty set). Order and
    /// repetitions do not matter; an unknown name is an error.
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        let mut set = Self::empty();
        if !s.is_empty() {
            for name in s.split(',') {
                set.insert(name.parse()?);
            }
        }
        Ok(set)
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for FaultSet {
    /// A sequence of fault names, in code order.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq;
        let mut seq = serializer.serialize_seq(Some(self.iter().count()))?;
        for fault in self.iter() {
            seq.serialize_element(&fault)?;
        }
        seq.end()
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for FaultSet {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct SetVisitor;
        impl<'de> serde::de::Visitor<'de> for SetVisitor {
            type Value = FaultSet;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a sequence of fault names")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<FaultSet, A::Error> {
                let mut set = FaultSet::empty();
                while let Some(fault) = seq.next_element::<Fault>()? {
                    set.insert(fault);
                }
                Ok(set)
            }
        }
        deserializer.deserialize_seq(SetVisitor)
    }
}
