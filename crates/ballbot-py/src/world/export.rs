//! `ballbot.export`: the world's robot as MJCF or URDF (`ballbot_sim::export`).

use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use ballbot_sim::export::{ExportError, ExportFormat, export as export_robot};
use ballbot_sim::world::WorldParams;
use pyo3::prelude::*;

fn export_error(py: Python<'_>, e: ExportError) -> PyErr {
    match e {
        ExportError::World(e) => world_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// The robot of the world `params` (default: MiaPURE with 60 kg in the default world) as an
/// MJCF (`"mjcf"`, MuJoCo) or URDF (`"urdf"`) document, from the same parameters the 3D world
/// runs on: the ball, the body split into a chassis, three motor-driven omniwheels and their
/// rollers (together exactly the world body's mass, centre of mass and inertia), actuators with
/// the gear ratio and torque limits, friction. Written to `path` too when given.
///
/// Errors: `ParameterError` for an unknown format or parameters the world rejects,
/// `FileError` when `path` cannot be written.
#[pyfunction]
#[pyo3(name = "export", signature = (format, params = None, path = None))]
pub fn py_export(
    py: Python<'_>,
    format: &str,
    params: Option<PyRef<'_, PyWorldParams>>,
    path: Option<std::path::PathBuf>,
) -> PyResult<String> {
    let format: ExportFormat = format.parse().map_err(|e| export_error(py, e))?;
    let params = params.map_or_else(WorldParams::miapure_60kg, |p| p.inner);
    let text = export_robot(&params, format).map_err(|e| export_error(py, e))?;
    if let Some(path) = path {
        std::fs::write(&path, &text)
            .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
    }
    Ok(text)
}
