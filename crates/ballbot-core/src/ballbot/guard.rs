//! [`SpeedGuard`]: the 8 kHz motor loop guards its own encoder input. A sample that no wheel
//! could produce (not finite, beyond the encoder's range, or a change faster than the wheel
//! can accelerate) is replaced by the last plausible one, for at most
//! [`SpeedGuard::RESYNC_STEPS`] steps; then the measurement is taken again whatever it is (a
//! wheel that really changed speed that fast is followed 1 ms late, a dead encoder reaches
//! the PI, which gives no torque on a non-finite speed, and the supervisor's checks).

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
    rejected: u8,
}

impl<T: RealField + Copy> SpeedGuard<T> {
    /// Consecutive samples replaced at most (1 ms at 8 kHz).
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
    /// last plausible one (at most [`Self::RESYNC_STEPS`] times in a row).
    ///
    /// ```
    /// use ballbot_core::ballbot::SpeedGuard;
    /// let mut guard = SpeedGuard::new(20_000.0, 124.0);
    /// guard.filter(0.0, 1.25e-4);
    /// // A wheel that really jumped to 40 rad/s is followed after 8 steps.
    /// let seen: Vec<f64> = (0..10).map(|_| guard.filter(40.0, 1.25e-4)).collect();
    /// assert_eq!(seen[..8], [0.0; 8]);
    /// assert_eq!(seen[8], 40.0);
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
        let steps: T = nalgebra::convert(f64::from(self.rejected) + 1.0);
        let band =
            self.max_accel_rad_per_s2 * dt * steps + nalgebra::convert(Self::SLACK_RAD_PER_S);
        if plausible_value && (measured - held).abs() <= band {
            self.held = Some(measured);
            self.rejected = 0;
            measured
        } else if self.rejected >= Self::RESYNC_STEPS {
            // Long enough: take the measurement again, whatever it is.
            self.held = plausible_value.then_some(measured);
            self.rejected = 0;
            measured
        } else {
            self.rejected += 1;
            held
        }
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
    }
}
