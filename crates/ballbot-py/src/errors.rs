//! Raising the exceptions of `ballbot._errors` from Rust.

use ballbot_sim::world::WorldError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

/// The Python exception classes, by name in `ballbot._errors`.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// `ballbot.ParameterError` (a `ValueError`).
    Parameter,
    /// `ballbot.ShapeError` (a `ValueError`).
    Shape,
    /// `ballbot.FileError` (an `OSError`).
    File,
    /// `ballbot.SolverError`: a numerical solve failed (no stabilising gain, solver failure).
    Solver,
    /// `ballbot.BallbotError`.
    Other,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Parameter => "ParameterError",
            Kind::Shape => "ShapeError",
            Kind::File => "FileError",
            Kind::Solver => "SolverError",
            Kind::Other => "BallbotError",
        }
    }
}

static ERRORS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// Builds a `PyErr` of the given kind with `message`.
pub fn error(py: Python<'_>, kind: Kind, message: impl Into<String>) -> PyErr {
    let message = message.into();
    let class = ERRORS_MODULE
        .get_or_try_init(py, || py.import("ballbot._errors").map(|m| m.unbind()))
        .and_then(|module| module.bind(py).getattr(kind.class_name()))
        .and_then(|class| class.cast_into::<PyType>().map_err(PyErr::from));
    match class {
        Ok(class) => PyErr::from_type(class, message),
        Err(e) => e,
    }
}

/// Maps a core error: an invalid parameter to `ballbot.ParameterError`, a failed LQR design
/// to `ballbot.SolverError`.
pub fn core_error(py: Python<'_>, e: ballbot_core::Error) -> PyErr {
    let kind = match e {
        ballbot_core::Error::NoStabilizingGain { .. } => Kind::Solver,
        _ => Kind::Parameter,
    };
    error(py, kind, e.to_string())
}

/// Maps a world error: a robot or world parameter out of range to `ballbot.ParameterError`
/// (the message names the field), a failed controller design to `ballbot.SolverError`.
pub fn world_error(py: Python<'_>, e: WorldError) -> PyErr {
    match e {
        WorldError::Robot(e) => core_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}
