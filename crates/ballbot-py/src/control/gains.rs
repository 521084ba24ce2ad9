//! The controllers' gains (`LqrGains`, `PiPdGains`, `SpeedPiGains`) and `LqrPiOuterConfig`.

use crate::errors::{Kind, core_error, error};
use crate::models::PyWip;
use ballbot_core::control::{LqrGains, LqrPiOuterConfig, PiPdGains, SpeedPiGains};
use ballbot_core::lqr::LqrWeights;
use nalgebra::SMatrix;
use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Defines a frozen Python class over a `Copy` struct of `f64` fields: keyword-only
/// construction (all fields required), validation, getters, `replace`, `to_dict`, `__repr__`.
macro_rules! py_gains {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ident, $name:literal) { $($field:ident),* $(,)? }
        $(methods { $($extra:item)* })?
    ) => {
        $(#[$meta])*
        #[pyclass(name = $name, module = "ballbot", frozen, eq, from_py_object)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct $py_ty {
            /// The validated core struct.
            pub inner: $core<f64>,
        }

        impl $py_ty {
            const FIELDS: &'static [&'static str] = &[$(stringify!($field)),*];

            fn checked(py: Python<'_>, inner: $core<f64>) -> PyResult<Self> {
                inner.validate().map_err(|e| core_error(py, e))?;
                Ok(Self { inner })
            }

            /// The `__repr__` text.
            pub fn repr(&self) -> String {
                let fields: Vec<String> =
                    vec![$(format!("{}={:?}", stringify!($field), self.inner.$field)),*];
                format!("{}({})", $name, fields.join(", "))
            }
        }

        #[pymethods]
        impl $py_ty {
            #[new]
            #[pyo3(signature = (*, $($field),*))]
            fn py_new(py: Python<'_>, $($field: f64),*) -> PyResult<Self> {
                Self::checked(py, $core { $($field),* })
            }

            /// A copy with some fields replaced (validated).
            #[pyo3(signature = (**kwargs))]
            fn replace(&self, py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
                let mut inner = self.inner;
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
                Self::checked(py, inner)
            }

            /// The fields as a dict.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                [$((stringify!($field), self.inner.$field)),*].into_py_dict(py)
            }

            fn __repr__(&self) -> String {
                self.repr()
            }

            /// Pickling: re-created from `to_dict` by the constructor (validated again).
            fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
                let d = slf.get().to_dict(slf.py())?;
                crate::pickle::by_constructor(slf.as_any(), d)
            }

            $(
                #[getter]
                fn $field(&self) -> f64 {
                    self.inner.$field
                }
            )*

            $($($extra)*)?
        }
    };
}

py_gains! {
    /// Gains and torque limit of the LQR controller, `tau = k (s_c - s)`
    /// (`ballbot_core::control::LqrGains`).
    PyLqrGains(LqrGains, "LqrGains") {
        tilt_nm_per_rad, tilt_rate_nm_s_per_rad, ball_rate_nm_s_per_rad, max_torque_nm,
    }
    methods {
        /// Gains from `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]`.
        #[staticmethod]
        fn from_reduced(py: Python<'_>, k: [f64; 3], max_torque_nm: f64) -> PyResult<Self> {
            Self::checked(py, LqrGains::from_reduced(k, max_torque_nm))
        }

        /// Gains by the continuous LQR on `wip`'s upright linearisation; `q` (3,) or (3, 3)
        /// and `r` default to MODEL.md's `diag(100, 10, 1)` and 0.1.
        #[staticmethod]
        #[pyo3(signature = (wip, max_torque_nm, q = None, r = 0.1, dt_secs = None))]
        fn design(
            py: Python<'_>,
            wip: PyRef<'_, PyWip>,
            max_torque_nm: f64,
            q: Option<Arr<'_>>,
            r: f64,
            dt_secs: Option<f64>,
        ) -> PyResult<Self> {
            let weights = match q {
                None => LqrWeights { r, ..LqrWeights::model_default() },
                Some(q) => {
                    let shape = q.shape().to_vec();
                    let v: Vec<f64> = q.as_array().iter().copied().collect();
                    let m = match shape.as_slice() {
                        [3] => SMatrix::<f64, 3, 3>::from_diagonal(&nalgebra::Vector3::new(v[0], v[1], v[2])),
                        [3, 3] => SMatrix::<f64, 3, 3>::from_row_iterator(v.iter().copied()),
                        _ => {
                            return Err(error(
                                py,
                                Kind::Shape,
                                format!("`q` must have shape (3,) or (3, 3), got {shape:?}"),
                            ))
                        }
                    };
                    LqrWeights::new(m, r)
                }
            };
            let wip = wip.inner;
            let gains = py.detach(|| match dt_secs {
                None => LqrGains::design(&wip, &weights, max_torque_nm),
                Some(dt) => LqrGains::design_discrete(&wip, &weights, dt, max_torque_nm),
            });
            Ok(Self { inner: gains.map_err(|e| core_error(py, e))? })
        }

        /// MODEL.md's default design for `wip` with the torque limit `max_torque_nm`.
        #[staticmethod]
        fn for_wip(py: Python<'_>, wip: PyRef<'_, PyWip>, max_torque_nm: f64) -> PyResult<Self> {
            let inner = LqrGains::for_wip(&wip.inner, max_torque_nm).map_err(|e| core_error(py, e))?;
            Ok(Self { inner })
        }

        /// `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]`.
        fn reduced<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
            PyArray1::from_slice(py, self.inner.reduced().as_slice())
        }

        /// The paper's `[k1, 0, k2, k3]` on `[theta, phi, theta_dot, phi_dot]`.
        fn full<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
            PyArray1::from_slice(py, self.inner.full().as_slice())
        }
    }
}

py_gains! {
    /// Gains and limits of the cascaded PI-PD controller
    /// (`ballbot_core::control::PiPdGains`).
    PyPiPdGains(PiPdGains, "PiPdGains") {
        speed_p_secs, speed_i_rad_per_rad, tilt_p_nm_per_rad, tilt_d_nm_s_per_rad,
        max_tilt_rad, max_torque_nm,
    }
    methods {
        /// Gains by pole placement on `wip`'s upright linearisation: four real negative
        /// closed-loop poles (rad/s).
        #[staticmethod]
        fn design(
            py: Python<'_>,
            wip: PyRef<'_, PyWip>,
            poles_rad_per_s: [f64; 4],
            max_tilt_rad: f64,
            max_torque_nm: f64,
        ) -> PyResult<Self> {
            let inner = PiPdGains::design(&wip.inner, poles_rad_per_s, max_tilt_rad, max_torque_nm)
                .map_err(|e| core_error(py, e))?;
            Ok(Self { inner })
        }

        /// The documented default design for `wip` (poles at multiples of the open-loop pole).
        #[staticmethod]
        fn for_wip(py: Python<'_>, wip: PyRef<'_, PyWip>, max_torque_nm: f64) -> PyResult<Self> {
            let inner = PiPdGains::for_wip(&wip.inner, max_torque_nm).map_err(|e| core_error(py, e))?;
            Ok(Self { inner })
        }
    }
}

py_gains! {
    /// Gains and limit of the inner speed PI (`ballbot_core::control::SpeedPiGains`).
    PySpeedPiGains(SpeedPiGains, "SpeedPiGains") {
        proportional_nm_s_per_rad, integral_nm_per_rad, anti_windup_per_s, max_torque_nm,
    }
    methods {
        /// Gains placing a critically damped double pole at `-bandwidth_rad_per_s` for a plant
        /// with `accel_per_torque` (rad/s^2 per N m).
        #[staticmethod]
        fn from_bandwidth(
            py: Python<'_>,
            accel_per_torque: f64,
            bandwidth_rad_per_s: f64,
            max_torque_nm: f64,
        ) -> PyResult<Self> {
            let inner = SpeedPiGains::from_bandwidth(accel_per_torque, bandwidth_rad_per_s, max_torque_nm)
                .map_err(|e| core_error(py, e))?;
            Ok(Self { inner })
        }

        /// `from_bandwidth` for the ball rate of `wip` (`b = B4` of the upright linearisation).
        #[staticmethod]
        fn for_wip_ball_rate(
            py: Python<'_>,
            wip: PyRef<'_, PyWip>,
            bandwidth_rad_per_s: f64,
            max_torque_nm: f64,
        ) -> PyResult<Self> {
            let inner = SpeedPiGains::for_wip_ball_rate(&wip.inner, bandwidth_rad_per_s, max_torque_nm)
                .map_err(|e| core_error(py, e))?;
            Ok(Self { inner })
        }
    }
}

/// Configuration of the LQR-PI outer loop (`ballbot_core::control::LqrPiOuterConfig`).
#[pyclass(
    name = "LqrPiOuterConfig",
    module = "ballbot",
    frozen,
    eq,
    from_py_object
)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyLqrPiOuterConfig {
    pub(crate) inner: LqrPiOuterConfig<f64>,
}

#[pymethods]
impl PyLqrPiOuterConfig {
    #[new]
    #[pyo3(signature = (*, lqr, max_speed_error_rad_per_s))]
    fn py_new(py: Python<'_>, lqr: PyLqrGains, max_speed_error_rad_per_s: f64) -> PyResult<Self> {
        let inner = LqrPiOuterConfig {
            lqr: lqr.inner,
            max_speed_error_rad_per_s,
        };
        inner.validate().map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The configuration whose anchor band is `max_torque_nm / kp` of the inner PI `inner`.
    #[staticmethod]
    fn for_inner(py: Python<'_>, lqr: PyLqrGains, inner: PySpeedPiGains) -> PyResult<Self> {
        let inner =
            LqrPiOuterConfig::new(lqr.inner, &inner.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The LQR gains (their `max_torque_nm` saturates the reference torque).
    #[getter]
    fn lqr(&self) -> PyLqrGains {
        PyLqrGains {
            inner: self.inner.lqr,
        }
    }

    /// The anchor band of the reference integrator (rad/s).
    #[getter]
    fn max_speed_error_rad_per_s(&self) -> f64 {
        self.inner.max_speed_error_rad_per_s
    }

    /// Pickling: re-created by the constructor (validated again).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let py = slf.py();
        let d = [
            ("lqr", slf.get().lqr().into_bound_py_any(py)?),
            (
                "max_speed_error_rad_per_s",
                slf.get()
                    .inner
                    .max_speed_error_rad_per_s
                    .into_bound_py_any(py)?,
            ),
        ]
        .into_py_dict(py)?;
        crate::pickle::by_constructor(slf.as_any(), d)
    }

    fn __repr__(&self) -> String {
        format!(
            "LqrPiOuterConfig(lqr={}, max_speed_error_rad_per_s={:?})",
            PyLqrGains {
                inner: self.inner.lqr
            }
            .repr(),
            self.inner.max_speed_error_rad_per_s
        )
    }
}
