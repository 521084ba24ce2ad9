//! Whole robots: [`BallbotParams`] (two planes, spin, drivetrain, actuator) and
//! [`PlanarRobotParams`] (one plane and its actuator).

use super::{ActuatorParams, DrivetrainParams, SpinParams, WipParams};
use crate::Error;
use nalgebra::RealField;

/// A complete 3D ballbot: sagittal and frontal planes, spin, drivetrain.
///
/// ```
/// use ballbot_core::{BallbotParams, WipParams};
/// // MiaPURE carrying 60 kg, its payload's COM 10 cm higher in the frontal plane only.
/// let mut params = BallbotParams::<f64>::miapure_60kg();
/// params.frontal = WipParams {
///     com_height_m: 0.60,
///     ..params.frontal
/// };
/// params.validate()?;
/// assert_ne!(params.sagittal, params.frontal);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct BallbotParams<T> {
    /// The sagittal plane (subscript y: travel along body x, rotation about y).
    pub sagittal: WipParams<T>,
    /// The frontal plane (subscript x: travel along body y, rotation about x).
    pub frontal: WipParams<T>,
    /// The spin model about the vertical.
    pub spin: SpinParams<T>,
    /// The omniwheel drivetrain.
    pub drivetrain: DrivetrainParams<T>,
}

impl<T: RealField + Copy> BallbotParams<T> {
    /// MiaPURE carrying a 60 kg payload.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, WipParams};
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// // The two planes are alike (a symmetric robot), and total 77.9 kg with the ball.
    /// assert_eq!(params.sagittal, params.frontal);
    /// assert_eq!(params.sagittal, WipParams::miapure_60kg());
    /// approx::assert_relative_eq!(
    ///     params.sagittal.body_mass_kg + params.sagittal.ball_mass_kg,
    ///     77.9
    /// );
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            sagittal: WipParams::miapure_60kg(),
            frontal: WipParams::miapure_60kg(),
            spin: SpinParams::miapure_60kg(),
            drivetrain: DrivetrainParams::miapure(),
        }
    }

    /// MiaPURE without payload.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// let empty = BallbotParams::<f64>::miapure_unloaded();
    /// let loaded = BallbotParams::<f64>::miapure_60kg();
    /// // Same drivetrain and ball, 60 kg less on top.
    /// assert_eq!(empty.drivetrain, loaded.drivetrain);
    /// approx::assert_relative_eq!(
    ///     loaded.frontal.body_mass_kg - empty.frontal.body_mass_kg,
    ///     60.0,
    ///     epsilon = 1e-12
    /// );
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            sagittal: WipParams::miapure_unloaded(),
            frontal: WipParams::miapure_unloaded(),
            spin: SpinParams::miapure_unloaded(),
            drivetrain: DrivetrainParams::miapure(),
        }
    }

    /// The ball radius shared by both planes (m).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// // MiaPURE's ball is 22.9 cm across.
    /// assert_eq!(BallbotParams::<f64>::miapure_60kg().ball_radius_m(), 0.1145);
    /// ```
    pub fn ball_radius_m(&self) -> T {
        self.sagittal.ball_radius_m
    }

    /// Checks every part and that both planes agree on the ball.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, Error};
    /// // One ball: both planes must agree on its radius.
    /// let mut params = BallbotParams::<f64>::miapure_60kg();
    /// params.frontal.ball_radius_m = 0.12;
    /// assert_eq!(
    ///     params.validate(),
    ///     Err(Error::invalid(
    ///         "frontal.ball_radius_m",
    ///         "must equal sagittal.ball_radius_m (one ball)"
    ///     ))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.sagittal.validate()?;
        self.frontal.validate()?;
        self.spin.validate()?;
        self.drivetrain.validate()?;
        if self.sagittal.ball_radius_m != self.frontal.ball_radius_m {
            return Err(Error::invalid(
                "frontal.ball_radius_m",
                "must equal sagittal.ball_radius_m (one ball)",
            ));
        }
        Ok(())
    }
}

/// A planar robot (the PIPTB): one WIP plane driven by one actuator.
///
/// ```
/// use ballbot_core::{ActuatorParams, PlanarRobotParams};
/// // The PIPTB with an actuator of half the peak torque.
/// let actuator = ActuatorParams {
///     peak_torque_nm: 21.6,
///     ..ActuatorParams::<f64>::miapure()
/// };
/// let robot = PlanarRobotParams {
///     actuator,
///     ..PlanarRobotParams::piptb()
/// };
/// robot.validate()?;
/// assert_eq!(robot.actuator.torque_bounds_nm(0.0), (-21.6, 21.6));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct PlanarRobotParams<T> {
    /// The WIP plane.
    pub plane: WipParams<T>,
    /// The actuator driving the wheel directly (limits at the wheel).
    pub actuator: ActuatorParams<T>,
}

impl<T: RealField + Copy> PlanarRobotParams<T> {
    /// The PIPTB testbed (estimates, see [`WipParams::piptb`]).
    ///
    /// ```
    /// use ballbot_core::{ActuatorParams, PlanarRobotParams, WipParams};
    /// let robot = PlanarRobotParams::<f64>::piptb();
    /// assert_eq!(robot.plane, WipParams::piptb());
    /// assert_eq!(robot.actuator, ActuatorParams::miapure());
    /// // At the testbed's 1 m/s cruise the wheel turns at 17.5 rad/s, well below the 62 rad/s
    /// // no-load speed: 31 N m of the 43.2 N m peak is left to accelerate.
    /// let wheel_rate_rad_per_s = 1.0 / robot.plane.ball_radius_m;
    /// approx::assert_relative_eq!(wheel_rate_rad_per_s, 17.45, epsilon = 0.01);
    /// approx::assert_relative_eq!(
    ///     robot.actuator.torque_bounds_nm(wheel_rate_rad_per_s).1,
    ///     31.04,
    ///     epsilon = 0.01
    /// );
    /// ```
    pub fn piptb() -> Self {
        Self {
            plane: WipParams::piptb(),
            actuator: ActuatorParams::miapure(),
        }
    }

    /// Checks every part.
    ///
    /// ```
    /// use ballbot_core::{Error, PlanarRobotParams};
    /// let mut robot = PlanarRobotParams::<f64>::piptb();
    /// robot.validate()?;
    /// robot.actuator.no_load_speed_rad_per_s = f64::INFINITY;
    /// assert_eq!(
    ///     robot.validate(),
    ///     Err(Error::invalid(
    ///         "no_load_speed_rad_per_s",
    ///         "must be finite and > 0"
    ///     ))
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.plane.validate()?;
        self.actuator.validate()
    }
}
