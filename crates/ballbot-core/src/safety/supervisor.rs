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
    /// `cos` of the tilt limits: a tilt from the vertical beyond a limit is a
    /// `cos(roll) cos(pitch)` below its cosine (see [`tilt_from_vertical_rad`](super::tilt_from_vertical_rad)).
    cos_tilt_limit: T,
    cos_arm_tilt_limit: T,
    /// The watchdogs counted in outer steps (ticks), whatever the timestamps say.
    ticks: TickWatchdogs,
}

/// Staleness counted in outer steps: how many steps since each sample was last refreshed (a
/// new timestamp), and the limits from the timeouts ([`SafetyParams::timeout_ticks`]). The
/// counters saturate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct TickWatchdogs {
    imu: TickCounter,
    encoders: TickCounter,
    command: TickCounter,
    /// Steps since the IMU's values last changed.
    imu_unchanged: u32,
    imu_limit: u32,
    encoder_limit: u32,
    command_limit: Option<u32>,
    frozen_limit: Option<u32>,
}

/// Steps since a sample's timestamp last changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct TickCounter {
    stamp_us: Option<u64>,
    ticks: u32,
}

impl TickCounter {
    const NEW: Self = Self {
        stamp_us: None,
        ticks: 0,
    };

    /// One step: refreshed if `stamp_us` is a timestamp not seen in the previous refresh.
    fn step(&mut self, stamp_us: Option<u64>) {
        if stamp_us.is_some() && stamp_us != self.stamp_us {
            self.stamp_us = stamp_us;
            self.ticks = 0;
        } else {
            self.ticks = self.ticks.saturating_add(1);
        }
    }

    /// Whether the sample went unrefreshed for more than `limit` steps.
    fn stale(&self, limit: u32) -> bool {
        self.ticks > limit
    }
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
        let ticks = TickWatchdogs {
            imu: TickCounter::NEW,
            encoders: TickCounter::NEW,
            command: TickCounter::NEW,
            imu_unchanged: 0,
            imu_limit: params.timeout_ticks(params.imu_timeout_us),
            encoder_limit: params.timeout_ticks(params.encoder_timeout_us),
            command_limit: params.command_timeout_us.map(|t| params.timeout_ticks(t)),
            frozen_limit: params
                .frozen_imu_timeout_us
                .map(|t| params.timeout_ticks(t)),
        };
        Ok(Self {
            cos_tilt_limit: params.tilt_limit_rad.cos(),
            cos_arm_tilt_limit: params.arm_tilt_limit_rad.cos(),
            ticks,
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
        let mut faults = core::mem::take(&mut self.reported);
        self.check_clock(input.now_us, &mut faults);
        let imu_valid = self.check_imu(&input.imu, input.now_us, &mut faults);
        let encoders_valid = self.check_encoders(&input.encoders, input.now_us, &mut faults);
        self.check_command(input, &mut faults);
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

    /// Whether a body at `roll_rad`, `pitch_rad` (ZYX Euler angles, as
    /// [`ImuSample`]) is within the tilt limit from the vertical
    /// ([`SafetyParams::tilt_limit_rad`], [`tilt_from_vertical_rad`](super::tilt_from_vertical_rad)).
    ///
    /// ```
    /// use ballbot_core::safety::{SafetyParams, SafetySupervisor};
    /// let sup = SafetySupervisor::new(SafetyParams::<f64>::miapure())?;
    /// let deg = 15f64.to_radians();
    /// assert!(sup.within_tilt_limit(0.0, deg));
    /// // 15 deg in roll and in pitch: 21 deg from the vertical, beyond the 20 deg limit.
    /// assert!(!sup.within_tilt_limit(deg, deg));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn within_tilt_limit(&self, roll_rad: T, pitch_rad: T) -> bool {
        within(
            roll_rad,
            pitch_rad,
            self.params.tilt_limit_rad,
            self.cos_tilt_limit,
        )
    }

    /// Whether a body at `roll_rad`, `pitch_rad` is upright enough to arm: within
    /// [`SafetyParams::arm_tilt_limit_rad`] from the vertical.
    ///
    /// ```
    /// use ballbot_core::safety::{SafetyParams, SafetySupervisor};
    /// let sup = SafetySupervisor::new(SafetyParams::<f64>::miapure())?;
    /// let deg = 2.5f64.to_radians();
    /// assert!(sup.within_arm_tilt(deg, 0.0));
    /// assert!(!sup.within_arm_tilt(deg, deg)); // 3.5 deg from the vertical: beyond 3 deg
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn within_arm_tilt(&self, roll_rad: T, pitch_rad: T) -> bool {
        within(
            roll_rad,
            pitch_rad,
            self.params.arm_tilt_limit_rad,
            self.cos_arm_tilt_limit,
        )
    }

    /// Loop timing: a clock that went backwards, stalled, or a step that came late.
    fn check_clock(&mut self, now: u64, faults: &mut FaultSet) {
        if let Some(last) = self.last_step_us {
            if now < last {
                faults.insert(Fault::ClockFault);
                // Nothing can have arrived after `now`: times kept from before the jump would
                // hold the stale checks off until the clock caught up with them.
                self.last_valid_imu_us = self.last_valid_imu_us.map(|t| t.min(now));
                self.last_valid_encoder_us = self.last_valid_encoder_us.map(|t| t.min(now));
                self.imu_unchanged_since_us = self.imu_unchanged_since_us.min(now);
            } else if now == last {
                // A whole outer period without a microsecond: the clock is not running, and
                // every timeout measured with it is blind (the tick watchdogs are not).
                faults.insert(Fault::ClockStalled);
            } else if now - last > self.params.max_loop_period_us {
                faults.insert(Fault::LoopOverrun);
            }
        }
        self.last_step_us = Some(now);
    }

    /// The IMU sample: validity, tilt, frozen readings, staleness by time and by ticks.
    /// Returns whether the sample may be used.
    fn check_imu(&mut self, imu: &ImuSample<T>, now: u64, faults: &mut FaultSet) -> bool {
        let imu_valid = if !imu.is_finite() {
            faults.insert(Fault::ImuNonFinite);
            false
        } else if !self.imu_in_range(imu) {
            faults.insert(Fault::ImuOutOfRange);
            false
        } else {
            true
        };
        let ticks = &mut self.ticks;
        ticks.imu.step(imu_valid.then_some(imu.timestamp_us));
        ticks.imu_unchanged = ticks.imu_unchanged.saturating_add(1);
        if imu_valid {
            // A sample stamped in the future counts as taken now: one bad stamp must not hold
            // the stale check off until the clock reaches it.
            let stamp = imu.timestamp_us.min(now);
            self.last_valid_imu_us = Some(self.last_valid_imu_us.map_or(stamp, |t| t.max(stamp)));
            // The tilt from the vertical, not roll and pitch each: a body falling between the
            // axes passes 25 deg from the vertical with 18 deg in each.
            if !self.within_tilt_limit(imu.roll_rad, imu.pitch_rad) {
                faults.insert(Fault::TiltLimit);
            }
            self.check_frozen(imu, now, faults);
        }
        if is_stale(self.last_valid_imu_us, now, self.params.imu_timeout_us)
            || self.ticks.imu.stale(self.ticks.imu_limit)
        {
            faults.insert(Fault::ImuStale);
        }
        imu_valid
    }

    /// Bit-identical IMU readings for longer than the frozen timeout, by time or by ticks.
    fn check_frozen(&mut self, imu: &ImuSample<T>, now: u64, faults: &mut FaultSet) {
        let w = imu.angular_velocity_rad_per_s;
        let values = [imu.roll_rad, imu.pitch_rad, imu.yaw_rad, w[0], w[1], w[2]];
        if self.last_imu_values != Some(values) {
            self.last_imu_values = Some(values);
            self.imu_unchanged_since_us = now;
            self.ticks.imu_unchanged = 0;
        }
        if let (Some(limit_us), Some(limit_ticks)) =
            (self.params.frozen_imu_timeout_us, self.ticks.frozen_limit)
            && (now.saturating_sub(self.imu_unchanged_since_us) > limit_us
                || self.ticks.imu_unchanged > limit_ticks)
        {
            faults.insert(Fault::ImuFrozen);
        }
    }

    /// The encoder sample: validity, wheel-speed limit, staleness by time and by ticks.
    /// Returns whether the sample may be used.
    fn check_encoders(&mut self, enc: &EncoderSample<T>, now: u64, faults: &mut FaultSet) -> bool {
        let p = &self.params;
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
        self.ticks
            .encoders
            .step(encoders_valid.then_some(enc.timestamp_us));
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
        if is_stale(self.last_valid_encoder_us, now, p.encoder_timeout_us)
            || self.ticks.encoders.stale(self.ticks.encoder_limit)
        {
            faults.insert(Fault::EncoderStale);
        }
        encoders_valid
    }

    /// The command link: a non-finite command, no fresh command by time or by ticks.
    fn check_command(&mut self, input: &SafetyInput<T>, faults: &mut FaultSet) {
        if !input.command_finite {
            faults.insert(Fault::CommandNonFinite);
        }
        self.ticks.command.step(input.command_timestamp_us);
        if let (Some(timeout), Some(limit)) =
            (self.params.command_timeout_us, self.ticks.command_limit)
            && (is_stale(input.command_timestamp_us, input.now_us, timeout)
                || self.ticks.command.stale(limit))
        {
            faults.insert(Fault::CommandLinkLost);
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
                    let upright = self.within_arm_tilt(imu.roll_rad, imu.pitch_rad);
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

/// Whether the tilt from the vertical of `roll`, `pitch` is within `limit` (whose cosine is
/// `cos_limit`). The tilt is the hypotenuse of a right spherical triangle with legs `roll`
/// and `pitch` (`cos(tilt) = cos(roll) cos(pitch)`), never longer than the flat one: within
/// `roll^2 + pitch^2 <= limit^2` (the upright robot's every step) no cosine is needed.
fn within<T: RealField + Copy>(roll: T, pitch: T, limit: T, cos_limit: T) -> bool {
    roll * roll + pitch * pitch <= limit * limit || roll.cos() * pitch.cos() >= cos_limit
}
