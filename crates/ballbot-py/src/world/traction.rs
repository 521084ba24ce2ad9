//! Traction-aware control's report and envelope (`ballbot_core::traction`) as result classes:
//! `WorldLoop.traction` and `WorldLoop.traction_envelope()`.

use super::telemetry::vec_out;
use ballbot_core::traction::{ENVELOPE_DIRECTIONS, TractionControl, TractionStatus};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// `TractionStatus` of `ballbot._results` from the core's report of one outer step.
pub(crate) fn status<'py>(
    py: Python<'py>,
    status: &TractionStatus<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let d = PyDict::new(py);
    let slip = &status.slip;
    d.set_item("accel_limit_m_per_s2", status.accel_limit_m_per_s2)?;
    d.set_item("limited", status.limited)?;
    d.set_item("limited_steps", status.limited_steps)?;
    d.set_item("slip_speed_m_per_s", vec_out(py, &slip.slip_speed_m_per_s))?;
    d.set_item("slipping", PyTuple::new(py, slip.slipping)?)?;
    d.set_item(
        "predicted_normal_force_n",
        vec_out(py, &slip.predicted_normal_force_n),
    )?;
    d.set_item("lift_off_imminent", slip.lift_off_imminent)?;
    d.set_item("accel_scale", slip.accel_scale)?;
    d.set_item("friction_estimate", slip.friction_estimate)?;
    d.set_item("slip_events", slip.slip_events)?;
    crate::results::make(py, "TractionStatus", d)
}

/// `TractionEnvelope` of `ballbot._results`: the controller's table over direction.
pub(crate) fn envelope<'py>(
    py: Python<'py>,
    control: &TractionControl<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let e = control.envelope();
    let headings: Vec<f64> = (0..ENVELOPE_DIRECTIONS)
        .map(|k| e.table_heading_rad(k))
        .collect();
    let d = PyDict::new(py);
    d.set_item("heading_rad", PyArray1::from_vec(py, headings))?;
    d.set_item(
        "accel_m_per_s2",
        PyArray1::from_slice(py, e.table_m_per_s2()),
    )?;
    crate::results::make(py, "TractionEnvelope", d)
}
