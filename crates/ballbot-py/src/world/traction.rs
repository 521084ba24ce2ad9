//! Traction-aware control's report and envelope (`ballbot_core::traction`) as result classes:
//! `WorldLoop.traction` and `WorldLoop.traction_envelope()`, through
//! [`crate::results::build`].

use crate::results::Array;
use ballbot_core::traction::{ENVELOPE_DIRECTIONS, TractionControl, TractionStatus};
use pyo3::prelude::*;
use schemars::JsonSchema;
use serde::Serialize;

/// Traction-aware control's report of one outer step (`WorldLoop.traction`).
// The core's report with the slip monitor's fields beside the envelope's.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "TractionStatus")]
pub(crate) struct TractionStatusView {
    /// The acceleration limit along the direction the command wanted to accelerate in
    /// (m/s^2): envelope, actuators, slip reaction and braking floor; `None` when the command
    /// did not ask to accelerate.
    accel_limit_m_per_s2: Option<f64>,
    /// Whether the envelope held the command back in this step.
    limited: bool,
    /// Outer steps with a limited command so far.
    limited_steps: u32,
    /// Each omniwheel's estimated slip speed at the rim (m/s).
    #[schemars(extend("x-python-dtype" = "f8", "x-python-shape" = [3]))]
    slip_speed_m_per_s: Array,
    /// Which omniwheels slip (estimated slip speed above the threshold).
    #[schemars(extend("x-python-type" = "tuple[bool, bool, bool]"))]
    slipping: [bool; 3],
    /// The contact model's normal forces for the measured state and the reference torque
    /// (N).
    #[schemars(extend("x-python-dtype" = "f8", "x-python-shape" = [3]))]
    predicted_normal_force_n: Array,
    /// Whether a predicted normal force is below the envelope's minimum.
    lift_off_imminent: bool,
    /// The factor on the envelope after a slip or an imminent lift-off (1 when quiet).
    accel_scale: f64,
    /// The wheel-ball friction the envelope uses now.
    friction_estimate: f64,
    /// Slip events so far.
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
    crate::results::build(py, &view)
}

/// The controller's traction envelope (`WorldLoop.traction_envelope()`): the largest
/// acceleration that keeps every omniwheel inside its margin, per direction.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "TractionEnvelope")]
pub(crate) struct TractionEnvelopeView {
    /// Table headings (rad, body frame, 0 towards OW1, in (-pi, pi]).
    #[schemars(extend("x-python-dtype" = "f8", "x-python-shape" = [ENVELOPE_DIRECTIONS]))]
    heading_rad: Array,
    /// Largest acceleration towards each heading (m/s^2).
    #[schemars(extend("x-python-dtype" = "f8", "x-python-shape" = [ENVELOPE_DIRECTIONS]))]
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
    crate::results::build(py, &view)
}
