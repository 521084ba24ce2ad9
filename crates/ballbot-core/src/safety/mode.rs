//! The supervisor's [`Mode`]s and the operator's [`ModeRequest`]s.

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
