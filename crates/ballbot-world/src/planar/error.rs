//! Errors of the planar simulator.

/// What is wrong with a planar simulator's inputs. Checked once, at construction.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanarError {
    /// A setting is out of range; `key` is spelled as in a scenario file (`friction.…`,
    /// `sensors.…`, `sim.…`).
    #[error("invalid `{key}`: {requirement}")]
    Invalid {
        /// The offending key, e.g. `"sim.outer_rate_hz"`.
        key: String,
        /// The rule it breaks, in words.
        requirement: String,
    },
    /// The robot's physical parameters are invalid (the core names the field).
    #[error("invalid robot parameter: {0}")]
    Model(#[from] ballbot_core::Error),
}

impl PlanarError {
    /// Shorthand for [`PlanarError::Invalid`].
    pub fn invalid(key: impl Into<String>, requirement: impl Into<String>) -> Self {
        Self::Invalid {
            key: key.into(),
            requirement: requirement.into(),
        }
    }
}
