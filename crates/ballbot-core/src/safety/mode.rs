//! The supervisor's [`Mode`]s and the operator's [`ModeRequest`]s.

use crate::ParseNameError;
use crate::names::parse_name;
use core::fmt;
use core::str::FromStr;

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
#[cfg_attr(
    feature = "schema",
    derive(schemars::JsonSchema),
    schemars(rename_all = "snake_case")
)]
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
    /// Every mode, in declaration order (for bindings and logs that list them).
    ///
    /// ```
    /// use ballbot_core::safety::Mode;
    /// let names = Mode::ALL.map(|m| m.as_str());
    /// assert_eq!(names, ["idle", "balancing", "controlled_stop", "fault"]);
    /// ```
    pub const ALL: [Self; 4] = [
        Self::Idle,
        Self::Balancing,
        Self::ControlledStop,
        Self::Fault,
    ];

    /// The mode's canonical name (snake_case), the one string form used by `Display`, `FromStr`
    /// and serde.
    ///
    /// ```
    /// use ballbot_core::safety::Mode;
    /// assert_eq!(Mode::ControlledStop.as_str(), "controlled_stop");
    /// assert_eq!(Mode::ControlledStop.to_string(), "controlled_stop");
    /// assert_eq!("controlled_stop".parse(), Ok(Mode::ControlledStop));
    /// ```
    pub const fn as_str(&self) -> &'static str {
        match self {
            Self::Idle => "idle",
            Self::Balancing => "balancing",
            Self::ControlledStop => "controlled_stop",
            Self::Fault => "fault",
        }
    }

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

impl fmt::Display for Mode {
    /// Writes [`Mode::as_str`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Mode {
    type Err = ParseNameError;

    /// The mode named `s` ([`Mode::as_str`]).
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        parse_name(s, &Self::ALL, Self::as_str, "mode")
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Mode {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Mode {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        crate::names::serde_name::deserialize(deserializer, "mode")
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
