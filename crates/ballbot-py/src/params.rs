//! Parameter classes: the core's validated parameter structs, with the same field names.
//!
//! Every class is frozen and built the same way: keyword arguments overlay a preset (the
//! default one for the constructor, the instance itself for `replace`), the result is
//! deserialised into the core struct (unknown names rejected) and validated once. Nested
//! structs (`BallbotParams.sagittal`, `DrivetrainParams.actuator`) accept either an instance
//! of their class or a dict of some of its fields; array fields (`wheel_azimuths_rad`) accept
//! any sequence of the right length. The overlay goes through a TOML value tree, the same
//! serde representation as `load`/`save`, so the dict, keyword and file forms cannot drift.

use crate::errors::world_error;
use crate::errors::{Kind, core_error, error};
use ballbot_core::{
    ActuatorParams, BallbotParams, DrivetrainParams, PlanarRobotParams, SpinParams, WipParams,
};
use ballbot_sim::world::{
    AxleLossParams, ContactParams, DriverParams, FailureParams, FloorParams, ImuParams,
    RollerParams, RubberLayer, SensorParams, TransmissionParams, WorldParams,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyBool, PyDict, PyList};
use serde::Serialize;
use serde::de::DeserializeOwned;
use toml::{Table, Value};

/// A parameter struct (the core's or the world's), as the generic helpers below see it.
pub trait CoreParams: Copy + Serialize + DeserializeOwned {
    /// The Python class name.
    const NAME: &'static str;
    /// The struct's own validation, as the Python exception it raises.
    fn check(&self, py: Python<'_>) -> PyResult<()>;
}

macro_rules! core_params {
    ($($core:ident => $name:literal),* $(,)?) => {$(
        impl CoreParams for $core<f64> {
            const NAME: &'static str = $name;
            fn check(&self, py: Python<'_>) -> PyResult<()> {
                self.validate().map_err(|e| core_error(py, e))
            }
        }
    )*};
}

core_params! {
    WipParams => "WipParams",
    SpinParams => "SpinParams",
    ActuatorParams => "ActuatorParams",
    DrivetrainParams => "DrivetrainParams",
    BallbotParams => "BallbotParams",
    PlanarRobotParams => "PlanarRobotParams",
}

/// The serde table of `params` (the TOML file's content).
fn to_table<P: CoreParams>(py: Python<'_>, params: &P) -> PyResult<Table> {
    Table::try_from(params).map_err(|e| error(py, Kind::Other, format!("{}: {e}", P::NAME)))
}

/// A number that is not a bool.
fn number(py: Python<'_>, value: &Bound<'_, PyAny>, path: &str) -> PyResult<f64> {
    if value.is_instance_of::<PyBool>() {
        return Err(error(
            py,
            Kind::Parameter,
            format!("`{path}` must be a number, got a bool"),
        ));
    }
    value.extract::<f64>().map_err(|_| {
        error(
            py,
            Kind::Parameter,
            format!(
                "`{path}` must be a number, got {}",
                value
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ),
        )
    })
}

/// A non-negative integer that is not a bool.
fn integer(py: Python<'_>, value: &Bound<'_, PyAny>, path: &str) -> PyResult<i64> {
    let bad = || {
        error(
            py,
            Kind::Parameter,
            format!("`{path}` must be an integer in [0, 2^63)"),
        )
    };
    if value.is_instance_of::<PyBool>() {
        return Err(bad());
    }
    match value.extract::<i64>() {
        Ok(i) if i >= 0 => Ok(i),
        _ => Err(bad()),
    }
}

/// Overlays the Python `fields` (a dict) onto `base`, checking names and kinds against it.
/// `owner` names the class (or nested field) for the messages.
fn overlay(
    py: Python<'_>,
    base: &mut Table,
    fields: &Bound<'_, PyDict>,
    owner: &str,
    prefix: &str,
) -> PyResult<()> {
    for (key, value) in fields.iter() {
        let key: String = key.extract().map_err(|_| {
            error(
                py,
                Kind::Parameter,
                format!("{owner}: parameter names must be strings"),
            )
        })?;
        let path = format!("{prefix}{key}");
        // A dotted key (`robot.drivetrain.wheel_ball_friction`, as sweeps and parameter-file
        // errors name fields) sets that field of the nested struct.
        if let Some((head, rest)) = key.split_once('.') {
            let Some(Value::Table(inner)) = base.get_mut(head) else {
                return Err(error(
                    py,
                    Kind::Parameter,
                    format!(
                        "unknown parameter `{path}` for {owner}: `{prefix}{head}` is not a \
                         nested parameter struct"
                    ),
                ));
            };
            let one = [(rest, &value)].into_py_dict(py)?;
            overlay(py, inner, &one, owner, &format!("{prefix}{head}."))?;
            continue;
        }
        let Some(slot) = base.get_mut(&key) else {
            let known: Vec<&str> = base.keys().map(String::as_str).collect();
            return Err(error(
                py,
                Kind::Parameter,
                format!(
                    "unknown parameter `{path}` for {owner}; known: {}",
                    known.join(", ")
                ),
            ));
        };
        match slot {
            Value::Float(x) => *x = number(py, &value, &path)?,
            Value::Integer(i) => *i = integer(py, &value, &path)?,
            Value::Boolean(b) => {
                if !value.is_instance_of::<PyBool>() {
                    return Err(error(
                        py,
                        Kind::Parameter,
                        format!("`{path}` must be a bool"),
                    ));
                }
                *b = value.extract::<bool>()?;
            }
            Value::String(s) => {
                // A named choice (an enum's snake_case name); serde checks the name.
                *s = value
                    .extract::<String>()
                    .map_err(|_| error(py, Kind::Parameter, format!("`{path}` must be a str")))?;
            }
            Value::Array(items) => {
                let n = items.len();
                let bad = || {
                    error(
                        py,
                        Kind::Parameter,
                        format!("`{path}` must be a sequence of {n} numbers"),
                    )
                };
                let seq: Vec<Bound<'_, PyAny>> = value
                    .try_iter()
                    .map_err(|_| bad())?
                    .collect::<PyResult<_>>()
                    .map_err(|_| bad())?;
                if seq.len() != n {
                    return Err(bad());
                }
                let mut out = Vec::with_capacity(n);
                for (i, v) in seq.iter().enumerate() {
                    out.push(Value::Float(number(py, v, &format!("{path}[{i}]"))?));
                }
                *items = out;
            }
            Value::Table(inner) => {
                let dict = if let Ok(dict) = value.cast::<PyDict>() {
                    dict.clone()
                } else {
                    // An instance of the nested class: all of its fields, same names.
                    let dict = value
                        .call_method0("to_dict")
                        .ok()
                        .and_then(|d| d.cast_into::<PyDict>().ok())
                        .filter(|d| {
                            d.len() == inner.len()
                                && d.keys().iter().all(|k| {
                                    k.extract::<String>()
                                        .map(|k| inner.contains_key(&k))
                                        .unwrap_or(false)
                                })
                        });
                    match dict {
                        Some(dict) => dict,
                        None => {
                            return Err(error(
                                py,
                                Kind::Parameter,
                                format!(
                                    "`{path}` must be a parameter object of the right class or \
                                     a dict of its fields ({})",
                                    inner.keys().cloned().collect::<Vec<_>>().join(", ")
                                ),
                            ));
                        }
                    }
                };
                overlay(py, inner, &dict, owner, &format!("{path}."))?;
            }
            _ => {
                return Err(error(
                    py,
                    Kind::Other,
                    format!("{owner}: field `{path}` has an unsupported kind"),
                ));
            }
        }
    }
    Ok(())
}

/// `base` with `fields` overlaid, deserialised and validated.
pub fn with_fields<P: CoreParams>(
    py: Python<'_>,
    base: &P,
    fields: Option<&Bound<'_, PyDict>>,
) -> PyResult<P> {
    let Some(fields) = fields else {
        base.check(py)?;
        return Ok(*base);
    };
    let mut table = to_table(py, base)?;
    overlay(py, &mut table, fields, P::NAME, "")?;
    let params: P = table
        .try_into()
        .map_err(|e| error(py, Kind::Parameter, format!("{}: {e}", P::NAME)))?;
    params.check(py)?;
    Ok(params)
}

/// The fields of `params` as a dict of plain Python values (nested dicts, lists of floats):
/// its TOML table through `pythonize`, as every serde value the bindings hand over.
pub fn to_dict<'py, P: CoreParams>(py: Python<'py>, params: &P) -> PyResult<Bound<'py, PyDict>> {
    let table = to_table(py, params)?;
    Ok(pythonize::pythonize(py, &table)?.cast_into::<PyDict>()?)
}

/// Writes `params` to a TOML file.
pub fn save<P: CoreParams>(py: Python<'_>, params: &P, path: &std::path::Path) -> PyResult<()> {
    let text = toml::to_string(params)
        .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
    std::fs::write(path, text)
        .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))
}

/// Reads and validates `P` from a TOML file (every field required, unknown keys rejected).
pub fn load<P: CoreParams>(py: Python<'_>, path: &std::path::Path) -> PyResult<P> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
    let params: P = toml::from_str(&text)
        .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
    params.check(py).map_err(|e| {
        let reason = e.value(py).to_string();
        error(py, Kind::Parameter, format!("{}: {reason}", path.display()))
    })?;
    Ok(params)
}

/// The serde name of a unit enum value (`DriverModel::Odrive` -> `"odrive"`).
fn serde_name<T: Serialize>(value: &T) -> String {
    match Value::try_from(value) {
        Ok(Value::String(s)) => s,
        _ => String::new(),
    }
}

/// Defines a frozen Python class mirroring a core parameter struct: keyword construction
/// (defaults from a preset), validation, getters, `replace`, `to_dict`/`from_dict`, TOML
/// `load`/`save`, and named presets. Fields come in three kinds: `floats`, `arrays` (fixed
/// length, returned as numpy arrays), `nested` (another parameter class) and, optionally,
/// `ints` (unsigned integers such as a seed), `bools` and `names` (an enum field, read and
/// written as its serde name, e.g. `"odrive"`). `$core` is the struct's type
/// (`WipParams<f64>`).
macro_rules! py_params {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ty, $name:literal, default = $default:path) {
            floats { $($field:ident),* $(,)? }
            $(ints { $($ifield:ident: $ity:ty),* $(,)? })?
            $(bools { $($bfield:ident),* $(,)? })?
            $(names { $($sfield:ident),* $(,)? })?
            arrays { $($afield:ident),* $(,)? }
            nested { $($nfield:ident: $nty:ident),* $(,)? }
        }
        presets { $($preset:literal => $ctor:path),* $(,)? }
        $(methods { $($extra:item)* })?
    ) => {
        $(#[$meta])*
        #[pyclass(name = $name, module = "ballbot", frozen, eq, from_py_object)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct $py_ty {
            /// The validated core struct.
            pub inner: $core,
        }

        impl $py_ty {
            const PRESETS: &'static [&'static str] = &[$($preset),*];

            /// The `__repr__` text, also used by classes that nest this one.
            pub fn repr(&self) -> String {
                let fields: Vec<String> = vec![
                    $(format!("{}={:?}", stringify!($field), self.inner.$field),)*
                    $($(format!("{}={:?}", stringify!($ifield), self.inner.$ifield),)*)?
                    $($(format!("{}={}", stringify!($bfield), if self.inner.$bfield { "True" } else { "False" }),)*)?
                    $($(format!("{}={:?}", stringify!($sfield), serde_name(&self.inner.$sfield)),)*)?
                    $(format!("{}={:?}", stringify!($afield), self.inner.$afield),)*
                    $(format!("{}={}", stringify!($nfield), $nty { inner: self.inner.$nfield }.repr()),)*
                ];
                format!("{}({})", $name, fields.join(", "))
            }
        }

        #[pymethods]
        impl $py_ty {
            #[new]
            #[pyo3(signature = (**kwargs))]
            fn py_new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                Ok(Self { inner: with_fields(py, &$default(), kwargs)? })
            }

            /// A named preset.
            #[staticmethod]
            fn preset(py: Python<'_>, name: &str) -> PyResult<Self> {
                let inner = match name {
                    $($preset => $ctor(),)*
                    _ => {
                        return Err(error(
                            py,
                            Kind::Parameter,
                            format!(
                                "unknown preset `{name}` for {}; known: {}",
                                $name,
                                Self::PRESETS.join(", ")
                            ),
                        ))
                    }
                };
                Ok(Self { inner })
            }

            /// The preset names.
            #[staticmethod]
            fn presets() -> Vec<&'static str> {
                Self::PRESETS.to_vec()
            }

            /// A copy with some fields replaced (validated). Nested fields take a parameter
            /// object, a dict of some of its fields, or a dotted key as sweeps name them:
            /// `replace(**{"robot.drivetrain.wheel_ball_friction": 0.5})`.
            #[pyo3(signature = (**kwargs))]
            fn replace(&self, py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                Ok(Self { inner: with_fields(py, &self.inner, kwargs)? })
            }

            /// The fields as a dict (nested structs as dicts, arrays as lists).
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                to_dict(py, &self.inner)
            }

            /// Builds from a dict of fields (missing fields keep the default preset's values).
            #[staticmethod]
            fn from_dict(py: Python<'_>, fields: &Bound<'_, PyDict>) -> PyResult<Self> {
                Ok(Self { inner: with_fields(py, &$default(), Some(fields))? })
            }

            /// Writes the fields to a TOML file.
            fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
                save(py, &self.inner, &path)
            }

            /// Reads the fields from a TOML file (every field required; unknown keys rejected).
            #[staticmethod]
            fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
                Ok(Self { inner: load(py, &path)? })
            }

            fn __repr__(&self) -> String {
                self.repr()
            }

            /// Pickling: re-created from `to_dict` by the constructor (validated again).
            fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
                let d = to_dict(slf.py(), &slf.get().inner)?;
                crate::pickle::by_constructor(slf.as_any(), d)
            }

            $(
                #[getter]
                fn $field(&self) -> f64 {
                    self.inner.$field
                }
            )*

            $($(
                #[getter]
                fn $ifield(&self) -> $ity {
                    self.inner.$ifield
                }
            )*)?

            $($(
                #[getter]
                fn $bfield(&self) -> bool {
                    self.inner.$bfield
                }
            )*)?

            $($(
                #[getter]
                fn $sfield(&self) -> String {
                    serde_name(&self.inner.$sfield)
                }
            )*)?

            $(
                #[getter]
                fn $afield<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                    PyArray1::from_slice(py, &self.inner.$afield)
                }
            )*

            $(
                #[getter]
                fn $nfield(&self) -> $nty {
                    $nty { inner: self.inner.$nfield }
                }
            )*

            $($($extra)*)?
        }
    };
}

py_params! {
    /// One plane of the wheeled inverted pendulum (`ballbot_core::WipParams`).
    PyWipParams(WipParams<f64>, "WipParams", default = WipParams::miapure_60kg) {
        floats {
            ball_radius_m, ball_mass_kg, ball_inertia_kg_m2, body_mass_kg, com_height_m,
            body_inertia_kg_m2, wheel_inertia_kg_m2, ball_damping_nm_s_per_rad,
            drive_damping_nm_s_per_rad, gravity_m_per_s2,
        }
        arrays {}
        nested {}
    }
    presets {
        "miapure_60kg" => WipParams::miapure_60kg,
        "miapure_unloaded" => WipParams::miapure_unloaded,
        "piptb" => WipParams::piptb,
    }
}

py_params! {
    /// The spin model (`ballbot_core::SpinParams`).
    PySpinParams(SpinParams<f64>, "SpinParams", default = SpinParams::miapure_60kg) {
        floats { inertia_kg_m2, damping_nm_s_per_rad }
        arrays {}
        nested {}
    }
    presets {
        "miapure_60kg" => SpinParams::miapure_60kg,
        "miapure_unloaded" => SpinParams::miapure_unloaded,
    }
}

py_params! {
    /// One actuator, limits at the output (`ballbot_core::ActuatorParams`).
    PyActuatorParams(ActuatorParams<f64>, "ActuatorParams", default = ActuatorParams::miapure) {
        floats { gear_ratio, peak_torque_nm, no_load_speed_rad_per_s }
        arrays {}
        nested {}
    }
    presets {
        "miapure" => ActuatorParams::miapure,
    }
    methods {
        /// The torque range `(min, max)` (N m) at the output speed `speed_rad_per_s`: motoring
        /// torque falls linearly to zero at the no-load speed, braking torque keeps the peak.
        fn torque_bounds_nm(&self, speed_rad_per_s: f64) -> (f64, f64) {
            self.inner.torque_bounds_nm(speed_rad_per_s)
        }

        /// `torque_nm` clamped into the range of `torque_bounds_nm` at `speed_rad_per_s`.
        fn clamp_torque_nm(&self, torque_nm: f64, speed_rad_per_s: f64) -> f64 {
            self.inner.clamp_torque_nm(torque_nm, speed_rad_per_s)
        }
    }
}

py_params! {
    /// The omniwheel drivetrain (`ballbot_core::DrivetrainParams`).
    PyDrivetrainParams(DrivetrainParams<f64>, "DrivetrainParams", default = DrivetrainParams::miapure) {
        floats { contact_angle_rad, wheel_radius_m, wheel_ball_friction, ball_floor_friction }
        arrays { wheel_azimuths_rad }
        nested { actuator: PyActuatorParams }
    }
    presets {
        "miapure" => DrivetrainParams::miapure,
    }
}

py_params! {
    /// A complete 3D ballbot (`ballbot_core::BallbotParams`).
    PyBallbotParams(BallbotParams<f64>, "BallbotParams", default = BallbotParams::miapure_60kg) {
        floats {}
        arrays {}
        nested {
            sagittal: PyWipParams,
            frontal: PyWipParams,
            spin: PySpinParams,
            drivetrain: PyDrivetrainParams,
        }
    }
    presets {
        "miapure_60kg" => BallbotParams::miapure_60kg,
        "miapure_unloaded" => BallbotParams::miapure_unloaded,
    }
    methods {
        /// The ball radius shared by both planes (m).
        #[getter]
        fn ball_radius_m(&self) -> f64 {
            self.inner.ball_radius_m()
        }
    }
}

py_params! {
    /// A planar robot, one WIP plane and its actuator (`ballbot_core::PlanarRobotParams`).
    PyPlanarRobotParams(PlanarRobotParams<f64>, "PlanarRobotParams", default = PlanarRobotParams::piptb) {
        floats {}
        arrays {}
        nested { plane: PyWipParams, actuator: PyActuatorParams }
    }
    presets {
        "piptb" => PlanarRobotParams::piptb,
    }
}

mod controller;
mod world;
pub use controller::PyControllerConfig;
pub use world::PyWorldParams;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWipParams>()?;
    m.add_class::<PySpinParams>()?;
    m.add_class::<PyActuatorParams>()?;
    m.add_class::<PyDrivetrainParams>()?;
    m.add_class::<PyBallbotParams>()?;
    m.add_class::<PyPlanarRobotParams>()?;
    controller::register(m)?;
    world::register(m)
}
