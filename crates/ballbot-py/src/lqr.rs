//! LQR synthesis (`ballbot_core::lqr`) and the linear-algebra helpers it rests on
//! (`ballbot_core::linalg`: matrix exponential, zero-order hold).
//!
//! The core is fixed-size; Python arrays are not. The functions here dispatch on the array
//! sizes to the core's monomorphised code for `1 <= n <= 6` states and `1 <= m <= 3` inputs.

use crate::arrays::{array_out, matrix};
use crate::control::PyLqrGains;
use crate::errors::{Kind, core_error, error};
use crate::models::{PySpin, PyWip};
use ballbot_core::control::LqrGains;
use ballbot_core::lqr::{
    Lqr, LqrWeights, RiccatiSettings, RiccatiSolution, RiccatiStatus, solve_care, solve_dare,
};
use ballbot_core::rates::OUTER_LOOP_DT_SECS;
use nalgebra::{Complex, SMatrix, SVector};
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;
type Out<'py> = PyResult<Bound<'py, PyArrayDyn<f64>>>;
type Dyn<'py> = Bound<'py, PyArrayDyn<f64>>;

/// The largest state dimension the generic functions accept.
const MAX_STATES: usize = 6;
/// The largest input dimension the Riccati solvers accept.
const MAX_INPUTS: usize = 3;

/// Runs `$body` with `const $N: usize` bound to the runtime value `$n` (1 to 6).
macro_rules! with_states {
    ($n:expr, $N:ident => $body:expr, else $other:expr) => {
        match $n {
            1 => {
                const $N: usize = 1;
                $body
            }
            2 => {
                const $N: usize = 2;
                $body
            }
            3 => {
                const $N: usize = 3;
                $body
            }
            4 => {
                const $N: usize = 4;
                $body
            }
            5 => {
                const $N: usize = 5;
                $body
            }
            6 => {
                const $N: usize = 6;
                $body
            }
            _ => $other,
        }
    };
}

/// Runs `$body` with `const $M: usize` bound to the runtime value `$m` (1 to 3).
macro_rules! with_inputs {
    ($m:expr, $M:ident => $body:expr, else $other:expr) => {
        match $m {
            1 => {
                const $M: usize = 1;
                $body
            }
            2 => {
                const $M: usize = 2;
                $body
            }
            3 => {
                const $M: usize = 3;
                $body
            }
            _ => $other,
        }
    };
}

fn to_smatrix<const R: usize, const C: usize>(values: &[f64]) -> SMatrix<f64, R, C> {
    SMatrix::from_row_iterator(values.iter().copied())
}

fn from_smatrix<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> Vec<f64> {
    let mut v = Vec::with_capacity(R * C);
    for i in 0..R {
        for j in 0..C {
            v.push(m[(i, j)]);
        }
    }
    v
}

/// A plant `(A (n, n), B (n, m))` read and checked; `B` may be 1-D for a single input.
struct Plant {
    n: usize,
    m: usize,
    a: Vec<f64>,
    b: Vec<f64>,
}

fn plant(py: Python<'_>, a: &Arr<'_>, b: &Arr<'_>, max_inputs: usize) -> PyResult<Plant> {
    let (ar, ac, av) = matrix(py, a, "a", false)?;
    if ar != ac || ar == 0 || ar > MAX_STATES {
        return Err(error(
            py,
            Kind::Shape,
            format!("`a` must have shape (n, n) with 1 <= n <= {MAX_STATES}, got ({ar}, {ac})"),
        ));
    }
    let (br, bc, bv) = matrix(py, b, "b", true)?;
    if br != ar || bc == 0 || bc > max_inputs {
        return Err(error(
            py,
            Kind::Shape,
            format!(
                "`b` must have shape ({ar},) or ({ar}, m) with 1 <= m <= {max_inputs}, got \
                 ({br}, {bc})"
            ),
        ));
    }
    Ok(Plant {
        n: ar,
        m: bc,
        a: av,
        b: bv,
    })
}

/// A state weight: `(n,)` for a diagonal, or `(n, n)`.
fn state_weight(py: Python<'_>, q: &Arr<'_>, n: usize) -> PyResult<Vec<f64>> {
    let shape = q.shape().to_vec();
    let (r, c, v) = matrix(py, q, "q", true)?;
    if r == n && c == 1 && shape.len() == 1 {
        let mut full = vec![0.0; n * n];
        for (i, d) in v.iter().enumerate() {
            full[i * n + i] = *d;
        }
        return Ok(full);
    }
    if r == n && c == n {
        return Ok(v);
    }
    Err(error(
        py,
        Kind::Shape,
        format!("`q` must have shape ({n},) (a diagonal) or ({n}, {n}), got {shape:?}"),
    ))
}

/// An input weight: a scalar (one input), `(m,)` for a diagonal, or `(m, m)`.
fn input_weight(py: Python<'_>, r: &Arr<'_>, m: usize) -> PyResult<Vec<f64>> {
    let shape = r.shape().to_vec();
    let values: Vec<f64> = r.as_array().iter().copied().collect();
    match shape.as_slice() {
        [] if m == 1 => Ok(values),
        [k] if *k == m => {
            let mut full = vec![0.0; m * m];
            for (i, d) in values.iter().enumerate() {
                full[i * m + i] = *d;
            }
            Ok(full)
        }
        [k, l] if *k == m && *l == m => Ok(values),
        _ => Err(error(
            py,
            Kind::Shape,
            format!("`r` must be a scalar (one input), shape ({m},) or ({m}, {m}), got {shape:?}"),
        )),
    }
}

/// A single-input LQR design (`ballbot_core::lqr::Lqr`): the gain `k` for
/// `u = k . (s_c - s)`, the closed loop, the cost-to-go and how the Riccati solve went.
#[pyclass(name = "Lqr", module = "ballbot", frozen)]
pub struct PyLqr {
    n: usize,
    gain: Vec<f64>,
    closed_loop: Vec<f64>,
    cost_to_go: Vec<f64>,
    dt_secs: Option<f64>,
    iterations: u32,
    residual: f64,
    eigenvalues: Option<Vec<Complex<f64>>>,
}

impl PyLqr {
    fn from_core<const N: usize>(
        lqr: &Lqr<f64, N>,
        eigenvalues: Option<Vec<Complex<f64>>>,
    ) -> Self {
        Self {
            n: N,
            gain: lqr.gain.iter().copied().collect(),
            closed_loop: from_smatrix(&lqr.closed_loop),
            cost_to_go: from_smatrix(&lqr.cost_to_go),
            dt_secs: lqr.dt_secs,
            iterations: lqr.iterations,
            residual: lqr.residual,
            eigenvalues,
        }
    }

    /// The gain as a 3-state WIP gain, or a `ShapeError`.
    pub fn wip_gain(&self, py: Python<'_>) -> PyResult<[f64; 3]> {
        match self.gain.as_slice() {
            [k1, k2, k3] => Ok([*k1, *k2, *k3]),
            _ => Err(error(
                py,
                Kind::Shape,
                format!(
                    "this LQR has {} states; WIP gains need the reduced state [theta, \
                     theta_dot, phi_dot] (3)",
                    self.n
                ),
            )),
        }
    }
}

/// Designs a continuous (`dt_secs = None`) or discrete LQR on an `n`-state single-input plant.
fn design(
    py: Python<'_>,
    n: usize,
    a: &[f64],
    b: &[f64],
    q: &[f64],
    r: f64,
    dt_secs: Option<f64>,
) -> PyResult<PyLqr> {
    let result = py.detach(|| {
        with_states!(n, N => {
            let a = to_smatrix::<N, N>(a);
            let b = SVector::<f64, N>::from_iterator(b.iter().copied());
            let weights = LqrWeights::new(to_smatrix::<N, N>(q), r);
            let lqr = match dt_secs {
                None => Lqr::continuous(&a, &b, &weights),
                Some(dt) => Lqr::discrete(&a, &b, &weights, dt),
            };
            lqr.map(|lqr| {
                let eig = ballbot_core::linalg::eigenvalues(&lqr.closed_loop)
                    .map(|e| e.iter().copied().collect());
                PyLqr::from_core(&lqr, eig)
            })
        }, else Err(ballbot_core::Error::invalid("a", "size out of range")))
    });
    result.map_err(|e| core_error(py, e))
}

#[pymethods]
impl PyLqr {
    /// Continuous-time LQR for `s_dot = A s + B u`, one input: `a` (n, n), `b` (n,), `q`
    /// (n,) diagonal or (n, n), `r` > 0. Raises `SolverError` when no stabilising gain exists.
    #[staticmethod]
    fn continuous(py: Python<'_>, a: Arr<'_>, b: Arr<'_>, q: Arr<'_>, r: f64) -> PyResult<Self> {
        let p = plant(py, &a, &b, 1)?;
        let q = state_weight(py, &q, p.n)?;
        design(py, p.n, &p.a, &p.b, &q, r, None)
    }

    /// Discrete-time LQR at `dt_secs` on the zero-order-hold discretisation of `(a, b)`, with
    /// the same weights per sample.
    #[staticmethod]
    fn discrete(
        py: Python<'_>,
        a: Arr<'_>,
        b: Arr<'_>,
        q: Arr<'_>,
        r: f64,
        dt_secs: f64,
    ) -> PyResult<Self> {
        let p = plant(py, &a, &b, 1)?;
        let q = state_weight(py, &q, p.n)?;
        design(py, p.n, &p.a, &p.b, &q, r, Some(dt_secs))
    }

    /// The gain `k` (n,) in `u = k . (s_c - s)`.
    #[getter]
    fn gain<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.gain)
    }

    /// The closed-loop matrix `A - B k^T` (n, n); the sampled one for a discrete design.
    #[getter]
    fn closed_loop<'py>(&self, py: Python<'py>) -> Out<'py> {
        array_out(py, self.closed_loop.clone(), &[self.n, self.n])
    }

    /// The Riccati solution `X` (n, n): the cost-to-go is `s^T X s`.
    #[getter]
    fn cost_to_go<'py>(&self, py: Python<'py>) -> Out<'py> {
        array_out(py, self.cost_to_go.clone(), &[self.n, self.n])
    }

    /// The sample time of a discrete design (s); `None` for a continuous one.
    #[getter]
    fn dt_secs(&self) -> Option<f64> {
        self.dt_secs
    }

    /// Doubling steps the Riccati solve took.
    #[getter]
    fn iterations(&self) -> u32 {
        self.iterations
    }

    /// The Riccati solve's relative residual.
    #[getter]
    fn residual(&self) -> f64 {
        self.residual
    }

    /// Eigenvalues of the closed loop (complex, (n,)): poles in rad/s for a continuous
    /// design, z-plane eigenvalues for a discrete one.
    fn closed_loop_eigenvalues<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Bound<'py, PyArray1<numpy::Complex64>>> {
        match &self.eigenvalues {
            Some(e) => Ok(PyArray1::from_vec(
                py,
                e.iter()
                    .map(|z| numpy::Complex64::new(z.re, z.im))
                    .collect(),
            )),
            None => Err(error(
                py,
                Kind::Solver,
                "the eigenvalue iteration of the closed loop did not converge",
            )),
        }
    }

    /// The control `u = k . (reference - measured)` for states of shape (n,).
    fn control(&self, py: Python<'_>, reference: Arr<'_>, measured: Arr<'_>) -> PyResult<f64> {
        let read = |x: &Arr<'_>, name: &str| -> PyResult<Vec<f64>> {
            if x.shape() != [self.n] {
                return Err(error(
                    py,
                    Kind::Shape,
                    format!(
                        "`{name}` must have shape ({},), got {:?}",
                        self.n,
                        x.shape()
                    ),
                ));
            }
            Ok(x.as_array().iter().copied().collect())
        };
        let reference = read(&reference, "reference")?;
        let measured = read(&measured, "measured")?;
        Ok(self
            .gain
            .iter()
            .zip(reference.iter().zip(&measured))
            .map(|(k, (r, m))| k * (r - m))
            .sum())
    }

    /// The WIP gains `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]` (3-state designs only).
    fn reduced_gains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_slice(py, &self.wip_gain(py)?))
    }

    /// The paper's `[k1, 0, k2, k3]` on `[theta, phi, theta_dot, phi_dot]` (3-state designs).
    fn paper_gains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let [k1, k2, k3] = self.wip_gain(py)?;
        Ok(PyArray1::from_slice(py, &[k1, 0.0, k2, k3]))
    }

    /// The gains for an `LqrController` with torque limit `max_torque_nm` (3-state designs).
    fn controller_gains(&self, py: Python<'_>, max_torque_nm: f64) -> PyResult<PyLqrGains> {
        let gains = LqrGains::from_reduced(self.wip_gain(py)?, max_torque_nm);
        gains.validate().map_err(|e| core_error(py, e))?;
        Ok(PyLqrGains { inner: gains })
    }

    fn __repr__(&self) -> String {
        format!(
            "Lqr(gain={:?}, dt_secs={:?}, iterations={}, residual={:e})",
            self.gain, self.dt_secs, self.iterations, self.residual
        )
    }
}

/// WIP weights: `None` for MODEL.md's `diag(100, 10, 1)`.
fn wip_weights(py: Python<'_>, q: Option<Arr<'_>>) -> PyResult<Vec<f64>> {
    match q {
        Some(q) => state_weight(py, &q, 3),
        None => Ok(from_smatrix(&LqrWeights::<f64, 3>::model_default().q)),
    }
}

/// Continuous LQR for the WIP on `[theta, theta_dot, phi_dot]`, designed on the upright
/// linearisation. Defaults: MODEL.md's `q = diag(100, 10, 1)`, `r = 0.1`.
#[pyfunction]
#[pyo3(signature = (wip, q = None, r = 0.1))]
fn wip_lqr(py: Python<'_>, wip: PyRef<'_, PyWip>, q: Option<Arr<'_>>, r: f64) -> PyResult<PyLqr> {
    let (a, b) = wip.inner.linearize_upright().reduced();
    let q = wip_weights(py, q)?;
    design(py, 3, &from_smatrix(&a), b.as_slice(), &q, r, None)
}

/// Discrete LQR for the WIP on `[theta, theta_dot, phi_dot]` at `dt_secs` (default the
/// paper's 400 Hz), on the zero-order-hold discretisation of the upright linearisation.
#[pyfunction]
#[pyo3(signature = (wip, dt_secs = OUTER_LOOP_DT_SECS, q = None, r = 0.1))]
fn wip_lqr_discrete(
    py: Python<'_>,
    wip: PyRef<'_, PyWip>,
    dt_secs: f64,
    q: Option<Arr<'_>>,
    r: f64,
) -> PyResult<PyLqr> {
    let (a, b) = wip.inner.linearize_upright().reduced();
    let q = wip_weights(py, q)?;
    design(py, 3, &from_smatrix(&a), b.as_slice(), &q, r, Some(dt_secs))
}

/// Continuous LQR for the spin model on `[theta_z, theta_z_dot]`.
#[pyfunction]
fn spin_lqr(py: Python<'_>, spin: PyRef<'_, PySpin>, q: Arr<'_>, r: f64) -> PyResult<PyLqr> {
    let (a, b) = spin.inner.state_space();
    let q = state_weight(py, &q, 2)?;
    design(py, 2, &from_smatrix(&a), b.as_slice(), &q, r, None)
}

/// Discrete LQR for the spin model at `dt_secs` (zero-order hold).
#[pyfunction]
fn spin_lqr_discrete(
    py: Python<'_>,
    spin: PyRef<'_, PySpin>,
    q: Arr<'_>,
    r: f64,
    dt_secs: f64,
) -> PyResult<PyLqr> {
    let (a, b) = spin.inner.state_space();
    let q = state_weight(py, &q, 2)?;
    design(py, 2, &from_smatrix(&a), b.as_slice(), &q, r, Some(dt_secs))
}

/// The result of a Riccati solve (`ballbot_core::lqr::RiccatiSolution`).
#[pyclass(name = "RiccatiSolution", module = "ballbot", frozen)]
pub struct PyRiccatiSolution {
    n: usize,
    m: usize,
    x: Vec<f64>,
    gain: Vec<f64>,
    status: RiccatiStatus,
    iterations: u32,
    residual: f64,
}

impl PyRiccatiSolution {
    fn from_core<const N: usize, const M: usize>(s: &RiccatiSolution<f64, N, M>) -> Self {
        Self {
            n: N,
            m: M,
            x: from_smatrix(&s.x),
            gain: from_smatrix(&s.gain),
            status: s.status,
            iterations: s.iterations,
            residual: s.residual,
        }
    }
}

#[pymethods]
impl PyRiccatiSolution {
    /// The solution `X` (n, n).
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Out<'py> {
        array_out(py, self.x.clone(), &[self.n, self.n])
    }

    /// The optimal gain `K` (m, n) for `u = -K x`.
    #[getter]
    fn gain<'py>(&self, py: Python<'py>) -> Out<'py> {
        array_out(py, self.gain.clone(), &[self.m, self.n])
    }

    /// How the solve ended: a `RiccatiStatus` (`CONVERGED`, `MAX_ITERATIONS`,
    /// `NOT_STABILIZABLE` or `NON_FINITE`). Use `x` and `gain` only when converged.
    #[getter]
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::enums::riccati_status(py, self.status)
    }

    /// Doubling steps taken.
    #[getter]
    fn iterations(&self) -> u32 {
        self.iterations
    }

    /// Relative residual of the Riccati equation at `x`.
    #[getter]
    fn residual(&self) -> f64 {
        self.residual
    }

    /// Whether the status is `"converged"`.
    fn is_converged(&self) -> bool {
        self.status.is_converged()
    }

    fn __repr__(&self) -> String {
        format!(
            "RiccatiSolution(status=RiccatiStatus.{}, iterations={}, residual={:e})",
            self.status.as_str().to_uppercase(),
            self.iterations,
            self.residual
        )
    }
}

/// Solves a Riccati equation for `(a, b, q, r)`; `continuous` picks the CARE, else the DARE.
fn riccati(
    py: Python<'_>,
    a: &Arr<'_>,
    b: &Arr<'_>,
    q: &Arr<'_>,
    r: &Arr<'_>,
    continuous: bool,
) -> PyResult<PyRiccatiSolution> {
    let p = plant(py, a, b, MAX_INPUTS)?;
    let q = state_weight(py, q, p.n)?;
    let r = input_weight(py, r, p.m)?;
    let result = py.detach(|| {
        with_states!(p.n, N => {
            with_inputs!(p.m, M => {
                let a = to_smatrix::<N, N>(&p.a);
                let b = to_smatrix::<N, M>(&p.b);
                let q = to_smatrix::<N, N>(&q);
                let r = to_smatrix::<M, M>(&r);
                let settings = RiccatiSettings::default();
                let sol = if continuous {
                    solve_care(&a, &b, &q, &r, &settings)
                } else {
                    solve_dare(&a, &b, &q, &r, &settings)
                };
                sol.map(|s| PyRiccatiSolution::from_core(&s))
            }, else Err(ballbot_core::Error::invalid("b", "input count out of range")))
        }, else Err(ballbot_core::Error::invalid("a", "size out of range")))
    });
    result.map_err(|e| core_error(py, e))
}

/// Solves the continuous algebraic Riccati equation `A^T X + X A - X B R^-1 B^T X + Q = 0`
/// for `a` (n, n), `b` (n,) or (n, m), `q` (n,) or (n, n), `r` scalar, (m,) or (m, m);
/// `1 <= n <= 6`, `1 <= m <= 3`. Malformed input raises; the numerical outcome is the
/// solution's `status`.
#[pyfunction(name = "solve_care")]
fn py_solve_care(
    py: Python<'_>,
    a: Arr<'_>,
    b: Arr<'_>,
    q: Arr<'_>,
    r: Arr<'_>,
) -> PyResult<PyRiccatiSolution> {
    riccati(py, &a, &b, &q, &r, true)
}

/// Solves the discrete algebraic Riccati equation
/// `X = A^T X A - A^T X B (R + B^T X B)^-1 B^T X A + Q` (same shapes as `solve_care`).
#[pyfunction(name = "solve_dare")]
fn py_solve_dare(
    py: Python<'_>,
    a: Arr<'_>,
    b: Arr<'_>,
    q: Arr<'_>,
    r: Arr<'_>,
) -> PyResult<PyRiccatiSolution> {
    riccati(py, &a, &b, &q, &r, false)
}

/// The matrix exponential `exp(a)` of a square matrix (1 <= n <= 6).
#[pyfunction]
fn expm<'py>(py: Python<'py>, a: Arr<'py>) -> Out<'py> {
    let (r, c, v) = matrix(py, &a, "a", false)?;
    if r != c {
        return Err(error(
            py,
            Kind::Shape,
            format!("`a` must be square, got ({r}, {c})"),
        ));
    }
    let out = with_states!(r, N => {
        ballbot_core::linalg::expm(&to_smatrix::<N, N>(&v)).map(|m| from_smatrix(&m))
    }, else {
        return Err(error(
            py,
            Kind::Shape,
            format!("`a` must have shape (n, n) with 1 <= n <= {MAX_STATES}, got ({r}, {c})"),
        ));
    });
    match out {
        Some(m) => array_out(py, m, &[r, r]),
        None => Err(error(
            py,
            Kind::Parameter,
            "`a` must be finite (the matrix exponential overflowed or got NaN)",
        )),
    }
}

/// Zero-order-hold discretisation of `s_dot = A s + B u` at `dt_secs`: `(Ad (n, n), Bd)`
/// with `Bd` of the shape of `b`.
#[pyfunction]
fn zoh<'py>(
    py: Python<'py>,
    a: Arr<'py>,
    b: Arr<'py>,
    dt_secs: f64,
) -> PyResult<(Dyn<'py>, Dyn<'py>)> {
    let b_shape = b.shape().to_vec();
    let p = plant(py, &a, &b, MAX_INPUTS)?;
    let out = with_states!(p.n, N => {
        with_inputs!(p.m, M => {
            ballbot_core::linalg::zoh(
                &to_smatrix::<N, N>(&p.a),
                &to_smatrix::<N, M>(&p.b),
                dt_secs,
            )
            .map(|d| (from_smatrix(&d.a), from_smatrix(&d.b)))
        }, else Err(ballbot_core::Error::invalid("b", "input count out of range")))
    }, else Err(ballbot_core::Error::invalid("a", "size out of range")));
    let (ad, bd) = out.map_err(|e| core_error(py, e))?;
    Ok((
        array_out(py, ad, &[p.n, p.n])?,
        array_out(py, bd, &b_shape)?,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLqr>()?;
    m.add_class::<PyRiccatiSolution>()?;
    m.add_function(wrap_pyfunction!(wip_lqr, m)?)?;
    m.add_function(wrap_pyfunction!(wip_lqr_discrete, m)?)?;
    m.add_function(wrap_pyfunction!(spin_lqr, m)?)?;
    m.add_function(wrap_pyfunction!(spin_lqr_discrete, m)?)?;
    m.add_function(wrap_pyfunction!(py_solve_care, m)?)?;
    m.add_function(wrap_pyfunction!(py_solve_dare, m)?)?;
    m.add_function(wrap_pyfunction!(expm, m)?)?;
    m.add_function(wrap_pyfunction!(zoh, m)?)?;
    Ok(())
}
