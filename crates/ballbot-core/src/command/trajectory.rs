//! A sampled planar command [`Trajectory`] borrowed from a slice, linearly interpolated and
//! driven along a heading.

use super::TrajectoryLimits;
use crate::Error;
use crate::check::{finite, positive};
use crate::wip::WipState;
use nalgebra::RealField;

/// A sampled planar command trajectory borrowed from a slice: `samples[k]` is the command state
/// `[theta (rad), phi (rad), theta_dot (rad/s), phi_dot (rad/s)]` at `k * sample_period_secs`,
/// for travel along `heading_rad` in the body frame (0: towards omniwheel 1, sagittal plane;
/// `pi/2`: body +y).
///
/// Along a heading `h` the planar state maps to the sagittal plane as `cos(h) s` and to the
/// frontal plane as `-sin(h) s` (ball position `x = r phi_y`, `y = -r phi_x`).
///
/// A trajectory is checked once, when it is built, against [`TrajectoryLimits`] (sample
/// period, tilts, rates, accelerations, the tilt rate the tilt's derivative), and remembers
/// them ([`Self::limits`]). Build the trajectories a robot follows with
/// [`BallbotController::accept_trajectory`](crate::ballbot::BallbotController::accept_trajectory),
/// against the controller's own limits.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::BallbotControllerConfig;
/// use ballbot_core::command::Trajectory;
/// use nalgebra::Vector4;
/// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
///     .trajectory_limits()?;
/// // From 0.11 m/s to rest in 1 s (ball rate 1 rad/s, 0.11 m/s^2), leaning back into the
/// // deceleration, upright at the end.
/// let lean = -limits.lean_per_ball_accel_s2 * 1.0;
/// let samples = [Vector4::new(lean, 0.0, 0.0, 1.0), Vector4::new(0.0, 0.5, 0.0, 0.0)];
/// let traj = Trajectory::new(&samples, 1.0, 0.0, &limits)?;
/// approx::assert_relative_eq!(traj.sample(0.5)[3], 0.5);
/// assert_eq!(traj.sample(9.0), samples[1]); // held after the end
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trajectory<'a, T: nalgebra::Scalar> {
    samples: &'a [WipState<T>],
    sample_period_secs: T,
    heading_rad: T,
    yaw_rate_rad_per_s: T,
    limits: TrajectoryLimits<T>,
}

impl<'a, T: RealField + Copy> Trajectory<'a, T> {
    /// Validates the samples (at least one, all finite), the period (finite, > 0) and the
    /// heading (finite), then checks them against `limits` (see [`TrajectoryLimits`]: the
    /// period, every sample's tilt and rates, every interval's accelerations and torque, and
    /// the tilt rates against the tilt's finite differences). Checking every sample once here
    /// keeps [`Self::sample`] O(1). The error names the field and the bound it broke.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, Error};
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let samples = [Vector4::zeros(), Vector4::new(0.0, 0.0, 0.0, 0.01)];
    /// assert!(Trajectory::new(&samples, 0.01, 0.0, &limits).is_ok());
    /// // No samples, a NaN sample or a zero period are refused ...
    /// assert!(Trajectory::<f64>::new(&[], 0.01, 0.0, &limits).is_err());
    /// assert!(Trajectory::new(&[Vector4::repeat(f64::NAN)], 0.01, 0.0, &limits).is_err());
    /// assert!(Trajectory::new(&samples, 0.0, 0.0, &limits).is_err());
    /// // ... and so are samples closer than the outer period, and a tilt-rate step.
    /// let too_fine = Trajectory::new(&samples, 1e-300, 0.0, &limits);
    /// assert!(matches!(too_fine, Err(Error::InvalidParameter { field: "sample_period_secs", .. })));
    /// let step = [Vector4::zeros(), Vector4::new(0.0, 0.0, 1.0, 0.0)];
    /// assert!(Trajectory::new(&step, 0.0025, 0.0, &limits).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(
        samples: &'a [WipState<T>],
        sample_period_secs: T,
        heading_rad: T,
        limits: &TrajectoryLimits<T>,
    ) -> Result<Self, Error> {
        if samples.is_empty() {
            return Err(Error::invalid("samples", "must hold at least one state"));
        }
        if samples.iter().any(|s| !s.iter().all(|x| x.is_finite())) {
            return Err(Error::invalid("samples", "must be finite"));
        }
        positive(sample_period_secs, "sample_period_secs")?;
        finite(heading_rad, "heading_rad")?;
        limits.check(samples, sample_period_secs)?;
        Ok(Self {
            samples,
            sample_period_secs,
            heading_rad,
            yaw_rate_rad_per_s: T::zero(),
            limits: *limits,
        })
    }

    /// The limits the trajectory was checked against.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// assert_eq!(Trajectory::new(&samples, 0.01, 0.0, &limits)?.limits(), &limits);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn limits(&self) -> &TrajectoryLimits<T> {
        &self.limits
    }

    /// The same trajectory with a constant yaw rate commanded alongside (rad/s). A non-finite
    /// rate is replaced by 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// let traj = Trajectory::new(&samples, 0.01, 0.0, &limits)?.with_yaw_rate(0.3);
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
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// // Travel towards body +y.
    /// let traj = Trajectory::new(&samples, 0.01, core::f64::consts::FRAC_PI_2, &limits)?;
    /// assert_eq!(traj.heading_rad(), core::f64::consts::FRAC_PI_2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn heading_rad(&self) -> T {
        self.heading_rad
    }

    /// The commanded yaw rate (rad/s).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let samples = [Vector4::new(0.0, 0.0, 0.0, 1.0)];
    /// let traj = Trajectory::new(&samples, 0.01, 0.0, &limits)?;
    /// assert_eq!(traj.yaw_rate_rad_per_s(), 0.0); // none unless asked for
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn yaw_rate_rad_per_s(&self) -> T {
        self.yaw_rate_rad_per_s
    }

    /// The duration covered by the samples (s).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// // 101 samples 10 ms apart cover 1 s.
    /// let samples = [Vector4::<f64>::zeros(); 101];
    /// approx::assert_relative_eq!(Trajectory::new(&samples, 0.01, 0.0, &limits)?.duration_secs(), 1.0);
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
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// // Braking from 1 rad/s to rest in 1 s, leaning into it.
    /// let lean = -limits.lean_per_ball_accel_s2;
    /// let samples = [Vector4::new(lean, 0.0, 0.0, 1.0), Vector4::new(0.0, 0.5, 0.0, 0.0)];
    /// let traj = Trajectory::new(&samples, 1.0, 0.0, &limits)?;
    /// approx::assert_relative_eq!(traj.sample(0.75)[3], 0.25);
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
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::Trajectory;
    /// use nalgebra::Vector4;
    /// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
    ///     .trajectory_limits()?;
    /// let lean = -limits.lean_per_ball_accel_s2;
    /// let samples = [Vector4::new(lean, 0.0, 0.0, 1.0), Vector4::new(0.0, 0.5, 0.0, 0.0)];
    /// let traj = Trajectory::new(&samples, 1.0, 0.0, &limits)?;
    /// let (s, rate) = traj.sample_with_rate(0.5);
    /// assert_eq!(s[3], 0.5);
    /// assert_eq!(rate[3], -1.0); // decelerating at 1 rad/s^2
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
