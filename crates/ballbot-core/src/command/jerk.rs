//! The per-axis [`JerkLimiter`]: speed, acceleration and jerk bounded, so a step in a command
//! becomes a smooth ramp.

use crate::Error;
use crate::check::{lit, positive};
use crate::control::dt_is_valid;
use crate::num::{clamp_sym, hypot, min, smallest_normal};
use nalgebra::RealField;

/// Limits of one shaped axis: a bound on the value, on its rate of change and on the rate of
/// change of that rate.
///
/// For a translation axis the value is a speed: `max_value` in m/s, `max_rate_per_s` an
/// acceleration in m/s^2, `max_jerk_per_s2` a jerk in m/s^3. For yaw: rad/s, rad/s^2, rad/s^3.
///
/// ```
/// use ballbot_core::command::{AxisLimits, CommandShaperParams};
/// // MiaPURE's translation limits: 2 m/s, 1 m/s^2, 2 m/s^3.
/// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
/// assert_eq!(CommandShaperParams::<f64>::miapure().translation, limits);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct AxisLimits<T> {
    /// Largest magnitude of the value (m/s or rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_value: T,
    /// Largest magnitude of its rate of change, the acceleration (per s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_rate_per_s: T,
    /// Largest magnitude of the rate's rate of change, the jerk (per s^2).
    pub max_jerk_per_s2: T,
}

impl<T: RealField + Copy> AxisLimits<T> {
    /// The jerk limit that means "no jerk limit": positive infinity. The only non-finite limit
    /// [`Self::validate`] accepts; with it the [`JerkLimiter`] is a plain rate limiter (the
    /// acceleration may jump to any value within `max_rate_per_s` in one step).
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let jerk = AxisLimits::<f64>::unlimited_jerk_per_s2();
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: jerk };
    /// assert!(limits.validate().is_ok());
    /// // A step in the target: the full acceleration from the first step.
    /// let mut limiter = JerkLimiter::at(0.0);
    /// limiter.step(1.0, &limits, 0.0025);
    /// assert_eq!(limiter.rate_per_s(), 1.0);
    /// ```
    pub fn unlimited_jerk_per_s2() -> T {
        lit(f64::INFINITY)
    }

    /// Checks that every limit is finite and positive, except the jerk limit, which may also
    /// be [`Self::unlimited_jerk_per_s2`] (positive infinity: no jerk limit).
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::command::AxisLimits;
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 0.0 };
    /// assert!(matches!(
    ///     limits.validate(),
    ///     Err(Error::InvalidParameter { field: "max_jerk_per_s2", .. })
    /// ));
    /// let nan = AxisLimits { max_jerk_per_s2: f64::NAN, ..limits };
    /// assert!(nan.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.max_value, "max_value")?;
        positive(self.max_rate_per_s, "max_rate_per_s")?;
        if self.max_jerk_per_s2 == Self::unlimited_jerk_per_s2() {
            return Ok(());
        }
        if self.max_jerk_per_s2.is_finite() && self.max_jerk_per_s2 > T::zero() {
            Ok(())
        } else {
            Err(Error::invalid(
                "max_jerk_per_s2",
                "must be finite and > 0, or +infinity (no jerk limit)",
            ))
        }
    }
}

/// A jerk-limited rate limiter for one axis: the output follows a target as fast as
/// [`AxisLimits`] allow, without overshoot.
///
/// Each step it picks the acceleration that, decreased at the maximum jerk, would bring the
/// output to rest exactly on the target (discrete time: over `n` steps of `dt` with the rate
/// falling by `j dt` per step the value moves `a (a + j dt) / (2 j)`, so the braking-limited
/// rate is `a = sqrt((j dt)^2 / 4 + 2 j |e|) - j dt / 2` for an error `e`), caps it at the
/// acceleration limit and at `|e| / dt` (no overshoot within a step), and moves the present
/// acceleration towards it by at most `j dt`. Once the target is within one step's reach
/// (`|e| <= dt min(j dt, A)`, the rate within `j dt` of the target's) it lands on it exactly,
/// so it arrives from any finite state within [`Self::steps_to_rest_bound`] steps. A target
/// beyond `max_value` is clamped; a non-finite target holds the present value; a non-finite or
/// non-positive `dt_secs` leaves the state unchanged.
///
/// ```
/// use ballbot_core::command::{AxisLimits, JerkLimiter};
/// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 4.0 };
/// let mut limiter = JerkLimiter::<f64>::default();
/// let mut peak_rate: f64 = 0.0;
/// for _ in 0..1000 {
///     limiter.step(1.0, &limits, 0.005);
///     peak_rate = peak_rate.max(limiter.rate_per_s());
/// }
/// assert_eq!(limiter.value(), 1.0);
/// assert!(peak_rate <= 1.0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JerkLimiter<T> {
    value: T,
    rate_per_s: T,
    jerk_per_s2: T,
}

impl<T: RealField + Copy> JerkLimiter<T> {
    /// A limiter at rest at `value`.
    ///
    /// ```
    /// use ballbot_core::command::JerkLimiter;
    /// let limiter = JerkLimiter::at(1.5);
    /// assert_eq!((limiter.value(), limiter.rate_per_s()), (1.5, 0.0));
    /// ```
    pub fn at(value: T) -> Self {
        Self {
            value,
            rate_per_s: T::zero(),
            jerk_per_s2: T::zero(),
        }
    }

    /// The shaped value.
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let mut limiter = JerkLimiter::at(0.0);
    /// let returned = limiter.step(1.0, &limits, 0.0025);
    /// assert_eq!(limiter.value(), returned);
    /// ```
    pub fn value(&self) -> T {
        self.value
    }

    /// Its rate of change (the acceleration, per s).
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let mut limiter = JerkLimiter::at(0.0);
    /// // After 0.25 s of jerk at 2 m/s^3 the acceleration is 0.5 m/s^2.
    /// for _ in 0..100 {
    ///     limiter.step(1.0, &limits, 0.0025);
    /// }
    /// approx::assert_relative_eq!(limiter.rate_per_s(), 0.5, epsilon = 1e-9);
    /// ```
    pub fn rate_per_s(&self) -> T {
        self.rate_per_s
    }

    /// The jerk applied in the last step (per s^2).
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let mut limiter = JerkLimiter::at(0.0);
    /// limiter.step(1.0, &limits, 0.0025);
    /// // A step in the target starts at the full jerk, not at a jump in acceleration.
    /// approx::assert_relative_eq!(limiter.jerk_per_s2(), 2.0, epsilon = 1e-9);
    /// ```
    pub fn jerk_per_s2(&self) -> T {
        self.jerk_per_s2
    }

    /// Restarts from `value` moving at `rate_per_s` (bumpless hand-over from another source).
    /// Non-finite inputs restart at rest at 0.
    ///
    /// ```
    /// use ballbot_core::command::JerkLimiter;
    /// let mut limiter = JerkLimiter::at(0.0);
    /// // Take over from a source that is at 0.8 m/s and accelerating at 0.3 m/s^2.
    /// limiter.reset(0.8, 0.3);
    /// assert_eq!((limiter.value(), limiter.rate_per_s()), (0.8, 0.3));
    /// limiter.reset(f64::NAN, 0.3);
    /// assert_eq!(limiter, JerkLimiter::at(0.0));
    /// ```
    pub fn reset(&mut self, value: T, rate_per_s: T) {
        if value.is_finite() && rate_per_s.is_finite() {
            *self = Self {
                value,
                rate_per_s,
                jerk_per_s2: T::zero(),
            };
        } else {
            *self = Self::at(T::zero());
        }
    }

    /// An upper bound on the number of [`Self::step`]s of `dt_secs` towards the constant
    /// `target` after which the limiter is at rest exactly on it (`value == target` clamped
    /// to `max_value`, rate 0), from its present state; `None` for invalid limits or `dt_secs`,
    /// a non-finite target, or a bound beyond `u64`.
    ///
    /// With `M`, `A`, `j` the limits, `J = j dt` the rate change of one step (`0` ratios below
    /// when `j = inf`), `a = min(|rate|, A)` and `e = |target - clamp(value, M)|`:
    ///
    /// ```text
    /// N = 4 + ceil(a / J) + 2 ceil(A / J) + ceil(E / (A dt)),   E = e + a dt (ceil(a / J) + 1)
    /// ```
    ///
    /// Why: the first step brings the state within the limits (value and rate clamped). The
    /// rate then reaches 0 or turns towards the target within `ceil(a / J)` steps, moving the
    /// value by at most `a dt` per step, so the distance left is at most `E`. From there the
    /// rate rises to at most `A` in `ceil(A / J)` steps, covers `E` at no less than the pace of
    /// a full-acceleration cruise (`ceil(E / (A dt))` steps) and brakes along the braking curve
    /// (`braking_rate`: the rate from which braking at `J` per step ends exactly on the
    /// target) in `ceil(A / J)` steps. The last step lands exactly: once the distance left is
    /// within one step's reach (`|e| <= dt min(J, A)` with the rate within `J` of the target's)
    /// the value is set to the target and the rate to 0, so rounding cannot leave a residual
    /// (the braking rate is also computed without cancellation, so it never rounds to 0 short
    /// of the target). The constant 4 counts the clamping step, the switch between the
    /// phases and the landing. Rounding: each step's update of the value may lose up to the
    /// value's resolution `r_v = eps M + s` (`eps` the machine epsilon, `s` the smallest
    /// subnormal), and of the rate `r_a = eps A + s`, so the step counts above use `J - r_a`
    /// and `A dt - r_v` as the progress per step; the bound exists (`Some`) when one step's
    /// reach `dt min(J, A)` is at least `2 r_v` and `J` at least `2 r_a`. Below that a step's
    /// motion is not representable (e.g. `A dt` under the ulp of the value) and nothing
    /// bounds the arrival. Checked by a property test over the whole finite range of `f32`
    /// and `f64`, subnormals included.
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let dt = 0.0025;
    /// // Cruising at 2 m/s, then a stop: at rest within the bound.
    /// let mut limiter = JerkLimiter::at(2.0);
    /// let bound = limiter.steps_to_rest_bound(0.0, &limits, dt).ok_or("no bound")?;
    /// let mut steps = 0;
    /// while (limiter.value(), limiter.rate_per_s()) != (0.0, 0.0) {
    ///     limiter.step(0.0, &limits, dt);
    ///     steps += 1;
    /// }
    /// assert!(steps <= bound, "{steps} > {bound}");
    /// // About 2.5 s (1000 steps) at 1 m/s^2 and 2 m/s^3; the bound allows 1207.
    /// assert!((990..=1010).contains(&steps), "{steps}");
    /// assert_eq!(bound, 1207);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn steps_to_rest_bound(
        &self,
        target: T,
        limits: &AxisLimits<T>,
        dt_secs: T,
    ) -> Option<u64> {
        if limits.validate().is_err() || !dt_is_valid(dt_secs) || !target.is_finite() {
            return None;
        }
        let f = |x: T| nalgebra::try_convert::<T, f64>(x);
        let (m, a_max, j, dt) = (
            f(limits.max_value)?,
            f(limits.max_rate_per_s)?,
            f(limits.max_jerk_per_s2)?,
            f(dt_secs)?,
        );
        let (value, rate) = if self.value.is_finite() && self.rate_per_s.is_finite() {
            (f(self.value)?, f(self.rate_per_s)?)
        } else {
            (0.0, 0.0)
        };
        let target = f(target)?.clamp(-m, m);
        let a = rate.abs().min(a_max);
        let e = (target - value.clamp(-m, m)).abs();
        let jerk_step = j * dt;
        // The resolutions of a value within `M` and of a rate within `A`: one rounding of a
        // step's update may lose this much (relative, plus the smallest subnormal).
        let eps = f(T::default_epsilon())?;
        let subnormal = f(T::default_epsilon() * smallest_normal::<T>())?;
        let (value_res, rate_res) = (eps * m + subnormal, eps * a_max + subnormal);
        let reach = dt * jerk_step.min(a_max);
        if !(reach >= 2.0 * value_res && (jerk_step.is_infinite() || jerk_step >= 2.0 * rate_res)) {
            // A step's motion, or its change of rate, below the resolution: no bound.
            return None;
        }
        let steps = |x: f64| {
            if jerk_step.is_finite() {
                ceil(x / (jerk_step - rate_res))
            } else {
                0.0
            }
        };
        let turn = steps(a);
        let distance: f64 = e + a * dt * (turn + 1.0);
        let cruise = ceil(distance / (a_max * dt - value_res));
        let n: f64 = 4.0 + turn + 2.0 * steps(a_max) + cruise;
        // `as` saturates: reject what it would clip.
        (n.is_finite() && n < 1.8e19).then_some(n as u64)
    }

    /// Advances one step of `dt_secs` towards a constant `target` and returns the new value.
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// // MiaPURE's translation limits at 400 Hz: a 1 m/s step in the target becomes an S-ramp.
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let dt = 0.0025;
    /// let mut limiter = JerkLimiter::at(0.0);
    /// let (mut previous, mut arrived_at_secs): (f64, Option<f64>) = (0.0, None);
    /// for k in 1..=1000 {
    ///     let v = limiter.step(1.0, &limits, dt);
    ///     assert!(v >= previous && v <= 1.0); // monotonic, no overshoot
    ///     assert!(limiter.rate_per_s() <= 1.0 + 1e-12);
    ///     assert!(limiter.jerk_per_s2().abs() <= 2.0 + 1e-9);
    ///     if v == 1.0 && arrived_at_secs.is_none() {
    ///         arrived_at_secs = Some(f64::from(k) * dt);
    ///     }
    ///     previous = v;
    /// }
    /// // Jerk up 0.5 s, accelerate 0.5 s, jerk down 0.5 s: it arrives after about 1.5 s.
    /// let t = arrived_at_secs.ok_or("never arrived")?;
    /// assert!((1.45..1.6).contains(&t), "{t}");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn step(&mut self, target: T, limits: &AxisLimits<T>, dt_secs: T) -> T {
        self.step_tracking(target, T::zero(), limits, dt_secs)
    }

    /// Advances one step of `dt_secs` towards a `target` that is itself moving at
    /// `target_rate_per_s` (e.g. a trajectory's acceleration), and returns the new value.
    ///
    /// The target's rate is fed forward and the braking-limited correction added to it, so a
    /// target that respects the limits is followed with a lag of about one step instead of the
    /// `a^2 / (2 j)` a pure error-driven limiter would keep. A non-finite rate counts as 0.
    ///
    /// ```
    /// use ballbot_core::command::{AxisLimits, JerkLimiter};
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 2.0 };
    /// let dt = 0.0025;
    /// // Follow a gentle sine, 0.5 m/s amplitude at 0.5 rad/s, feeding its rate forward.
    /// let target = |t: f64| 0.5 * (0.5 * t).sin();
    /// let target_rate = |t: f64| 0.25 * (0.5 * t).cos();
    /// let (mut tracking, mut plain) = (JerkLimiter::at(0.0), JerkLimiter::at(0.0));
    /// let (mut worst_tracking, mut worst_plain): (f64, f64) = (0.0, 0.0);
    /// for k in 1..=4000 {
    ///     let t = f64::from(k) * dt;
    ///     let a = tracking.step_tracking(target(t), target_rate(t), &limits, dt);
    ///     let b = plain.step(target(t), &limits, dt);
    ///     if t > 2.0 {
    ///         worst_tracking = worst_tracking.max((a - target(t)).abs());
    ///         worst_plain = worst_plain.max((b - target(t)).abs());
    ///     }
    /// }
    /// // With the rate fed forward the lag is far smaller.
    /// assert!(worst_tracking < 0.1 * worst_plain, "{worst_tracking} {worst_plain}");
    /// ```
    pub fn step_tracking(
        &mut self,
        target: T,
        target_rate_per_s: T,
        limits: &AxisLimits<T>,
        dt_secs: T,
    ) -> T {
        if !dt_is_valid(dt_secs) {
            return self.value;
        }
        self.advance(target, target_rate_per_s, limits, dt_secs)
    }

    /// [`Self::step_tracking`] for a `dt_secs` known to be finite and positive.
    ///
    /// Settled on a still target (the usual case, e.g. cruising): nothing to do, checked
    /// inline at the caller; the motion itself is [`Self::advance_moving`], out of line.
    #[inline(always)]
    pub(super) fn advance(
        &mut self,
        target: T,
        target_rate_per_s: T,
        limits: &AxisLimits<T>,
        dt_secs: T,
    ) -> T {
        // The value is always within its bounds, so a target equal to it is too.
        let zero = T::zero();
        if target == self.value && self.rate_per_s == zero && target_rate_per_s == zero {
            self.jerk_per_s2 = zero;
            return self.value;
        }
        self.advance_moving(target, target_rate_per_s, limits, dt_secs)
    }

    /// [`Self::advance`] when not settled. Marked cold: most outer steps find every axis
    /// settled (standing, cruising), and the hint keeps the register spills around this call
    /// off that path (callgrind: the shaper's settled step 218 -> 208 instructions).
    #[cold]
    fn advance_moving(
        &mut self,
        target: T,
        target_rate_per_s: T,
        limits: &AxisLimits<T>,
        dt_secs: T,
    ) -> T {
        if !(self.value.is_finite() && self.rate_per_s.is_finite()) {
            *self = Self::at(T::zero());
        }
        let max_value = limits.max_value.abs();
        let max_rate = limits.max_rate_per_s.abs();
        let jerk = limits.max_jerk_per_s2.abs();
        let (target, feed) = if !target.is_finite() {
            (self.value, T::zero())
        } else if target.abs() > max_value {
            // Clamped: the clamped target does not move.
            (clamp_sym(target, max_value), T::zero())
        } else if target_rate_per_s.is_finite() {
            (target, clamp_sym(target_rate_per_s, max_rate))
        } else {
            (target, T::zero())
        };
        let error = target - self.value;
        let jerk_step = jerk * dt_secs;
        // Within one step's reach of the target (moving with it): land on it exactly. Without
        // this, rounding leaves a residual error whose braking rate is below one ulp of the
        // rate, and the limiter never arrives (the dead zone a stop used to wait in for ever).
        if (self.rate_per_s - feed).abs() <= jerk_step
            && error.abs() / dt_secs <= min(jerk_step, max_rate)
        {
            return self.settle(target + feed * dt_secs, feed, max_value, dt_secs);
        }
        let correction_mag = min(
            min(
                braking_rate(error.abs(), jerk, dt_secs),
                lit::<T>(2.0) * max_rate,
            ),
            error.abs() / dt_secs,
        );
        let correction = if error > T::zero() {
            correction_mag
        } else {
            -correction_mag
        };
        let wanted = clamp_sym(feed + correction, max_rate);
        let change = clamp_sym(wanted - self.rate_per_s, jerk_step);
        let mut rate = clamp_sym(self.rate_per_s + change, max_rate);
        let mut value = self.value + rate * dt_secs;
        // Arrived (or stepped across the target with a rate the jerk limit can match to the
        // target's in one step): settle exactly on it. The rate takes the target's at once
        // only if that is within one jerk step of the rate before this step; otherwise the
        // next step does it (the landing rule above), so the jerk limit holds on every step.
        let moved_target = target + feed * dt_secs;
        // Signs compared, not multiplied: the product of two tiny distances underflows to 0.
        let remaining = moved_target - value;
        let crossed = remaining == T::zero() || (remaining > T::zero()) != (error > T::zero());
        if crossed && (rate - feed).abs() <= jerk_step {
            value = moved_target;
            if (self.rate_per_s - feed).abs() <= jerk_step {
                rate = feed;
            }
        }
        self.settle(value, rate, max_value, dt_secs)
    }

    /// Commits `value` (clamped to `max_value`) and `rate` when both are finite, with the jerk
    /// that took the rate there; returns the (new) value.
    fn settle(&mut self, value: T, rate: T, max_value: T, dt_secs: T) -> T {
        let value = clamp_sym(value, max_value);
        if value.is_finite() && rate.is_finite() {
            self.jerk_per_s2 = (rate - self.rate_per_s) / dt_secs;
            self.value = value;
            self.rate_per_s = rate;
        }
        self.value
    }
}

/// The rate `a` from which, with the rate falling by `j dt` per step, the value comes to rest
/// exactly `error_abs` further on: `a (a + j dt) / (2 j) = |e|`, i.e. `sqrt((j dt / 2)^2 + 2 j
/// |e|) - j dt / 2`.
///
/// Computed without cancellation as `2 |e| / (dt / 2 + hypot(dt / 2, t_b))`, `t_b = sqrt(2 |e|
/// / j)` the braking time (from square roots, so nothing overflows for finite inputs): the
/// difference form rounds to 0 once `2 j |e|` is below one ulp of `(j dt / 2)^2`, which left
/// a dead zone around the target. `+inf` jerk (no jerk limit) gives `2 |e| / dt`; a braking
/// time beyond the largest finite number (a subnormal jerk) its limit `sqrt(2 j |e|)`.
fn braking_rate<T: RealField + Copy>(error_abs: T, jerk: T, dt_secs: T) -> T {
    let (root_error, root_jerk) = (error_abs.sqrt(), jerk.sqrt());
    let sqrt_2: T = lit(core::f64::consts::SQRT_2);
    let braking_secs = sqrt_2 * root_error / root_jerk;
    if !braking_secs.is_finite() {
        return sqrt_2 * root_error * root_jerk;
    }
    let half_dt = dt_secs * lit(0.5);
    lit::<T>(2.0) * root_error * (root_error / (half_dt + hypot(half_dt, braking_secs)))
}

/// `x` rounded up (libm's, through nalgebra: the core has no `std`).
fn ceil(x: f64) -> f64 {
    nalgebra::ComplexField::ceil(x)
}
