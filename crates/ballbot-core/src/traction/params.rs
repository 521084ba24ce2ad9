//! [`TractionParams`]: the settings of traction-aware control, with their sources.

use crate::check::{lit, positive};
use crate::{BallbotParams, Error};
use nalgebra::RealField;

/// Settings of traction-aware control ([`super`]): the envelope's margins, the slip detector's
/// threshold and the reactions.
///
/// The defaults ([`Self::recommended`]) are engineering choices fixed before any comparison
/// with the world or the paper; each field says why.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::traction::TractionParams;
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let p = TractionParams::recommended(&robot);
/// assert!(p.enabled && p.validate().is_ok());
/// // Plan with half the wheel-ball friction.
/// assert_eq!(p.friction_safety_factor, 2.0);
/// // A quarter of the static load per wheel, m_U g / (3 cos 45 deg) = 344 N, must stay.
/// approx::assert_relative_eq!(p.min_normal_force_n, 85.9, epsilon = 0.1);
/// let bad = TractionParams { friction_safety_factor: 0.9, ..p };
/// assert!(bad.validate().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct TractionParams<T> {
    /// Whether traction-aware control runs: the envelope shapes the commands and the slip
    /// monitor reacts. Off, the controller is exactly the one without it.
    pub enabled: bool,
    /// The envelope plans with `mu / friction_safety_factor` (>= 1). Default 2: half the
    /// friction. The quasi-static contact model leaves out the rollers' axle losses and the
    /// dynamics of a real ramp; the mechanism study measured the 3D world's failing
    /// acceleration towards OW1 at 0.60 to 0.62 of the model's quasi-static limit (1.35 to
    /// 1.4 against 2.25 m/s^2, docs/mechanisms.md), and `mu` itself is an estimate
    /// (MODEL.md). Half covers that gap with about 20 % to spare.
    #[cfg_attr(feature = "schema", schemars(range(min = 1)))]
    pub friction_safety_factor: T,
    /// The smallest normal force the envelope lets any wheel keep (N, > 0). Default a quarter
    /// of the static load `m_U g / (3 cos(alpha))`: margin for the dynamic load swings of the
    /// compliant contact.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub min_normal_force_n: T,
    /// Braking is never limited below this deceleration (m/s^2, > 0), whatever the envelope,
    /// the slip reaction or the friction estimate say: the envelope shapes a stop, it never
    /// blocks it. Default 0.5 (2 m/s to rest within 4 s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub min_braking_decel_m_per_s2: T,
    /// A wheel counts as slipping when its estimated slip speed exceeds this (m/s, > 0).
    /// Default 0.05: the 3D world's own definition of slip. (On gentle ramps in the default 3D
    /// world the estimate peaks at 0.040 / 0.033 / 0.030 m/s towards 0 / 90 / 180 deg: roller
    /// ripple, sensor noise, and the drivetrain's wind-up and backlash between the motor's
    /// encoder and the wheel; ballbot-sim test `gentle_ramps_raise_no_alarm`.)
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub slip_speed_threshold_m_per_s: T,
    /// Gain of the momentum observers (1/s, > 0): the residual forgets a model error within
    /// about `1 / gain`. Default 10.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub observer_gain_per_s: T,
    /// While a wheel slips or a lift-off is imminent the envelope is scaled by this
    /// (0 < scale <= 1). Default 0.5, as a traction control halves the drive on wheel spin.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0), range(max = 1)))]
    pub slip_accel_scale: T,
    /// After the slip ends the scale returns to 1 linearly over this time (s, > 0). Default 1.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub recovery_secs: T,
    /// Slip lasting longer than this raises [`Fault::WheelSlip`](crate::safety::Fault::WheelSlip), which starts the
    /// supervisor's controlled stop (s, > 0). Default 0.3: three times the world's definition
    /// of a sustained slip, time for the halved envelope to end it.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub slip_fault_secs: T,
    /// The observers coast on a slip for at most this long (s, > `slip_fault_secs`): then
    /// they take the measured momentum again and the flags fall, whatever the residual holds.
    /// This bounds how long any flag, and the correction of the ball-rate estimate it brings,
    /// can outlast consistent data. Default 0.5: longer than `slip_fault_secs`, so that a
    /// slip that goes on raises the fault first, and short enough that a false flag (an
    /// external force the detector took for a slip) leaves the estimate within half a
    /// second.
    pub max_coast_secs: T,
    /// Whether a detected slip lowers the friction estimate the envelope uses.
    pub estimate_friction: bool,
    /// The friction estimate never falls below this (> 0). Default 0.1.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub min_friction: T,
    /// Without slip, the friction estimate climbs back to the parameter's `mu` at the rate
    /// `mu / friction_recovery_secs` (s, > 0). Default 5.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub friction_recovery_secs: T,
}

impl<T: RealField + Copy> TractionParams<T> {
    /// The recommended settings for `robot`, enabled (see each field for its source).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::TractionParams;
    /// let p = TractionParams::recommended(&BallbotParams::<f64>::miapure_60kg());
    /// assert_eq!((p.slip_speed_threshold_m_per_s, p.slip_fault_secs), (0.05, 0.3));
    /// ```
    pub fn recommended(robot: &BallbotParams<T>) -> Self {
        let p = &robot.sagittal;
        let cos_alpha = robot.drivetrain.contact_angle_rad.cos();
        let static_load_n = p.body_mass_kg * p.gravity_m_per_s2 / (lit::<T>(3.0) * cos_alpha);
        Self {
            enabled: true,
            friction_safety_factor: lit(2.0),
            min_normal_force_n: static_load_n * lit(0.25),
            min_braking_decel_m_per_s2: lit(0.5),
            slip_speed_threshold_m_per_s: lit(0.05),
            observer_gain_per_s: lit(10.0),
            slip_accel_scale: lit(0.5),
            recovery_secs: T::one(),
            slip_fault_secs: lit(0.3),
            max_coast_secs: lit(0.5),
            estimate_friction: true,
            min_friction: lit(0.1),
            friction_recovery_secs: lit(5.0),
        }
    }

    /// [`Self::recommended`], switched off: what [`BallbotControllerConfig::paper`](crate::ballbot::BallbotControllerConfig::paper) uses.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::TractionParams;
    /// assert!(!TractionParams::off(&BallbotParams::<f64>::miapure_60kg()).enabled);
    /// ```
    pub fn off(robot: &BallbotParams<T>) -> Self {
        Self {
            enabled: false,
            ..Self::recommended(robot)
        }
    }

    /// Checks every field (also when disabled: a configuration is valid or not).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, Error};
    /// use ballbot_core::traction::TractionParams;
    /// let p = TractionParams::recommended(&BallbotParams::<f64>::miapure_60kg());
    /// let bad = TractionParams { slip_accel_scale: 1.5, ..p };
    /// assert!(matches!(
    ///     bad.validate(),
    ///     Err(Error::InvalidParameter { field: "slip_accel_scale", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.friction_safety_factor.is_finite() && self.friction_safety_factor >= T::one()) {
            return Err(Error::invalid(
                "friction_safety_factor",
                "must be finite and >= 1",
            ));
        }
        positive(self.min_normal_force_n, "min_normal_force_n")?;
        positive(
            self.min_braking_decel_m_per_s2,
            "min_braking_decel_m_per_s2",
        )?;
        positive(
            self.slip_speed_threshold_m_per_s,
            "slip_speed_threshold_m_per_s",
        )?;
        positive(self.observer_gain_per_s, "observer_gain_per_s")?;
        positive(self.slip_accel_scale, "slip_accel_scale")?;
        if self.slip_accel_scale > T::one() {
            return Err(Error::invalid("slip_accel_scale", "must be in (0, 1]"));
        }
        positive(self.recovery_secs, "recovery_secs")?;
        positive(self.slip_fault_secs, "slip_fault_secs")?;
        if !(self.max_coast_secs.is_finite() && self.max_coast_secs > self.slip_fault_secs) {
            return Err(Error::invalid(
                "max_coast_secs",
                "must be finite and > slip_fault_secs",
            ));
        }
        positive(self.min_friction, "min_friction")?;
        positive(self.friction_recovery_secs, "friction_recovery_secs")
    }
}
