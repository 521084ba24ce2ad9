//! The 3D world (`ballbot_sim::world`): `World` (the rapier3d ballbot driven by wheel torques),
//! `WorldLoop` (the core's 3D controller in the loop), their per-step records, and the
//! maximum-speed ramp. `run` and the experiments execute entirely in Rust without the GIL and
//! return dicts of numpy arrays, so Python threads run several worlds in parallel.

mod class;
mod export;
mod live;
mod ramp;
mod telemetry;
mod trace;
mod traction;
mod world_loop;

use crate::errors::{Kind, error};
use crate::params::PyWorldParams;
use ballbot_sim::world::{StopRules, WorldParams};
use numpy::{AllowTypeChange, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyString;

pub(crate) use class::*;
pub(crate) use export::*;
pub(crate) use live::*;
pub(crate) use ramp::*;
pub(crate) use telemetry::*;
pub(crate) use trace::{WorldLoopRunView, WorldRunView};
pub(crate) use traction::{TractionEnvelopeView, TractionStatusView};
pub(crate) use world_loop::*;

pub(crate) type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// A finite 3-vector from a sequence of three numbers or a numpy array of shape (3,).
pub(crate) fn vec3(py: Python<'_>, value: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    let v: [f64; 3] = value.extract().map_err(|_| {
        error(
            py,
            Kind::Shape,
            format!("`{name}` must be 3 numbers (a sequence or an array of shape (3,))"),
        )
    })?;
    finite(py, &v, name)?;
    Ok(v)
}

pub(crate) fn finite(py: Python<'_>, values: &[f64], name: &str) -> PyResult<()> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(error(
            py,
            Kind::Parameter,
            format!("`{name}` must be finite, got {values:?}"),
        ))
    }
}

/// Per-step rows for a run of `n_steps`: an array of shape (3,) (held for every step) or
/// (n_steps, 3), all finite. `None` gives zeros.
pub(crate) fn step_rows(
    py: Python<'_>,
    array: Option<Arr<'_>>,
    n_steps: usize,
    name: &str,
) -> PyResult<Vec<[f64; 3]>> {
    let Some(array) = array else {
        return Ok(vec![[0.0; 3]]);
    };
    let shape = array.shape().to_vec();
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    let rows: Vec<[f64; 3]> = match shape.as_slice() {
        [3] => vec![[values[0], values[1], values[2]]],
        [n, 3] if *n == n_steps => values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        _ => {
            return Err(error(
                py,
                Kind::Shape,
                format!(
                    "`{name}` must have shape (3,) or (n_steps, 3) = ({n_steps}, 3), got {shape:?}"
                ),
            ));
        }
    };
    if let Some((k, row)) = rows
        .iter()
        .enumerate()
        .find(|(_, r)| !r.iter().all(|x| x.is_finite()))
    {
        return Err(error(
            py,
            Kind::Parameter,
            format!("`{name}` must be finite; row {k} is {row:?}"),
        ));
    }
    Ok(rows)
}

/// The row used at step `k`: the only row, or row `k`.
pub(crate) fn row_at(rows: &[[f64; 3]], k: usize) -> [f64; 3] {
    if rows.len() == 1 { rows[0] } else { rows[k] }
}

pub(crate) fn non_negative(py: Python<'_>, value: f64, name: &str) -> PyResult<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(error(
            py,
            Kind::Parameter,
            format!("invalid parameter `{name}`: must be finite and >= 0, got {value}"),
        ))
    }
}

pub(crate) fn params_or_default(params: Option<PyWorldParams>) -> WorldParams {
    params.map_or_else(WorldParams::miapure_60kg, |p| p.inner)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWheelTelemetry>()?;
    m.add_class::<PyStepTelemetry>()?;
    m.add_class::<PyMeasurement>()?;
    m.add_class::<PyFailure>()?;
    m.add_class::<PyWorld>()?;
    m.add_class::<PyWorldLoop>()?;
    m.add_class::<PyLiveView>()?;
    m.add_function(wrap_pyfunction!(max_speed_ramp, m)?)?;
    m.add_function(wrap_pyfunction!(py_export, m)?)?;
    Ok(())
}

/// `stop_on=`: the stop rules as `ballbot world --stop-on` takes them (`"all"`, `"none"`, or
/// names among `tilt`, `slip`, `lift-off`, `driver-trip` separated by commas), or a list of the
/// names (an empty list: none).
pub(crate) fn stop_rules(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<StopRules> {
    let invalid = |detail: String| {
        error(
            py,
            Kind::Parameter,
            format!("invalid parameter `stop_on`: {detail}"),
        )
    };
    let text = if value.is_instance_of::<PyString>() {
        value.extract::<String>()?
    } else {
        let names: Vec<String> = value.extract().map_err(|_| {
            invalid(format!(
                "a string or a list of rule names, got {}",
                value
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })?;
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(",")
        }
    };
    text.parse().map_err(invalid)
}
