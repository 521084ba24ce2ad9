//! Lean-to-drive: a rider's torso lean ([`LeanInput`]) becomes a velocity command through a
//! deadband, a gain and a speed limit ([`LeanToDrive`]).

use super::VelocityCommand;
use crate::Error;
use crate::check::{lit, non_negative, positive};
use crate::num::direction;
use nalgebra::RealField;

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
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct LeanToDriveParams<T> {
    /// Lean magnitude that commands nothing (rad).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub deadband_rad: T,
    /// Speed per radian of lean beyond the deadband (m/s per rad).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub gain_m_per_s_per_rad: T,
    /// Largest commanded speed (m/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_speed_m_per_s: T,
    /// Largest acceleration while riding (m/s^2); the shaper uses the smaller of this and its
    /// translation limit.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_accel_m_per_s2: T,
    /// Largest yaw rate a rider may request (rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
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
        let mut out = VelocityCommand::zero();
        // Scaled before squaring (`crate::num::direction`): a huge lean is a large magnitude
        // with a direction, not an overflow.
        if let Some(((ux, uy), magnitude)) = direction(lx, ly)
            && magnitude > p.deadband_rad
        {
            let speed =
                (p.gain_m_per_s_per_rad * (magnitude - p.deadband_rad)).min(p.max_speed_m_per_s);
            out.vx_m_per_s = ux * speed;
            out.vy_m_per_s = uy * speed;
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
