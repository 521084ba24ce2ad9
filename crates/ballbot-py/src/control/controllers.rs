//! The planar controllers with `step` and `step_many` (a log replay in Rust).

use super::gains::{PyLqrGains, PyLqrPiOuterConfig, PyPiPdGains, PySpeedPiGains};
use super::outputs::{PyLqrOutput, PyLqrPiOuterOutput, PyPiPdOutput, PySpeedPiOutput};
use crate::arrays::{Rows, rows, vec4};
use crate::enums::step_status_code;
use crate::errors::{Kind, core_error, error};
use crate::models::PyWip;
use ballbot_core::WipState;
use ballbot_core::control::{
    LqrController, LqrPiOuter, PiPdController, PlaneController, PlaneOutput, SpeedCommand, SpeedPi,
    Terms,
};
use ballbot_core::rates::{INNER_LOOP_DT_SECS, OUTER_LOOP_DT_SECS};
use nalgebra::Vector4;
use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// The command state: zeros when omitted.
pub(crate) fn command4(
    py: Python<'_>,
    command: Option<&Bound<'_, PyAny>>,
) -> PyResult<WipState<f64>> {
    Ok(match command {
        Some(c) => Vector4::from(vec4(py, c, "command")?),
        None => Vector4::zeros(),
    })
}

/// The paper's LQR torque controller (`ballbot_core::control::LqrController`).
#[pyclass(name = "LqrController", module = "ballbot")]
pub struct PyLqrController {
    pub(crate) inner: LqrController<f64>,
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
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
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
    /// `status` as int8 codes (`StepStatus.from_code`, `StepStatus.decode`).
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
    fn step_many<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr<'py>,
        command: Option<Arr<'py>>,
        dt_secs: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        replay(py, &mut self.inner, &measured, command.as_ref(), dt_secs)
    }
}

/// The cascaded PI-PD controller (`ballbot_core::control::PiPdController`).
#[pyclass(name = "PiPdController", module = "ballbot")]
pub struct PyPiPdController {
    pub(crate) inner: PiPdController<f64>,
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
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
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
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
    fn step_many<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr<'py>,
        command: Option<Arr<'py>>,
        dt_secs: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        replay(py, &mut self.inner, &measured, command.as_ref(), dt_secs)
    }
}

/// The outer part of the cascaded LQR-PI (`ballbot_core::control::LqrPiOuter`).
#[pyclass(name = "LqrPiOuter", module = "ballbot")]
pub struct PyLqrPiOuter {
    pub(crate) inner: LqrPiOuter<f64>,
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
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
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

    /// Steps through measurements `(n, 4)` in Rust, the reference rate carried from step to
    /// step (see `LqrController.step_many`).
    #[pyo3(signature = (measured, command = None, dt_secs = OUTER_LOOP_DT_SECS))]
    fn step_many<'py>(
        &mut self,
        py: Python<'py>,
        measured: Arr<'py>,
        command: Option<Arr<'py>>,
        dt_secs: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        replay(py, &mut self.inner, &measured, command.as_ref(), dt_secs)
    }
}

/// The inner speed PI with feedforward and anti-windup (`ballbot_core::control::SpeedPi`).
#[pyclass(name = "SpeedPi", module = "ballbot")]
pub struct PySpeedPi {
    pub(crate) inner: SpeedPi<f64>,
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
        dt_secs = INNER_LOOP_DT_SECS,
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
pub(crate) type State = [f64; 4];

/// Measurements `(n, 4)` and commands (one row, or one per measurement).
pub(crate) fn replay_inputs(
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

/// Steps `ctrl` through the measurements in Rust (the GIL released) and returns its output
/// terms as a dict of `(n,)` arrays, one per `Terms::TERM_NAMES` entry, plus int8 `status`:
/// one replay for every plane controller.
fn replay<'py, C>(
    py: Python<'py>,
    ctrl: &mut C,
    measured: &Arr<'py>,
    command: Option<&Arr<'py>>,
    dt_secs: f64,
) -> PyResult<Bound<'py, PyDict>>
where
    C: PlaneController<f64> + Copy + Send,
    C::Output: Send,
{
    let (m, c) = replay_inputs(py, measured, command)?;
    let mut stepped = *ctrl;
    let outs = py.detach(|| {
        m.iter()
            .zip(c.iter().cycle())
            .map(|(m, c)| stepped.step(&Vector4::from(*m), &Vector4::from(*c), dt_secs))
            .collect::<Vec<_>>()
    });
    *ctrl = stepped;
    let names = <C::Output as Terms<f64>>::TERM_NAMES;
    let mut columns: Vec<Vec<f64>> = names
        .iter()
        .map(|_| Vec::with_capacity(outs.len()))
        .collect();
    for out in &outs {
        let mut column = columns.iter_mut();
        out.for_each_term(|_, value| {
            if let Some(c) = column.next() {
                c.push(value);
            }
        });
    }
    let status = outs.iter().map(|o| step_status_code(o.status())).collect();
    let terms = names
        .iter()
        .zip(columns)
        .map(|(name, values)| (*name, PyArray1::from_vec(py, values).into_any()));
    let status = ("status", PyArray1::<i8>::from_vec(py, status).into_any());
    terms.chain(std::iter::once(status)).into_py_dict(py)
}
