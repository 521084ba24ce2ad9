//! The error type of plotting.

use std::path::PathBuf;

/// What went wrong while drawing or writing a figure. Every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The file name does not end in `.svg` or `.png`.
    #[error("cannot tell the image format of {path}: use a .svg or .png file name")]
    UnsupportedFormat {
        /// The requested output file.
        path: PathBuf,
    },
    /// The figure has nothing to draw or is malformed (e.g. series of unequal lengths).
    #[error("invalid figure for {path}: {reason}")]
    InvalidFigure {
        /// The requested output file.
        path: PathBuf,
        /// What is wrong with the figure.
        reason: String,
    },
    /// The plotting backend failed (drawing, encoding, or writing the file).
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The requested output file.
        path: PathBuf,
        /// The backend's error message.
        message: String,
    },
}
