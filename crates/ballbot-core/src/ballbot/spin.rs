//! The spin (yaw) outer loop: a reference-model LQR-PI on the spin model, [`SpinOuter`].

use crate::check::{lit, positive};
use crate::control::StepStatus;
use crate::control::impl_terms;
use crate::num::{clamp_sym, max, min};
use crate::spin::SpinState;
use crate::{Error, Spin};
use nalgebra::RealField;

/// Gains of the spin LQR `tau_rz = k_heading (theta_zc - theta_z) + k_rate (theta_dot_zc -
/// theta_dot_z)`, saturated.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::BallbotControllerConfig;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let g = config.spin.gains;
/// // Turning left (positive yaw) needs positive torque: both gains are positive.
/// assert!(g.heading_nm_per_rad > 0.0 && g.rate_nm_s_per_rad > 0.0);
/// // The limit is the drivetrain's yaw torque capacity, 167.9 N m for MiaPURE.
/// approx::assert_relative_eq!(g.max_torque_nm, 167.9, epsilon = 0.05);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct SpinGains<T> {
    /// On the heading error (N m/rad).
    pub heading_nm_per_rad: T,
    /// On the yaw-rate error (N m s/rad).
    pub rate_nm_s_per_rad: T,
    /// Symmetric yaw-torque limit (N m, > 0).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_torque_nm: T,
}

/// Configuration of [`SpinOuter`].
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuterConfig};
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// config.validate()?;
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct SpinOuterConfig<T> {
    /// The LQR gains.
    pub gains: SpinGains<T>,
    /// Largest distance between the integrated reference yaw rate and the measured yaw rate
    /// (rad/s, > 0), as [`LqrPiOuterConfig::max_speed_error_rad_per_s`](crate::control::LqrPiOuterConfig::max_speed_error_rad_per_s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_rate_error_rad_per_s: T,
}

impl<T: RealField + Copy> SpinOuterConfig<T> {
    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::ballbot::{SpinGains, SpinOuterConfig};
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 0.0 };
    /// assert!(matches!(
    ///     config.validate(),
    ///     Err(Error::InvalidParameter { field: "max_rate_error_rad_per_s", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let g = &self.gains;
        crate::check::finite(g.heading_nm_per_rad, "heading_nm_per_rad")?;
        crate::check::finite(g.rate_nm_s_per_rad, "rate_nm_s_per_rad")?;
        positive(g.max_torque_nm, "max_torque_nm")?;
        positive(self.max_rate_error_rad_per_s, "max_rate_error_rad_per_s")
    }
}

/// One [`SpinOuter`] step.
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
/// use ballbot_core::control::StepStatus;
/// use ballbot_core::{Spin, SpinParams};
/// use nalgebra::Vector2;
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// let mut spin = SpinOuter::new(Spin::new(SpinParams::<f64>::miapure_60kg())?, config)?;
/// // 0.5 rad short of the commanded heading: 5 N m of yaw torque, the model accelerates.
/// let o = spin.step(&Vector2::zeros(), &Vector2::new(0.5, 0.0), 0.0025);
/// assert_eq!((o.reference_torque_nm, o.status), (5.0, StepStatus::Nominal));
/// assert!(o.reference_accel_rad_per_s2 > 0.0);
/// approx::assert_relative_eq!(
///     o.reference_rate_rad_per_s,
///     0.5 * 0.0025 * o.reference_accel_rad_per_s2,
///     epsilon = 1e-12
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinOuterOutput<T> {
    /// Reference yaw torque `tau_rz` after saturation (N m).
    pub reference_torque_nm: T,
    /// Reference yaw rate `theta_dot_rz` over the coming period (rad/s).
    pub reference_rate_rad_per_s: T,
    /// Reference yaw acceleration of the spin model (rad/s^2).
    pub reference_accel_rad_per_s2: T,
    /// Nominal, saturated or rejected.
    pub status: StepStatus,
}

impl_terms!(SpinOuterOutput {
    reference_torque_nm,
    reference_rate_rad_per_s,
    reference_accel_rad_per_s2,
});

/// The spin plane of the cascaded LQR-PI: LQR reference torque, reference spin model
/// `theta_ddot_rz = (tau_rz - D_z theta_dot_z) / I_z` at the measured state, integrated to the
/// reference yaw rate (anchored to the measured rate as [`LqrPiOuter`](crate::control::LqrPiOuter) does).
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
/// use ballbot_core::{Spin, SpinParams, rk4_step};
/// use nalgebra::Vector2;
/// // Turning the robot 90 deg with the spin outer loop alone (its reference torque applied).
/// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// let mut spin = SpinOuter::new(model, config)?;
/// let command = Vector2::new(core::f64::consts::FRAC_PI_2, 0.0);
/// let mut s = Vector2::zeros();
/// for _ in 0..10 * 400 {
///     let tau = spin.step(&s, &command, 0.0025).reference_torque_nm;
///     s = rk4_step(|x| model.derivative(x, tau), &s, 0.0025);
/// }
/// approx::assert_relative_eq!(s[0], core::f64::consts::FRAC_PI_2, epsilon = 1e-3);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinOuter<T> {
    model: Spin<T>,
    config: SpinOuterConfig<T>,
    reference_rate_rad_per_s: Option<T>,
}

impl<T: RealField + Copy> SpinOuter<T> {
    /// Validates `config`; `model` is the reference spin model.
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::{Spin, SpinParams};
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// assert!(SpinOuter::new(model, config).is_ok());
    /// let nan_gain = SpinGains { heading_nm_per_rad: f64::NAN, ..gains };
    /// let bad = SpinOuterConfig { gains: nan_gain, max_rate_error_rad_per_s: 2.0 };
    /// assert!(SpinOuter::new(model, bad).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(model: Spin<T>, config: SpinOuterConfig<T>) -> Result<Self, Error> {
        config.validate()?;
        Ok(Self {
            model,
            config,
            reference_rate_rad_per_s: None,
        })
    }

    /// Forgets the reference integral (re-anchored at the next step).
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// let mut spin = SpinOuter::new(model, config)?;
    /// spin.step(&Vector2::zeros(), &Vector2::new(1.0, 0.0), 0.0025);
    /// spin.reset();
    /// // Re-anchored at the measured 0.3 rad/s, on command: no torque; the reference starts
    /// // at the measurement.
    /// let s = Vector2::new(0.0, 0.3);
    /// let o = spin.step(&s, &s, 0.0025);
    /// let damping = model.params().damping_nm_s_per_rad;
    /// assert_eq!(o.reference_torque_nm, 0.0);
    /// let accel = o.reference_accel_rad_per_s2;
    /// approx::assert_relative_eq!(accel, -damping * 0.3 / model.params().inertia_kg_m2);
    /// approx::assert_relative_eq!(o.reference_rate_rad_per_s, 0.3 + 0.5 * 0.0025 * accel);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.reference_rate_rad_per_s = None;
    }

    /// One step: `measured` and `command` are `[theta_z, theta_dot_z]`. A non-finite input or
    /// a bad `dt_secs` gives zero torque, the held reference and
    /// [`StepStatus::InvalidInput`].
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::control::StepStatus;
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 20.0 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// let mut spin = SpinOuter::new(model, config)?;
    /// // Half a turn away: 31 N m asked, clipped to the 20 N m limit.
    /// let o = spin.step(&Vector2::zeros(), &Vector2::new(core::f64::consts::PI, 0.0), 0.0025);
    /// assert_eq!((o.reference_torque_nm, o.status), (20.0, StepStatus::Saturated));
    /// // A NaN heading: zero torque, flagged.
    /// let o = spin.step(&Vector2::new(f64::NAN, 0.0), &Vector2::zeros(), 0.0025);
    /// assert_eq!((o.reference_torque_nm, o.status), (0.0, StepStatus::InvalidInput));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        measured: &SpinState<T>,
        command: &SpinState<T>,
        dt_secs: T,
    ) -> SpinOuterOutput<T> {
        let g = &self.config.gains;
        let requested = g.heading_nm_per_rad * (command[0] - measured[0])
            + g.rate_nm_s_per_rad * (command[1] - measured[1]);
        let rate = measured[1];
        if !(requested.is_finite() && rate.is_finite() && dt_secs.is_finite())
            || dt_secs <= T::zero()
        {
            return SpinOuterOutput {
                reference_torque_nm: T::zero(),
                reference_rate_rad_per_s: self.reference_rate_rad_per_s.unwrap_or(T::zero()),
                reference_accel_rad_per_s2: T::zero(),
                status: StepStatus::InvalidInput,
            };
        }
        let torque = clamp_sym(requested, g.max_torque_nm);
        let status = if torque == requested {
            StepStatus::Nominal
        } else {
            StepStatus::Saturated
        };
        let accel = self.model.acceleration(measured, torque);
        let band = self.config.max_rate_error_rad_per_s;
        // Plain min/max: the stored rate, the measured rate and the band are finite.
        let stored = self.reference_rate_rad_per_s.unwrap_or(rate);
        let anchored = min(rate + band, max(rate - band, stored));
        self.reference_rate_rad_per_s = Some(anchored + accel * dt_secs);
        SpinOuterOutput {
            reference_torque_nm: torque,
            reference_rate_rad_per_s: anchored + accel * dt_secs * lit(0.5),
            reference_accel_rad_per_s2: accel,
            status,
        }
    }
}
