//! The status, mode and failure enums as Python `enum.Enum` members (`ballbot._enums`).
//!
//! Each Rust enum has ONE mapping to its canonical snake_case name here (or uses the crate's
//! own `as_str`), and the Python class has those names as values. Batch outputs keep statuses
//! as int8 codes for speed; the code of a step status is its index in
//! [`STEP_STATUS_NAMES`], exported as `ballbot._core.STEP_STATUS_NAMES` so that
//! `StepStatus.from_code` reads the mapping from here.
//!
//! `step_status_name`, `mode_name` and `riccati_status_name` stand in for the core's
//! `as_str` until it has one.

use ballbot_core::control::StepStatus;
use ballbot_core::lqr::RiccatiStatus;
use ballbot_core::safety::Mode;
use ballbot_sim::studies::push::PushOutcome;
use ballbot_sim::studies::world_braking::BrakingOutcome;
use ballbot_sim::world::FailureKind;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// Step-status names by int8 code: 0 nominal, 1 saturated, 2 invalid input.
pub const STEP_STATUS_NAMES: [&str; 3] = ["nominal", "saturated", "invalid_input"];

/// The int8 code of a step status in batch outputs (an index into [`STEP_STATUS_NAMES`]).
pub fn step_status_code(status: StepStatus) -> i8 {
    match status {
        StepStatus::Nominal => 0,
        StepStatus::Saturated => 1,
        _ => 2,
    }
}

/// The canonical name of a step status.
pub fn step_status_name(status: StepStatus) -> &'static str {
    STEP_STATUS_NAMES[step_status_code(status) as usize]
}

/// The canonical name of the safety supervisor's mode.
pub fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Idle => "idle",
        Mode::Balancing => "balancing",
        Mode::ControlledStop => "controlled_stop",
        Mode::Fault => "fault",
    }
}

/// The canonical name of a Riccati solve's status.
pub fn riccati_status_name(status: RiccatiStatus) -> &'static str {
    match status {
        RiccatiStatus::Converged => "converged",
        RiccatiStatus::MaxIterations => "max_iterations",
        RiccatiStatus::NotStabilizable => "not_stabilizable",
        RiccatiStatus::NonFinite => "non_finite",
    }
}

static ENUMS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// The member of the Python enum `class_name` (in `ballbot._enums`) whose value is `name`.
pub fn member<'py>(py: Python<'py>, class_name: &str, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let module =
        ENUMS_MODULE.get_or_try_init(py, || py.import("ballbot._enums").map(|m| m.unbind()))?;
    module.bind(py).getattr(class_name)?.call1((name,))
}

/// `ballbot.StepStatus`.
pub fn step_status(py: Python<'_>, status: StepStatus) -> PyResult<Bound<'_, PyAny>> {
    member(py, "StepStatus", step_status_name(status))
}

/// `ballbot.Mode`.
pub fn mode(py: Python<'_>, mode: Mode) -> PyResult<Bound<'_, PyAny>> {
    member(py, "Mode", mode_name(mode))
}

/// `ballbot.FailureKind`.
pub fn failure_kind<'py>(py: Python<'py>, kind: &FailureKind) -> PyResult<Bound<'py, PyAny>> {
    member(py, "FailureKind", kind.as_str())
}

/// `ballbot.RiccatiStatus`.
pub fn riccati_status(py: Python<'_>, status: RiccatiStatus) -> PyResult<Bound<'_, PyAny>> {
    member(py, "RiccatiStatus", riccati_status_name(status))
}

/// `ballbot.SolveStatus` of the trajectory optimiser.
pub fn solve_status(
    py: Python<'_>,
    status: ballbot_sim::trajopt::SolveStatus,
) -> PyResult<Bound<'_, PyAny>> {
    member(py, "SolveStatus", status.as_str())
}

/// `ballbot.BrakingOutcome`.
pub fn braking_outcome<'py>(
    py: Python<'py>,
    outcome: &BrakingOutcome,
) -> PyResult<Bound<'py, PyAny>> {
    member(py, "BrakingOutcome", outcome.label())
}

/// `ballbot.PushOutcome`.
pub fn push_outcome<'py>(py: Python<'py>, outcome: &PushOutcome) -> PyResult<Bound<'py, PyAny>> {
    member(py, "PushOutcome", outcome.label())
}

/// Adds the name tables the Python enums check themselves against.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("STEP_STATUS_NAMES", STEP_STATUS_NAMES)?;
    m.add("FAILURE_KIND_NAMES", FailureKind::NAMES)?;
    Ok(())
}
