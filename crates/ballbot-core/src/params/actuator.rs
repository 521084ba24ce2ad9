//! [`ActuatorParams`]: an omniwheel actuator's torque-speed limits, and its presets.

use crate::Error;
use crate::check::{lit, positive};
use nalgebra::RealField;

/// One actuator (motor plus gearbox), its limits stated at the output (the omniwheel).
///
/// ```
/// use ballbot_core::ActuatorParams;
/// // A weaker actuator: 20 N m peak, 80 rad/s no-load at the wheel.
/// let weak = ActuatorParams {
///     peak_torque_nm: 20.0,
///     no_load_speed_rad_per_s: 80.0,
///     ..ActuatorParams::<f64>::miapure()
/// };
/// weak.validate()?;
/// // At half the no-load speed, half the peak is left for motoring, all of it for braking.
/// assert_eq!(weak.torque_bounds_nm(40.0), (-20.0, 10.0));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct ActuatorParams<T> {
    /// Gear ratio, rotor turns per output turn (dimensionless).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub gear_ratio: T,
    /// Peak torque at the output (N m).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub peak_torque_nm: T,
    /// No-load speed at the output (rad/s); the available torque falls linearly to zero there.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub no_load_speed_rad_per_s: T,
}

impl<T: RealField + Copy> ActuatorParams<T> {
    /// The T-motor QDD actuator of MiaPURE: ratio 7.5, 43.2 N m peak, 62 rad/s no-load at
    /// 45 V (paper). The PIPTB uses similar hardware (paper); we assume the same actuator.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// assert_eq!(
    ///     (
    ///         qdd.gear_ratio,
    ///         qdd.peak_torque_nm,
    ///         qdd.no_load_speed_rad_per_s
    ///     ),
    ///     (7.5, 43.2, 62.0)
    /// );
    /// // The rotor's peak torque is the output's divided by the ratio: 5.76 N m.
    /// approx::assert_relative_eq!(qdd.peak_torque_nm / qdd.gear_ratio, 5.76, epsilon = 1e-12);
    /// ```
    pub fn miapure() -> Self {
        Self {
            gear_ratio: lit(7.5),
            peak_torque_nm: lit(43.2),
            no_load_speed_rad_per_s: lit(62.0),
        }
    }

    /// The output torque range `(min, max)` (N m) available at output speed
    /// `speed_rad_per_s`: the current limit `peak_torque_nm`, and, when the torque drives in
    /// the direction of motion, the line from the peak at rest to 0 at the no-load speed.
    /// Torque against the motion (braking) may use the full peak.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// // At rest: the full 43.2 N m either way.
    /// assert_eq!(qdd.torque_bounds_nm(0.0), (-43.2, 43.2));
    /// // Turning forward at half the no-load speed (31 rad/s): 21.6 N m left to speed up,
    /// // the full peak to brake; mirrored when turning backwards.
    /// let (lo, hi) = qdd.torque_bounds_nm(31.0);
    /// approx::assert_relative_eq!(hi, 21.6, epsilon = 1e-12);
    /// assert_eq!(lo, -43.2);
    /// assert_eq!(qdd.torque_bounds_nm(-31.0), (-hi, 43.2));
    /// // Beyond the no-load speed nothing is left for motoring.
    /// assert_eq!(qdd.torque_bounds_nm(70.0).1, 0.0);
    /// ```
    pub fn torque_bounds_nm(&self, speed_rad_per_s: T) -> (T, T) {
        let peak = self.peak_torque_nm;
        let line = peak * (T::one() - speed_rad_per_s.abs() / self.no_load_speed_rad_per_s);
        let motoring = line.max(T::zero()).min(peak);
        if speed_rad_per_s > T::zero() {
            (-peak, motoring)
        } else if speed_rad_per_s < T::zero() {
            (-motoring, peak)
        } else {
            (-peak, peak)
        }
    }

    /// `torque_nm` clamped to [`Self::torque_bounds_nm`] at `speed_rad_per_s`; a non-finite
    /// request gives 0.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// // 30 N m asked at 31 rad/s forward: only 21.6 N m can drive, braking passes in full.
    /// approx::assert_relative_eq!(qdd.clamp_torque_nm(30.0, 31.0), 21.6, epsilon = 1e-12);
    /// assert_eq!(qdd.clamp_torque_nm(-30.0, 31.0), -30.0);
    /// // A non-finite request (a failed computation upstream) gives no torque.
    /// assert_eq!(qdd.clamp_torque_nm(f64::NAN, 0.0), 0.0);
    /// ```
    pub fn clamp_torque_nm(&self, torque_nm: T, speed_rad_per_s: T) -> T {
        if !torque_nm.is_finite() {
            return T::zero();
        }
        let (lo, hi) = self.torque_bounds_nm(speed_rad_per_s);
        torque_nm.max(lo).min(hi)
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{ActuatorParams, Error};
    /// let no_gearbox = ActuatorParams {
    ///     gear_ratio: 0.0,
    ///     ..ActuatorParams::<f64>::miapure()
    /// };
    /// assert_eq!(
    ///     no_gearbox.validate(),
    ///     Err(Error::invalid("gear_ratio", "must be finite and > 0"))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.gear_ratio, "gear_ratio")?;
        positive(self.peak_torque_nm, "peak_torque_nm")?;
        positive(self.no_load_speed_rad_per_s, "no_load_speed_rad_per_s")?;
        Ok(())
    }
}
