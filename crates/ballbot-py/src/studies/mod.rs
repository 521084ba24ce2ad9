//! The paper's experiments in the 3D world, each in Rust without the GIL: the maximum-speed
//! study, braking, push recovery; and the reliability campaign (`robustness`). Results are built as `ballbot._results` classes.

mod braking;
mod max_speed;
mod push;
mod robustness;

use pyo3::prelude::*;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(braking::py_braking_run, m)?)?;
    m.add_function(wrap_pyfunction!(braking::py_braking_study, m)?)?;
    m.add_function(wrap_pyfunction!(push::py_push_trial, m)?)?;
    m.add_function(wrap_pyfunction!(push::py_push_recovery_limit, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_slow_ramp_trial, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_failing_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(max_speed::py_max_speed_study, m)?)?;
    m.add_function(wrap_pyfunction!(robustness::py_robustness_json, m)?)?;
    Ok(())
}
