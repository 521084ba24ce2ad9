//! Command shaping: what the robot is asked to do, made smooth and feasible.
//!
//! Three kinds of command reach a ballbot (see [`Command`]):
//! - **velocity** ([`VelocityCommand`]): remote control, `vx`, `vy` (m/s, body frame: x towards
//!   omniwheel 1, y to its left, z up) and a yaw rate (rad/s, counter-clockwise from above);
//! - **lean-to-drive** ([`LeanInput`], [`LeanToDrive`]): a rider's torso lean becomes a velocity
//!   command through a deadband, a gain and a speed limit;
//! - **trajectory** ([`Trajectory`]): a sampled planar command state `s_c(t) = [theta, phi,
//!   theta_dot, phi_dot]` (e.g. the optimal braking trajectory) borrowed from a slice, sampled
//!   every `sample_period_secs`, linearly interpolated, and driven along a heading.
//!
//! Every kind passes through the same per-axis [`JerkLimiter`]: speed, acceleration and jerk are
//! bounded, so a step in the command (a dropped remote, a rider jerking forward) becomes a smooth
//! ramp. The [`CommandShaper`] turns the shaped motion into the three planar command states the
//! plane controllers consume ([`PlanarCommands`]):
//!
//! ```text
//! sagittal (travel along x):  s_cy = [theta_ff(a_x),  phi_y, 0,  v_x / r]
//! frontal  (travel along -y): s_cx = [-theta_ff(a_y), phi_x, 0, -v_y / r]
//! spin:                       s_cz = [heading, yaw_rate]
//! ```
//!
//! (MODEL.md section 1: ball position `x = r phi_y`, `y = -r phi_x`.) The lean feedforward
//! `theta_ff` is the constant tilt at which the nominal WIP accelerates its ball at `a` without
//! tipping: with `theta_dot = theta_ddot = 0` the model gives `c phi_ddot = m_U g l theta - tau`
//! and `b phi_ddot = tau`, so, to first order, `theta_ff = (b + c0) a / (r m_U g l)`. Jerk
//! limiting is what makes that lean command continuous. (Trajectory commands carry their own
//! tilt and tilt rate.)
//!
//! ```
//! use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
//! use ballbot_core::BallbotParams;
//! let robot = BallbotParams::<f64>::miapure_60kg();
//! let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
//! let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, vy_m_per_s: 0.0, yaw_rate_rad_per_s: 0.0 });
//! // A 1 m/s step becomes a ramp: after one 400 Hz step the command has barely moved.
//! let shaped = shaper.step(&go, 0.0025);
//! assert!(shaped.velocity.vx_m_per_s > 0.0 && shaped.velocity.vx_m_per_s < 1e-3);
//! // Three seconds later it has arrived, and the sagittal plane is asked for v / r.
//! for _ in 0..1200 { shaper.step(&go, 0.0025); }
//! let shaped = shaper.step(&go, 0.0025);
//! approx::assert_relative_eq!(shaped.velocity.vx_m_per_s, 1.0, epsilon = 1e-9);
//! approx::assert_relative_eq!(shaped.planar.sagittal[3], 1.0 / 0.1145, epsilon = 1e-6);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use crate::check::{finite, lit, non_negative, positive};
use crate::control::dt_is_valid;
use crate::spin::SpinState;
use crate::wip::{BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{BallbotParams, Error, WipParams};
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
pub struct AxisLimits<T> {
    /// Largest magnitude of the value (m/s or rad/s).
    pub max_value: T,
    /// Largest magnitude of its rate of change, the acceleration (per s).
    pub max_rate_per_s: T,
    /// Largest magnitude of the rate's rate of change, the jerk (per s^2).
    pub max_jerk_per_s2: T,
}

impl<T: RealField + Copy> AxisLimits<T> {
    /// Checks that every limit is finite and positive.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::command::AxisLimits;
    /// let limits = AxisLimits { max_value: 2.0, max_rate_per_s: 1.0, max_jerk_per_s2: 0.0 };
    /// assert!(matches!(
    ///     limits.validate(),
    ///     Err(Error::InvalidParameter { field: "max_jerk_per_s2", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.max_value, "max_value")?;
        positive(self.max_rate_per_s, "max_rate_per_s")?;
        positive(self.max_jerk_per_s2, "max_jerk_per_s2")
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
/// acceleration towards it by at most `j dt`. A target beyond `max_value` is clamped; a
/// non-finite target holds the present value; a non-finite or non-positive `dt_secs` leaves
/// the state unchanged.
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
    fn advance(
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
        let half = jerk_step * lit(0.5);
        let braking = (half * half + lit::<T>(2.0) * jerk * error.abs()).sqrt() - half;
        let correction_mag = min(
            min(braking, lit::<T>(2.0) * max_rate),
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
        // target's in one step): settle exactly on it.
        let moved_target = target + feed * dt_secs;
        let crossed = (moved_target - value) * error <= T::zero();
        if crossed && (rate - feed).abs() <= jerk_step {
            value = moved_target;
            rate = feed;
        }
        let value = clamp_sym(value, max_value);
        if value.is_finite() && rate.is_finite() {
            self.jerk_per_s2 = (rate - self.rate_per_s) / dt_secs;
            self.value = value;
            self.rate_per_s = rate;
        }
        self.value
    }
}

/// A remote-control velocity command in the body frame.
///
/// ```
/// use ballbot_core::command::VelocityCommand;
/// // Forward and to the left at 0.5 m/s each, turning clockwise at 0.2 rad/s.
/// let v = VelocityCommand { vx_m_per_s: 0.5, vy_m_per_s: 0.5, yaw_rate_rad_per_s: -0.2 };
/// assert!(v.is_finite());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityCommand<T> {
    /// Forward speed, towards omniwheel 1 (body x) (m/s).
    pub vx_m_per_s: T,
    /// Sideways speed, to the left (body y) (m/s).
    pub vy_m_per_s: T,
    /// Yaw rate, counter-clockwise seen from above (rad/s).
    pub yaw_rate_rad_per_s: T,
}

impl<T: RealField + Copy> VelocityCommand<T> {
    /// Standing still.
    ///
    /// ```
    /// use ballbot_core::command::VelocityCommand;
    /// assert_eq!(VelocityCommand::<f64>::zero(), VelocityCommand::default());
    /// ```
    pub fn zero() -> Self {
        Self {
            vx_m_per_s: T::zero(),
            vy_m_per_s: T::zero(),
            yaw_rate_rad_per_s: T::zero(),
        }
    }

    /// Whether every component is finite.
    ///
    /// ```
    /// use ballbot_core::command::VelocityCommand;
    /// let v = VelocityCommand { vx_m_per_s: f64::NAN, ..VelocityCommand::zero() };
    /// assert!(!v.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        self.vx_m_per_s.is_finite()
            && self.vy_m_per_s.is_finite()
            && self.yaw_rate_rad_per_s.is_finite()
    }
}

/// A rider's torso lean, measured relative to the robot's body (e.g. by a seat-back or
/// rider-worn sensor), plus an optional yaw-rate request (e.g. a twist grip).
///
/// ```
/// use ballbot_core::command::{LeanInput, LeanToDrive, LeanToDriveParams};
/// let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider())?;
/// // 0.15 rad towards the front left: the command points the same way.
/// let input = LeanInput { towards_x_rad: 0.1, towards_y_rad: 0.1, yaw_rate_rad_per_s: 0.0 };
/// let v = lean.velocity(&input);
/// approx::assert_relative_eq!(v.vx_m_per_s, v.vy_m_per_s, epsilon = 1e-12);
/// assert!(v.vx_m_per_s > 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LeanInput<T> {
    /// Lean towards body +x (forward) (rad).
    pub towards_x_rad: T,
    /// Lean towards body +y (left) (rad).
    pub towards_y_rad: T,
    /// Requested yaw rate, counter-clockwise from above (rad/s).
    pub yaw_rate_rad_per_s: T,
}

/// Lean-to-drive settings: torso lean -> velocity command.
///
/// The lean vector's magnitude beyond the deadband, times the gain, is the speed along the
/// lean's direction, capped at `max_speed_m_per_s`. The deadband is radial, so small leans in
/// any direction do nothing and the speed is continuous in the lean.
///
/// ```
/// use ballbot_core::command::{LeanInput, LeanToDrive, LeanToDriveParams};
/// // A nervous rider: a wider 5 deg deadband, 0.5 m/s top speed.
/// let params = LeanToDriveParams {
///     deadband_rad: 5f64.to_radians(),
///     max_speed_m_per_s: 0.5,
///     ..LeanToDriveParams::rider()
/// };
/// let lean = LeanToDrive::new(params)?;
/// let far = LeanInput { towards_x_rad: 0.4, ..LeanInput::default() };
/// assert_eq!(lean.velocity(&far).vx_m_per_s, 0.5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeanToDriveParams<T> {
    /// Lean magnitude that commands nothing (rad).
    pub deadband_rad: T,
    /// Speed per radian of lean beyond the deadband (m/s per rad).
    pub gain_m_per_s_per_rad: T,
    /// Largest commanded speed (m/s).
    pub max_speed_m_per_s: T,
    /// Largest acceleration while riding (m/s^2); the shaper uses the smaller of this and its
    /// translation limit.
    pub max_accel_m_per_s2: T,
    /// Largest yaw rate a rider may request (rad/s).
    pub max_yaw_rate_rad_per_s: T,
}

impl<T: RealField + Copy> LeanToDriveParams<T> {
    /// Defaults for a seated rider on MiaPURE (engineering choices, not from the paper):
    /// 3 deg deadband, 6 m/s per rad (a 10 deg lean, 7 deg beyond the deadband, gives 0.73 m/s),
    /// 1.0 m/s, 0.5 m/s^2, 1.0 rad/s.
    ///
    /// ```
    /// use ballbot_core::command::{LeanInput, LeanToDrive, LeanToDriveParams};
    /// let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider())?;
    /// // A 10 deg lean, 7 deg beyond the 3 deg deadband, gives 0.73 m/s.
    /// let input = LeanInput { towards_x_rad: 10f64.to_radians(), ..LeanInput::default() };
    /// approx::assert_relative_eq!(lean.velocity(&input).vx_m_per_s, 0.733, epsilon = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn rider() -> Self {
        Self {
            deadband_rad: lit(0.0524),
            gain_m_per_s_per_rad: lit(6.0),
            max_speed_m_per_s: lit(1.0),
            max_accel_m_per_s2: lit(0.5),
            max_yaw_rate_rad_per_s: lit(1.0),
        }
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::command::LeanToDriveParams;
    /// let rider = LeanToDriveParams::<f64>::rider();
    /// let params = LeanToDriveParams { gain_m_per_s_per_rad: -6.0, ..rider };
    /// assert!(matches!(
    ///     params.validate(),
    ///     Err(Error::InvalidParameter { field: "gain_m_per_s_per_rad", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        non_negative(self.deadband_rad, "deadband_rad")?;
        positive(self.gain_m_per_s_per_rad, "gain_m_per_s_per_rad")?;
        positive(self.max_speed_m_per_s, "max_speed_m_per_s")?;
        positive(self.max_accel_m_per_s2, "max_accel_m_per_s2")?;
        positive(self.max_yaw_rate_rad_per_s, "max_yaw_rate_rad_per_s")
    }
}

/// The lean-to-drive map (stateless; acceleration and jerk are limited by the shaper).
///
/// ```
/// use ballbot_core::command::{LeanInput, LeanToDrive, LeanToDriveParams};
/// let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider())?;
/// // Inside the deadband: nothing.
/// let still = lean.velocity(&LeanInput { towards_x_rad: 0.03, towards_y_rad: 0.0, yaw_rate_rad_per_s: 0.0 });
/// assert_eq!(still.vx_m_per_s, 0.0);
/// // 0.1 rad forward: 6 * (0.1 - 0.0524) m/s forward.
/// let go = lean.velocity(&LeanInput { towards_x_rad: 0.1, towards_y_rad: 0.0, yaw_rate_rad_per_s: 0.0 });
/// approx::assert_relative_eq!(go.vx_m_per_s, 6.0 * (0.1 - 0.0524), epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeanToDrive<T> {
    params: LeanToDriveParams<T>,
}

impl<T: RealField + Copy> LeanToDrive<T> {
    /// Validates `params`.
    ///
    /// ```
    /// use ballbot_core::command::{LeanToDrive, LeanToDriveParams};
    /// assert!(LeanToDrive::new(LeanToDriveParams::<f64>::rider()).is_ok());
    /// let no_deadband = LeanToDriveParams { deadband_rad: -0.1, ..LeanToDriveParams::rider() };
    /// assert!(LeanToDrive::new(no_deadband).is_err());
    /// ```
    pub fn new(params: LeanToDriveParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self { params })
    }

    /// The settings.
    ///
    /// ```
    /// use ballbot_core::command::{LeanToDrive, LeanToDriveParams};
    /// let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider())?;
    /// assert_eq!(lean.params().max_speed_m_per_s, 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &LeanToDriveParams<T> {
        &self.params
    }

    /// The velocity command for a lean; a non-finite lean commands standing still.
    ///
    /// ```
    /// use ballbot_core::command::{LeanInput, LeanToDrive, LeanToDriveParams};
    /// let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider())?;
    /// // Leaning hard is capped at the 1 m/s top speed; a twist-grip request at 1 rad/s.
    /// let hard = LeanInput { towards_x_rad: 0.0, towards_y_rad: -0.5, yaw_rate_rad_per_s: 3.0 };
    /// let v = lean.velocity(&hard);
    /// assert_eq!((v.vx_m_per_s, v.vy_m_per_s, v.yaw_rate_rad_per_s), (0.0, -1.0, 1.0));
    /// // A broken sensor (NaN) commands standing still.
    /// let broken = LeanInput { towards_x_rad: f64::NAN, ..LeanInput::default() };
    /// assert_eq!(lean.velocity(&broken).vx_m_per_s, 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn velocity(&self, lean: &LeanInput<T>) -> VelocityCommand<T> {
        let p = &self.params;
        let (lx, ly) = (lean.towards_x_rad, lean.towards_y_rad);
        let magnitude = (lx * lx + ly * ly).sqrt();
        let mut out = VelocityCommand::zero();
        if magnitude.is_finite() && magnitude > p.deadband_rad {
            let speed =
                (p.gain_m_per_s_per_rad * (magnitude - p.deadband_rad)).min(p.max_speed_m_per_s);
            let scale = speed / magnitude;
            out.vx_m_per_s = lx * scale;
            out.vy_m_per_s = ly * scale;
        }
        if lean.yaw_rate_rad_per_s.is_finite() {
            out.yaw_rate_rad_per_s = lean
                .yaw_rate_rad_per_s
                .max(-p.max_yaw_rate_rad_per_s)
                .min(p.max_yaw_rate_rad_per_s);
        }
        out
    }
}

/// A sampled planar command trajectory borrowed from a slice: `samples[k]` is the command state
/// `[theta (rad), phi (rad), theta_dot (rad/s), phi_dot (rad/s)]` at `k * sample_period_secs`,
/// for travel along `heading_rad` in the body frame (0: towards omniwheel 1, sagittal plane;
/// `pi/2`: body +y).
///
/// Along a heading `h` the planar state maps to the sagittal plane as `cos(h) s` and to the
/// frontal plane as `-sin(h) s` (ball position `x = r phi_y`, `y = -r phi_x`).
///
/// ```
/// use ballbot_core::command::Trajectory;
/// use nalgebra::Vector4;
/// let samples = [Vector4::new(0.0, 0.0, 0.0, 10.0), Vector4::new(0.0, 0.1, 0.0, 0.0)];
/// let traj = Trajectory::new(&samples, 0.5, 0.0)?;
/// approx::assert_relative_eq!(traj.sample(0.25)[3], 5.0);
/// assert_eq!(traj.sample(9.0), samples[1]); // held after the end
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trajectory<'a, T: nalgebra::Scalar> {
    samples: &'a [WipState<T>],
    sample_period_secs: T,
    heading_rad: T,
    yaw_rate_rad_per_s: T,
}

impl<'a, T: RealField + Copy> Trajectory<'a, T> {
    /// Validates the samples (at least one, all finite) and the period (finite, > 0). Checking
    /// every sample once here keeps [`Self::sample`] O(1).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let samples = [Vector4::zeros(), Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// assert!(Trajectory::new(&samples, 0.01, 0.0).is_ok());
    /// // No samples, a NaN sample or a zero period are refused.
    /// assert!(Trajectory::<f64>::new(&[], 0.01, 0.0).is_err());
    /// assert!(Trajectory::new(&[Vector4::repeat(f64::NAN)], 0.01, 0.0).is_err());
    /// assert!(Trajectory::new(&samples, 0.0, 0.0).is_err());
    /// ```
    pub fn new(
        samples: &'a [WipState<T>],
        sample_period_secs: T,
        heading_rad: T,
    ) -> Result<Self, Error> {
        if samples.is_empty() {
            return Err(Error::invalid("samples", "must hold at least one state"));
        }
        if samples.iter().any(|s| !s.iter().all(|x| x.is_finite())) {
            return Err(Error::invalid("samples", "must be finite"));
        }
        positive(sample_period_secs, "sample_period_secs")?;
        finite(heading_rad, "heading_rad")?;
        Ok(Self {
            samples,
            sample_period_secs,
            heading_rad,
            yaw_rate_rad_per_s: T::zero(),
        })
    }

    /// The same trajectory with a constant yaw rate commanded alongside (rad/s). A non-finite
    /// rate is replaced by 0.
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// let traj = Trajectory::new(&samples, 0.01, 0.0)?.with_yaw_rate(0.3);
    /// assert_eq!(traj.yaw_rate_rad_per_s(), 0.3);
    /// assert_eq!(traj.with_yaw_rate(f64::NAN).yaw_rate_rad_per_s(), 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn with_yaw_rate(mut self, yaw_rate_rad_per_s: T) -> Self {
        self.yaw_rate_rad_per_s = if yaw_rate_rad_per_s.is_finite() {
            yaw_rate_rad_per_s
        } else {
            T::zero()
        };
        self
    }

    /// The travel heading in the body frame (rad).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// // Travel towards body +y.
    /// let traj = Trajectory::new(&samples, 0.01, core::f64::consts::FRAC_PI_2)?;
    /// assert_eq!(traj.heading_rad(), core::f64::consts::FRAC_PI_2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn heading_rad(&self) -> T {
        self.heading_rad
    }

    /// The commanded yaw rate (rad/s).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// let traj = Trajectory::new(&samples, 0.01, 0.0)?;
    /// assert_eq!(traj.yaw_rate_rad_per_s(), 0.0); // none unless asked for
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn yaw_rate_rad_per_s(&self) -> T {
        self.yaw_rate_rad_per_s
    }

    /// The duration covered by the samples (s).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// // 101 samples 10 ms apart cover 1 s.
    /// let samples = [Vector4::<f64>::zeros(); 101];
    /// approx::assert_relative_eq!(Trajectory::new(&samples, 0.01, 0.0)?.duration_secs(), 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn duration_secs(&self) -> T {
        let n: T = nalgebra::convert(self.samples.len().saturating_sub(1) as f64);
        n * self.sample_period_secs
    }

    /// The command state at `time_secs` after the start, linearly interpolated; the first
    /// sample before the start, the last after the end (and for a non-finite time).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// // Braking from 8 rad/s to rest in 1 s.
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 8.0), Vector4::new(0.0, 4.0, 0.0, 0.0)];
    /// let traj = Trajectory::new(&samples, 1.0, 0.0)?;
    /// approx::assert_relative_eq!(traj.sample(0.75)[3], 2.0);
    /// assert_eq!(traj.sample(-1.0), samples[0]); // before the start: the first sample
    /// assert_eq!(traj.sample(f64::NAN), samples[1]); // non-finite time: the last
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn sample(&self, time_secs: T) -> WipState<T> {
        self.sample_with_rate(time_secs).0
    }

    /// The interpolated command state at `time_secs` and its time derivative (the slope of
    /// the interval it falls in; zero before the start and after the end).
    ///
    /// ```
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 8.0), Vector4::new(0.0, 4.0, 0.0, 0.0)];
    /// let traj = Trajectory::new(&samples, 1.0, 0.0)?;
    /// let (s, rate) = traj.sample_with_rate(0.5);
    /// assert_eq!(s[3], 4.0);
    /// assert_eq!(rate[3], -8.0); // decelerating at 8 rad/s^2
    /// assert_eq!(traj.sample_with_rate(2.0).1, Vector4::zeros()); // held after the end
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn sample_with_rate(&self, time_secs: T) -> (WipState<T>, WipState<T>) {
        // `new` refuses an empty slice; matching on first/last keeps this free of panic paths.
        let (Some(&first), Some(&final_state)) = (self.samples.first(), self.samples.last()) else {
            return (WipState::zeros(), WipState::zeros());
        };
        let last = self.samples.len() - 1;
        if !time_secs.is_finite() {
            return (final_state, WipState::zeros());
        }
        if time_secs < T::zero() {
            return (first, WipState::zeros());
        }
        let position = time_secs / self.sample_period_secs;
        let index_f = position.floor();
        let index = nalgebra::try_convert::<T, f64>(index_f).unwrap_or(f64::INFINITY);
        // `as` saturates; compare in f64 so the cast is exact when it matters.
        if index.partial_cmp(&(last as f64)) != Some(core::cmp::Ordering::Less) {
            return (final_state, WipState::zeros());
        }
        let k = index as usize;
        let frac = position - index_f;
        match (self.samples.get(k), self.samples.get(k + 1)) {
            (Some(a), Some(b)) => {
                let slope = b - a;
                (a + slope * frac, slope / self.sample_period_secs)
            }
            _ => (final_state, WipState::zeros()),
        }
    }
}

/// What the robot is asked to do this step.
///
/// ```
/// use ballbot_core::command::{Command, LeanInput, Trajectory, VelocityCommand};
/// use nalgebra::Vector4;
/// let samples = [Vector4::new(0.0, 0.0, 0.0, 5.0)];
/// let commands = [
///     Command::Stop,
///     Command::Velocity(VelocityCommand { vx_m_per_s: 0.5, ..VelocityCommand::zero() }),
///     Command::Lean(LeanInput { towards_x_rad: 0.1, ..LeanInput::default() }),
///     Command::Trajectory { trajectory: Trajectory::new(&samples, 0.01, 0.0)?, time_secs: 0.0 },
/// ];
/// assert!(commands.iter().all(|c| c.is_finite()));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command<'a, T: nalgebra::Scalar> {
    /// Come to rest and hold upright (the controlled stop uses this).
    Stop,
    /// Remote-control velocity.
    Velocity(VelocityCommand<T>),
    /// A rider's lean.
    Lean(LeanInput<T>),
    /// Follow a trajectory, `time_secs` after its start.
    Trajectory {
        /// The trajectory.
        trajectory: Trajectory<'a, T>,
        /// Time since its start (s).
        time_secs: T,
    },
}

impl<T: RealField + Copy> Command<'_, T> {
    /// Whether every number in the command is finite (a trajectory's samples were checked when
    /// it was built).
    ///
    /// ```
    /// use ballbot_core::command::{Command, VelocityCommand};
    /// let garbled = VelocityCommand { yaw_rate_rad_per_s: f64::INFINITY, ..Default::default() };
    /// assert!(!Command::Velocity(garbled).is_finite());
    /// assert!(Command::<f64>::Stop.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        match self {
            Self::Stop => true,
            Self::Velocity(v) => v.is_finite(),
            Self::Lean(l) => {
                l.towards_x_rad.is_finite()
                    && l.towards_y_rad.is_finite()
                    && l.yaw_rate_rad_per_s.is_finite()
            }
            Self::Trajectory { time_secs, .. } => time_secs.is_finite(),
        }
    }
}

/// Limits and settings of the [`CommandShaper`].
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{AxisLimits, CommandShaper, CommandShaperParams};
/// // A cautious setting: 0.5 m/s and 0.3 m/s^2 at most.
/// let params = CommandShaperParams {
///     translation: AxisLimits { max_value: 0.5, max_rate_per_s: 0.3, max_jerk_per_s2: 1.0 },
///     ..CommandShaperParams::miapure()
/// };
/// let shaper = CommandShaper::new(params, &BallbotParams::<f64>::miapure_60kg())?;
/// assert_eq!(shaper.params().translation.max_value, 0.5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandShaperParams<T> {
    /// Limits of each translation axis, body x and body y (m/s, m/s^2, m/s^3).
    pub translation: AxisLimits<T>,
    /// Limits of the yaw rate (rad/s, rad/s^2, rad/s^3).
    pub yaw: AxisLimits<T>,
    /// Lean-to-drive settings.
    pub lean_to_drive: LeanToDriveParams<T>,
    /// Largest commanded tilt (rad), feedforward or from a trajectory.
    pub max_tilt_command_rad: T,
    /// Largest commanded tilt rate (rad/s).
    pub max_tilt_rate_command_rad_per_s: T,
    /// Time constant of the reference filter (s, >= 0; 0 = off). When positive, velocity and
    /// lean commands build the planar reference from the jerk-limited speed `v` passed through
    /// `v_f' = (v - v_f) / tau`: tilt `k a_f`, tilt rate `k j_f`, ball rate `v_f / r`, with
    /// `a_f = (v - v_f) / tau` and `j_f = (a - a_f) / tau` (and [`ShapedCommand::acceleration`]
    /// is `a_f`). That reference is consistent (the tilt rate is the tilt's derivative) and
    /// continuous, so the LQR no longer rights the body by running the ball ahead when the
    /// acceleration ends: on MiaPURE with 60 kg a ramp at 1 m/s^2 to 1.5 m/s peaks at 1.786 m/s
    /// ball speed with 0, 1.500 m/s with 0.3 s, at the price of a delay of about `tau`
    /// (docs/embedding.md, "Speed overshoot"). Trajectories are not filtered.
    pub reference_filter_secs: T,
}

impl<T: RealField + Copy> CommandShaperParams<T> {
    /// Defaults for MiaPURE with a payload (engineering choices): 2.0 m/s (the paper's design
    /// target), 1.0 m/s^2, 2.0 m/s^3 (the lean changes by 7 deg over 0.5 s); yaw 1.5 rad/s, 3 rad/s^2, 20 rad/s^3; the rider
    /// lean-to-drive defaults; tilt command within 0.2 rad and 1.0 rad/s.
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let p = CommandShaperParams::<f64>::miapure();
    /// // The paper's 2 m/s design target.
    /// assert_eq!((p.translation.max_value, p.yaw.max_value), (2.0, 1.5));
    /// ```
    pub fn miapure() -> Self {
        Self {
            translation: AxisLimits {
                max_value: lit(2.0),
                max_rate_per_s: lit(1.0),
                max_jerk_per_s2: lit(2.0),
            },
            yaw: AxisLimits {
                max_value: lit(1.5),
                max_rate_per_s: lit(3.0),
                max_jerk_per_s2: lit(20.0),
            },
            lean_to_drive: LeanToDriveParams::rider(),
            max_tilt_command_rad: lit(0.2),
            max_tilt_rate_command_rad_per_s: lit(1.0),
            reference_filter_secs: T::zero(),
        }
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let mut p = CommandShaperParams::<f64>::miapure();
    /// assert!(p.validate().is_ok());
    /// p.max_tilt_command_rad = 0.0;
    /// assert!(p.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.translation.validate()?;
        self.yaw.validate()?;
        self.lean_to_drive.validate()?;
        positive(self.max_tilt_command_rad, "max_tilt_command_rad")?;
        positive(
            self.max_tilt_rate_command_rad_per_s,
            "max_tilt_rate_command_rad_per_s",
        )?;
        non_negative(self.reference_filter_secs, "reference_filter_secs")
    }
}

/// Body-frame motion: velocity, or one of its derivatives.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let turn = Command::Velocity(VelocityCommand { yaw_rate_rad_per_s: 1.0, ..Default::default() });
/// // The yaw acceleration after one step is the 20 rad/s^3 jerk limit times 2.5 ms.
/// let a = shaper.step(&turn, 0.0025).acceleration;
/// assert_eq!((a.x, a.y), (0.0, 0.0));
/// approx::assert_relative_eq!(a.yaw, 20.0 * 0.0025, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyMotion<T> {
    /// Along body x (m/s, m/s^2 or m/s^3).
    pub x: T,
    /// Along body y (m/s, m/s^2 or m/s^3).
    pub y: T,
    /// About body z (rad/s, rad/s^2 or rad/s^3).
    pub yaw: T,
}

/// The command state of each planar controller.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// // Sideways to the left: the frontal plane travels along -y, so its ball rate is negative.
/// let left = Command::Velocity(VelocityCommand { vy_m_per_s: 0.5, ..VelocityCommand::zero() });
/// let mut planar = shaper.step(&left, 0.0025).planar;
/// for _ in 0..800 {
///     planar = shaper.step(&left, 0.0025).planar;
/// }
/// let r = robot.frontal.ball_radius_m;
/// approx::assert_relative_eq!(planar.frontal[3], -0.5 / r, epsilon = 1e-9);
/// assert_eq!(planar.sagittal[3], 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarCommands<T: nalgebra::Scalar> {
    /// Sagittal plane `s_cy = [theta_y, phi_y, theta_dot_y, phi_dot_y]`.
    pub sagittal: WipState<T>,
    /// Frontal plane `s_cx = [theta_x, phi_x, theta_dot_x, phi_dot_x]`.
    pub frontal: WipState<T>,
    /// Spin `s_cz = [theta_z, theta_dot_z]` (heading, yaw rate).
    pub spin: SpinState<T>,
}

/// One step of shaped command.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let garbled = Command::Velocity(VelocityCommand { vx_m_per_s: f64::NAN, ..Default::default() });
/// // A non-finite command is flagged and replaced by a stop.
/// let shaped = shaper.step(&garbled, 0.0025);
/// assert!(!shaped.command_finite);
/// assert_eq!(shaped.velocity.vx_m_per_s, 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapedCommand<T: nalgebra::Scalar> {
    /// Shaped body velocity (m/s, m/s, rad/s).
    pub velocity: BodyVelocity<T>,
    /// Its acceleration (m/s^2, m/s^2, rad/s^2); with the reference filter on, that of the
    /// filtered speed (see [`CommandShaperParams::reference_filter_secs`]).
    pub acceleration: BodyMotion<T>,
    /// The planar command states.
    pub planar: PlanarCommands<T>,
    /// Commanded tilt accelerations `[theta_ddot_x, theta_ddot_y]` of the frontal and
    /// sagittal planes (rad/s^2): for a trajectory, the slope of its linearly interpolated tilt
    /// rate, along its heading (zero where the tilt-rate command is clamped); zero for the
    /// other commands, whose lean command is the equilibrium lean.
    pub tilt_accel_rad_per_s2: [T; 2],
    /// Whether the command was finite; a non-finite command is replaced by [`Command::Stop`].
    pub command_finite: bool,
}

/// A shaped velocity with named fields (m/s, m/s, rad/s).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{BodyVelocity, CommandShaper, CommandShaperParams};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// assert_eq!(shaper.velocity(), BodyVelocity::default()); // starts at rest
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyVelocity<T> {
    /// Along body x (m/s).
    pub vx_m_per_s: T,
    /// Along body y (m/s).
    pub vy_m_per_s: T,
    /// About body z (rad/s).
    pub yaw_rate_rad_per_s: T,
}

/// Per-plane constants of the lean feedforward.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlaneShaping<T> {
    /// `1 / r` (1/m).
    inv_radius_per_m: T,
    /// Tilt per unit ball acceleration `(b + c0) / (r m_U g l)` (rad per m/s^2).
    lean_rad_per_m_per_s2: T,
}

impl<T: RealField + Copy> PlaneShaping<T> {
    fn new(p: &WipParams<T>) -> Self {
        let r = p.ball_radius_m;
        let l = p.com_height_m;
        let b = p.ball_inertia_kg_m2 + (p.ball_mass_kg + p.body_mass_kg) * r * r;
        let c0 = p.body_mass_kg * r * l;
        let mgl = p.body_mass_kg * p.gravity_m_per_s2 * l;
        Self {
            inv_radius_per_m: T::one() / r,
            lean_rad_per_m_per_s2: (b + c0) / (r * mgl),
        }
    }
}

/// Shapes any [`Command`] into smooth, feasible planar command states.
///
/// Holds three [`JerkLimiter`]s (body x speed, body y speed, yaw rate), the integrated heading
/// command and the integrated ball-angle commands. Allocation-free and O(1) per step.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 2.0, ..VelocityCommand::zero() });
/// // Mid-ramp, accelerating at the 1 m/s^2 limit: the sagittal command leans forward by the
/// // equilibrium lean theta_ff = (b + c0) a / (r m_U g l), 7.3 deg for MiaPURE with 60 kg.
/// let mut shaped = shaper.step(&go, 0.0025);
/// for _ in 0..400 {
///     shaped = shaper.step(&go, 0.0025);
/// }
/// let p = &robot.sagittal;
/// let (r, l, m) = (p.ball_radius_m, p.com_height_m, p.body_mass_kg);
/// let b = p.ball_inertia_kg_m2 + (p.ball_mass_kg + m) * r * r;
/// let lean_rad_per_m_per_s2 = (b + m * r * l) / (r * m * p.gravity_m_per_s2 * l);
/// assert_eq!(shaped.acceleration.x, 1.0);
/// approx::assert_relative_eq!(shaped.planar.sagittal[0], lean_rad_per_m_per_s2, epsilon = 1e-12);
/// assert!((shaped.planar.sagittal[0].to_degrees() - 7.3).abs() < 0.1);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandShaper<T> {
    params: CommandShaperParams<T>,
    lean: LeanToDrive<T>,
    sagittal: PlaneShaping<T>,
    frontal: PlaneShaping<T>,
    vx: JerkLimiter<T>,
    vy: JerkLimiter<T>,
    yaw_rate: JerkLimiter<T>,
    heading_rad: T,
    phi_x_rad: T,
    phi_y_rad: T,
    /// The filtered speeds `v_f` (m/s, body x and y; equal to the shaped speeds when the
    /// reference filter is off or a trajectory runs).
    filtered_m_per_s: (T, T),
}

impl<T: RealField + Copy> CommandShaper<T> {
    /// Validates `params` and `robot` and starts at rest with heading 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// assert!(shaper.is_at_rest());
    /// let mut bad = CommandShaperParams::miapure();
    /// bad.yaw.max_rate_per_s = f64::NAN;
    /// assert!(CommandShaper::new(bad, &robot).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: CommandShaperParams<T>, robot: &BallbotParams<T>) -> Result<Self, Error> {
        params.validate()?;
        robot.validate()?;
        Ok(Self {
            params,
            lean: LeanToDrive::new(params.lean_to_drive)?,
            sagittal: PlaneShaping::new(&robot.sagittal),
            frontal: PlaneShaping::new(&robot.frontal),
            vx: JerkLimiter::at(T::zero()),
            vy: JerkLimiter::at(T::zero()),
            yaw_rate: JerkLimiter::at(T::zero()),
            heading_rad: T::zero(),
            phi_x_rad: T::zero(),
            phi_y_rad: T::zero(),
            filtered_m_per_s: (T::zero(), T::zero()),
        })
    }

    /// The settings.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// assert_eq!(shaper.params(), &CommandShaperParams::miapure());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &CommandShaperParams<T> {
        &self.params
    }

    /// Restarts at rest with heading command `heading_rad` (use the measured heading when
    /// arming) and ball-angle commands `phi_x_rad`, `phi_y_rad`. Non-finite values become 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// // Arming while the robot faces 1.2 rad: hold that heading, not 0.
    /// shaper.reset(1.2, 0.0, 0.0);
    /// let shaped = shaper.step(&Command::Stop, 0.0025);
    /// assert_eq!(shaped.planar.spin[0], 1.2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self, heading_rad: T, phi_x_rad: T, phi_y_rad: T) {
        let or_zero = |x: T| if x.is_finite() { x } else { T::zero() };
        self.vx = JerkLimiter::at(T::zero());
        self.vy = JerkLimiter::at(T::zero());
        self.yaw_rate = JerkLimiter::at(T::zero());
        self.heading_rad = or_zero(heading_rad);
        self.phi_x_rad = or_zero(phi_x_rad);
        self.phi_y_rad = or_zero(phi_y_rad);
        self.filtered_m_per_s = (T::zero(), T::zero());
    }

    /// The shaped velocity now.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
    /// let shaped = shaper.step(&go, 0.0025);
    /// assert_eq!(shaper.velocity(), shaped.velocity);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn velocity(&self) -> BodyVelocity<T> {
        BodyVelocity {
            vx_m_per_s: self.vx.value(),
            vy_m_per_s: self.vy.value(),
            yaw_rate_rad_per_s: self.yaw_rate.value(),
        }
    }

    /// Whether the shaped command is at rest (speeds and accelerations exactly 0).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
    /// for _ in 0..800 {
    ///     shaper.step(&go, 0.0025);
    /// }
    /// // A controlled stop: Stop until the shaped command is at rest, exactly.
    /// let mut steps = 0;
    /// while !shaper.is_at_rest() && steps < 4000 {
    ///     shaper.step(&Command::Stop, 0.0025);
    ///     steps += 1;
    /// }
    /// assert!(shaper.is_at_rest() && steps < 4000);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn is_at_rest(&self) -> bool {
        let z = T::zero();
        self.vx.value() == z
            && self.vy.value() == z
            && self.yaw_rate.value() == z
            && self.vx.rate_per_s() == z
            && self.vy.rate_per_s() == z
            && self.yaw_rate.rate_per_s() == z
            && self.filtered_m_per_s == (z, z)
    }

    /// Advances one step of `dt_secs` (non-finite or non-positive: no motion) towards
    /// `command`. A non-finite command is treated as [`Command::Stop`] and flagged in the
    /// output.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, Trajectory};
    /// use nalgebra::Vector4;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// // A trajectory driven towards body +y (heading pi/2): it lands in the frontal plane with
    /// // the opposite sign (y = -r phi_x), and its own tilt is passed through.
    /// let samples = [Vector4::new(0.05, 0.0, 0.0, 0.0); 2];
    /// let trajectory = Trajectory::new(&samples, 0.1, core::f64::consts::FRAC_PI_2)?;
    /// let shaped = shaper.step(&Command::Trajectory { trajectory, time_secs: 0.0 }, 0.0025);
    /// approx::assert_relative_eq!(shaped.planar.frontal[0], -0.05, epsilon = 1e-12);
    /// approx::assert_relative_eq!(shaped.planar.sagittal[0], 0.0, epsilon = 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(&mut self, command: &Command<'_, T>, dt_secs: T) -> ShapedCommand<T> {
        let command_finite = command.is_finite();
        let command = if command_finite {
            *command
        } else {
            Command::Stop
        };
        let mut translation = self.params.translation;
        let zero = T::zero();
        // Targets (vx, vy, yaw rate) and, for a trajectory, its tilt and tilt rate along the
        // heading with the heading's (sin, cos).
        let mut trajectory_tilt: Option<(T, T, T, T, T)> = None;
        // Each target's own rate (nonzero only for a trajectory).
        let mut feed = (zero, zero);
        let (target_x, target_y, target_yaw) = match command {
            Command::Stop => (zero, zero, zero),
            Command::Velocity(v) => {
                let (vx, vy) = clamp_norm(v.vx_m_per_s, v.vy_m_per_s, translation.max_value);
                (vx, vy, v.yaw_rate_rad_per_s)
            }
            Command::Lean(lean) => {
                let v = self.lean.velocity(&lean);
                translation.max_rate_per_s = translation
                    .max_rate_per_s
                    .min(self.params.lean_to_drive.max_accel_m_per_s2);
                let (vx, vy) = clamp_norm(v.vx_m_per_s, v.vy_m_per_s, translation.max_value);
                (vx, vy, v.yaw_rate_rad_per_s)
            }
            Command::Trajectory {
                trajectory,
                time_secs,
            } => {
                let (s, rate) = trajectory.sample_with_rate(time_secs);
                let (sin_h, cos_h) = trajectory.heading_rad().sin_cos();
                // Ball rate along the heading in m/s (one ball: the sagittal radius).
                let radius = T::one() / self.sagittal.inv_radius_per_m;
                let speed = s[BALL_RATE] * radius;
                let accel = rate[BALL_RATE] * radius;
                trajectory_tilt = Some((s[TILT], s[TILT_RATE], rate[TILT_RATE], sin_h, cos_h));
                feed = (accel * cos_h, accel * sin_h);
                let (vx, vy) = clamp_norm(speed * cos_h, speed * sin_h, translation.max_value);
                (vx, vy, trajectory.yaw_rate_rad_per_s())
            }
        };
        let dt_ok = dt_is_valid(dt_secs);
        let (vx, vy, wz) = if dt_ok {
            (
                self.vx.advance(target_x, feed.0, &translation, dt_secs),
                self.vy.advance(target_y, feed.1, &translation, dt_secs),
                self.yaw_rate
                    .advance(target_yaw, zero, &self.params.yaw, dt_secs),
            )
        } else {
            (self.vx.value(), self.vy.value(), self.yaw_rate.value())
        };
        // The reference filter (see `CommandShaperParams::reference_filter_secs`): the speeds,
        // accelerations and jerks the planar reference is built from.
        let tau = self.params.reference_filter_secs;
        let (ax, ay) = (self.vx.rate_per_s(), self.vy.rate_per_s());
        let ((rvx, rvy), (rax, ray), (rjx, rjy)) = if tau > zero && trajectory_tilt.is_none() {
            let (fx, fy) = self.filtered_m_per_s;
            let (afx, afy) = ((vx - fx) / tau, (vy - fy) / tau);
            if dt_ok {
                // Exact for a held input up to first order, stable for any `dt_secs / tau`.
                let gain = min(dt_secs / tau, T::one());
                let settle = |f: T, v: T| {
                    let next = f + (v - f) * gain;
                    // Within 0.1 mm/s the filter is settled: snap (an exponential never is).
                    if (v - next).abs() <= lit(1e-4) {
                        v
                    } else {
                        next
                    }
                };
                self.filtered_m_per_s = (settle(fx, vx), settle(fy, vy));
            }
            ((fx, fy), (afx, afy), ((ax - afx) / tau, (ay - afy) / tau))
        } else {
            self.filtered_m_per_s = (vx, vy);
            ((vx, vy), (ax, ay), (zero, zero))
        };
        if dt_ok {
            self.heading_rad += wz * dt_secs;
            self.phi_y_rad += rvx * self.sagittal.inv_radius_per_m * dt_secs;
            self.phi_x_rad -= rvy * self.frontal.inv_radius_per_m * dt_secs;
        }
        let ky = self.sagittal.lean_rad_per_m_per_s2;
        let kx = self.frontal.lean_rad_per_m_per_s2;
        // Velocity and lean commands: the equilibrium lean of the shaped acceleration, and no
        // tilt-rate command. (Feeding the lean's rate, `k j`, forward makes the LQR's tilt-rate
        // term step by `k2 k dj` wherever the jerk switches: on MiaPURE braking from 1.5 m/s
        // that raised the peak ball acceleration from 1.7 to 6.7 m/s^2 for a 0.04 m/s smaller
        // speed error.) Trajectories bring their own tilt and tilt rate.
        let max_tilt = self.params.max_tilt_command_rad;
        let max_rate = self.params.max_tilt_rate_command_rad_per_s;
        // A clamped tilt-rate command does not change: no tilt acceleration then.
        let unless_clamped = |rate: T, accel: T| if rate.abs() > max_rate { zero } else { accel };
        let (tilt_y, rate_y, tilt_x, rate_x, accel_y, accel_x) = match trajectory_tilt {
            Some((tilt, rate, accel, sin_h, cos_h)) => (
                cos_h * tilt,
                cos_h * rate,
                -sin_h * tilt,
                -sin_h * rate,
                unless_clamped(cos_h * rate, cos_h * accel),
                unless_clamped(sin_h * rate, -sin_h * accel),
            ),
            None => (ky * rax, ky * rjx, -kx * ray, -kx * rjy, zero, zero),
        };
        let clamp = clamp_sym::<T>;
        let planar = PlanarCommands {
            sagittal: WipState::new(
                clamp(tilt_y, max_tilt),
                self.phi_y_rad,
                clamp(rate_y, max_rate),
                rvx * self.sagittal.inv_radius_per_m,
            ),
            frontal: WipState::new(
                clamp(tilt_x, max_tilt),
                self.phi_x_rad,
                clamp(rate_x, max_rate),
                -rvy * self.frontal.inv_radius_per_m,
            ),
            spin: SpinState::new(self.heading_rad, wz),
        };
        ShapedCommand {
            velocity: BodyVelocity {
                vx_m_per_s: vx,
                vy_m_per_s: vy,
                yaw_rate_rad_per_s: wz,
            },
            acceleration: BodyMotion {
                x: rax,
                y: ray,
                yaw: self.yaw_rate.rate_per_s(),
            },
            planar,
            tilt_accel_rad_per_s2: [accel_x, accel_y],
            command_finite,
        }
    }
}

/// `x` limited to `[-limit, limit]` (`limit >= 0`) with plain comparisons: a NaN passes
/// through (callers check finiteness where it matters). `max`/`min` of `RealField` are
/// NaN-aware and cost several instructions each; these run every outer step.
///
/// Written as `min(limit, max(-limit, x))` with the plain [`min`] and [`max`] (one `maxsd` and
/// one `minsd` on x86_64, no branch): their NaN operand comes second, so a NaN `x` passes
/// through both, and ties keep `x`.
#[inline]
pub(crate) fn clamp_sym<T: RealField + Copy>(x: T, limit: T) -> T {
    min(limit, max(-limit, x))
}

/// The smaller of `a` and `b` (plain comparison; `b` if either is NaN or they are equal): one
/// `minsd` on x86_64, where `RealField::min` is NaN-aware and several instructions.
#[inline]
pub(crate) fn min<T: RealField + Copy>(a: T, b: T) -> T {
    if a < b { a } else { b }
}

/// The larger of `a` and `b` (plain comparison; `b` if either is NaN or they are equal): one
/// `maxsd` on x86_64.
#[inline]
pub(crate) fn max<T: RealField + Copy>(a: T, b: T) -> T {
    if a > b { a } else { b }
}

/// Scales `(x, y)` down to length `max` if longer.
fn clamp_norm<T: RealField + Copy>(x: T, y: T, max: T) -> (T, T) {
    let norm2 = x * x + y * y;
    if norm2 > max * max && norm2.is_finite() {
        let scale = max / norm2.sqrt();
        (x * scale, y * scale)
    } else {
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Wip;
    use crate::wip::BALL_ANGLE;
    use approx::assert_relative_eq;
    use nalgebra::Vector4;

    const DT: f64 = 0.0025;

    fn limits() -> AxisLimits<f64> {
        AxisLimits {
            max_value: 2.0,
            max_rate_per_s: 1.0,
            max_jerk_per_s2: 4.0,
        }
    }

    /// Runs the limiter towards `target` and checks the limits every step; returns the time of
    /// arrival.
    fn run_checked(limiter: &mut JerkLimiter<f64>, target: f64, steps: usize) -> Option<f64> {
        let l = limits();
        let start = limiter.value();
        let mut arrival = None;
        for k in 0..steps {
            let before_rate = limiter.rate_per_s();
            let v = limiter.step(target, &l, DT);
            assert!(limiter.rate_per_s().abs() <= l.max_rate_per_s + 1e-12);
            assert!(
                (limiter.rate_per_s() - before_rate).abs() <= l.max_jerk_per_s2 * DT + 1e-12,
                "jerk limit broken at step {k}"
            );
            // Never beyond the target, seen from the start.
            assert!(
                (v - target) * (start - target) >= -1e-12,
                "overshoot at {k}: {v}"
            );
            if v == target && arrival.is_none() {
                arrival = Some((k + 1) as f64 * DT);
            }
        }
        arrival
    }

    #[test]
    fn branch_free_clamp_matches_the_branchy_one_bit_for_bit() {
        // clamp_sym and min/max replaced comparisons chains: NaN passes, ties keep x, and the
        // sign of zero survives.
        let reference = |x: f64, limit: f64| {
            if x > limit {
                limit
            } else if x < -limit {
                -limit
            } else {
                x
            }
        };
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            2.0,
            -2.0,
            2.5,
            -2.5,
            1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for limit in [0.0, 2.0, 1e300, f64::INFINITY] {
            for x in specials {
                let (got, want) = (clamp_sym(x, limit), reference(x, limit));
                assert!(
                    got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                    "clamp_sym({x}, {limit}) = {got}, want {want}"
                );
            }
        }
        for (a, b) in [
            (1.0, 2.0),
            (2.0, 1.0),
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
            (0.0, -0.0),
        ] {
            assert_eq!(min(a, b).to_bits(), (if a < b { a } else { b }).to_bits());
            assert_eq!(max(a, b).to_bits(), (if a > b { a } else { b }).to_bits());
        }
    }

    #[test]
    fn jerk_limiter_reaches_a_step_target_in_near_minimum_time_within_limits() {
        let mut limiter = JerkLimiter::at(0.0);
        let arrival = run_checked(&mut limiter, 1.0, 2000).unwrap();
        // S-curve minimum time: v / a + a / j = 1 + 0.25 s.
        assert!(arrival > 1.24 && arrival < 1.30, "arrival {arrival}");
        assert_eq!(limiter.rate_per_s(), 0.0);
    }

    #[test]
    fn jerk_limiter_short_move_never_reaches_full_acceleration() {
        // 0.05 m/s at 4 m/s^3: triangular acceleration, peak sqrt(j dv) = 0.447 m/s^2.
        let mut limiter = JerkLimiter::at(0.0);
        let mut peak: f64 = 0.0;
        for _ in 0..400 {
            limiter.step(0.05, &limits(), DT);
            peak = peak.max(limiter.rate_per_s());
        }
        assert_eq!(limiter.value(), 0.05);
        assert!(peak < 0.5 && peak > 0.4, "peak {peak}");
    }

    #[test]
    fn jerk_limiter_reverses_without_overshoot() {
        let mut limiter = JerkLimiter::at(0.0);
        run_checked(&mut limiter, 1.5, 300);
        assert!(limiter.rate_per_s() > 0.5);
        // Reverse while still accelerating: first the motion must turn around.
        let arrival = run_checked(&mut limiter, -1.0, 4000);
        assert!(arrival.is_some());
        assert_eq!(limiter.value(), -1.0);
    }

    #[test]
    fn jerk_limiter_clamps_targets_and_ignores_bad_inputs() {
        let mut limiter = JerkLimiter::at(0.0);
        run_checked(&mut limiter, 2.0, 2000);
        for _ in 0..2000 {
            limiter.step(50.0, &limits(), DT);
        }
        assert_eq!(limiter.value(), 2.0);
        // A non-finite target holds; a bad dt changes nothing.
        let before = limiter;
        limiter.step(f64::NAN, &limits(), DT);
        assert_eq!(limiter.value(), 2.0);
        limiter.step(0.0, &limits(), f64::INFINITY);
        limiter.step(0.0, &limits(), -DT);
        limiter.step(0.0, &limits(), f64::NAN);
        assert_eq!(limiter.value(), before.value());
        limiter.reset(f64::NAN, 1.0);
        assert_eq!(limiter, JerkLimiter::at(0.0));
    }

    #[test]
    fn lean_to_drive_deadband_gain_speed_limit_and_direction() {
        let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider()).unwrap();
        let p = *lean.params();
        let input = |x: f64, y: f64| LeanInput {
            towards_x_rad: x,
            towards_y_rad: y,
            yaw_rate_rad_per_s: 0.0,
        };
        // Inside the (radial) deadband, in any direction.
        for angle in [0.0f64, 1.0, 2.5, 4.0] {
            let v = lean.velocity(&input(
                0.99 * p.deadband_rad * angle.cos(),
                0.99 * p.deadband_rad * angle.sin(),
            ));
            assert_eq!((v.vx_m_per_s, v.vy_m_per_s), (0.0, 0.0));
        }
        // Continuous at the deadband edge, linear beyond it.
        let v = lean.velocity(&input(p.deadband_rad + 1e-9, 0.0));
        assert!(v.vx_m_per_s < 1e-8 && v.vx_m_per_s > 0.0);
        let v = lean.velocity(&input(0.0, -(p.deadband_rad + 0.05)));
        assert_relative_eq!(
            v.vy_m_per_s,
            -p.gain_m_per_s_per_rad * 0.05,
            epsilon = 1e-12
        );
        assert_eq!(v.vx_m_per_s, 0.0);
        // Diagonal: direction kept, speed capped.
        let v = lean.velocity(&input(0.5, 0.5));
        assert_relative_eq!(v.vx_m_per_s, v.vy_m_per_s, epsilon = 1e-12);
        assert_relative_eq!(
            v.vx_m_per_s.hypot(v.vy_m_per_s),
            p.max_speed_m_per_s,
            epsilon = 1e-12
        );
        // Garbage in, standing still out; yaw capped.
        let v = lean.velocity(&LeanInput {
            towards_x_rad: f64::NAN,
            towards_y_rad: 0.1,
            yaw_rate_rad_per_s: 100.0,
        });
        assert_eq!((v.vx_m_per_s, v.vy_m_per_s), (0.0, 0.0));
        assert_eq!(v.yaw_rate_rad_per_s, p.max_yaw_rate_rad_per_s);
    }

    fn shaper() -> CommandShaper<f64> {
        CommandShaper::new(
            CommandShaperParams::miapure(),
            &BallbotParams::miapure_60kg(),
        )
        .unwrap()
    }

    fn velocity(vx: f64, vy: f64, wz: f64) -> Command<'static, f64> {
        Command::Velocity(VelocityCommand {
            vx_m_per_s: vx,
            vy_m_per_s: vy,
            yaw_rate_rad_per_s: wz,
        })
    }

    #[test]
    fn lean_feedforward_holds_the_nominal_wip_balanced_while_accelerating() {
        // The commanded tilt for a forward acceleration must be the tilt at which the nominal
        // WIP can accelerate its ball at that rate with zero tilt acceleration.
        let robot = BallbotParams::<f64>::miapure_60kg();
        let wip = Wip::new(robot.sagittal).unwrap();
        let mut s = shaper();
        let mut shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
        for _ in 0..400 {
            shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
        }
        let accel = shaped.acceleration.x;
        assert_relative_eq!(accel, 1.0, epsilon = 1e-12); // at the acceleration limit
        let tilt = shaped.planar.sagittal[TILT];
        assert!(tilt > 0.05, "leans forward to accelerate forward: {tilt}");
        let state = Vector4::new(tilt, 0.0, 0.0, 0.0);
        // theta_ddot is affine in the torque: pick the torque that zeroes it.
        let at0 = wip.accelerations(&state, 0.0);
        let at1 = wip.accelerations(&state, 1.0);
        let torque = -at0[0] / (at1[0] - at0[0]);
        let ball_accel = wip.accelerations(&state, torque)[1] * robot.sagittal.ball_radius_m;
        // First-order feedforward: within 1 % at 1 m/s^2.
        assert_relative_eq!(ball_accel, accel, max_relative = 0.01);
        // At constant speed the lean command is gone.
        for _ in 0..2000 {
            shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
        }
        assert_eq!(shaped.planar.sagittal[TILT], 0.0);
        assert_relative_eq!(
            shaped.planar.sagittal[BALL_RATE],
            2.0 / 0.1145,
            epsilon = 1e-9
        );
    }

    #[test]
    fn sideways_and_yaw_commands_map_to_frontal_and_spin_with_model_signs() {
        let mut s = shaper();
        let mut shaped = s.step(&velocity(0.0, 0.5, 0.3), DT);
        assert!(
            shaped.planar.frontal[TILT] < 0.0,
            "+y acceleration leans towards +y"
        );
        for _ in 0..2000 {
            shaped = s.step(&velocity(0.0, 0.5, 0.3), DT);
        }
        // y = -r phi_x: +y travel is negative frontal ball rate.
        assert_relative_eq!(
            shaped.planar.frontal[BALL_RATE],
            -0.5 / 0.1145,
            epsilon = 1e-9
        );
        assert!(shaped.planar.frontal[BALL_ANGLE] < 0.0);
        assert_eq!(shaped.planar.sagittal, WipState::zeros());
        assert_eq!(shaped.planar.spin[1], 0.3);
        // The heading command integrates the shaped yaw rate.
        assert!(shaped.planar.spin[0] > 0.3 * 4.0 && shaped.planar.spin[0] < 0.3 * 5.01);
    }

    #[test]
    fn commands_beyond_the_speed_limit_keep_their_direction() {
        let mut s = shaper();
        let mut shaped = s.step(&velocity(30.0, 40.0, 0.0), DT);
        for _ in 0..4000 {
            shaped = s.step(&velocity(30.0, 40.0, 0.0), DT);
        }
        assert_relative_eq!(shaped.velocity.vx_m_per_s, 1.2, epsilon = 1e-9);
        assert_relative_eq!(shaped.velocity.vy_m_per_s, 1.6, epsilon = 1e-9);
    }

    #[test]
    fn non_finite_command_is_a_stop() {
        let mut s = shaper();
        for _ in 0..800 {
            s.step(&velocity(1.0, 0.0, 0.0), DT);
        }
        let v0 = s.velocity().vx_m_per_s;
        let shaped = s.step(&velocity(f64::NAN, 0.0, 0.0), DT);
        assert!(!shaped.command_finite);
        assert!(shaped.velocity.vx_m_per_s <= v0 + 1e-12);
        for _ in 0..2000 {
            s.step(&velocity(f64::INFINITY, 0.0, 0.0), DT);
        }
        assert!(s.is_at_rest());
    }

    #[test]
    fn lean_mode_uses_the_riders_acceleration_limit() {
        let mut s = shaper();
        let lean = Command::Lean(LeanInput {
            towards_x_rad: 0.4,
            towards_y_rad: 0.0,
            yaw_rate_rad_per_s: 0.0,
        });
        let mut peak: f64 = 0.0;
        for _ in 0..2000 {
            let shaped = s.step(&lean, DT);
            peak = peak.max(shaped.acceleration.x);
        }
        assert_relative_eq!(peak, 0.5, epsilon = 1e-12);
        assert_relative_eq!(s.velocity().vx_m_per_s, 1.0, epsilon = 1e-12);
    }

    #[test]
    fn trajectory_interpolates_and_maps_along_its_heading() {
        let samples = [
            Vector4::new(0.0, 0.0, 0.0, 0.0),
            Vector4::new(0.02, 0.1, 0.04, 0.4),
            Vector4::new(0.04, 0.3, 0.0, 0.8),
        ];
        let traj = Trajectory::new(&samples, 0.5, 0.0).unwrap();
        assert_relative_eq!(traj.sample(0.75), Vector4::new(0.03, 0.2, 0.02, 0.6));
        assert_eq!(traj.sample(-1.0), samples[0]);
        assert_eq!(traj.sample(f64::NAN), samples[2]);
        assert_eq!(traj.sample(1.0), samples[2]);
        assert_eq!(traj.duration_secs(), 1.0);
        assert!(Trajectory::<f64>::new(&[], 0.5, 0.0).is_err());
        assert!(Trajectory::new(&samples, 0.0, 0.0).is_err());
        let bad = [Vector4::new(0.0, f64::NAN, 0.0, 0.0)];
        assert!(Trajectory::new(&bad, 0.1, 0.0).is_err());

        // Heading 90 deg (body +y): tilt goes to the frontal plane with a minus sign.
        let traj = Trajectory::new(&samples, 0.5, core::f64::consts::FRAC_PI_2).unwrap();
        let mut s = shaper();
        let shaped = s.step(
            &Command::Trajectory {
                trajectory: traj,
                time_secs: 0.75,
            },
            DT,
        );
        assert_relative_eq!(shaped.planar.frontal[TILT], -0.03, epsilon = 1e-12);
        assert_relative_eq!(shaped.planar.frontal[TILT_RATE], -0.02, epsilon = 1e-12);
        assert_relative_eq!(shaped.planar.sagittal[TILT], 0.0, epsilon = 1e-12);
        // The speed target jumped to 0.6 rad/s: the limiter only lets it start moving.
        assert!(shaped.velocity.vy_m_per_s > 0.0 && shaped.velocity.vy_m_per_s < 1e-3);
    }

    #[test]
    fn a_feasible_trajectory_passes_the_limiter_unchanged() {
        // A braking-like profile: speed 1 m/s -> 0 as a cosine over 3 s (peak decel 0.52
        // m/s^2, peak jerk 0.55 m/s^3: well inside the limits). Start the limiter on it.
        let r = 0.1145;
        let period = 0.01;
        let samples: [WipState<f64>; 301] = core::array::from_fn(|k| {
            let t = k as f64 * period;
            let v = 0.5 * (1.0 + (core::f64::consts::PI * t / 3.0).cos());
            Vector4::new(0.0, 0.0, 0.0, v / r)
        });
        let traj = Trajectory::new(&samples, period, core::f64::consts::PI).unwrap();
        let mut s = shaper();
        s.vx.reset(-1.0, 0.0); // heading 180 deg: moving towards -x
        let mut worst: f64 = 0.0;
        for k in 1..1200 {
            let t = k as f64 * DT;
            let shaped = s.step(
                &Command::Trajectory {
                    trajectory: traj,
                    time_secs: t,
                },
                DT,
            );
            let expected = -traj.sample(t)[BALL_RATE] * r;
            worst = worst.max((shaped.velocity.vx_m_per_s - expected).abs());
        }
        // One step of lag at most (0.52 m/s^2 x 2.5 ms = 1.3e-3 m/s); without the rate
        // feedforward the lag would be a^2 / (2 j) = 0.034 m/s.
        assert!(worst < 1.5e-3, "worst deviation {worst} m/s");
        assert!(s.velocity().vx_m_per_s.abs() < 1e-9);
    }
}
