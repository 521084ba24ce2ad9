//! The reliability campaign (`ballbot_sim::report::robustness`, `ballbot robustness`): run
//! without the GIL, returned as the JSON that `robustness.json` holds; `ballbot.studies`
//! builds the typed result classes from it.

use crate::errors::{Kind, error};
use ballbot_sim::report::reproduce::Quiet;
use ballbot_sim::report::{ReportError, RobustnessOptions, robustness};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Runs the campaign into `out` (the fault matrix's MCAP logs, `robustness.json`; no
/// figures) on `threads` threads (0: every core) without the GIL, and returns the JSON text.
#[pyfunction(name = "robustness_json")]
#[pyo3(signature = (out, *, quick = false, seed = 1, threads = 0))]
pub(crate) fn py_robustness_json(
    py: Python<'_>,
    out: PathBuf,
    quick: bool,
    seed: u64,
    threads: usize,
) -> PyResult<String> {
    let options = RobustnessOptions {
        out,
        quick,
        plots: false,
        threads,
        seed,
    };
    let value = py
        .detach(|| robustness(&options, &Quiet))
        .map_err(|e| report_error(py, e))?;
    serde_json::to_string(&value).map_err(|e| error(py, Kind::Other, e.to_string()))
}

fn report_error(py: Python<'_>, e: ReportError) -> PyErr {
    let kind = match &e {
        ReportError::Io { .. } => Kind::File,
        ReportError::World(_) => Kind::Parameter,
        _ => Kind::Other,
    };
    error(py, kind, e.to_string())
}
