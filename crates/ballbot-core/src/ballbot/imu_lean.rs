//! The lean an IMU's attitude filter reads into an acceleration, and its correction.
//!
//! An attitude filter that pulls its estimate towards the accelerometer's vertical (a VN-100,
//! a Mahony or Madgwick filter) cannot tell an acceleration from gravity. Under a sustained
//! horizontal acceleration `a` the vertical it sees leans by `atan(a / g)`, and with the
//! filter's time constant `tau` the reported tilt follows it: the estimate is the true tilt
//! minus a first-order lag of that lean. A ballbot that accelerates leans into the acceleration,
//! about along the apparent vertical, so after a few `tau` it reads upright. When the
//! acceleration ends, the error decays with `tau`, and the LQR holds the wrong lean and the
//! speed error that goes with it: in the 3D world with the VN-100 model, 0.2 m/s is left 2 s
//! after a stop from 1.4 m/s at `tau` = 2.3 s (docs/world-sensing.md).
//!
//! [`ImuLean`] runs the same first-order lag on the acceleration the controller commands
//! (the shaped command's, one outer period late) and adds it back to the measured tilt:
//! `theta_y += L(atan(a_x / g))`, `theta_x += L(-atan(a_y / g))` (pitch > 0 leans towards +x,
//! roll > 0 towards -y). It needs the filter's time constant, which the robot's engineer knows
//! from the IMU's configuration or measures; [`ImuLeanParams::off`] (the default of every
//! designed configuration) leaves the tilt as measured, right for an IMU that reports the true
//! attitude. The commanded acceleration stands in for the body's, which is what the
//! accelerometer feels; they differ in the non-minimum-phase start of a manoeuvre, briefly
//! against `tau`.

use crate::check::non_negative;
use crate::error::Error;
use nalgebra::{RealField, Vector2};

/// The IMU filter to correct for.
///
/// ```
/// use ballbot_core::ballbot::ImuLeanParams;
/// assert!(!ImuLeanParams::<f64>::off().enabled());
/// assert!(ImuLeanParams::for_filter(2.29).enabled());
/// assert!(ImuLeanParams::for_filter(-1.0_f64).validate().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct ImuLeanParams<T> {
    /// Time constant of the IMU filter's pull towards the accelerometer's vertical (s); 0:
    /// no correction.
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub filter_time_constant_secs: T,
}

impl<T: RealField + Copy> ImuLeanParams<T> {
    /// No correction: the IMU reports the true attitude.
    ///
    /// ```
    /// use ballbot_core::ballbot::ImuLeanParams;
    /// assert_eq!(ImuLeanParams::<f64>::off().filter_time_constant_secs, 0.0);
    /// ```
    pub fn off() -> Self {
        Self {
            filter_time_constant_secs: T::zero(),
        }
    }

    /// The correction for a filter of time constant `filter_time_constant_secs` (s).
    ///
    /// ```
    /// use ballbot_core::ballbot::ImuLeanParams;
    /// assert_eq!(ImuLeanParams::for_filter(2.29).filter_time_constant_secs, 2.29);
    /// ```
    pub fn for_filter(filter_time_constant_secs: T) -> Self {
        Self {
            filter_time_constant_secs,
        }
    }

    /// Whether the tilt is corrected: a time constant above 0.
    ///
    /// ```
    /// use ballbot_core::ballbot::ImuLeanParams;
    /// assert!(ImuLeanParams::for_filter(0.5).enabled());
    /// assert!(!ImuLeanParams::for_filter(0.0).enabled());
    /// ```
    pub fn enabled(&self) -> bool {
        self.filter_time_constant_secs > T::zero()
    }

    /// [`Error::InvalidParameter`] naming `imu_lean.filter_time_constant_secs` unless it is
    /// finite and >= 0.
    ///
    /// ```
    /// use ballbot_core::ballbot::ImuLeanParams;
    /// assert!(ImuLeanParams::for_filter(2.29).validate().is_ok());
    /// assert!(ImuLeanParams::for_filter(f64::NAN).validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        non_negative(
            self.filter_time_constant_secs,
            "imu_lean.filter_time_constant_secs",
        )
    }
}

/// The filter's lean as the controller tracks it (module documentation).
///
/// ```
/// use ballbot_core::ballbot::{ImuLean, ImuLeanParams};
/// let mut lean = ImuLean::new(ImuLeanParams::for_filter(2.0), 0.0025, 9.81)?;
/// // Twenty time constants at 1 m/s^2 forward: the filter reads atan(1 / 9.81) less pitch.
/// for _ in 0..16_000 {
///     lean.follow(1.0, 0.0);
/// }
/// let [roll, pitch] = lean.correction_rad();
/// assert!((pitch - (1.0_f64 / 9.81).atan()).abs() < 1e-6 && roll == 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuLean<T> {
    /// The lag's weight per outer period, `1 - exp(-dt / tau)`.
    weight: T,
    gravity_m_per_s2: T,
    /// `[roll, pitch]` to add to the measured tilt (rad).
    correction_rad: Vector2<T>,
}

impl<T: RealField + Copy> ImuLean<T> {
    /// The tracker for `params` at the outer period `outer_dt_secs` under gravity
    /// `gravity_m_per_s2`; [`Error::InvalidParameter`] unless `params` validates and is
    /// enabled.
    ///
    /// ```
    /// use ballbot_core::ballbot::{ImuLean, ImuLeanParams};
    /// assert!(ImuLean::new(ImuLeanParams::for_filter(2.29), 0.0025, 9.81).is_ok());
    /// assert!(ImuLean::new(ImuLeanParams::<f64>::off(), 0.0025, 9.81).is_err());
    /// ```
    pub fn new(
        params: ImuLeanParams<T>,
        outer_dt_secs: T,
        gravity_m_per_s2: T,
    ) -> Result<Self, Error> {
        params.validate()?;
        if !params.enabled() {
            return Err(Error::InvalidParameter {
                field: "imu_lean.filter_time_constant_secs",
                requirement: "must be > 0 for the correction",
            });
        }
        let weight = T::one() - (-outer_dt_secs / params.filter_time_constant_secs).exp();
        Ok(Self {
            weight,
            gravity_m_per_s2,
            correction_rad: Vector2::zeros(),
        })
    }

    /// One outer period of the commanded horizontal acceleration `[accel_x, accel_y]`
    /// (m/s^2, yaw frame): the correction moves towards the lean it makes, by
    /// `1 - exp(-dt / tau)` of the way.
    ///
    /// ```
    /// use ballbot_core::ballbot::{ImuLean, ImuLeanParams};
    /// let mut lean = ImuLean::new(ImuLeanParams::for_filter(1.0), 0.5, 9.81)?;
    /// // Sideways (+y): the filter reads the body rolled towards +y, a negative roll.
    /// lean.follow(0.0, 2.0);
    /// let expected = -(2.0_f64 / 9.81).atan() * (1.0 - (-0.5_f64).exp());
    /// assert!((lean.correction_rad()[0] - expected).abs() < 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn follow(&mut self, accel_x_m_per_s2: T, accel_y_m_per_s2: T) {
        let g = self.gravity_m_per_s2;
        let lean = Vector2::new(-accel_y_m_per_s2.atan2(g), accel_x_m_per_s2.atan2(g));
        self.correction_rad += (lean - self.correction_rad) * self.weight;
    }

    /// `[roll, pitch]` to add to the measured tilt (rad); 0 before any acceleration.
    ///
    /// ```
    /// use ballbot_core::ballbot::{ImuLean, ImuLeanParams};
    /// let lean = ImuLean::new(ImuLeanParams::for_filter(2.29), 0.0025, 9.81)?;
    /// assert_eq!(lean.correction_rad(), [0.0, 0.0]);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn correction_rad(&self) -> [T; 2] {
        [self.correction_rad.x, self.correction_rad.y]
    }
}
