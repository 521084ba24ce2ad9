//! [`WipParams`]: one plane of the wheeled inverted pendulum, and its presets.

use crate::Error;
use crate::check::{lit, non_negative, positive};
use nalgebra::RealField;

/// One plane of the wheeled inverted pendulum (WIP): ball plus upper body.
///
/// The upper body is everything but the ball (chassis, omniwheels, payload).
///
/// ```
/// use ballbot_core::{Wip, WipParams};
/// // A variant of a preset: MiaPURE with a lighter, 40 kg payload.
/// let params = WipParams {
///     body_mass_kg: 54.3,
///     ..WipParams::<f64>::miapure_60kg()
/// };
/// params.validate()?;
/// // A lighter body falls more slowly.
/// let light = Wip::new(params)?.upright_unstable_pole_rad_per_s();
/// assert!(light < Wip::new(WipParams::miapure_60kg())?.upright_unstable_pole_rad_per_s());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct WipParams<T> {
    /// Ball radius `r` (m). For the PIPTB, the wheel radius.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub ball_radius_m: T,
    /// Ball mass `m_S` (kg).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub ball_mass_kg: T,
    /// Ball moment of inertia about its centre `I_S` (kg m^2).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub ball_inertia_kg_m2: T,
    /// Upper-body mass `m_U` (kg), payload included.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub body_mass_kg: T,
    /// Distance `l` from the ball centre to the upper body's centre of mass (m).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub com_height_m: T,
    /// Upper-body moment of inertia about its own centre of mass, about the plane's
    /// horizontal axis, `I_U` (kg m^2).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub body_inertia_kg_m2: T,
    /// Omniwheel plus rotor inertia reflected onto the relative rate `phi_dot - theta_dot`,
    /// `I_W` (kg m^2); 0 neglects it.
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub wheel_inertia_kg_m2: T,
    /// Viscous friction between ball and floor, on `phi_dot`, `b_k` (N m s/rad).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub ball_damping_nm_s_per_rad: T,
    /// Viscous drivetrain friction on the relative rate `phi_dot - theta_dot`, `b_m`
    /// (N m s/rad).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub drive_damping_nm_s_per_rad: T,
    /// Gravitational acceleration `g` (m/s^2).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub gravity_m_per_s2: T,
}

impl<T: RealField + Copy> WipParams<T> {
    /// MiaPURE carrying a 60 kg payload (one plane; sagittal and frontal are alike).
    ///
    /// Ball: 22.9 cm, 3.6 kg, 0.047 kg m^2 (paper). Upper body 74.3 kg = 17.9 - 3.6 + 60
    /// (derived). COM height 0.50 m and body inertia 4.0 kg m^2 are estimates (seated-human
    /// COM with the chassis). Frictions and wheel inertia are 0: the nominal design model.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let params = WipParams::<f64>::miapure_60kg();
    /// // Robot (17.9 kg) plus payload (60 kg), ball included.
    /// approx::assert_relative_eq!(
    ///     params.ball_mass_kg + params.body_mass_kg,
    ///     77.9,
    ///     epsilon = 1e-12
    /// );
    /// // MODEL.md section 6: open-loop poles 0, 0, +-8.04 rad/s.
    /// approx::assert_relative_eq!(
    ///     Wip::new(params)?.upright_unstable_pole_rad_per_s(),
    ///     8.04,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            ball_radius_m: lit(0.1145),
            ball_mass_kg: lit(3.6),
            ball_inertia_kg_m2: lit(0.047),
            body_mass_kg: lit(74.3),
            com_height_m: lit(0.50),
            body_inertia_kg_m2: lit(4.0),
            wheel_inertia_kg_m2: T::zero(),
            ball_damping_nm_s_per_rad: T::zero(),
            drive_damping_nm_s_per_rad: T::zero(),
            gravity_m_per_s2: lit(9.81),
        }
    }

    /// MiaPURE without payload: the 14.3 kg drivetrain chassis alone.
    ///
    /// COM height 0.20 m and body inertia 0.40 kg m^2 are estimates (a 14.3 kg,
    /// 0.45 x 0.36 x 0.36 m box whose centre sits 0.2 m above the ball centre).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let params = WipParams::<f64>::miapure_unloaded();
    /// // The 14.3 kg chassis on the same 3.6 kg ball.
    /// assert_eq!(params.body_mass_kg, 14.3);
    /// assert_eq!(
    ///     params.ball_radius_m,
    ///     WipParams::<f64>::miapure_60kg().ball_radius_m
    /// );
    /// // Lower COM, lighter body: the upright falls more slowly than with payload (6.89 rad/s).
    /// approx::assert_relative_eq!(
    ///     Wip::new(params)?.upright_unstable_pole_rad_per_s(),
    ///     6.89,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            body_mass_kg: lit(14.3),
            com_height_m: lit(0.20),
            body_inertia_kg_m2: lit(0.40),
            ..Self::miapure_60kg()
        }
    }

    /// The planar inverted-pendulum testbed (PIPTB).
    ///
    /// The paper gives only "half the size, one fifth of the weight of MiaPURE with payload";
    /// every number here is an estimate: wheel 0.0573 m, 0.9 kg, inertia 0.5 m r^2; body
    /// 14.7 kg, COM 0.25 m, 0.25 kg m^2.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let piptb = WipParams::<f64>::piptb();
    /// let mia = WipParams::<f64>::miapure_60kg();
    /// // "One fifth of the weight of MiaPURE with payload" and half its ball size.
    /// let mass_ratio =
    ///     (piptb.ball_mass_kg + piptb.body_mass_kg) / (mia.ball_mass_kg + mia.body_mass_kg);
    /// approx::assert_relative_eq!(mass_ratio, 0.2, epsilon = 0.001);
    /// approx::assert_relative_eq!(
    ///     piptb.ball_radius_m / mia.ball_radius_m,
    ///     0.5,
    ///     epsilon = 0.001
    /// );
    /// // The smaller pendulum falls faster: 10.50 rad/s.
    /// approx::assert_relative_eq!(
    ///     Wip::new(piptb)?.upright_unstable_pole_rad_per_s(),
    ///     10.50,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn piptb() -> Self {
        let wheel_radius_m: T = lit(0.0573);
        let wheel_mass_kg: T = lit(0.9);
        Self {
            ball_radius_m: wheel_radius_m,
            ball_mass_kg: wheel_mass_kg,
            ball_inertia_kg_m2: lit::<T>(0.5) * wheel_mass_kg * wheel_radius_m * wheel_radius_m,
            body_mass_kg: lit(14.7),
            com_height_m: lit(0.25),
            body_inertia_kg_m2: lit(0.25),
            wheel_inertia_kg_m2: T::zero(),
            ball_damping_nm_s_per_rad: T::zero(),
            drive_damping_nm_s_per_rad: T::zero(),
            gravity_m_per_s2: lit(9.81),
        }
    }

    /// The body's lean per unit ball acceleration in steady acceleration,
    /// `K = (b + m_U r l) / (m_U g l)` with `b = I_S + (m_S + m_U) r^2` (rad per rad/s^2, i.e.
    /// s^2): the equilibrium lean that drives the ball at `phi_ddot` is `K phi_ddot`, or
    /// `K / r` per m/s^2. The command shaper's lean feedforward and the balance-point
    /// estimator use it.
    ///
    /// ```
    /// use ballbot_core::WipParams;
    /// let p = WipParams::<f64>::miapure_60kg();
    /// // 7.3 deg per m/s^2 on MiaPURE with 60 kg.
    /// let deg_per_m_per_s2 = (p.lean_per_ball_accel_s2() / p.ball_radius_m).to_degrees();
    /// assert!((deg_per_m_per_s2 - 7.3).abs() < 0.1, "{deg_per_m_per_s2}");
    /// ```
    pub fn lean_per_ball_accel_s2(&self) -> T {
        let (r, l, m) = (self.ball_radius_m, self.com_height_m, self.body_mass_kg);
        let b = self.ball_inertia_kg_m2 + (self.ball_mass_kg + m) * r * r;
        (b + m * r * l) / (m * self.gravity_m_per_s2 * l)
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{Error, WipParams};
    /// assert_eq!(WipParams::<f64>::piptb().validate(), Ok(()));
    /// // Friction may be zero but not negative; the error names the field.
    /// let params = WipParams {
    ///     ball_damping_nm_s_per_rad: -0.1,
    ///     ..WipParams::<f64>::piptb()
    /// };
    /// assert_eq!(
    ///     params.validate(),
    ///     Err(Error::invalid(
    ///         "ball_damping_nm_s_per_rad",
    ///         "must be finite and >= 0"
    ///     ))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.ball_radius_m, "ball_radius_m")?;
        positive(self.ball_mass_kg, "ball_mass_kg")?;
        positive(self.ball_inertia_kg_m2, "ball_inertia_kg_m2")?;
        positive(self.body_mass_kg, "body_mass_kg")?;
        positive(self.com_height_m, "com_height_m")?;
        positive(self.body_inertia_kg_m2, "body_inertia_kg_m2")?;
        non_negative(self.wheel_inertia_kg_m2, "wheel_inertia_kg_m2")?;
        non_negative(self.ball_damping_nm_s_per_rad, "ball_damping_nm_s_per_rad")?;
        non_negative(
            self.drive_damping_nm_s_per_rad,
            "drive_damping_nm_s_per_rad",
        )?;
        positive(self.gravity_m_per_s2, "gravity_m_per_s2")?;
        Ok(())
    }
}
