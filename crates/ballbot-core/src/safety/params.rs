//! The supervisor's limits and timeouts, [`SafetyParams`], validated once.

use crate::check::{lit, positive};
use crate::rates::OUTER_LOOP_PERIOD_US;
use crate::{ActuatorParams, Error};
use nalgebra::RealField;

/// Thresholds and timeouts of the [`SafetySupervisor`](super::SafetySupervisor). Times in microseconds of the robot's
/// monotonic clock.
///
/// ```
/// use ballbot_core::safety::{SafetyParams, SafetySupervisor};
/// // MiaPURE's defaults, without a remote control (no command-link supervision).
/// let params = SafetyParams::<f64> { command_timeout_us: None, ..SafetyParams::miapure() };
/// let sup = SafetySupervisor::new(params)?;
/// assert_eq!(sup.params().command_timeout_us, None);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct SafetyParams<T> {
    /// Longest age of the newest valid IMU sample (us).
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub imu_timeout_us: u64,
    /// Longest age of the newest valid encoder sample (us).
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub encoder_timeout_us: u64,
    /// How long bit-identical IMU readings may last before the IMU counts as frozen (us);
    /// `None` disables the check (needed for noiseless simulated sensors at rest).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub frozen_imu_timeout_us: Option<u64>,
    /// Longest age of the newest command (us); `None` disables link supervision (a robot
    /// without a remote).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub command_timeout_us: Option<u64>,
    /// Longest time between two supervisor steps (us).
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub max_loop_period_us: u64,
    /// The outer loop's nominal period (us): one supervisor step per period. The watchdogs
    /// also count steps (ticks): a sample not refreshed (its timestamp unchanged) for
    /// `timeout / outer_period_us` ticks, rounded up, is stale whatever the clock says
    /// ([`Self::timeout_ticks`]).
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub outer_period_us: u64,
    /// Largest tilt from the vertical (the angle between the body's z axis and the world's,
    /// [`tilt_from_vertical_rad`]) from which balancing is still attempted (rad).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub tilt_limit_rad: T,
    /// Largest tilt from the vertical at which arming is allowed (rad).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub arm_tilt_limit_rad: T,
    /// Largest body rate (each gyro axis) at which arming is allowed (rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub arm_rate_limit_rad_per_s: T,
    /// Gyro measurement range: beyond it a reading is out of range (rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub gyro_range_rad_per_s: T,
    /// Omniwheel speed beyond which a controlled stop starts (rad/s, at the omniwheel).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub wheel_speed_limit_rad_per_s: T,
    /// Encoder measurement range: beyond it a reading is out of range (rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub encoder_range_rad_per_s: T,
}

impl<T: RealField + Copy> SafetyParams<T> {
    /// Defaults for MiaPURE at a 400 Hz outer loop (engineering choices, not from the paper):
    /// IMU and encoder timeouts 20 ms (8 periods), frozen IMU 100 ms, command link 250 ms, loop
    /// period 5 ms (2 periods), outer period 2.5 ms, tilt limit 20 deg from the vertical, arming within 3 deg and 0.2 rad/s, gyro range
    /// 2000 deg/s, wheel-speed limit 90 % of the 62 rad/s no-load speed, encoder range twice
    /// the no-load speed.
    ///
    /// ```
    /// use ballbot_core::safety::SafetyParams;
    /// let p = SafetyParams::<f64>::miapure();
    /// approx::assert_relative_eq!(p.tilt_limit_rad.to_degrees(), 20.0, epsilon = 1e-9);
    /// // 90 % of the actuator's 62 rad/s no-load speed.
    /// approx::assert_relative_eq!(p.wheel_speed_limit_rad_per_s, 55.8, epsilon = 1e-9);
    /// assert_eq!(p.imu_timeout_us, 20_000); // 8 periods at 400 Hz
    /// ```
    pub fn miapure() -> Self {
        Self::for_actuator(&ActuatorParams::miapure())
    }

    /// The [`Self::miapure`] thresholds with the wheel-speed limits taken from `actuator`.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::safety::SafetyParams;
    /// // A faster gearing: 100 rad/s no-load at the omniwheel.
    /// let actuator = ActuatorParams {
    ///     no_load_speed_rad_per_s: 100.0,
    ///     ..ActuatorParams::<f64>::miapure()
    /// };
    /// let p = SafetyParams::for_actuator(&actuator);
    /// approx::assert_relative_eq!(p.wheel_speed_limit_rad_per_s, 90.0, epsilon = 1e-9);
    /// approx::assert_relative_eq!(p.encoder_range_rad_per_s, 200.0, epsilon = 1e-9);
    /// ```
    pub fn for_actuator(actuator: &ActuatorParams<T>) -> Self {
        let deg = T::pi() / lit(180.0);
        Self {
            imu_timeout_us: 20_000,
            encoder_timeout_us: 20_000,
            frozen_imu_timeout_us: Some(100_000),
            command_timeout_us: Some(250_000),
            max_loop_period_us: 5_000,
            outer_period_us: OUTER_LOOP_PERIOD_US,
            tilt_limit_rad: lit::<T>(20.0) * deg,
            arm_tilt_limit_rad: lit::<T>(3.0) * deg,
            arm_rate_limit_rad_per_s: lit(0.2),
            gyro_range_rad_per_s: lit::<T>(2000.0) * deg,
            wheel_speed_limit_rad_per_s: lit::<T>(0.9) * actuator.no_load_speed_rad_per_s,
            encoder_range_rad_per_s: lit::<T>(2.0) * actuator.no_load_speed_rad_per_s,
        }
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::safety::SafetyParams;
    /// let p = SafetyParams::<f64>::miapure();
    /// assert!(p.validate().is_ok());
    /// // Arming must not be allowed beyond the tilt at which balancing is given up.
    /// let bad = SafetyParams { arm_tilt_limit_rad: 0.5, ..p };
    /// assert!(matches!(
    ///     bad.validate(),
    ///     Err(Error::InvalidParameter { field: "arm_tilt_limit_rad", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let nonzero = |v: u64, field| {
            if v > 0 {
                Ok(())
            } else {
                Err(Error::invalid(field, "must be > 0"))
            }
        };
        nonzero(self.imu_timeout_us, "imu_timeout_us")?;
        nonzero(self.encoder_timeout_us, "encoder_timeout_us")?;
        if let Some(v) = self.frozen_imu_timeout_us {
            nonzero(v, "frozen_imu_timeout_us")?;
        }
        if let Some(v) = self.command_timeout_us {
            nonzero(v, "command_timeout_us")?;
        }
        nonzero(self.max_loop_period_us, "max_loop_period_us")?;
        nonzero(self.outer_period_us, "outer_period_us")?;
        if self.outer_period_us > self.max_loop_period_us {
            return Err(Error::invalid(
                "outer_period_us",
                "must not exceed max_loop_period_us",
            ));
        }
        positive(self.tilt_limit_rad, "tilt_limit_rad")?;
        if self.tilt_limit_rad > T::pi() {
            return Err(Error::invalid("tilt_limit_rad", "must not exceed pi"));
        }
        positive(self.arm_tilt_limit_rad, "arm_tilt_limit_rad")?;
        if self.arm_tilt_limit_rad > self.tilt_limit_rad {
            return Err(Error::invalid(
                "arm_tilt_limit_rad",
                "must not exceed tilt_limit_rad",
            ));
        }
        positive(self.arm_rate_limit_rad_per_s, "arm_rate_limit_rad_per_s")?;
        positive(self.gyro_range_rad_per_s, "gyro_range_rad_per_s")?;
        positive(
            self.wheel_speed_limit_rad_per_s,
            "wheel_speed_limit_rad_per_s",
        )?;
        positive(self.encoder_range_rad_per_s, "encoder_range_rad_per_s")?;
        if self.wheel_speed_limit_rad_per_s > self.encoder_range_rad_per_s {
            return Err(Error::invalid(
                "wheel_speed_limit_rad_per_s",
                "must not exceed encoder_range_rad_per_s",
            ));
        }
        Ok(())
    }

    /// The number of outer steps (ticks) that `timeout_us` lasts at [`Self::outer_period_us`],
    /// rounded up: a sample not refreshed for more ticks than this is stale even when the
    /// clock says otherwise (a clock stepped back, or stalled). Saturates at `u32::MAX`.
    ///
    /// ```
    /// use ballbot_core::safety::SafetyParams;
    /// let p = SafetyParams::<f64>::miapure();
    /// assert_eq!(p.timeout_ticks(p.imu_timeout_us), 8); // 20 ms at 2.5 ms
    /// assert_eq!(p.timeout_ticks(2_501), 2); // rounded up
    /// ```
    pub fn timeout_ticks(&self, timeout_us: u64) -> u32 {
        let ticks = timeout_us.div_ceil(self.outer_period_us.max(1));
        u32::try_from(ticks).unwrap_or(u32::MAX)
    }
}

/// The tilt of the body from the vertical (rad, in `[0, pi]`): the angle between the body's z
/// axis and the world's, from the IMU's ZYX Euler angles ([`crate::estimation::ImuSample`]).
/// The body's z axis in the world is `Rz(yaw) [sin(pitch) cos(roll), -sin(roll),
/// cos(pitch) cos(roll)]`, so the angle is `acos(cos(roll) cos(pitch))`; it is computed as
/// `atan2(hypot(sin(roll), cos(roll) sin(pitch)), cos(roll) cos(pitch))`, which is exact
/// near 0 (where `acos` loses half the digits) and cannot overflow. A fall between the axes
/// is seen whole: 15 deg of roll and 15 deg of pitch are 21.09 deg from the vertical.
///
/// ```
/// use ballbot_core::safety::tilt_from_vertical_rad;
/// let r = 15f64.to_radians();
/// let tilt = tilt_from_vertical_rad(r, r).to_degrees();
/// approx::assert_relative_eq!(tilt, 21.09, epsilon = 0.01);
/// // Along one axis it is that axis's angle; tiny tilts keep their digits.
/// approx::assert_relative_eq!(tilt_from_vertical_rad(0.0, 0.3), 0.3, epsilon = 1e-15);
/// approx::assert_relative_eq!(tilt_from_vertical_rad(1e-9, 0.0), 1e-9, max_relative = 1e-12);
/// ```
pub fn tilt_from_vertical_rad<T: RealField + Copy>(roll_rad: T, pitch_rad: T) -> T {
    let (sin_roll, cos_roll) = roll_rad.sin_cos();
    let (sin_pitch, cos_pitch) = pitch_rad.sin_cos();
    let horizontal = sin_roll.hypot(cos_roll * sin_pitch);
    horizontal.atan2(cos_roll * cos_pitch)
}
