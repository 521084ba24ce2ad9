//! The paper's experiments in the 3D world, each in Rust without the GIL: the maximum-speed
//! study, braking, push recovery; and the reliability campaign (`robustness`). Results are built as `ballbot._results` classes
//! through [`crate::results::build`].

mod braking;
mod max_speed;
mod push;
mod robustness;
pub(crate) mod settings;

pub(crate) use braking::{BrakingRunView, BrakingStudyView};
pub(crate) use max_speed::{
    FailingAccelerationView, MaxSpeedStudyView, SlowRampTrialView, TrialOutcomeView,
};
pub(crate) use push::{PushRecoveryView, PushTrialView};

use ballbot_sim::world::StopRules;
use pyo3::prelude::*;
use pyo3::types::PyString;

/// The world's stop rules from `stop_on` (`"all"`, `"none"` or names separated by commas,
/// as `ballbot world --stop-on` takes them), by the gym's parser ([`crate::world::stop_rules`]);
/// an unknown name is a `ParameterError` naming `stop_on`.
fn stop_rules(py: Python<'_>, stop_on: &str) -> PyResult<StopRules> {
    crate::world::stop_rules(py, PyString::new(py, stop_on).as_any())
}

/// The canonical form of `stop_on` (`"all"` -> `"tilt,slip,lift-off,driver-trip"`, names in
/// their order, `"none"`), or a `ParameterError` naming the unknown rule: how the settings
/// classes check their `stop_on` without a second list of the rules.
#[pyfunction(name = "canonical_stop_rules")]
fn py_canonical_stop_rules(py: Python<'_>, stop_on: &str) -> PyResult<String> {
    Ok(stop_rules(py, stop_on)?.to_string())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(braking::py_braking_run, m)?)?;
    m.add_function(wrap_pyfunction!(braking::py_braking_study, m)?)?;
    m.add_function(wrap_pyfunction!(push::py_push_trial, m)?)?;
    m.add_function(wrap_pyfunction!(push::py_push_recovery_limit, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_slow_ramp_trial, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_failing_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_max_speed_study, m)?)?;
    m.add_function(wrap_pyfunction!(robustness::py_robustness_json, m)?)?;
    m.add_function(wrap_pyfunction!(py_canonical_stop_rules, m)?)?;
    Ok(())
}
