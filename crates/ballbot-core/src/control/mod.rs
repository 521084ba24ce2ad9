//! Planar controllers for one wheeled-inverted-pendulum plane (a ballbot plane or the PIPTB):
//! the paper's LQR, the CMU-style cascaded PI-PD, and the cascaded LQR-PI (outer part plus the
//! inner speed PI that runs on the motor driver).
//!
//! Every controller has the same shape:
//!
//! - gains (and limits) in their own struct, validated once by `validate()`, the error naming
//!   the offending field;
//! - state kept in the controller, cleared by `reset()`;
//! - `step(&mut self, measured, command, dt_secs) -> Output`, where the output carries the
//!   applied value and every term that made it (feedforward, P, I, D, saturation) for logging,
//!   and a [`StepStatus`].
//!
//! Sign convention (MODEL.md section 2): `tau` is the torque the body applies to the ball;
//! positive `theta` leans towards +travel. In the paper's form `tau = k (s_c - s)` a balancing
//! gain has *negative* tilt and tilt-rate entries: for MiaPURE with 60 kg,
//! `k = [-234.8, 0, -45.70, -3.162]` on `[theta, phi, theta_dot, phi_dot]`.
//!
//! Robustness contract (tested by proptest): for any input, including NaN and infinities,
//! `step` never panics, and the torque it returns is finite and within the configured limit.
//! A non-finite measurement, command or step length gives zero torque, leaves the state
//! untouched and reports [`StepStatus::InvalidInput`]; what to do then (a controlled stop, or
//! disabling the motors) is the safety supervisor's decision, not the controller's.
//!
//! | controller | rate | gains from the model | default |
//! |---|---|---|---|
//! | [`LqrController`] | 400 Hz | [`LqrGains::design`] (CARE), [`LqrGains::design_discrete`] (DARE) | [`LqrGains::for_wip`]: MODEL.md weights |
//! | [`PiPdController`] | 400 Hz | [`PiPdGains::design`] (pole placement) | [`PiPdGains::for_wip`]: poles [`PI_PD_DEFAULT_POLES_PER_P0`] |
//! | [`LqrPiOuter`] | 400 Hz | its [`LqrGains`] | [`LqrPiOuterConfig::new`]: anchor band from the inner PI |
//! | [`SpeedPi`] | 8 kHz | [`SpeedPiGains::for_wip_ball_rate`], [`SpeedPiGains::from_bandwidth`] | 30 rad/s in the tests |
//!
//! The cascaded LQR-PI on one plane, outer loop at 400 Hz and inner loop at 8 kHz:
//!
//! ```
//! use ballbot_core::control::{
//!     LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains,
//! };
//! use ballbot_core::{Wip, WipParams, rk4_step};
//! use nalgebra::Vector4;
//! let wip = Wip::new(WipParams::<f64>::piptb())?;
//! let max_torque_nm = 43.2;
//! let inner_gains = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, max_torque_nm)?;
//! let config = LqrPiOuterConfig::new(LqrGains::for_wip(&wip, max_torque_nm)?, &inner_gains)?;
//! let mut outer = LqrPiOuter::new(wip, config)?;
//! let mut inner = SpeedPi::new(inner_gains)?;
//! let mut s = Vector4::new(0.1, 0.0, 0.0, 0.0); // 5.7 deg forward
//! let command = Vector4::zeros(); // stand still, upright
//! let mut reference = SpeedCommand { speed_rad_per_s: 0.0, feedforward_torque_nm: 0.0 };
//! for k in 0..3 * 8000 {
//!     if k % 20 == 0 {
//!         let o = outer.step(&s, &command, 1.0 / 400.0);
//!         reference = SpeedCommand {
//!             speed_rad_per_s: o.reference_ball_rate_rad_per_s,
//!             feedforward_torque_nm: o.reference_torque_nm,
//!         };
//!     }
//!     let tau = inner.step(s[3], &reference, 1.0 / 8000.0).torque_nm;
//!     s = rk4_step(|x| wip.derivative(x, tau), &s, 1.0 / 8000.0);
//! }
//! assert!(s[0].abs() < 1e-3 && s[3].abs() < 0.1);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

mod feedforward;
mod lqr;
mod lqr_pi;
mod motor_pi;
mod pi_pd;
mod plane;
mod terms;

pub use feedforward::accelerating_command;
pub use lqr::{LqrController, LqrGains, LqrOutput};
pub use lqr_pi::{LqrPiOuter, LqrPiOuterConfig, LqrPiOuterOutput};
pub use motor_pi::{SpeedCommand, SpeedPi, SpeedPiGains, SpeedPiOutput};
pub use pi_pd::{
    PI_PD_DEFAULT_MAX_TILT_RAD, PI_PD_DEFAULT_POLES_PER_P0, PiPdController, PiPdGains, PiPdOutput,
};
pub use plane::{PlaneController, PlaneOutput};
pub use terms::Terms;
pub(crate) use terms::impl_terms;

use crate::ParseNameError;
use crate::check::{lit, positive};
use crate::names::parse_name;
use crate::{Error, WipState};
use core::fmt;
use core::str::FromStr;
use nalgebra::RealField;

/// What happened in one controller step (for logging and for the safety supervisor).
///
/// ```
/// use ballbot_core::control::{LqrController, LqrGains, StepStatus};
/// use nalgebra::Vector4;
/// let mut lqr = LqrController::new(LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9))?;
/// let mut status = |tilt_rad: f64| {
///     lqr.step(&Vector4::new(tilt_rad, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025).status
/// };
/// assert_eq!(status(0.1), StepStatus::Nominal); // 23.5 N m
/// assert_eq!(status(0.5), StepStatus::Saturated); // 117 N m asked, 83.9 N m given
/// assert_eq!(status(f64::INFINITY), StepStatus::InvalidInput);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "schema",
    derive(schemars::JsonSchema),
    schemars(rename_all = "snake_case")
)]
#[non_exhaustive]
pub enum StepStatus {
    /// The output was computed from valid inputs and is within its limits unchanged.
    Nominal,
    /// The output was computed from valid inputs but clipped to its limit; the output's
    /// `saturation_nm` term says by how much.
    Saturated,
    /// A measurement, command or the step length was non-finite (or the step length not
    /// positive), or the arithmetic overflowed: the output is zero torque and the controller
    /// state was left unchanged.
    InvalidInput,
}

impl StepStatus {
    /// Every status, in declaration order (for bindings and logs that list them).
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// let names = StepStatus::ALL.map(|s| s.as_str());
    /// assert_eq!(names, ["nominal", "saturated", "invalid_input"]);
    /// ```
    pub const ALL: [Self; 3] = [Self::Nominal, Self::Saturated, Self::InvalidInput];

    /// The status's canonical name (snake_case), the one string form used by `Display`,
    /// `FromStr` and serde.
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// assert_eq!(StepStatus::InvalidInput.as_str(), "invalid_input");
    /// assert_eq!(StepStatus::Saturated.to_string(), "saturated");
    /// assert_eq!("nominal".parse(), Ok(StepStatus::Nominal));
    /// ```
    pub const fn as_str(&self) -> &'static str {
        match self {
            Self::Nominal => "nominal",
            Self::Saturated => "saturated",
            Self::InvalidInput => "invalid_input",
        }
    }

    /// The status's numeric code, the one code mapping for logs and batch outputs that store
    /// statuses as numbers: 0 nominal, 1 saturated, 2 invalid input (the index in
    /// [`StepStatus::ALL`]).
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// assert_eq!(StepStatus::Nominal.code(), 0);
    /// assert_eq!(StepStatus::Saturated.code(), 1);
    /// assert_eq!(StepStatus::InvalidInput.code(), 2);
    /// ```
    pub const fn code(self) -> u8 {
        match self {
            Self::Nominal => 0,
            Self::Saturated => 1,
            Self::InvalidInput => 2,
        }
    }

    /// The status whose [`StepStatus::code`] is `code`, `None` for a code no status has.
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// for status in StepStatus::ALL {
    ///     assert_eq!(StepStatus::from_code(status.code()), Some(status));
    /// }
    /// assert_eq!(StepStatus::from_code(3), None);
    /// ```
    pub const fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Nominal),
            1 => Some(Self::Saturated),
            2 => Some(Self::InvalidInput),
            _ => None,
        }
    }

    /// `true` unless the step was rejected ([`StepStatus::InvalidInput`]).
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// assert!(StepStatus::Saturated.is_valid());
    /// assert!(!StepStatus::InvalidInput.is_valid());
    /// ```
    pub fn is_valid(self) -> bool {
        self != Self::InvalidInput
    }
}

impl fmt::Display for StepStatus {
    /// Writes [`StepStatus::as_str`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for StepStatus {
    type Err = ParseNameError;

    /// The status named `s` ([`StepStatus::as_str`]).
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        parse_name(s, &Self::ALL, Self::as_str, "step status")
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for StepStatus {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for StepStatus {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        crate::names::serde_name::deserialize(deserializer, "step status")
    }
}

/// `true` when every entry of the state is finite.
#[inline]
pub(crate) fn state_is_finite<T: RealField + Copy>(s: &WipState<T>) -> bool {
    s.iter().all(|v| v.is_finite())
}

/// `true` when `dt_secs` is a usable step length: finite and strictly positive.
#[inline]
///
/// Two float comparisons (`0 < dt < inf`; a NaN fails both) instead of the bit-level
/// `is_finite` and a comparison: this runs in every controller step.
pub(crate) fn dt_is_valid<T: RealField + Copy>(dt_secs: T) -> bool {
    dt_secs > T::zero() && dt_secs < lit(f64::INFINITY)
}

/// Clamps a finite `value` to `[-limit, limit]` (`limit > 0`): `(clamped, status)`.
#[inline]
pub(crate) fn saturate<T: RealField + Copy>(value: T, limit: T) -> (T, StepStatus) {
    if value > limit {
        (limit, StepStatus::Saturated)
    } else if value < -limit {
        (-limit, StepStatus::Saturated)
    } else {
        (value, StepStatus::Nominal)
    }
}

/// Checks a torque limit: finite and strictly positive.
#[inline]
pub(crate) fn check_limit<T: RealField + Copy>(value: T, field: &'static str) -> Result<(), Error> {
    positive(value, field)
}

/// Checks a gain that may take either sign but must be finite.
#[inline]
pub(crate) fn check_gain<T: RealField + Copy>(value: T, field: &'static str) -> Result<(), Error> {
    crate::check::finite(value, field)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn saturate_clips_both_sides_and_reports_it() {
        assert_eq!(saturate(5.0, 3.0), (3.0, StepStatus::Saturated));
        assert_eq!(saturate(-5.0, 3.0), (-3.0, StepStatus::Saturated));
        assert_eq!(saturate(2.0, 3.0), (2.0, StepStatus::Nominal));
    }

    #[test]
    fn dt_validity() {
        assert!(dt_is_valid(0.0025));
        assert!(!dt_is_valid(0.0));
        assert!(!dt_is_valid(-1.0));
        assert!(!dt_is_valid(f64::NAN));
        assert!(!dt_is_valid(f64::INFINITY));
    }
}
