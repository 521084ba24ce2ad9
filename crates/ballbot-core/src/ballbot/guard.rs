//! [`SpeedGuard`]: the 8 kHz motor loop guards its own encoder input. A sample that no wheel
//! could produce (not finite, beyond the encoder's range, or a change faster than the wheel
//! can accelerate) is replaced by the last plausible one.
//!
//! - **Seeded.** An empty guard (the motors were off) takes its first value from
//!   [`SpeedGuard::seed`]: [`super::MotorSpeedLoop`] seeds it with the outer loop's reference
//!   speed, so a wild first reading after the motors are enabled is rejected like any other,
//!   instead of becoming the speed the PI regulates (it drove a motor to its peak torque for
//!   a millisecond).
//! - **Within reach.** A sample is taken if it is within one step's acceleration of the held
//!   speed; after rejections, also if it is within what the wheel could reach since and
//!   continues the sample before it.
//! - **Re-synchronised only on a trajectory.** After [`SpeedGuard::RESYNC_STEPS`] rejected
//!   samples the guard takes the measurement again only if the rejected samples form a
//!   physically continuous trajectory: the last `RESYNC_STEPS + 1` of them within the encoder
//!   range and each within one step's acceleration of the previous (a wheel that really
//!   changed speed that fast is followed 1.1 ms late). Incoherent wild samples are never
//!   taken: the guard keeps holding and reports itself [`SpeedGuard::implausible`] (the loop
//!   raises [`crate::safety::Fault::EncoderImplausible`]).

use nalgebra::RealField;

/// The plausibility filter of one wheel's speed (see the module docs).
///
/// ```
/// use ballbot_core::ballbot::SpeedGuard;
/// let mut guard = SpeedGuard::new(20_000.0, 124.0);
/// assert_eq!(guard.filter(10.0, 1.25e-4), 10.0);
/// // One sample of 100 rad/s 125 us later: no omniwheel accelerates that fast.
/// assert_eq!(guard.filter(100.0, 1.25e-4), 10.0);
/// assert_eq!(guard.filter(f64::NAN, 1.25e-4), 10.0);
/// // A plausible change goes through.
/// assert_eq!(guard.filter(11.0, 1.25e-4), 11.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedGuard<T> {
    max_accel_rad_per_s2: T,
    range_rad_per_s: T,
    held: Option<T>,
    /// Consecutive rejected samples (saturating).
    rejected: u16,
    /// The last rejected sample, if its value was within the range.
    candidate: Option<T>,
    /// How many of the latest rejected samples form a continuous trajectory (saturating).
    consistent: u8,
}

impl<T: RealField + Copy> SpeedGuard<T> {
    /// Consecutive samples replaced before a continuous trajectory of measurements is taken
    /// instead (1 ms at 8 kHz).
    ///
    /// ```
    /// assert_eq!(ballbot_core::ballbot::SpeedGuard::<f64>::RESYNC_STEPS, 8);
    /// ```
    pub const RESYNC_STEPS: u8 = 8;

    /// Slack on top of the acceleration bound, for encoder quantisation (rad/s).
    ///
    /// ```
    /// assert_eq!(ballbot_core::ballbot::SpeedGuard::<f64>::SLACK_RAD_PER_S, 0.5);
    /// ```
    pub const SLACK_RAD_PER_S: f64 = 0.5;

    /// A guard for a wheel that accelerates at most `max_accel_rad_per_s2` and an encoder
    /// that reads at most `range_rad_per_s`.
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let guard = SpeedGuard::new(20_000.0_f32, 124.0);
    /// assert_eq!(guard.held(), None);
    /// ```
    pub fn new(max_accel_rad_per_s2: T, range_rad_per_s: T) -> Self {
        Self {
            max_accel_rad_per_s2,
            range_rad_per_s,
            held: None,
            rejected: 0,
            candidate: None,
            consistent: 0,
        }
    }

    /// The last plausible speed (rad/s), if any.
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.filter(3.0, 1.25e-4);
    /// assert_eq!(guard.held(), Some(3.0));
    /// ```
    pub fn held(&self) -> Option<T> {
        self.held
    }

    /// The speed the PI should use this step of `dt_secs`: `measured` if plausible, else the
    /// last plausible one; after [`Self::RESYNC_STEPS`] rejections in a row, `measured` again
    /// only once the rejected samples form a continuous trajectory (see the module docs). An
    /// empty guard takes the first sample within the range as it is (seed it first).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.filter(0.0, 1.25e-4);
    /// // A wheel that really jumped to 40 rad/s is followed after 8 steps.
    /// let seen: Vec<f64> = (0..10).map(|_| guard.filter(40.0, 1.25e-4)).collect();
    /// assert_eq!(seen[..8], [0.0; 8]);
    /// assert_eq!(seen[8], 40.0);
    /// // Wild samples that jump about are never taken: the guard holds and says so.
    /// for i in 0..50 {
    ///     let wild = if i % 2 == 0 { 110.0 } else { -90.0 };
    ///     assert_eq!(guard.filter(wild, 1.25e-4), 40.0);
    /// }
    /// assert!(guard.implausible());
    /// ```
    pub fn filter(&mut self, measured: T, dt_secs: T) -> T {
        let plausible_value = measured.is_finite() && measured.abs() <= self.range_rad_per_s;
        let Some(held) = self.held else {
            if plausible_value {
                self.held = Some(measured);
            }
            return measured;
        };
        let dt = if dt_secs.is_finite() && dt_secs > T::zero() {
            dt_secs
        } else {
            T::zero()
        };
        let slack: T = nalgebra::convert(Self::SLACK_RAD_PER_S);
        let one_step = self.max_accel_rad_per_s2 * dt;
        let tight = one_step + slack;
        let from_held = (measured - held).abs();
        // Whether it continues the previous (rejected) sample within one step's change.
        let continuous = self
            .candidate
            .is_some_and(|c| plausible_value && (measured - c).abs() <= tight);
        // What the wheel can reach from the held speed in the time since (up to the hold);
        // after rejections, a sample far from the held speed must also continue the one
        // before it: a lone wild sample within the reach is not taken.
        let steps: T =
            nalgebra::convert(f64::from(self.rejected.min(Self::RESYNC_STEPS.into())) + 1.0);
        let reachable = from_held <= one_step * steps + slack;
        if plausible_value && (from_held <= tight || (reachable && continuous)) {
            self.accept(measured);
            return measured;
        }
        self.rejected = self.rejected.saturating_add(1);
        self.consistent = if continuous {
            self.consistent.saturating_add(1)
        } else {
            u8::from(plausible_value)
        };
        self.candidate = plausible_value.then_some(measured);
        if self.rejected > u16::from(Self::RESYNC_STEPS) && self.consistent > Self::RESYNC_STEPS {
            // A continuous trajectory the held speed cannot explain: the wheel is there.
            self.accept(measured);
            return measured;
        }
        held
    }

    fn accept(&mut self, measured: T) {
        self.held = Some(measured);
        self.rejected = 0;
        self.candidate = None;
        self.consistent = 0;
    }

    /// Seeds an empty guard with `speed_rad_per_s` (a speed known from elsewhere, such as the
    /// outer loop's reference) as its last plausible speed; a guard that holds a speed, or a
    /// seed that is not finite or beyond the range, changes nothing.
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.seed(0.0);
    /// // The first reading after enabling is wild: rejected like any other.
    /// assert_eq!(guard.filter(100.0, 1.25e-4), 0.0);
    /// ```
    pub fn seed(&mut self, speed_rad_per_s: T) {
        if self.held.is_none()
            && speed_rad_per_s.is_finite()
            && speed_rad_per_s.abs() <= self.range_rad_per_s
        {
            self.accept(speed_rad_per_s);
        }
    }

    /// Whether the guard has rejected more than [`Self::RESYNC_STEPS`] samples in a row
    /// without a continuous trajectory to re-synchronise on: the encoder cannot be trusted
    /// (see [`Self::rejected_steps`] for how long).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.seed(0.0);
    /// assert!(!guard.implausible());
    /// for _ in 0..9 {
    ///     guard.filter(f64::NAN, 1.25e-4);
    /// }
    /// assert!(guard.implausible() && guard.rejected_steps() == 9);
    /// ```
    pub fn implausible(&self) -> bool {
        self.rejected > u16::from(Self::RESYNC_STEPS)
    }

    /// How many samples in a row were rejected (saturates at `u16::MAX`).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.filter(1.0, 1.25e-4);
    /// guard.filter(f64::INFINITY, 1.25e-4);
    /// assert_eq!(guard.rejected_steps(), 1);
    /// ```
    pub fn rejected_steps(&self) -> u16 {
        self.rejected
    }

    /// The encoder range it was built with (rad/s).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// assert_eq!(SpeedGuard::new(20_000.0, 124.0).range_rad_per_s(), 124.0);
    /// ```
    pub fn range_rad_per_s(&self) -> T {
        self.range_rad_per_s
    }

    /// Forgets the held speed (the motors were off).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.filter(3.0, 1.25e-4);
    /// guard.reset();
    /// assert_eq!(guard.held(), None);
    /// ```
    pub fn reset(&mut self) {
        self.held = None;
        self.rejected = 0;
        self.candidate = None;
        self.consistent = 0;
    }
}
