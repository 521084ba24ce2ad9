//! How a Riccati solve ended: [`RiccatiStatus`], with its canonical name. It imports nothing
//! from the solver or the error type, so [`crate::Error`] can name it without an import cycle.

use crate::ParseNameError;
use crate::names::parse_name;
use core::fmt;
use core::str::FromStr;

/// The numerical outcome of a Riccati solve.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, RiccatiStatus, solve_care};
/// use nalgebra::{Matrix1, Matrix2, Vector2};
/// let (q, r, settings) = (
///     Matrix2::identity(),
///     Matrix1::new(1.0),
///     RiccatiSettings::default(),
/// );
/// // A double integrator is stabilisable ...
/// let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
/// assert_eq!(
///     solve_care(&a, &Vector2::new(0.0, 1.0), &q, &r, &settings)?.status,
///     RiccatiStatus::Converged
/// );
/// // ... a second, unstable mode that the input cannot reach is not: a status, not an Err.
/// let a = Matrix2::new(0.0, 0.0, 0.0, 1.0);
/// let sol = solve_care(&a, &Vector2::new(1.0, 0.0), &q, &r, &settings)?;
/// assert_eq!(sol.status, RiccatiStatus::NotStabilizable);
/// assert_eq!(sol.status.to_string(), "not_stabilizable");
/// assert_eq!(
///     sol.status.description(),
///     "no stabilising solution (unstabilisable or undetectable)"
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "schema",
    derive(schemars::JsonSchema),
    schemars(rename_all = "snake_case")
)]
pub enum RiccatiStatus {
    /// Converged to the tolerance, and the closed loop `A - B K` is certified asymptotically
    /// stable.
    Converged,
    /// Stopped at the iteration limit before the tolerance; the closed loop of the last
    /// iterate is stable, but the solution is not accurate to the tolerance.
    MaxIterations,
    /// No stabilising solution: an unstable (or, for the DARE, unit-circle; for the CARE,
    /// imaginary-axis) mode is not stabilisable through `B`, or is not weighted by `Q`
    /// (not detectable). The doubling diverged or the closed loop is not stable.
    NotStabilizable,
    /// A non-finite number appeared (overflow in the setup or the gain).
    NonFinite,
}

impl RiccatiStatus {
    /// `true` for [`RiccatiStatus::Converged`].
    ///
    /// ```
    /// use ballbot_core::lqr::RiccatiStatus;
    /// assert!(RiccatiStatus::Converged.is_converged());
    /// assert!(!RiccatiStatus::MaxIterations.is_converged());
    /// ```
    pub fn is_converged(self) -> bool {
        self == Self::Converged
    }
}

impl RiccatiStatus {
    /// Every status, in declaration order (for bindings and logs that list them).
    ///
    /// ```
    /// use ballbot_core::lqr::RiccatiStatus;
    /// let names = RiccatiStatus::ALL.map(|s| s.as_str());
    /// assert_eq!(
    ///     names,
    ///     ["converged", "max_iterations", "not_stabilizable", "non_finite"]
    /// );
    /// ```
    pub const ALL: [Self; 4] = [
        Self::Converged,
        Self::MaxIterations,
        Self::NotStabilizable,
        Self::NonFinite,
    ];

    /// The status's canonical name (snake_case), the one string form used by `Display`,
    /// `FromStr` and serde.
    ///
    /// ```
    /// use ballbot_core::lqr::RiccatiStatus;
    /// assert_eq!(RiccatiStatus::MaxIterations.as_str(), "max_iterations");
    /// assert_eq!(RiccatiStatus::NonFinite.to_string(), "non_finite");
    /// assert_eq!("converged".parse(), Ok(RiccatiStatus::Converged));
    /// ```
    pub const fn as_str(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "max_iterations",
            Self::NotStabilizable => "not_stabilizable",
            Self::NonFinite => "non_finite",
        }
    }

    /// What the status means, in words (for messages to people; `Display` is the name).
    ///
    /// ```
    /// use ballbot_core::lqr::RiccatiStatus;
    /// assert_eq!(
    ///     RiccatiStatus::MaxIterations.description(),
    ///     "iteration limit reached"
    /// );
    /// ```
    pub const fn description(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "iteration limit reached",
            Self::NotStabilizable => "no stabilising solution (unstabilisable or undetectable)",
            Self::NonFinite => "non-finite numbers",
        }
    }
}

impl fmt::Display for RiccatiStatus {
    /// Writes [`RiccatiStatus::as_str`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for RiccatiStatus {
    type Err = ParseNameError;

    /// The status named `s` ([`RiccatiStatus::as_str`]).
    fn from_str(s: &str) -> Result<Self, ParseNameError> {
        parse_name(s, &Self::ALL, Self::as_str, "Riccati status")
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for RiccatiStatus {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for RiccatiStatus {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        crate::names::serde_name::deserialize(deserializer, "Riccati status")
    }
}
