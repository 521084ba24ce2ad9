//! The planar controllers (`ballbot_core::control`) with `step`, their gains, and a batch
//! closed-loop rollout on the nonlinear WIP that runs entirely in Rust without the GIL.

mod controllers;
mod gains;
mod outputs;
mod rollout;

use pyo3::prelude::*;

pub(crate) use controllers::*;
pub(crate) use gains::*;
pub(crate) use outputs::*;
pub(crate) use rollout::*;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(py_accelerating_command, m)?)?;
    m.add_class::<PyLqrGains>()?;
    m.add_class::<PyPiPdGains>()?;
    m.add_class::<PySpeedPiGains>()?;
    m.add_class::<PyLqrPiOuterConfig>()?;
    m.add_class::<PyLqrOutput>()?;
    m.add_class::<PyPiPdOutput>()?;
    m.add_class::<PyLqrPiOuterOutput>()?;
    m.add_class::<PySpeedPiOutput>()?;
    m.add_class::<PyLqrController>()?;
    m.add_class::<PyPiPdController>()?;
    m.add_class::<PyLqrPiOuter>()?;
    m.add_class::<PySpeedPi>()?;
    m.add_function(wrap_pyfunction!(closed_loop_rollout, m)?)?;
    Ok(())
}
