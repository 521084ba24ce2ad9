//! The planar controllers (`ballbot_core::control`) with `step`, their gains, and a batch
//! closed-loop rollout on the nonlinear WIP that runs entirely in Rust without the GIL.

use crate::arrays::{Rows, array_out, reserve, rows, vec4};
use crate::errors::{Kind, core_error, error};
use crate::models::PyWip;
use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedCommand,
    SpeedPi, SpeedPiGains, StepStatus,
};
use ballbot_core::lqr::LqrWeights;
use ballbot_core::{Wip, WipState};
use ballbot_sim::planar::{PlanarError, RolloutController, RolloutSettings, rollout};
use nalgebra::{SMatrix, Vector4};
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// The name of a step status in Python.
pub fn status_name(status: StepStatus) -> &'static str {
    match status {
        StepStatus::Nominal => "nominal",
        StepStatus::Saturated => "saturated",
        _ => "invalid_input",
    }
}

/// The integer code of a step status in batch outputs: 0 nominal, 1 saturated, 2 invalid.
fn status_code(status: StepStatus) -> i8 {
    match status {
        StepStatus::Nominal => 0,
        StepStatus::Saturated => 1,
        _ => 2,
    }
}

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
                let d = PyDict::new(py);
                $(d.set_item(stringify!($field), self.inner.$field)?;)*
                Ok(d)
            }

            fn __repr__(&self) -> String {
                self.repr()
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
    inner: LqrPiOuterConfig<f64>,
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

/// Defines a frozen output class: float fields plus a `status` string.
macro_rules! py_output {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ty, $name:literal) { $($field:ident),* $(,)? }
    ) => {
        $(#[$meta])*
        // A free list: `step` creates one output per call, so reusing the allocations
        // shortens the call from Python.
        #[pyclass(name = $name, module = "ballbot", frozen, freelist = 32)]
        pub struct $py_ty {
            inner: $core,
        }

        #[pymethods]
        impl $py_ty {
            $(
                #[getter]
                fn $field(&self) -> f64 {
                    self.inner.$field
                }
            )*

            /// `"nominal"`, `"saturated"` or `"invalid_input"`.
            #[getter]
            fn status(&self) -> &'static str {
                status_name(self.inner.status)
            }

            /// The fields as a dict.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let d = PyDict::new(py);
                $(d.set_item(stringify!($field), self.inner.$field)?;)*
                d.set_item("status", status_name(self.inner.status))?;
                Ok(d)
            }

            fn __repr__(&self) -> String {
                let fields: Vec<String> =
                    vec![$(format!("{}={:?}", stringify!($field), self.inner.$field)),*];
                format!("{}({}, status={:?})", $name, fields.join(", "), status_name(self.inner.status))
            }
        }
    };
}

py_output! {
    /// One LQR step's result, with each term.
    PyLqrOutput(ballbot_core::control::LqrOutput<f64>, "LqrOutput") {
        torque_nm, tilt_term_nm, tilt_rate_term_nm, ball_rate_term_nm, saturation_nm,
    }
}

py_output! {
    /// One PI-PD step's result, with each term.
    PyPiPdOutput(ballbot_core::control::PiPdOutput<f64>, "PiPdOutput") {
        torque_nm, reference_tilt_rad, tilt_feedforward_rad, speed_p_term_rad, speed_i_term_rad,
        tilt_limit_rad, tilt_p_term_nm, tilt_d_term_nm, saturation_nm,
    }
}

py_output! {
    /// One LQR-PI outer step's result: what goes to the inner speed PI, and each term.
    PyLqrPiOuterOutput(ballbot_core::control::LqrPiOuterOutput<f64>, "LqrPiOuterOutput") {
        reference_torque_nm, reference_ball_rate_rad_per_s, reference_ball_accel_rad_per_s2,
        tilt_term_nm, tilt_rate_term_nm, ball_rate_term_nm, saturation_nm,
        anchor_correction_rad_per_s,
    }
}

py_output! {
    /// One speed-PI step's result, with each term.
    PySpeedPiOutput(ballbot_core::control::SpeedPiOutput<f64>, "SpeedPiOutput") {
        torque_nm, feedforward_nm, proportional_nm, integral_nm, saturation_nm,
        speed_error_rad_per_s,
    }
}

/// The command state: zeros when omitted.
fn command4(py: Python<'_>, command: Option<&Bound<'_, PyAny>>) -> PyResult<WipState<f64>> {
    Ok(match command {
        Some(c) => Vector4::from(vec4(py, c, "command")?),
        None => Vector4::zeros(),
    })
}

/// The paper's LQR torque controller (`ballbot_core::control::LqrController`).
#[pyclass(name = "LqrController", module = "ballbot")]
pub struct PyLqrController {
    inner: LqrController<f64>,
}

#[pymethods]
impl PyLqrController {
    #[new]
    fn py_new(py: Python<'_>, gains: PyLqrGains) -> PyResult<Self> {
        let inner = LqrController::new(gains.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The gains in use.
    #[getter]
    fn gains(&self) -> PyLqrGains {
        PyLqrGains {
            inner: *self.inner.gains(),
        }
    }

    /// Nothing to clear (the LQR is static); present for the common controller shape.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// `tau = k (s_c - s)`, saturated. `measured`, `command`: WIP states
    /// `[theta, phi, theta_dot, phi_dot]` (command defaults to zeros).
    #[pyo3(signature = (measured, command = None, dt_secs = 0.0025))]
    fn step(
        &mut self,
        py: Python<'_>,
        measured: &Bound<'_, PyAny>,
        command: Option<&Bound<'_, PyAny>>,
        dt_secs: f64,
    ) -> PyResult<PyLqrOutput> {
        let m = Vector4::from(vec4(py, measured, "measured")?);
        let c = command4(py, command)?;
        Ok(PyLqrOutput {
            inner: self.inner.step(&m, &c, dt_secs),
        })
    }

    /// Steps through a sequence of measurements `(n, 4)` (commands `(4,)` or `(n, 4)`) in
    /// Rust: a log replay. Returns a dict of `(n,)` arrays, one per output field, and
    /// `status` as int8 codes (0 nominal, 1 saturated, 2 invalid input).
    #[pyo3(signature = (measured, command = None, dt_secs = 0.0025))]
    fn step_many<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr<'py>,
        command: Option<Arr<'py>>,
        dt_secs: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (m, c) = replay_inputs(py, &measured, command.as_ref())?;
        let mut ctrl = self.inner;
        let outs = py.detach(|| {
            m.iter()
                .zip(c.iter().cycle())
                .map(|(m, c)| ctrl.step(&Vector4::from(*m), &Vector4::from(*c), dt_secs))
                .collect::<Vec<_>>()
        });
        self.inner = ctrl;
        columns(
            py,
            &outs,
            &[
                ("torque_nm", |o| o.torque_nm),
                ("tilt_term_nm", |o| o.tilt_term_nm),
                ("tilt_rate_term_nm", |o| o.tilt_rate_term_nm),
                ("ball_rate_term_nm", |o| o.ball_rate_term_nm),
                ("saturation_nm", |o| o.saturation_nm),
            ],
            |o| o.status,
        )
    }
}

/// The cascaded PI-PD controller (`ballbot_core::control::PiPdController`).
#[pyclass(name = "PiPdController", module = "ballbot")]
pub struct PyPiPdController {
    inner: PiPdController<f64>,
}

#[pymethods]
impl PyPiPdController {
    #[new]
    fn py_new(py: Python<'_>, gains: PyPiPdGains) -> PyResult<Self> {
        let inner = PiPdController::new(gains.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The gains in use.
    #[getter]
    fn gains(&self) -> PyPiPdGains {
        PyPiPdGains {
            inner: *self.inner.gains(),
        }
    }

    /// The integrated ball-rate error (rad).
    #[getter]
    fn speed_error_integral_rad(&self) -> f64 {
        self.inner.speed_error_integral_rad()
    }

    /// Clears the speed integral.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// One step; `measured`, `command`: WIP states (command defaults to zeros).
    #[pyo3(signature = (measured, command = None, dt_secs = 0.0025))]
    fn step(
        &mut self,
        py: Python<'_>,
        measured: &Bound<'_, PyAny>,
        command: Option<&Bound<'_, PyAny>>,
        dt_secs: f64,
    ) -> PyResult<PyPiPdOutput> {
        let m = Vector4::from(vec4(py, measured, "measured")?);
        let c = command4(py, command)?;
        Ok(PyPiPdOutput {
            inner: self.inner.step(&m, &c, dt_secs),
        })
    }

    /// Steps through measurements `(n, 4)` in Rust (see `LqrController.step_many`).
    #[pyo3(signature = (measured, command = None, dt_secs = 0.0025))]
    fn step_many<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr<'py>,
        command: Option<Arr<'py>>,
        dt_secs: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (m, c) = replay_inputs(py, &measured, command.as_ref())?;
        let mut ctrl = self.inner;
        let outs = py.detach(|| {
            m.iter()
                .zip(c.iter().cycle())
                .map(|(m, c)| ctrl.step(&Vector4::from(*m), &Vector4::from(*c), dt_secs))
                .collect::<Vec<_>>()
        });
        self.inner = ctrl;
        columns(
            py,
            &outs,
            &[
                ("torque_nm", |o| o.torque_nm),
                ("reference_tilt_rad", |o| o.reference_tilt_rad),
                ("tilt_feedforward_rad", |o| o.tilt_feedforward_rad),
                ("speed_p_term_rad", |o| o.speed_p_term_rad),
                ("speed_i_term_rad", |o| o.speed_i_term_rad),
                ("tilt_limit_rad", |o| o.tilt_limit_rad),
                ("tilt_p_term_nm", |o| o.tilt_p_term_nm),
                ("tilt_d_term_nm", |o| o.tilt_d_term_nm),
                ("saturation_nm", |o| o.saturation_nm),
            ],
            |o| o.status,
        )
    }
}

/// The outer part of the cascaded LQR-PI (`ballbot_core::control::LqrPiOuter`).
#[pyclass(name = "LqrPiOuter", module = "ballbot")]
pub struct PyLqrPiOuter {
    inner: LqrPiOuter<f64>,
}

#[pymethods]
impl PyLqrPiOuter {
    #[new]
    fn py_new(
        py: Python<'_>,
        model: PyRef<'_, PyWip>,
        config: PyLqrPiOuterConfig,
    ) -> PyResult<Self> {
        let inner = LqrPiOuter::new(model.inner, config.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The configuration in use.
    #[getter]
    fn config(&self) -> PyLqrPiOuterConfig {
        PyLqrPiOuterConfig {
            inner: *self.inner.config(),
        }
    }

    /// The stored reference ball rate (rad/s), `None` before the first valid step.
    #[getter]
    fn reference_ball_rate_rad_per_s(&self) -> Option<f64> {
        self.inner.reference_ball_rate_rad_per_s()
    }

    /// Forgets the reference integral (re-anchored at the next step).
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// One outer step; `measured`, `command`: WIP states (command defaults to zeros).
    #[pyo3(signature = (measured, command = None, dt_secs = 0.0025))]
    fn step(
        &mut self,
        py: Python<'_>,
        measured: &Bound<'_, PyAny>,
        command: Option<&Bound<'_, PyAny>>,
        dt_secs: f64,
    ) -> PyResult<PyLqrPiOuterOutput> {
        let m = Vector4::from(vec4(py, measured, "measured")?);
        let c = command4(py, command)?;
        Ok(PyLqrPiOuterOutput {
            inner: self.inner.step(&m, &c, dt_secs),
        })
    }
}

/// The inner speed PI with feedforward and anti-windup (`ballbot_core::control::SpeedPi`).
#[pyclass(name = "SpeedPi", module = "ballbot")]
pub struct PySpeedPi {
    inner: SpeedPi<f64>,
}

#[pymethods]
impl PySpeedPi {
    #[new]
    fn py_new(py: Python<'_>, gains: PySpeedPiGains) -> PyResult<Self> {
        let inner = SpeedPi::new(gains.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The gains in use.
    #[getter]
    fn gains(&self) -> PySpeedPiGains {
        PySpeedPiGains {
            inner: *self.inner.gains(),
        }
    }

    /// The integral term (N m) the next step uses.
    #[getter]
    fn integral_nm(&self) -> f64 {
        self.inner.integral_nm()
    }

    /// Clears the integral.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// One PI step toward `speed_rad_per_s` with the feedforward `feedforward_torque_nm`, from
    /// the measured speed, within `[lower_nm, upper_nm]` (default: the symmetric limit).
    #[pyo3(signature = (
        measured_speed_rad_per_s,
        speed_rad_per_s,
        feedforward_torque_nm = 0.0,
        dt_secs = 0.000125,
        lower_nm = None,
        upper_nm = None,
    ))]
    fn step(
        &mut self,
        measured_speed_rad_per_s: f64,
        speed_rad_per_s: f64,
        feedforward_torque_nm: f64,
        dt_secs: f64,
        lower_nm: Option<f64>,
        upper_nm: Option<f64>,
    ) -> PySpeedPiOutput {
        let lower_nm = lower_nm.unwrap_or(f64::NEG_INFINITY);
        let upper_nm = upper_nm.unwrap_or(f64::INFINITY);
        let cmd = SpeedCommand {
            speed_rad_per_s,
            feedforward_torque_nm,
        };
        PySpeedPiOutput {
            inner: self.inner.step_within(
                measured_speed_rad_per_s,
                &cmd,
                dt_secs,
                lower_nm,
                upper_nm,
            ),
        }
    }
}

/// A WIP state as a plain array.
type State = [f64; 4];

/// Measurements `(n, 4)` and commands (one row, or one per measurement).
fn replay_inputs(
    py: Python<'_>,
    measured: &Arr<'_>,
    command: Option<&Arr<'_>>,
) -> PyResult<(Vec<State>, Vec<State>)> {
    let m: Rows<4> = rows(py, measured, "measured")?;
    let c = match command {
        Some(c) => {
            let c: Rows<4> = rows(py, c, "command")?;
            if !c.single && c.rows.len() != m.rows.len() {
                return Err(error(
                    py,
                    Kind::Shape,
                    format!(
                        "`command` must have shape (4,) or ({}, 4) like `measured`, got ({}, 4)",
                        m.rows.len(),
                        c.rows.len()
                    ),
                ));
            }
            c.rows
        }
        None => vec![[0.0; 4]],
    };
    Ok((m.rows, c))
}

/// Output columns as a dict of `(n,)` arrays plus int8 `status`.
type Column<O> = (&'static str, fn(&O) -> f64);

fn columns<'py, O>(
    py: Python<'py>,
    outs: &[O],
    fields: &[Column<O>],
    status: fn(&O) -> StepStatus,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, get) in fields {
        d.set_item(
            *name,
            PyArray1::from_vec(py, outs.iter().map(get).collect()),
        )?;
    }
    d.set_item(
        "status",
        PyArray1::from_vec(py, outs.iter().map(|o| status_code(status(o))).collect()),
    )?;
    Ok(d)
}

/// Runs `n_steps` controller periods from each initial state on the planar simulator's
/// scheduler (`ballbot_sim::planar::rollout`, the one planar loop); appends the flat states
/// (per trajectory `n_steps + 1` rows of 4), torques and status codes (`n_steps` each).
#[allow(clippy::too_many_arguments)]
fn run_rollouts(
    plant: &Wip<f64>,
    controller: &RolloutController,
    initial: &[[f64; 4]],
    commands: &[[f64; 4]],
    settings: &RolloutSettings,
    states: &mut Vec<f64>,
    torques: &mut Vec<f64>,
    statuses: &mut Vec<i8>,
) -> Result<(), PlanarError> {
    let commands: Vec<WipState<f64>> = commands.iter().map(|c| Vector4::from(*c)).collect();
    for s0 in initial {
        let run = rollout(
            *plant.params(),
            controller,
            Vector4::from(*s0),
            &commands,
            settings,
        )?;
        for s in &run.states {
            states.extend_from_slice(s.as_slice());
        }
        torques.extend_from_slice(&run.torque_nm);
        statuses.extend(run.status.iter().map(|s| status_code(*s)));
    }
    Ok(())
}

/// Closed-loop rollouts of `controller` on the nonlinear WIP `plant`, entirely in Rust and
/// without the GIL.
///
/// From each initial state (`(4,)`, or `(n, 4)` for a batch) the controller (a copy of it, as
/// it is now: the caller's object is not stepped) runs `n_steps` periods of `dt_secs` (default
/// 1/400 s). Its torque is held over the period while the plant advances by `substeps` RK4
/// steps. An `LqrPiOuter` needs its inner loop `inner` (a `SpeedPi`), which then runs at every
/// substep in the drive, on the joint (motor) rate its encoder measures, the ball-rate
/// reference shifted by the tilt rate of the outer sample (the paper: 400 Hz outer, 8 kHz inner,
/// `substeps=20`). The loop is the planar simulator's scheduler on the ideal WIP (no friction,
/// no actuator limit beyond the controllers' own, perfect sensors, no delay); a state that
/// becomes non-finite ends the trajectory with NaN rows of status 2.
/// `command` is a WIP state `(4,)` held throughout, or one per period `(n_steps, 4)`.
///
/// Returns a dict: `time_secs` `(n_steps + 1,)`; `state` `(n_steps + 1, 4)` or
/// `(n, n_steps + 1, 4)`; `torque_nm` (the mean torque applied over each period) and `status`
/// (int8: 0 nominal, 1 saturated, 2 invalid input) `(n_steps,)` or `(n, n_steps)`; and
/// `compute_secs`, the time spent in the Rust loop. Raises `ParameterError` for a bad
/// `dt_secs`/`substeps`/`inner`, `ShapeError` for bad shapes, `MemoryError` when the result
/// cannot be allocated.
#[pyfunction]
#[pyo3(signature = (
    plant, controller, initial_state, *, n_steps, dt_secs = 0.0025, command = None,
    inner = None, substeps = 1,
))]
#[allow(clippy::too_many_arguments)]
fn closed_loop_rollout<'py>(
    py: Python<'py>,
    plant: PyRef<'py, PyWip>,
    controller: &Bound<'py, PyAny>,
    initial_state: Arr<'py>,
    n_steps: usize,
    dt_secs: f64,
    command: Option<Arr<'py>>,
    inner: Option<PyRef<'py, PySpeedPi>>,
    substeps: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if !(dt_secs.is_finite() && dt_secs > 0.0) {
        return Err(error(
            py,
            Kind::Parameter,
            "invalid parameter `dt_secs`: must be finite and > 0",
        ));
    }
    if substeps == 0 {
        return Err(error(
            py,
            Kind::Parameter,
            "invalid parameter `substeps`: must be >= 1",
        ));
    }
    let ctrl = if let Ok(c) = controller.cast::<PyLqrController>() {
        RolloutController::Lqr(c.borrow().inner)
    } else if let Ok(c) = controller.cast::<PyPiPdController>() {
        RolloutController::PiPd(c.borrow().inner)
    } else if let Ok(c) = controller.cast::<PyLqrPiOuter>() {
        let Some(inner) = &inner else {
            return Err(error(
                py,
                Kind::Parameter,
                "an LqrPiOuter controller needs its inner loop: pass `inner=SpeedPi(...)`",
            ));
        };
        RolloutController::LqrPi {
            outer: c.borrow().inner,
            inner: inner.inner,
        }
    } else {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "`controller` must be an LqrController, PiPdController or LqrPiOuter",
        ));
    };
    if inner.is_some() && !matches!(ctrl, RolloutController::LqrPi { .. }) {
        return Err(error(
            py,
            Kind::Parameter,
            "`inner` is only used with an LqrPiOuter controller",
        ));
    }
    let init: Rows<4> = rows(py, &initial_state, "initial_state")?;
    let commands = match &command {
        Some(c) => {
            let c: Rows<4> = rows(py, c, "command")?;
            if !c.single && c.rows.len() != n_steps {
                return Err(error(
                    py,
                    Kind::Shape,
                    format!(
                        "`command` must have shape (4,) or (n_steps, 4) = ({n_steps}, 4), got \
                         ({}, 4)",
                        c.rows.len()
                    ),
                ));
            }
            if c.rows.is_empty() {
                vec![[0.0; 4]]
            } else {
                c.rows
            }
        }
        None => vec![[0.0; 4]],
    };
    let n = init.rows.len();
    let too_big = || {
        pyo3::exceptions::PyMemoryError::new_err(format!(
            "a rollout of {n} trajectories x {n_steps} steps is too large"
        ))
    };
    let state_len = n
        .checked_mul(n_steps.checked_add(1).ok_or_else(too_big)?)
        .and_then(|x| x.checked_mul(4))
        .ok_or_else(too_big)?;
    let step_len = n.checked_mul(n_steps).ok_or_else(too_big)?;
    let mut states = reserve::<f64>(state_len)?;
    let mut torques = reserve::<f64>(step_len)?;
    let mut statuses = reserve::<i8>(step_len)?;
    let wip = plant.inner;
    let settings = RolloutSettings {
        dt_secs,
        n_steps,
        substeps,
    };
    let (result, compute_secs) = py.detach(|| {
        let start = std::time::Instant::now();
        let result = run_rollouts(
            &wip,
            &ctrl,
            &init.rows,
            &commands,
            &settings,
            &mut states,
            &mut torques,
            &mut statuses,
        );
        (result, start.elapsed().as_secs_f64())
    });
    result.map_err(|e| error(py, Kind::Parameter, e.to_string()))?;
    let time: Vec<f64> = (0..=n_steps).map(|k| k as f64 * dt_secs).collect();
    let d = PyDict::new(py);
    d.set_item("time_secs", PyArray1::from_vec(py, time))?;
    let (state_shape, step_shape): (Vec<usize>, Vec<usize>) = if init.single {
        (vec![n_steps + 1, 4], vec![n_steps])
    } else {
        (vec![n, n_steps + 1, 4], vec![n, n_steps])
    };
    d.set_item("state", array_out(py, states, &state_shape)?)?;
    d.set_item("torque_nm", array_out(py, torques, &step_shape)?)?;
    let status: Bound<'py, PyArrayDyn<i8>> = {
        use numpy::PyArrayMethods;
        PyArray1::from_vec(py, statuses)
            .reshape(step_shape)?
            .to_dyn()
            .clone()
    };
    d.set_item("status", status)?;
    d.set_item("compute_secs", compute_secs)?;
    Ok(d)
}

/// The steady command that accelerates the ball at `ball_accel_rad_per_s2` while rolling at
/// `ball_rate_rad_per_s` on `wip`'s nonlinear model (`theta_dot = 0`, constant `phi_ddot`):
/// `(command_state (4,), torque_nm)`, the lean and torque that hold that acceleration; `None`
/// when no lean can hold it (or for non-finite input).
#[pyfunction(name = "accelerating_command")]
fn py_accelerating_command<'py>(
    py: Python<'py>,
    wip: PyRef<'py, PyWip>,
    ball_rate_rad_per_s: f64,
    ball_accel_rad_per_s2: f64,
) -> Option<(Bound<'py, PyArray1<f64>>, f64)> {
    ballbot_core::control::accelerating_command(
        &wip.inner,
        ball_rate_rad_per_s,
        ball_accel_rad_per_s2,
    )
    .map(|(s, tau)| (PyArray1::from_slice(py, s.as_slice()), tau))
}

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
