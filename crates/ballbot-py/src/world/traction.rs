//! Traction-aware control's report and envelope (`ballbot_core::traction`) as result classes:
//! `WorldLoop.traction` and `WorldLoop.traction_envelope()`, through
//! [`crate::results::build`].

use crate::results::Array;
use ballbot_core::traction::{ENVELOPE_DIRECTIONS, TractionControl, TractionStatus};
use pyo3::prelude::*;
use serde::Serialize;

/// The core's report of one outer step as `ballbot._results.TractionStatus` has it: the slip
/// monitor's fields beside the envelope's.
#[derive(Serialize)]
struct TractionStatusView {
    accel_limit_m_per_s2: Option<f64>,
    limited: bool,
    limited_steps: u32,
    slip_speed_m_per_s: Array,
    slipping: [bool; 3],
    predicted_normal_force_n: Array,
    lift_off_imminent: bool,
    accel_scale: f64,
    friction_estimate: f64,
    slip_events: u32,
}

/// `TractionStatus` of `ballbot._results` from the core's report of one outer step.
pub(crate) fn status<'py>(
    py: Python<'py>,
    status: &TractionStatus<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let slip = &status.slip;
    let view = TractionStatusView {
        accel_limit_m_per_s2: status.accel_limit_m_per_s2,
        limited: status.limited,
        limited_steps: status.limited_steps,
        slip_speed_m_per_s: Array::column(slip.slip_speed_m_per_s.iter().copied()),
        slipping: slip.slipping,
        predicted_normal_force_n: Array::column(slip.predicted_normal_force_n.iter().copied()),
        lift_off_imminent: slip.lift_off_imminent,
        accel_scale: slip.accel_scale,
        friction_estimate: slip.friction_estimate,
        slip_events: slip.slip_events,
    };
    crate::results::build(py, "TractionStatus", &view)
}

/// The envelope as `ballbot._results.TractionEnvelope` has it.
#[derive(Serialize)]
struct TractionEnvelopeView {
    heading_rad: Array,
    accel_m_per_s2: Array,
}

/// `TractionEnvelope` of `ballbot._results`: the controller's table over direction.
pub(crate) fn envelope<'py>(
    py: Python<'py>,
    control: &TractionControl<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let e = control.envelope();
    let view = TractionEnvelopeView {
        heading_rad: Array::column((0..ENVELOPE_DIRECTIONS).map(|k| e.table_heading_rad(k))),
        accel_m_per_s2: Array::column(e.table_m_per_s2().iter().copied()),
    };
    crate::results::build(py, "TractionEnvelope", &view)
}
