//! [`TrajectoryLimits`]: what a [`Trajectory`](super::Trajectory) must keep to be one the
//! controller can follow, and the check of one trajectory against them.

use crate::Error;
use crate::check::{lit, positive};
use crate::num::is_nan;
use crate::wip::{BALL_RATE, TILT, TILT_RATE, WipState};
use nalgebra::RealField;

/// The bounds a [`Trajectory`](super::Trajectory) is checked against when it is built.
///
/// Derived from a controller's configuration by
/// [`BallbotControllerConfig::trajectory_limits`](crate::ballbot::BallbotControllerConfig::trajectory_limits)
/// (the derivation of each bound is documented there), and checked by
/// [`BallbotController::accept_trajectory`](crate::ballbot::BallbotController::accept_trajectory).
/// Every field is finite and > 0.
///
/// A trajectory is accepted when:
/// - its sample period is at least `min_sample_period_secs`;
/// - every sample's tilt, tilt rate and ball rate are within their bounds;
/// - on every interval the slopes of the linearly interpolated rates, the tilt acceleration
///   `theta_ddot` and the ball acceleration `phi_ddot`, are ones the robot can produce: the
///   ball acceleration within `max_ball_accel_rad_per_s2`, and the torque the controller
///   feeds forward for them (the second row of the WIP equations, `c0 theta_ddot + b
///   phi_ddot`) within `max_torque_nm`, and the lean they need within `max_tilt_rad`:
///   eliminating the torque from the two rows of the linearised WIP equations, the body
///   must lean `theta* = ((a + c0) theta_ddot + (b + c0) phi_ddot) / (m_U g l)` to produce
///   them, whatever tilt the trajectory itself commands (a trajectory that accelerates the
///   ball without leaning makes the controller lean the body anyway): `|theta*| <=
///   max_tilt_rad`;
/// - the tilt rates are the tilt's derivative: on every interval of length `h`, both end
///   rates are within `theta_ddot_max h / 2` of the finite difference `(theta_{k+1} -
///   theta_k) / h`, `theta_ddot_max = max_torque_nm / tilt_inertia_kg_m2` (what a motion
///   whose tilt acceleration the torque can produce shows between its rate at an end of an
///   interval and its mean rate over it), and the last rate within `theta_ddot_max h / 2`
///   of 0 (the last sample is held, at rate 0);
/// - no interval's interpolation holds the robot away from its dynamics for long (see
///   [`Self::CONSISTENCY_SECS`]): its mean tilt is the lean `theta*` its accelerations need
///   within `lean_per_ball_accel_s2 max_ball_accel_rad_per_s2 CONSISTENCY_SECS / h`, and its
///   end tilt rates the tilt's slope within `max_tilt_rate_rad_per_s CONSISTENCY_SECS / h`
///   (without these the two tolerances above grow with `h`: a trajectory sampled every
///   1.5e54 s held a 3.4 deg lean and a 0.52 rad/s tilt rate for good, and the fuzzer's robot
///   fell);
/// - the last tilt is upright within `max_tilt_rate_rad_per_s min_sample_period_secs / 2`
///   (the last sample is held for as long as the controller runs, and a held lean
///   accelerates the ball for ever).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::BallbotControllerConfig;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let limits = config.trajectory_limits()?;
/// // Samples no closer than the 400 Hz outer period, tilts within the shaper's 0.2 rad.
/// assert_eq!(limits.min_sample_period_secs, 0.0025);
/// assert_eq!(limits.max_tilt_rad, 0.2);
/// assert!(limits.validate().is_ok());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrajectoryLimits<T> {
    /// Shortest sample period (s).
    pub min_sample_period_secs: T,
    /// Largest tilt magnitude (rad).
    pub max_tilt_rad: T,
    /// Largest tilt-rate magnitude (rad/s).
    pub max_tilt_rate_rad_per_s: T,
    /// Largest ball-rate magnitude (rad/s).
    pub max_ball_rate_rad_per_s: T,
    /// Largest ball acceleration (rad/s^2), the slope of the ball rate on an interval.
    pub max_ball_accel_rad_per_s2: T,
    /// Largest feedforward torque (N m) between body and ball along any heading.
    pub max_torque_nm: T,
    /// The torque per unit tilt acceleration in the feedforward, `c0 = m_U r l - I_W`
    /// (kg m^2, the larger of the two planes').
    pub tilt_inertia_kg_m2: T,
    /// The torque per unit ball acceleration in the feedforward, `b = I_S + (m_S + m_U) r^2 +
    /// I_W` (kg m^2, the larger of the two planes').
    pub ball_inertia_kg_m2: T,
    /// The lean the body needs per unit tilt acceleration, `(a + c0) / (m_U g l)` (s^2, the
    /// larger of the two planes'; `a = I_U + m_U l^2 + I_W`).
    pub lean_per_tilt_accel_s2: T,
    /// The lean the body needs per unit ball acceleration, `(b + c0) / (m_U g l)` (s^2, the
    /// larger of the two planes').
    pub lean_per_ball_accel_s2: T,
}

impl<T: RealField + Copy> TrajectoryLimits<T> {
    /// Checks that every field is finite and > 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::TrajectoryLimits;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let limits = TrajectoryLimits { max_tilt_rad: f64::NAN, ..config.trajectory_limits()? };
    /// assert!(limits.validate().is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.min_sample_period_secs, "min_sample_period_secs")?;
        positive(self.max_tilt_rad, "max_tilt_rad")?;
        positive(self.max_tilt_rate_rad_per_s, "max_tilt_rate_rad_per_s")?;
        positive(self.max_ball_rate_rad_per_s, "max_ball_rate_rad_per_s")?;
        positive(self.max_ball_accel_rad_per_s2, "max_ball_accel_rad_per_s2")?;
        positive(self.max_torque_nm, "max_torque_nm")?;
        positive(self.tilt_inertia_kg_m2, "tilt_inertia_kg_m2")?;
        positive(self.ball_inertia_kg_m2, "ball_inertia_kg_m2")?;
        positive(self.lean_per_tilt_accel_s2, "lean_per_tilt_accel_s2")?;
        positive(self.lean_per_ball_accel_s2, "lean_per_ball_accel_s2")
    }

    /// The largest tilt acceleration the torque allows when the ball does not accelerate,
    /// `max_torque_nm / tilt_inertia_kg_m2` (rad/s^2): what sets the tolerance of the
    /// tilt-rate consistency check.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let max = limits.max_tilt_accel_rad_per_s2();
    /// approx::assert_relative_eq!(max * limits.tilt_inertia_kg_m2, limits.max_torque_nm);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn max_tilt_accel_rad_per_s2(&self) -> T {
        self.max_torque_nm / self.tilt_inertia_kg_m2
    }

    /// Whether these limits are at least as strict as `other` in every field (a trajectory
    /// checked against them passes `other` too).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::TrajectoryLimits;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let gentler = TrajectoryLimits { max_tilt_rad: 0.1, ..limits };
    /// assert!(gentler.is_within(&limits) && !limits.is_within(&gentler));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn is_within(&self, other: &Self) -> bool {
        self.min_sample_period_secs >= other.min_sample_period_secs
            && self.max_tilt_rad <= other.max_tilt_rad
            && self.max_tilt_rate_rad_per_s <= other.max_tilt_rate_rad_per_s
            && self.max_ball_rate_rad_per_s <= other.max_ball_rate_rad_per_s
            && self.max_ball_accel_rad_per_s2 <= other.max_ball_accel_rad_per_s2
            && self.max_torque_nm <= other.max_torque_nm
            && self.tilt_inertia_kg_m2 >= other.tilt_inertia_kg_m2
            && self.ball_inertia_kg_m2 >= other.ball_inertia_kg_m2
            && self.lean_per_tilt_accel_s2 >= other.lean_per_tilt_accel_s2
            && self.lean_per_ball_accel_s2 >= other.lean_per_ball_accel_s2
    }

    /// Checks `samples` (finite, at least one) with `sample_period_secs` against the limits
    /// (see the type's docs); the error names the bound broken.
    pub(super) fn check(
        &self,
        samples: &[WipState<T>],
        sample_period_secs: T,
    ) -> Result<(), Error> {
        self.validate()?;
        if !within(self.min_sample_period_secs, sample_period_secs) {
            return Err(Error::invalid(
                "sample_period_secs",
                "must be >= min_sample_period_secs (the controller's outer period)",
            ));
        }
        for s in samples {
            self.check_sample(s)?;
        }
        let h = sample_period_secs;
        let mut unexplained = Unexplained {
            lean_rad_s: T::zero(),
            tilt_rad: T::zero(),
        };
        for pair in samples.windows(2) {
            if let [a, b] = pair {
                unexplained.worst(self.check_interval(a, b, h)?);
            }
        }
        self.check_unexplained(&unexplained)?;
        // After the end the last sample is held, its rates 0, for as long as the controller
        // runs: its tilt rate one the tilt acceleration bound brings to rest within one
        // period, its tilt upright within what the tilt rate bound covers in half an outer
        // period (a held lean accelerates the ball for ever).
        if let Some(last) = samples.last() {
            let slack = T::one() + lit::<T>(8.0) * T::default_epsilon();
            if last[TILT_RATE].abs() > self.max_tilt_accel_rad_per_s2() * h * lit(0.5) * slack {
                return Err(Error::invalid(
                    "samples",
                    "the last tilt rate must be within max_torque_nm / tilt_inertia_kg_m2 * sample_period_secs / 2 of 0 (the last sample is held, at rate 0)",
                ));
            }
            let period = self.min_sample_period_secs * lit(0.5);
            if last[TILT].abs() > self.max_tilt_rate_rad_per_s * period * slack {
                return Err(Error::invalid(
                    "samples",
                    "the last tilt must be within max_tilt_rate_rad_per_s * min_sample_period_secs / 2 of 0 (the last sample is held, and a held lean accelerates the ball for ever)",
                ));
            }
        }
        Ok(())
    }

    /// How long one interval of a trajectory's linear interpolation may disagree with the
    /// robot's dynamics, measured at the limits' own rates (s). On every interval of length
    /// `h`: its mean tilt against the lean its accelerations need, `|theta_mid - theta*| h <=
    /// lean_per_ball_accel_s2 * max_ball_accel_rad_per_s2 * CONSISTENCY_SECS` (the ball speed
    /// the disagreement adds that the trajectory does not account for: at most what its
    /// largest acceleration adds in this time, 0.2 m/s on MiaPURE), and its end tilt rates
    /// against the tilt's slope, `|theta_dot - slope| h <= max_tilt_rate_rad_per_s *
    /// CONSISTENCY_SECS` (tilt the trajectory does not account for: 0.1 rad). A smooth motion
    /// sampled finely disagrees by little (the project's braking profiles, which leave out the
    /// lean of the tilt acceleration, by 1.6 % of the first bound per interval; the core's
    /// deliberately inconsistent random trajectories by 34 % of it at most); a coarse
    /// interpolant holding a lean or a tilt rate its accelerations or its tilts do not have
    /// runs the robot away, and one held for 1.5e54 s made it fall.
    ///
    /// ```
    /// use ballbot_core::command::TrajectoryLimits;
    /// assert_eq!(TrajectoryLimits::<f64>::CONSISTENCY_SECS, 0.1);
    /// ```
    pub const CONSISTENCY_SECS: f64 = 0.1;

    fn check_unexplained(&self, unexplained: &Unexplained<T>) -> Result<(), Error> {
        let budget_secs: T = lit(Self::CONSISTENCY_SECS);
        let slack = T::one() + lit::<T>(8.0) * T::default_epsilon();
        let lean_budget =
            self.lean_per_ball_accel_s2 * self.max_ball_accel_rad_per_s2 * budget_secs * slack;
        if !within(unexplained.lean_rad_s, lean_budget) {
            return Err(Error::invalid(
                "samples",
                "on every interval the mean tilt must be the lean the accelerations need: |mean tilt - lean| * sample_period_secs within lean_per_ball_accel_s2 * max_ball_accel_rad_per_s2 * 0.1 s",
            ));
        }
        let rate_budget = self.max_tilt_rate_rad_per_s * budget_secs * slack;
        if !within(unexplained.tilt_rad, rate_budget) {
            return Err(Error::invalid(
                "samples",
                "on every interval the tilt rates must be the tilt's derivative: |tilt rate - finite difference| * sample_period_secs within max_tilt_rate_rad_per_s * 0.1 s",
            ));
        }
        Ok(())
    }

    fn check_sample(&self, s: &WipState<T>) -> Result<(), Error> {
        if !within(s[TILT].abs(), self.max_tilt_rad) {
            return Err(Error::invalid(
                "samples",
                "every tilt must be within max_tilt_rad",
            ));
        }
        if !within(s[TILT_RATE].abs(), self.max_tilt_rate_rad_per_s) {
            return Err(Error::invalid(
                "samples",
                "every tilt rate must be within max_tilt_rate_rad_per_s",
            ));
        }
        if !within(s[BALL_RATE].abs(), self.max_ball_rate_rad_per_s) {
            return Err(Error::invalid(
                "samples",
                "every ball rate must be within max_ball_rate_rad_per_s",
            ));
        }
        Ok(())
    }

    fn check_interval(
        &self,
        a: &WipState<T>,
        b: &WipState<T>,
        h: T,
    ) -> Result<Unexplained<T>, Error> {
        let eps = T::default_epsilon();
        // Rounding of the differences below: a few ulps of the values differenced.
        let round = |x: T, y: T| lit::<T>(4.0) * eps * (x.abs() + y.abs());
        let tilt_accel = (b[TILT_RATE] - a[TILT_RATE]) / h;
        let ball_accel = (b[BALL_RATE] - a[BALL_RATE]) / h;
        let slack = T::one() + lit::<T>(8.0) * eps;
        if !within(ball_accel.abs(), self.max_ball_accel_rad_per_s2 * slack) {
            return Err(Error::invalid(
                "samples",
                "on every interval the ball acceleration must be within max_ball_accel_rad_per_s2",
            ));
        }
        let torque_nm = self.tilt_inertia_kg_m2 * tilt_accel + self.ball_inertia_kg_m2 * ball_accel;
        if !within(torque_nm.abs(), self.max_torque_nm * slack) {
            return Err(Error::invalid(
                "samples",
                "on every interval the feedforward torque tilt_inertia_kg_m2 * tilt accel + ball_inertia_kg_m2 * ball accel must be within max_torque_nm",
            ));
        }
        // The lean the interval's accelerations need: the body goes there whatever tilt the
        // trajectory commands.
        let lean_rad =
            self.lean_per_tilt_accel_s2 * tilt_accel + self.lean_per_ball_accel_s2 * ball_accel;
        if !within(lean_rad.abs(), self.max_tilt_rad * slack) {
            return Err(Error::invalid(
                "samples",
                "on every interval the lean the accelerations need, lean_per_tilt_accel_s2 * tilt accel + lean_per_ball_accel_s2 * ball accel, must be within max_tilt_rad",
            ));
        }
        let slope = (b[TILT] - a[TILT]) / h;
        let tolerance = self.max_tilt_accel_rad_per_s2() * h * lit(0.5)
            + round(a[TILT], b[TILT]) / h
            + round(a[TILT_RATE], b[TILT_RATE]);
        if !((a[TILT_RATE] - slope).abs() <= tolerance && (b[TILT_RATE] - slope).abs() <= tolerance)
        {
            return Err(Error::invalid(
                "samples",
                "every tilt rate must be within max_torque_nm / tilt_inertia_kg_m2 * sample_period_secs / 2 of the tilt's finite difference on its intervals",
            ));
        }
        // What the interpolant leaves unexplained on this interval, beyond rounding.
        let mean_tilt = (a[TILT] + b[TILT]) * lit(0.5);
        let lean_error = (mean_tilt - lean_rad).abs() - round(a[TILT], b[TILT]);
        let (ea, eb) = ((a[TILT_RATE] - slope).abs(), (b[TILT_RATE] - slope).abs());
        let rate_error = if eb > ea || is_nan(eb) { eb } else { ea }
            - round(a[TILT], b[TILT]) / h
            - round(a[TILT_RATE], b[TILT_RATE]);
        // The positive part; a NaN (an overflow of loose limits) stays NaN and is refused.
        let excess = |e: T| {
            if e > T::zero() || is_nan(e) {
                e * h
            } else {
                T::zero()
            }
        };
        Ok(Unexplained {
            lean_rad_s: excess(lean_error),
            tilt_rad: excess(rate_error),
        })
    }
}

/// What a trajectory's interpolation leaves unexplained by the dynamics, the largest over its
/// intervals (see [`TrajectoryLimits::CONSISTENCY_SECS`]).
#[derive(Clone, Copy, Debug)]
struct Unexplained<T> {
    /// `|theta_mid - theta*| h` (rad s).
    lean_rad_s: T,
    /// `|theta_dot - slope| h` (rad).
    tilt_rad: T,
}

impl<T: RealField + Copy> Unexplained<T> {
    fn worst(&mut self, other: Self) {
        // A NaN, once in, stays (`max` would drop it).
        let worse = |mine: T, theirs: T| {
            if is_nan(mine) || !(theirs > mine || is_nan(theirs)) {
                mine
            } else {
                theirs
            }
        };
        self.lean_rad_s = worse(self.lean_rad_s, other.lean_rad_s);
        self.tilt_rad = worse(self.tilt_rad, other.tilt_rad);
    }
}

/// `x <= bound`, false when either is NaN.
fn within<T: RealField + Copy>(x: T, bound: T) -> bool {
    x <= bound
}
