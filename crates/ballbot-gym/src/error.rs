//! [`GymError`]: what the environments reject.

use ballbot_world::world::WorldError;

/// An environment's configuration was rejected, or it was used out of order.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GymError {
    /// A configuration field is out of range.
    #[error("invalid parameter `{field}`: {requirement}, got {value}")]
    InvalidParameter {
        /// The field's name (dotted for nested fields, e.g. `randomization.com_height_m`).
        field: String,
        /// The bound it violates.
        requirement: &'static str,
        /// The rejected value, as text.
        value: String,
    },
    /// The world rejected the parameters of an episode.
    #[error("world: {0}")]
    World(#[from] WorldError),
    /// `step` before the first `reset`, or after the episode ended.
    #[error("step called {0}: call reset first")]
    NeedsReset(&'static str),
    /// An action component is NaN or infinite.
    #[error("invalid action: every component must be finite, got {0:?}")]
    NonFiniteAction([f64; 3]),
}

impl GymError {
    pub(crate) fn invalid(field: &str, requirement: &'static str, value: impl ToString) -> Self {
        Self::InvalidParameter {
            field: field.to_owned(),
            requirement,
            value: value.to_string(),
        }
    }
}
