//! Python bindings of ballbot: the private native module `ballbot._core`.
//!
//! The public, typed Python API lives in `python/ballbot/` (re-exports plus a hand-written
//! `.pyi` checked by `mypy.stubtest`). Conventions: keyword arguments with the Rust field
//! names (units in the names); numpy arrays in, with shape checks that raise
//! `ballbot.ShapeError` (also a `ValueError`) naming the expected shape; owned arrays out;
//! long calls release the GIL.

mod arrays;
mod control;
mod enums;
mod errors;
mod gym;
mod kinematics;
mod log;
mod lqr;
mod mirror;
mod models;
mod params;
mod pickle;
mod render;
mod results;
mod sim;
mod studies;
mod trajopt;
mod world;

use ballbot_core::rates;
use pyo3::prelude::*;

/// The native module. Everything here is re-exported by the `ballbot` package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("OUTER_LOOP_RATE_HZ", rates::OUTER_LOOP_RATE_HZ)?;
    m.add("OUTER_LOOP_DT_SECS", rates::OUTER_LOOP_DT_SECS)?;
    m.add("INNER_LOOP_RATE_HZ", rates::INNER_LOOP_RATE_HZ)?;
    m.add("INNER_LOOP_DT_SECS", rates::INNER_LOOP_DT_SECS)?;
    enums::register(m)?;
    params::register(m)?;
    models::register(m)?;
    kinematics::register(m)?;
    lqr::register(m)?;
    control::register(m)?;
    log::register(m)?;
    trajopt::register(m)?;
    sim::register(m)?;
    world::register(m)?;
    gym::register(m)?;
    render::register(m)?;
    studies::register(m)?;
    mirror::register(m)?;
    Ok(())
}
