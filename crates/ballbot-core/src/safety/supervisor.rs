//! The [`SafetySupervisor`]: sensor and timing checks and the mode state machine (see the
//! [module](super) doc for the transitions).

use super::{Fault, FaultSet, Mode, ModeRequest, SafetyParams, Severity};
use crate::Error;
use crate::check::lit;
use crate::estimation::{EncoderSample, ImuSample};
use nalgebra::RealField;

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
                // Nothing can have arrived after `now`: times kept from before the jump would
                // hold the stale checks off until the clock caught up with them.
                self.last_valid_imu_us = self.last_valid_imu_us.map(|t| t.min(now));
                self.last_valid_encoder_us = self.last_valid_encoder_us.map(|t| t.min(now));
                self.imu_unchanged_since_us = self.imu_unchanged_since_us.min(now);
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
            // A sample stamped in the future counts as taken now: one bad stamp must not hold
            // the stale check off until the clock reaches it.
            let stamp = imu.timestamp_us.min(now);
            self.last_valid_imu_us = Some(self.last_valid_imu_us.map_or(stamp, |t| t.max(stamp)));
            // Roll and pitch each against the limit. (A body falling between the axes passes
            // 25 deg from the vertical with 18 deg in each: the fault-injection matrix saw it
            // with a stuck motor. Checking the tilt from the vertical instead moves more than 260
            // figures of the full `reproduce`, which would have to be measured again: left.)
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
            let stamp = enc.timestamp_us.min(now);
            self.last_valid_encoder_us =
                Some(self.last_valid_encoder_us.map_or(stamp, |t| t.max(stamp)));
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
/// at all is stale). The kept sample times are never ahead of the clock (see `step`); a
/// command timestamp ahead of it counts as fresh.
fn is_stale(last_us: Option<u64>, now_us: u64, timeout_us: u64) -> bool {
    match last_us {
        Some(t) => now_us.saturating_sub(t) > timeout_us,
        None => true,
    }
}
