//! What can go wrong setting up a braking problem.

/// What went wrong building a braking problem from its inputs. The outcome of a solve
/// (solved, infeasible, ...) is a [`super::SolveStatus`], not an error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TrajoptError {
    /// A field of the problem, its limits or the options is out of range.
    #[error("invalid braking problem: `{field}` {requirement}")]
    InvalidInput {
        /// The field's name.
        field: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// The plant parameters were rejected by the core model.
    #[error("invalid plant: {0}")]
    Model(#[from] ballbot_core::Error),
    /// clarabel refused the quadratic program (a bug: the transcription is malformed).
    #[error("QP setup failed: {0}")]
    QpSetup(String),
}

pub(crate) fn invalid(field: &'static str, requirement: &'static str) -> TrajoptError {
    TrajoptError::InvalidInput { field, requirement }
}
