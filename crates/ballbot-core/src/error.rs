//! The core's error type: small, `Copy`, allocation-free.

use core::fmt;

/// What went wrong when building a model, a controller or a solver from its inputs.
///
/// Errors are for malformed input, checked once at construction. The outcome of a numerical
/// solve (converged or not) is a status in its result, not an `Error`.
///
/// ```
/// use ballbot_core::{Error, WipParams};
/// let mut params = WipParams::<f64>::miapure_60kg();
/// params.body_mass_kg = -1.0;
/// let err = Error::InvalidParameter {
///     field: "body_mass_kg",
///     requirement: "must be finite and > 0",
/// };
/// assert_eq!(params.validate(), Err(err));
/// assert_eq!(
///     err.to_string(),
///     "invalid parameter `body_mass_kg`: must be finite and > 0"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is outside its allowed range.
    InvalidParameter {
        /// The field's name, as spelled in its struct (e.g. `"body_mass_kg"`).
        field: &'static str,
        /// The bound it violates, in words (e.g. `"must be finite and > 0"`).
        requirement: &'static str,
    },
    /// An LQR design found no stabilising gain: the Riccati solve ended with this status.
    NoStabilizingGain {
        /// How the Riccati solve ended.
        status: crate::lqr::RiccatiStatus,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidParameter`].
    ///
    /// ```
    /// use ballbot_core::Error;
    /// const TOO_FAST: Error = Error::invalid("speed_m_per_s", "must be <= 3");
    /// assert!(matches!(
    ///     TOO_FAST,
    ///     Error::InvalidParameter {
    ///         field: "speed_m_per_s",
    ///         ..
    ///     }
    /// ));
    /// ```
    pub const fn invalid(field: &'static str, requirement: &'static str) -> Self {
        Self::InvalidParameter { field, requirement }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter { field, requirement } => {
                write!(f, "invalid parameter `{field}`: {requirement}")
            }
            Self::NoStabilizingGain { status } => {
                write!(
                    f,
                    "LQR design found no stabilising gain: {}",
                    status.description()
                )
            }
        }
    }
}

impl core::error::Error for Error {}
