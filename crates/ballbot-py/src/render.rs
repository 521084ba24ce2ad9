//! `ballbot.SceneRenderer`: frames of the 3D world's robot (`ballbot_render::SceneRenderer`),
//! the Gymnasium environments' `rgb_array` and `human` pictures.

use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use crate::world::PyStepTelemetry;
use ballbot_render::{DEFAULT_HEIGHT, DEFAULT_WIDTH, RenderError, SceneRenderer};
use ballbot_sim::export::ExportError;
use ballbot_sim::world::WorldParams;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

// The Python signature's defaults (written out there) are the renderer's.
const _: () = assert!(DEFAULT_WIDTH == 480 && DEFAULT_HEIGHT == 360);

fn render_error(py: Python<'_>, e: RenderError) -> PyErr {
    match e {
        RenderError::Model(ExportError::World(e)) => world_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// Draws a world's robot: a 3/4 perspective view that follows the ball over a floor grid
/// fixed to the world (so motion shows), the ball, the body, the three omniwheels with their
/// rollers where the world's parameters put them, and per wheel an arrow of the force it
/// applies to the ball coloured by friction-cone use (green 0, yellow 0.5, red 1). A wheel
/// without normal force is painted red with a ring and a "lift-off" label; a sliding one is
/// labelled "slip". Headless (tiny-skia, an embedded font).
///
/// `params` (default: MiaPURE with 60 kg) is the world whose robot is drawn; `width` and
/// `height` are the frame's size in pixels (16 to 4096).
///
/// Errors: `ParameterError` for a size out of range or parameters the world rejects.
#[pyclass(name = "SceneRenderer", module = "ballbot")]
pub struct PySceneRenderer {
    inner: SceneRenderer,
}

#[pymethods]
impl PySceneRenderer {
    #[new]
    // The defaults are ballbot_render::{DEFAULT_WIDTH, DEFAULT_HEIGHT}, written out so that
    // the signature Python sees shows them.
    #[pyo3(signature = (params = None, width = 480, height = 360))]
    fn py_new(
        py: Python<'_>,
        params: Option<PyRef<'_, PyWorldParams>>,
        width: u32,
        height: u32,
    ) -> PyResult<Self> {
        let params = params.map_or_else(WorldParams::miapure_60kg, |p| p.inner);
        let inner = SceneRenderer::new(&params, width, height).map_err(|e| render_error(py, e))?;
        Ok(Self { inner })
    }

    /// Frame width (px).
    #[getter]
    fn width(&self) -> u32 {
        self.inner.width()
    }

    /// Frame height (px).
    #[getter]
    fn height(&self) -> u32 {
        self.inner.height()
    }

    /// The frame of the state `telemetry`: a `(height, width, 3)` uint8 array (RGB).
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        telemetry: PyRef<'_, PyStepTelemetry>,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let t = telemetry.inner;
        let frame = py.detach(|| self.inner.render(&t));
        let (w, h) = (frame.width as usize, frame.height as usize);
        PyArray1::from_vec(py, frame.rgb).reshape([h, w, 3])
    }

    /// The frame of the state `telemetry` as the bytes of a PNG file.
    fn png<'py>(
        &mut self,
        py: Python<'py>,
        telemetry: PyRef<'_, PyStepTelemetry>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let t = telemetry.inner;
        self.inner.draw(&t);
        let bytes = self.inner.png().map_err(|e| render_error(py, e))?;
        Ok(PyBytes::new(py, &bytes))
    }
}

/// Registers `SceneRenderer`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySceneRenderer>()
}
