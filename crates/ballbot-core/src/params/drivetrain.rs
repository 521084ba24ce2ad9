//! [`DrivetrainParams`]: the omniwheel layout, and its presets.

use super::ActuatorParams;
use crate::Error;
use crate::check::{finite, lit, positive};
use nalgebra::RealField;

/// Number of omniwheels. The kinematics and the controllers are written for three.
///
/// ```
/// use ballbot_core::{DrivetrainParams, WHEEL_COUNT};
/// assert_eq!(
///     DrivetrainParams::<f64>::miapure().wheel_azimuths_rad.len(),
///     WHEEL_COUNT
/// );
/// ```
pub const WHEEL_COUNT: usize = 3;

/// The omniwheel drivetrain geometry (MODEL.md section 1) and its actuators.
///
/// ```
/// use ballbot_core::{DrivetrainParams, OmniKinematics};
/// // MiaPURE's drivetrain with the contacts nearer the top of the ball (40 deg from the vertical).
/// let steep = DrivetrainParams {
///     contact_angle_rad: 40f64.to_radians(),
///     ..DrivetrainParams::miapure()
/// };
/// let kin = OmniKinematics::new(steep, 0.1145)?;
/// let nominal = OmniKinematics::new(DrivetrainParams::miapure(), 0.1145)?;
/// // That trades yaw torque capacity for tilt torque capacity.
/// let (cap, cap0) = (
///     kin.planar_torque_capacity_nm(),
///     nominal.planar_torque_capacity_nm(),
/// );
/// assert!(cap[1] > cap0[1] && cap[2] < cap0[2]);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct DrivetrainParams<T> {
    /// Azimuth `beta_i` of each omniwheel's contact, counter-clockwise from the body x axis
    /// seen from above (rad). MiaPURE: 0, 120, 240 deg.
    pub wheel_azimuths_rad: [T; WHEEL_COUNT],
    /// Contact angle `alpha` between the vertical and the line from the ball centre to each
    /// contact (rad), in (0, pi/2). MiaPURE: 45 deg.
    #[cfg_attr(
        feature = "schema",
        schemars(extend("exclusiveMinimum" = 0, "exclusiveMaximum" = core::f64::consts::FRAC_PI_2))
    )]
    pub contact_angle_rad: T,
    /// Omniwheel radius `r_W` (m).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub wheel_radius_m: T,
    /// Each omniwheel's actuator.
    pub actuator: ActuatorParams<T>,
    /// Friction coefficient between omniwheel rollers and ball (estimate 0.6: TPU on rubber).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub wheel_ball_friction: T,
    /// Friction coefficient between ball and floor (estimate 0.9).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub ball_floor_friction: T,
}

impl<T: RealField + Copy> DrivetrainParams<T> {
    /// MiaPURE: wheels at 0, 120, 240 deg, 45 deg contact angle, 125 mm omniwheels, the QDD
    /// actuator (paper); friction coefficients are estimates.
    ///
    /// ```
    /// use ballbot_core::DrivetrainParams;
    /// let d = DrivetrainParams::<f64>::miapure();
    /// // Wheels 120 deg apart, contacts 45 deg from the vertical, 125 mm omniwheels.
    /// approx::assert_relative_eq!(
    ///     d.wheel_azimuths_rad[2] - d.wheel_azimuths_rad[1],
    ///     120f64.to_radians()
    /// );
    /// approx::assert_relative_eq!(d.contact_angle_rad, std::f64::consts::FRAC_PI_4);
    /// assert_eq!(2.0 * d.wheel_radius_m, 0.125);
    /// ```
    pub fn miapure() -> Self {
        let deg = T::pi() / lit(180.0);
        Self {
            wheel_azimuths_rad: [T::zero(), lit::<T>(120.0) * deg, lit::<T>(240.0) * deg],
            contact_angle_rad: lit::<T>(45.0) * deg,
            wheel_radius_m: lit(0.0625),
            actuator: ActuatorParams::miapure(),
            wheel_ball_friction: lit(0.6),
            ball_floor_friction: lit(0.9),
        }
    }

    /// Checks every field, including that the three wheels span all three rotation axes
    /// (a singular layout, e.g. two wheels at the same azimuth, is rejected).
    ///
    /// ```
    /// use ballbot_core::{DrivetrainParams, Error};
    /// let mut d = DrivetrainParams::<f64>::miapure();
    /// d.validate()?;
    /// // Two wheels at the same azimuth cannot drive all three axes.
    /// d.wheel_azimuths_rad[2] = d.wheel_azimuths_rad[1];
    /// assert!(matches!(
    ///     d.validate(),
    ///     Err(Error::InvalidParameter {
    ///         field: "wheel_azimuths_rad",
    ///         ..
    ///     })
    /// ));
    /// // A contact at 90 deg from the vertical cannot carry the robot's weight.
    /// let flat = DrivetrainParams {
    ///     contact_angle_rad: std::f64::consts::FRAC_PI_2,
    ///     ..DrivetrainParams::miapure()
    /// };
    /// assert!(matches!(
    ///     flat.validate(),
    ///     Err(Error::InvalidParameter {
    ///         field: "contact_angle_rad",
    ///         ..
    ///     })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        for beta in self.wheel_azimuths_rad {
            finite(beta, "wheel_azimuths_rad")?;
        }
        let a = self.contact_angle_rad;
        if !(a.is_finite() && a > T::zero() && a < T::frac_pi_2()) {
            return Err(Error::invalid(
                "contact_angle_rad",
                "must be in (0, pi/2) rad, i.e. (0, 90) deg",
            ));
        }
        positive(self.wheel_radius_m, "wheel_radius_m")?;
        self.actuator.validate()?;
        positive(self.wheel_ball_friction, "wheel_ball_friction")?;
        positive(self.ball_floor_friction, "ball_floor_friction")?;
        // The rows u_i = [-cos a cos b_i, -cos a sin b_i, sin a] must be independent. The
        // determinant is cos^2 a sin a times a purely azimuthal factor; compare that factor
        // with the best layout's (3 sqrt 3 / 2, wheels 120 deg apart).
        let [b1, b2, b3] = self.wheel_azimuths_rad;
        let azimuthal = (b2 - b1).sin() + (b3 - b2).sin() + (b1 - b3).sin();
        if azimuthal.abs() < lit(1e-3) {
            return Err(Error::invalid(
                "wheel_azimuths_rad",
                "wheel layout is singular: no two wheels may share an azimuth",
            ));
        }
        Ok(())
    }
}
