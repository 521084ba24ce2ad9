//! [`SpinParams`]: the rotation about the vertical axis, and its presets.

use crate::Error;
use crate::check::{lit, non_negative, positive};
use nalgebra::RealField;

/// The spin (yaw) model: `I_z theta_z_ddot + D_z theta_z_dot = tau_z`.
///
/// ```
/// use ballbot_core::{Spin, SpinParams};
/// // A heavier, better-lubricated variant.
/// let spin = Spin::new(SpinParams {
///     inertia_kg_m2: 2.5,
///     damping_nm_s_per_rad: 0.5,
/// })?;
/// // The yaw rate of a coasting robot decays with time constant I_z / D_z = 5 s.
/// let (a, _) = spin.state_space();
/// approx::assert_relative_eq!(-1.0 / a[(1, 1)], 5.0, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct SpinParams<T> {
    /// Lumped yaw inertia of upper body and omniwheels `I_z` (kg m^2).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub inertia_kg_m2: T,
    /// Viscous yaw friction `D_z` (N m s/rad).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub damping_nm_s_per_rad: T,
}

impl<T: RealField + Copy> SpinParams<T> {
    /// MiaPURE with 60 kg payload: I_z 1.8 kg m^2, D_z 1.0 N m s/rad (both estimates).
    ///
    /// ```
    /// use ballbot_core::SpinParams;
    /// let spin = SpinParams::<f64>::miapure_60kg();
    /// assert_eq!((spin.inertia_kg_m2, spin.damping_nm_s_per_rad), (1.8, 1.0));
    /// // The payload dominates the yaw inertia: about 5 times the unloaded chassis's.
    /// assert!(spin.inertia_kg_m2 > 5.0 * SpinParams::<f64>::miapure_unloaded().inertia_kg_m2);
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            inertia_kg_m2: lit(1.8),
            damping_nm_s_per_rad: lit(1.0),
        }
    }

    /// MiaPURE without payload: I_z 0.35 kg m^2 (estimate: chassis box plus wheels),
    /// D_z 1.0 N m s/rad (estimate).
    ///
    /// ```
    /// use ballbot_core::SpinParams;
    /// let spin = SpinParams::<f32>::miapure_unloaded();
    /// assert_eq!(spin.inertia_kg_m2, 0.35);
    /// assert_eq!(spin.validate(), Ok(()));
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            inertia_kg_m2: lit(0.35),
            damping_nm_s_per_rad: lit(1.0),
        }
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{Error, SpinParams};
    /// let spin = SpinParams {
    ///     inertia_kg_m2: f64::NAN,
    ///     damping_nm_s_per_rad: 1.0,
    /// };
    /// assert_eq!(
    ///     spin.validate(),
    ///     Err(Error::invalid("inertia_kg_m2", "must be finite and > 0"))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.inertia_kg_m2, "inertia_kg_m2")?;
        non_negative(self.damping_nm_s_per_rad, "damping_nm_s_per_rad")?;
        Ok(())
    }
}
