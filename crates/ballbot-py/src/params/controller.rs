//! `ControllerConfig`: the 3D controller's configuration
//! (`ballbot_core::ballbot::BallbotControllerConfig<f64>`) as data, the same file as
//! `ballbot params show --kind controller` writes and `ballbot world --controller FILE` reads.
//!
//! Every value goes through `ballbot_sim::params_file` (`ParamsFile::check` for a file,
//! `ParamsFile::validate` for a built value), so the errors are the command line's and name the
//! dotted key (`` `traction.friction_safety_factor` must be finite and >= 1 ``).

use super::*;
use ballbot_core::ballbot::{BallbotControllerConfig, WheelMapping};
use ballbot_sim::params_file::{FileKind, ParamsFile, ParamsFileError, commented_toml, preset};
use pyo3::types::{IntoPyDict, PyFloat, PyInt, PyString, PyTuple};

type Config = BallbotControllerConfig<f64>;

/// The controller presets, as `ballbot params show --kind controller --preset NAME` names them.
const PRESETS: [&str; 2] = ["design", "paper"];

/// A parameter-file error as the Python exception: a file that is not TOML at all is a
/// `FileError` when it came from a file, every other error (a key that does not fit, a value
/// out of range) a `ParameterError`; `origin` (a path) prefixes the message.
fn file_error(py: Python<'_>, e: &ParamsFileError, origin: Option<&std::path::Path>) -> PyErr {
    let kind = match (e, origin) {
        (ParamsFileError::Toml { .. }, Some(_)) => Kind::File,
        _ => Kind::Parameter,
    };
    match origin {
        Some(path) => error(py, kind, format!("{}: {e}", path.display())),
        None => error(py, kind, e.to_string()),
    }
}

impl CoreParams for Config {
    const NAME: &'static str = "ControllerConfig";
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        ParamsFile::Controller(Box::new(*self))
            .validate()
            .map_err(|e| file_error(py, &e, None))
    }
}

/// A plain Python value (dict, list or tuple, str, bool, int, float) as a TOML value, for the
/// fields whose shape the overlay cannot take from the current value (`balancing`, an enum
/// with data: `"lqr_pi"` or `{"pi_pd": {...}}`).
fn py_to_value(py: Python<'_>, value: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(Value::Integer(value.extract().map_err(|_| {
            error(
                py,
                Kind::Parameter,
                format!("`{path}`: integer out of range"),
            )
        })?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(Value::String(value.extract()?));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = Table::new();
        for (k, v) in dict.iter() {
            let k: String = k.extract().map_err(|_| {
                error(
                    py,
                    Kind::Parameter,
                    format!("`{path}`: keys must be strings"),
                )
            })?;
            let inner = py_to_value(py, &v, &format!("{path}.{k}"))?;
            table.insert(k, inner);
        }
        return Ok(Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, v) in value.try_iter()?.enumerate() {
            items.push(py_to_value(py, &v?, &format!("{path}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    Err(error(
        py,
        Kind::Parameter,
        format!("`{path}` must be a str, a number, a bool, a list or a dict"),
    ))
}

/// `base` with `fields` overlaid (dotted keys allowed: `traction.friction_safety_factor`),
/// then checked as a controller file is (`ParamsFile::validate`, errors naming the key).
fn with_controller_fields(
    py: Python<'_>,
    base: &Config,
    fields: Option<&Bound<'_, PyDict>>,
) -> PyResult<Config> {
    let Some(fields) = fields else {
        base.check(py)?;
        return Ok(*base);
    };
    let mut table = to_table(py, base)?;
    let mut rest = Vec::new();
    for (key, value) in fields.iter() {
        // The balancing law is an enum with data: replaced whole, serde checks its shape.
        if key.extract::<String>().is_ok_and(|k| k == "balancing") {
            table.insert(
                "balancing".to_owned(),
                py_to_value(py, &value, "balancing")?,
            );
        } else {
            rest.push((key, value));
        }
    }
    let rest = rest.into_py_dict(py)?;
    overlay(py, &mut table, &rest, Config::NAME, "")?;
    // Read back as a file is, so that a value of the wrong shape is named by its key.
    let text = toml::to_string(&table)
        .map_err(|e| error(py, Kind::Other, format!("{}: {e}", Config::NAME)))?;
    match ParamsFile::check(&text, FileKind::Controller) {
        Ok(ParamsFile::Controller(config)) => Ok(*config),
        Ok(other) => Err(error(
            py,
            Kind::Other,
            format!("expected a controller, read a {} file", other.kind()),
        )),
        // The line and column are of the text written here, not the caller's: left out.
        Err(ParamsFileError::Key { key, message, .. }) => {
            Err(error(py, Kind::Parameter, format!("`{key}`: {message}")))
        }
        Err(e) => Err(file_error(py, &e, None)),
    }
}

/// A controller file's text, checked (`ParamsFile::check`).
fn from_text(py: Python<'_>, text: &str, origin: Option<&std::path::Path>) -> PyResult<Config> {
    match ParamsFile::check(text, FileKind::Controller) {
        Ok(ParamsFile::Controller(config)) => Ok(*config),
        Ok(other) => Err(error(
            py,
            Kind::Parameter,
            format!("a {} file, not a controller file", other.kind()),
        )),
        Err(e) => Err(file_error(py, &e, origin)),
    }
}

/// The robot a controller is designed for: `robot`, or MiaPURE carrying 60 kg.
fn robot_or_default(robot: Option<PyBallbotParams>) -> BallbotParams<f64> {
    robot.map_or_else(BallbotParams::miapure_60kg, |r| r.inner)
}

/// The 3D robot's controller configuration (`ballbot_core::ballbot::BallbotControllerConfig`):
/// the robot model it was designed for, the planes' LQR-PI gains, the spin loop, the motor
/// PIs, the command shaping and its caps, the safety thresholds, traction-aware control,
/// balance-point estimation, the balancing law and the IMU-lean correction. The same data as a
/// controller file (`ballbot params show --kind controller --preset design`, read by
/// `ballbot world --controller FILE`): `from_toml`/`from_file` read one, `to_toml`/`save`
/// write one. `WorldLoop(controller=...)` and `max_speed_ramp(controller=...)` run it.
///
/// Frozen; `replace` makes a changed copy, with dotted keys
/// (`cfg.replace({"traction.friction_safety_factor": 3.0})`). Every value is checked as
/// `ballbot params check` checks a file: a `ParameterError` names the dotted key.
#[pyclass(
    name = "ControllerConfig",
    module = "ballbot",
    frozen,
    eq,
    from_py_object
)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyControllerConfig {
    /// The validated configuration.
    pub inner: Config,
}

#[pymethods]
impl PyControllerConfig {
    /// The designed controller of MiaPURE carrying 60 kg (`design()`) with the fields given
    /// overlaid (dotted keys allowed), checked.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn py_new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let base = Config::design(&BallbotParams::miapure_60kg()).map_err(|e| core_error(py, e))?;
        Ok(Self {
            inner: with_controller_fields(py, &base, kwargs)?,
        })
    }

    /// The shipped controller designed for `robot` (default MiaPURE carrying 60 kg):
    /// traction-aware control and balance-point estimation on
    /// (`BallbotControllerConfig::design`; the preset `design` for the default robot).
    #[staticmethod]
    #[pyo3(signature = (robot = None))]
    fn design(py: Python<'_>, robot: Option<PyBallbotParams>) -> PyResult<Self> {
        let inner = Config::design(&robot_or_default(robot)).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The paper's configuration designed for `robot` (default MiaPURE carrying 60 kg): the
    /// same gains, shaping and safety as `design`, traction-aware control and balance-point
    /// estimation off (`BallbotControllerConfig::paper`; the preset `paper`).
    #[staticmethod]
    #[pyo3(signature = (robot = None))]
    fn paper(py: Python<'_>, robot: Option<PyBallbotParams>) -> PyResult<Self> {
        let inner = Config::paper(&robot_or_default(robot)).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// A named preset (`"design"` or `"paper"`, for MiaPURE carrying 60 kg), the file
    /// `ballbot params show --kind controller --preset NAME` writes.
    #[staticmethod]
    fn preset(py: Python<'_>, name: &str) -> PyResult<Self> {
        if !PRESETS.contains(&name) {
            return Err(error(
                py,
                Kind::Parameter,
                format!(
                    "unknown preset `{name}` for ControllerConfig; known: {}",
                    PRESETS.join(", ")
                ),
            ));
        }
        match preset(name, Some(FileKind::Controller)) {
            Ok((_, ParamsFile::Controller(config))) => Ok(Self { inner: *config }),
            Ok((_, other)) => Err(error(
                py,
                Kind::Other,
                format!("preset `{name}` is a {} file", other.kind()),
            )),
            Err(e) => Err(file_error(py, &e, None)),
        }
    }

    /// The preset names.
    #[staticmethod]
    fn presets() -> Vec<&'static str> {
        PRESETS.to_vec()
    }

    /// Reads a controller file's text (what `to_toml` and `ballbot params show --kind
    /// controller` write; comments allowed): every key required, unknown keys rejected, every
    /// value checked. A `ParameterError` names the dotted key.
    #[staticmethod]
    fn from_toml(py: Python<'_>, text: &str) -> PyResult<Self> {
        Ok(Self {
            inner: from_text(py, text, None)?,
        })
    }

    /// Reads a controller file (`from_toml` on its text). `FileError` when it cannot be read
    /// or is not TOML; `ParameterError` (the path and the dotted key) when a key does not fit
    /// or a value is out of range.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
        Ok(Self {
            inner: from_text(py, &text, Some(&path))?,
        })
    }

    /// `from_file`, under the name the other parameter classes use.
    #[staticmethod]
    fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        Self::from_file(py, path)
    }

    /// The controller file: every key, each with its description, unit and bound as a comment
    /// above it (as `ballbot params show --kind controller` writes it); `ballbot world
    /// --controller FILE` and `from_toml` read it back to an equal configuration.
    fn to_toml(&self, py: Python<'_>) -> PyResult<String> {
        let header = [
            "controller file (BallbotControllerConfig), written by ballbot.ControllerConfig.to_toml().",
            "Check a copy with `ballbot params check FILE`; run it with `ballbot world --controller FILE`.",
        ];
        commented_toml(&ParamsFile::Controller(Box::new(self.inner)), &header)
            .map_err(|e| error(py, Kind::Other, e.to_string()))
    }

    /// Writes `to_toml()` to a file.
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        let text = self.to_toml(py)?;
        std::fs::write(&path, text)
            .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))
    }

    /// A copy with some fields replaced, checked. Keys are the file's, dotted for nested
    /// tables (`"traction.friction_safety_factor"`, `"shaping.translation.max_value"`), given
    /// as a dict, as keywords (`replace(**{"traction.enabled": False})`) or both; a nested
    /// table also takes a dict of some of its fields (`traction={"enabled": False}`), `robot` a
    /// `BallbotParams` (the model only: the gains are not designed again, see `design`), and
    /// `balancing` `"lqr_pi"` or `{"pi_pd": {"frontal": {...}, "sagittal": {...}}}`.
    #[pyo3(signature = (fields = None, /, **kwargs))]
    fn replace(
        &self,
        py: Python<'_>,
        fields: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let merged = PyDict::new(py);
        for part in [fields, kwargs].into_iter().flatten() {
            merged.update(part.as_mapping())?;
        }
        Ok(Self {
            inner: with_controller_fields(py, &self.inner, Some(&merged))?,
        })
    }

    /// Every field as a dict of plain values (nested tables as dicts), the file's keys.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        to_dict(py, &self.inner)
    }

    /// Builds from a dict of fields (`to_dict`'s keys; missing fields keep `design()`'s values).
    #[staticmethod]
    fn from_dict(py: Python<'_>, fields: &Bound<'_, PyDict>) -> PyResult<Self> {
        Self::py_new(py, Some(fields))
    }

    /// The traction envelope's friction safety factor (`traction.friction_safety_factor`,
    /// >= 1): traction-aware control plans with `mu / factor` (2 in `design`; used only where
    /// traction-aware control is on, `traction_control`).
    #[getter]
    fn traction_safety_factor(&self) -> f64 {
        self.inner.traction.friction_safety_factor
    }

    /// This configuration with `traction.friction_safety_factor = factor` (checked: finite and
    /// >= 1), what `ballbot world --traction-safety-factor F` sets.
    fn with_traction_safety_factor(&self, py: Python<'_>, factor: f64) -> PyResult<Self> {
        let mut inner = self.inner;
        inner.traction.friction_safety_factor = factor;
        inner.check(py)?;
        Ok(Self { inner })
    }

    /// Traction-aware control on (`traction.enabled`).
    #[getter]
    fn traction_control(&self) -> bool {
        self.inner.traction.enabled
    }

    /// Balance-point estimation on (`balance_point.enabled`).
    #[getter]
    fn balance_point(&self) -> bool {
        self.inner.balance_point.enabled
    }

    /// The robot model the controller was designed for (`robot`).
    #[getter]
    fn robot(&self) -> PyBallbotParams {
        PyBallbotParams {
            inner: self.inner.robot,
        }
    }

    /// How the reference rates map to the omniwheels: `"rolling_ball"` or `"upright"`.
    #[getter]
    fn wheel_mapping(&self) -> String {
        serde_name::<WheelMapping>(&self.inner.wheel_mapping)
    }

    /// The outer loop's period (s; 1/400 as designed).
    #[getter]
    fn outer_dt_secs(&self) -> f64 {
        self.inner.outer_dt_secs
    }

    /// A summary (`to_dict()` has every field).
    fn __repr__(&self) -> String {
        let c = &self.inner;
        let law = match Value::try_from(c.balancing) {
            Ok(Value::String(s)) => s,
            Ok(Value::Table(t)) => t.keys().next().cloned().unwrap_or_default(),
            _ => String::new(),
        };
        let py_bool = |b: bool| if b { "True" } else { "False" };
        format!(
            "ControllerConfig(traction_control={}, traction_safety_factor={:?}, \
             balance_point={}, balancing={law:?}, wheel_mapping={:?}, max_speed_m_per_s={:?}, \
             max_accel_m_per_s2={:?}, outer_dt_secs={:?}, body_mass_kg={:?})",
            py_bool(c.traction.enabled),
            c.traction.friction_safety_factor,
            py_bool(c.balance_point.enabled),
            serde_name(&c.wheel_mapping),
            c.shaping.translation.max_value,
            c.shaping.translation.max_rate_per_s,
            c.outer_dt_secs,
            c.robot.sagittal.body_mass_kg,
        )
    }

    /// Pickling: through the controller file's TOML (exact for floats, `inf` included), read
    /// back and checked by `from_toml`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let text = ParamsFile::Controller(Box::new(slf.get().inner))
            .to_toml()
            .map_err(|e| error(py, Kind::Other, format!("pickling: {e}")))?;
        crate::pickle::by_toml(slf.as_any(), text)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyControllerConfig>()
}
