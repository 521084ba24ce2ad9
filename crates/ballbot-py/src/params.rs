//! Parameter classes: the core's validated parameter structs, with the same field names.

use crate::errors::{Kind, core_error, error};
use ballbot_core::{ActuatorParams, SpinParams, WipParams};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Defines a frozen Python class mirroring a core parameter struct of `f64` fields:
/// keyword-only construction (defaults from a preset), validation, getters, `replace`,
/// `to_dict`/`from_dict`, TOML `load`/`save`, and named presets.
macro_rules! py_params {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ident, $name:literal, default = $default:path) {
            $($field:ident),* $(,)?
        }
        presets { $($preset:literal => $ctor:path),* $(,)? }
    ) => {
        $(#[$meta])*
        #[pyclass(name = $name, module = "ballbot", frozen, eq, from_py_object)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct $py_ty {
            pub inner: $core<f64>,
        }

        impl $py_ty {
            const FIELDS: &'static [&'static str] = &[$(stringify!($field)),*];
            const PRESETS: &'static [&'static str] = &[$($preset),*];

            fn from_kwargs(
                py: Python<'_>,
                mut inner: $core<f64>,
                kwargs: Option<&Bound<'_, PyDict>>,
            ) -> PyResult<Self> {
                if let Some(kwargs) = kwargs {
                    for (key, value) in kwargs.iter() {
                        let key: String = key.extract()?;
                        let value: f64 = value.extract().map_err(|_| {
                            error(py, Kind::Parameter, format!("`{key}` must be a number"))
                        })?;
                        match key.as_str() {
                            $(stringify!($field) => inner.$field = value,)*
                            _ => {
                                return Err(error(
                                    py,
                                    Kind::Parameter,
                                    format!(
                                        "unknown parameter `{key}` for {}; known: {}",
                                        $name,
                                        Self::FIELDS.join(", ")
                                    ),
                                ))
                            }
                        }
                    }
                }
                inner.validate().map_err(|e| core_error(py, e))?;
                Ok(Self { inner })
            }
        }

        #[pymethods]
        impl $py_ty {
            #[new]
            #[pyo3(signature = (**kwargs))]
            fn py_new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                Self::from_kwargs(py, $default(), kwargs)
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

            /// A copy with some fields replaced (validated).
            #[pyo3(signature = (**kwargs))]
            fn replace(&self, py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                Self::from_kwargs(py, self.inner, kwargs)
            }

            /// The fields as a dict.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let d = PyDict::new(py);
                $(d.set_item(stringify!($field), self.inner.$field)?;)*
                Ok(d)
            }

            /// Builds from a dict of fields (missing fields keep the default preset's values).
            #[staticmethod]
            fn from_dict(py: Python<'_>, fields: &Bound<'_, PyDict>) -> PyResult<Self> {
                Self::from_kwargs(py, $default(), Some(fields))
            }

            /// Writes the fields to a TOML file.
            fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
                let text = toml::to_string(&self.inner).map_err(|e| {
                    error(py, Kind::File, format!("{}: {e}", path.display()))
                })?;
                std::fs::write(&path, text)
                    .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))
            }

            /// Reads the fields from a TOML file (every field required; unknown keys rejected).
            #[staticmethod]
            fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
                let text = std::fs::read_to_string(&path)
                    .map_err(|e| error(py, Kind::File, format!("{}: {e}", path.display())))?;
                let inner: $core<f64> = toml::from_str(&text).map_err(|e| {
                    error(py, Kind::File, format!("{}: {e}", path.display()))
                })?;
                inner.validate().map_err(|e| core_error(py, e))?;
                Ok(Self { inner })
            }

            fn __repr__(&self) -> String {
                let fields: Vec<String> =
                    vec![$(format!("{}={:?}", stringify!($field), self.inner.$field)),*];
                format!("{}({})", $name, fields.join(", "))
            }

            $(
                #[getter]
                fn $field(&self) -> f64 {
                    self.inner.$field
                }
            )*
        }
    };
}

py_params! {
    /// One plane of the wheeled inverted pendulum (`ballbot_core::WipParams`).
    PyWipParams(WipParams, "WipParams", default = WipParams::miapure_60kg) {
        ball_radius_m, ball_mass_kg, ball_inertia_kg_m2, body_mass_kg, com_height_m,
        body_inertia_kg_m2, wheel_inertia_kg_m2, ball_damping_nm_s_per_rad,
        drive_damping_nm_s_per_rad, gravity_m_per_s2,
    }
    presets {
        "miapure_60kg" => WipParams::miapure_60kg,
        "miapure_unloaded" => WipParams::miapure_unloaded,
        "piptb" => WipParams::piptb,
    }
}

py_params! {
    /// The spin model (`ballbot_core::SpinParams`).
    PySpinParams(SpinParams, "SpinParams", default = SpinParams::miapure_60kg) {
        inertia_kg_m2, damping_nm_s_per_rad,
    }
    presets {
        "miapure_60kg" => SpinParams::miapure_60kg,
        "miapure_unloaded" => SpinParams::miapure_unloaded,
    }
}

py_params! {
    /// One actuator, limits at the output (`ballbot_core::ActuatorParams`).
    PyActuatorParams(ActuatorParams, "ActuatorParams", default = ActuatorParams::miapure) {
        gear_ratio, peak_torque_nm, no_load_speed_rad_per_s,
    }
    presets {
        "miapure" => ActuatorParams::miapure,
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWipParams>()?;
    m.add_class::<PySpinParams>()?;
    m.add_class::<PyActuatorParams>()?;
    Ok(())
}
