//! The WIP and spin models.

use crate::arrays::{broadcast, column_out, reserve, rows, rows_out};
use crate::errors::core_error;
use crate::params::{PySpinParams, PyWipParams};
use ballbot_core::{Spin, Wip};
use nalgebra::{Vector2, Vector4};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayDyn, PyArrayLikeDyn, ToPyArray};
use pyo3::prelude::*;

/// A linear model `(A, B)` as numpy arrays.
type StateSpace<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// The planar wheeled inverted pendulum (`ballbot_core::Wip`), vectorised over states.
#[pyclass(name = "Wip", module = "ballbot", frozen)]
pub struct PyWip {
    /// The core model.
    pub inner: Wip<f64>,
}

#[pymethods]
impl PyWip {
    #[new]
    fn py_new(py: Python<'_>, params: PyWipParams) -> PyResult<Self> {
        let inner = Wip::new(params.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The parameters.
    #[getter]
    fn params(&self) -> PyWipParams {
        PyWipParams {
            inner: *self.inner.params(),
        }
    }

    /// `[theta_ddot, phi_ddot]` for state(s) of shape (4,) or (n, 4) and torque(s).
    #[pyo3(signature = (state, torque_nm = None))]
    fn accelerations<'py>(
        &self,
        py: Python<'py>,
        state: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        torque_nm: Option<PyArrayLikeDyn<'py, f64, AllowTypeChange>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let s = rows::<4>(py, &state, "state")?;
        let tau = match torque_nm {
            Some(t) => broadcast(py, &t, s.rows.len(), "torque_nm")?,
            None => vec![0.0; s.rows.len()],
        };
        let out: Vec<[f64; 2]> = s
            .rows
            .iter()
            .zip(&tau)
            .map(|(r, t)| {
                let a = self.inner.accelerations(&Vector4::from(*r), *t);
                [a[0], a[1]]
            })
            .collect();
        rows_out(py, out, s.single)
    }

    /// State derivative for state(s) of shape (4,) or (n, 4) and torque(s).
    #[pyo3(signature = (state, torque_nm = None))]
    fn derivative<'py>(
        &self,
        py: Python<'py>,
        state: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        torque_nm: Option<PyArrayLikeDyn<'py, f64, AllowTypeChange>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let s = rows::<4>(py, &state, "state")?;
        let tau = match torque_nm {
            Some(t) => broadcast(py, &t, s.rows.len(), "torque_nm")?,
            None => vec![0.0; s.rows.len()],
        };
        let out: Vec<[f64; 4]> = s
            .rows
            .iter()
            .zip(&tau)
            .map(|(r, t)| self.inner.derivative(&Vector4::from(*r), *t).into())
            .collect();
        rows_out(py, out, s.single)
    }

    /// Total mechanical energy (J) of state(s) of shape (4,) or (n, 4).
    fn energy_j<'py>(
        &self,
        py: Python<'py>,
        state: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let s = rows::<4>(py, &state, "state")?;
        let out = s
            .rows
            .iter()
            .map(|r| self.inner.energy_j(&Vector4::from(*r)))
            .collect();
        column_out(py, out, s.single)
    }

    /// Analytic linearisation `(A (4, 4), B (4,))` at a state (default upright) and torque.
    #[pyo3(signature = (state = None, torque_nm = 0.0))]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        state: Option<PyArrayLikeDyn<'py, f64, AllowTypeChange>>,
        torque_nm: f64,
    ) -> PyResult<StateSpace<'py>> {
        let s = match state {
            Some(state) => {
                let r = rows::<4>(py, &state, "state")?;
                if !r.single {
                    return Err(crate::errors::error(
                        py,
                        crate::errors::Kind::Shape,
                        "`state` must have shape (4,) for linearize",
                    ));
                }
                Vector4::from(r.rows[0])
            }
            None => Vector4::zeros(),
        };
        let lin = self.inner.linearize(&s, torque_nm);
        let a: Vec<Vec<f64>> = (0..4)
            .map(|i| (0..4).map(|j| lin.A[(i, j)]).collect())
            .collect();
        let a = PyArray2::from_vec2(py, &a)
            .map_err(|e| crate::errors::error(py, crate::errors::Kind::Other, e.to_string()))?;
        Ok((a, lin.B.as_slice().to_pyarray(py)))
    }

    /// Growth rate of the unstable upright mode of the frictionless model (rad/s).
    fn upright_unstable_pole_rad_per_s(&self) -> f64 {
        self.inner.upright_unstable_pole_rad_per_s()
    }

    /// Eigenvalues of the upright linearisation (complex array of 4).
    fn open_loop_poles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<numpy::Complex64>> {
        let eig = self.inner.linearize_upright().A.complex_eigenvalues();
        let v: Vec<numpy::Complex64> = eig
            .iter()
            .map(|z| numpy::Complex64::new(z.re, z.im))
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// Integrates `n_steps` RK4 steps of `dt_secs` under a constant torque from `state` (4,);
    /// returns the (n_steps + 1, 4) trajectory. Runs without the GIL.
    #[pyo3(signature = (state, dt_secs, n_steps, torque_nm = 0.0))]
    fn rollout<'py>(
        &self,
        py: Python<'py>,
        state: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        dt_secs: f64,
        n_steps: usize,
        torque_nm: f64,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let r = rows::<4>(py, &state, "state")?;
        if !r.single {
            return Err(crate::errors::error(
                py,
                crate::errors::Kind::Shape,
                "`state` must have shape (4,) for rollout",
            ));
        }
        if !(dt_secs.is_finite() && dt_secs > 0.0) {
            return Err(crate::errors::error(
                py,
                crate::errors::Kind::Parameter,
                "invalid parameter `dt_secs`: must be finite and > 0",
            ));
        }
        let wip = self.inner;
        let s0 = Vector4::from(r.rows[0]);
        let mut out = reserve::<[f64; 4]>(n_steps.saturating_add(1))?;
        let out = py.detach(move || {
            let mut s = s0;
            out.push(<[f64; 4]>::from(s));
            for _ in 0..n_steps {
                s = ballbot_core::rk4_step(|x| wip.derivative(x, torque_nm), &s, dt_secs);
                out.push(s.into());
            }
            out
        });
        rows_out(py, out, false)
    }
}

/// The spin model (`ballbot_core::Spin`).
#[pyclass(name = "Spin", module = "ballbot", frozen)]
pub struct PySpin {
    /// The core model.
    pub inner: Spin<f64>,
}

#[pymethods]
impl PySpin {
    #[new]
    fn py_new(py: Python<'_>, params: PySpinParams) -> PyResult<Self> {
        let inner = Spin::new(params.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// `[theta_z_dot, theta_z_ddot]` at state `[theta_z, theta_z_dot]` and yaw torque.
    fn derivative<'py>(
        &self,
        py: Python<'py>,
        state: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        torque_nm: f64,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let s = rows::<2>(py, &state, "state")?;
        let out: Vec<[f64; 2]> = s
            .rows
            .iter()
            .map(|r| self.inner.derivative(&Vector2::from(*r), torque_nm).into())
            .collect();
        rows_out(py, out, s.single)
    }

    /// The state space `(A (2, 2), B (2,))`.
    fn state_space<'py>(&self, py: Python<'py>) -> PyResult<StateSpace<'py>> {
        let (a, b) = self.inner.state_space();
        let rows: Vec<Vec<f64>> = (0..2)
            .map(|i| (0..2).map(|j| a[(i, j)]).collect())
            .collect();
        let a = PyArray2::from_vec2(py, &rows)
            .map_err(|e| crate::errors::error(py, crate::errors::Kind::Other, e.to_string()))?;
        Ok((a, b.as_slice().to_pyarray(py)))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWip>()?;
    m.add_class::<PySpin>()?;
    Ok(())
}
