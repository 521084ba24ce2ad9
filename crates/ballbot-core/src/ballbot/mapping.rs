//! [`WheelMapping`]: how the outer loop maps the reference rates to the omniwheels' yaw-like
//! component (the third relative rate).

use crate::ParseNameError;
use crate::names::parse_name;
use core::fmt;
use core::str::FromStr;

/// How [`BallbotController`](super::BallbotController) forms the third relative rate, the one
/// the omniwheels see about the body's z axis, from the reference rates
/// `[phi_dot_rx, phi_dot_ry, theta_dot_rz]`:
///
/// - [`RollingBall`](Self::RollingBall) (default): `k . [phi_dot_rx, phi_dot_ry] -
///   theta_dot_rz`, `k` from
///   [`ball_body_z_rate_per_ball_rate`](crate::estimation::ball_body_z_rate_per_ball_rate) at
///   the measured tilt: the rolling ball's rate about the leaning body's z axis when the ball
///   does not spin about the vertical. Without it the wheels turn a sideways lean at speed into
///   a yaw rate (`-tan(roll) phi_dot_y`).
/// - [`Upright`](Self::Upright): `-theta_dot_rz`, the mapping of MODEL.md section 4 (the
///   paper's robot), exact only when the body is upright. **An ablation**, kept to reproduce
///   the paper's controller in the world, not a recommendation: in the world it loses yaw
///   control at speed (see `docs/world-reproduce.md`, "Yaw at speed").
///
/// The same choice applies to the reference speeds and to the reference accelerations sent to
/// the motor drivers. One canonical name per value (`as_str`, `Display`, `FromStr`, serde).
///
/// ```
/// use ballbot_core::ballbot::WheelMapping;
/// assert_eq!(WheelMapping::default(), WheelMapping::RollingBall);
/// assert_eq!(WheelMapping::Upright.to_string(), "upright");
/// assert_eq!("rolling_ball".parse(), Ok(WheelMapping::RollingBall));
/// assert!("Upright".parse::<WheelMapping>().is_err()); // names are snake_case
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub enum WheelMapping {
    /// The lean-corrected mapping `k . [phi_dot_rx, phi_dot_ry] - theta_dot_rz` (default).
    #[default]
    RollingBall,
    /// The upright mapping `-theta_dot_rz` of MODEL.md section 4 (the paper's; an ablation).
    Upright,
}

impl WheelMapping {
    /// Every mapping, in declaration order (for bindings and logs that list them).
    ///
    /// ```
    /// use ballbot_core::ballbot::WheelMapping;
    /// assert_eq!(WheelMapping::ALL.map(|m| m.as_str()), ["rolling_ball", "upright"]);
    /// ```
    pub const ALL: [Self; 2] = [Self::RollingBall, Self::Upright];

    /// The mapping's canonical name (snake_case), the one string form used by `Display`,
    /// `FromStr` and serde.
    ///
    /// ```
    /// use ballbot_core::ballbot::WheelMapping;
    /// assert_eq!(WheelMapping::RollingBall.as_str(), "rolling_ball");
    /// ```
    pub const fn as_str(&self) -> &'static str {
        match self {
            Self::RollingBall => "rolling_ball",
            Self::Upright => "upright",
        }
    }
}

impl fmt::Display for WheelMapping {
    /// Writes [`WheelMapping::as_str`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for WheelMapping {
    type Err = ParseNameError;

    /// The mapping named `s` ([`WheelMapping::as_str`]).
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        parse_name(s, &Self::ALL, Self::as_str, "wheel mapping")
    }
}
