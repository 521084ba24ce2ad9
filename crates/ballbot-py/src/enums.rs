//! The status, mode and failure enums as Python `enum.Enum` members (`ballbot._enums`).
//!
//! The names are the Rust crates' own (`as_str`, `label`), and the Python classes have them
//! as values. Batch outputs keep step statuses as int8 codes for speed: the code is the core's
//! [`StepStatus::code`], and the names by code are exported as `ballbot._core.STEP_STATUS_NAMES`
//! so that `StepStatus.from_code` reads the core's mapping.

use ballbot_core::control::StepStatus;
use ballbot_core::lqr::RiccatiStatus;
use ballbot_core::safety::Mode;
use ballbot_sim::world::FailureKind;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// Step-status names by code ([`StepStatus::from_code`]): 0 nominal, 1 saturated, 2 invalid
/// input.
pub fn step_status_names() -> Vec<&'static str> {
    (0..=u8::MAX)
        .map_while(StepStatus::from_code)
        .map(|s| s.as_str())
        .collect()
}

/// The int8 code of a step status in batch outputs: the core's [`StepStatus::code`] (at most
/// 2, so the conversion is exact).
pub fn step_status_code(status: StepStatus) -> i8 {
    status.code() as i8
}

static ENUMS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// The member of the Python enum `class_name` (in `ballbot._enums`) whose value is `name`.
pub fn member<'py>(py: Python<'py>, class_name: &str, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let module =
        ENUMS_MODULE.get_or_try_init(py, || py.import("ballbot._enums").map(|m| m.unbind()))?;
    module.bind(py).getattr(class_name)?.call1((name,))
}

/// One function per status enum, `name(py, value)`: the member of `ballbot._enums.<Class>`
/// whose value is `value.as_str()`, the Rust enum's canonical name (written once, in Rust; the
/// Python classes check themselves against it).
macro_rules! python_enums {
    ($($(#[$doc:meta])* $name:ident($ty:ty) => $class:literal;)*) => {$(
        $(#[$doc])*
        pub fn $name<'py>(py: Python<'py>, value: $ty) -> PyResult<Bound<'py, PyAny>> {
            member(py, $class, value.as_str())
        }
    )*};
}

python_enums! {
    /// `ballbot.StepStatus`.
    step_status(StepStatus) => "StepStatus";
    /// `ballbot.Mode`.
    mode(Mode) => "Mode";
    /// `ballbot.FailureKind`.
    failure_kind(&FailureKind) => "FailureKind";
    /// `ballbot.RiccatiStatus`.
    riccati_status(RiccatiStatus) => "RiccatiStatus";
    /// `ballbot.SolveStatus` of the trajectory optimiser.
    solve_status(ballbot_sim::trajopt::SolveStatus) => "SolveStatus";
}

/// Adds the name tables the Python enums check themselves against.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("STEP_STATUS_NAMES", step_status_names())?;
    m.add("FAILURE_KIND_NAMES", FailureKind::NAMES)?;
    Ok(())
}
