//! What can go wrong producing a report.

use crate::studies::piptb::ExperimentError;
use crate::studies::replay::ReplayError;
use crate::studies::world_braking::BrakingError;
use ballbot_trajopt::TrajoptError;
use ballbot_world::world::WorldError;
use std::path::PathBuf;

/// What can go wrong running the studies of a report and writing its files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// A file or folder could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The PIPTB experiment failed.
    #[error(transparent)]
    Experiment(#[from] ExperimentError),
    /// A trajectory optimisation was malformed.
    #[error(transparent)]
    Trajopt(#[from] TrajoptError),
    /// A 3D-world study (maximum speed, mechanisms, traction) rejected its parameters or its
    /// world failed to build.
    #[error("3D world study: {0}")]
    World(#[from] WorldError),
    /// A world braking or push study rejected its parameters.
    #[error(transparent)]
    Braking(#[from] BrakingError),
    /// A logged replay failed or differs from the study's run.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// A figure could not be drawn or written.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] crate::report::plot::PlotError),
    /// The summary could not be serialised.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A cell of the fault-injection matrix failed to run or to log.
    #[error("fault-injection matrix: {0}")]
    FaultCell(#[from] crate::studies::robustness::CellError),
}
