//! Trajectory optimisation (`ballbot_sim::trajopt`): minimum-effort braking by direct
//! collocation and the minimum braking time. Solves run without the GIL.

use crate::arrays::{array_out, rows_out};
use crate::errors::{Kind, error};
use crate::params::{PyActuatorParams, PyDrivetrainParams, PyWipParams};
use ballbot_sim::trajopt::{
    BrakingProblem, BrakingSolution, Drive, InitialGuess, Limits, Method, MinTimeOptions,
    SolveOptions, TrajoptError, min_braking_time, solve,
};
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};
use schemars::JsonSchema;

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;
type Out<'py> = PyResult<Bound<'py, PyArrayDyn<f64>>>;

fn trajopt_error(py: Python<'_>, e: TrajoptError) -> PyErr {
    let kind = match e {
        TrajoptError::QpSetup(_) => Kind::Solver,
        _ => Kind::Parameter,
    };
    error(py, kind, e.to_string())
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::HermiteSimpson => "hermite_simpson",
        Method::Trapezoidal => "trapezoidal",
    }
}

fn parse_method(py: Python<'_>, name: &str) -> PyResult<Method> {
    match name {
        "hermite_simpson" => Ok(Method::HermiteSimpson),
        "trapezoidal" => Ok(Method::Trapezoidal),
        _ => Err(error(
            py,
            Kind::Parameter,
            format!("unknown method `{name}`; known: hermite_simpson, trapezoidal"),
        )),
    }
}

/// Path limits of a braking problem (`ballbot_sim::trajopt::Limits`); `None` leaves a
/// quantity free.
#[pyclass(name = "BrakingLimits", module = "ballbot", frozen, eq, from_py_object)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyBrakingLimits {
    inner: Limits,
}

#[pymethods]
impl PyBrakingLimits {
    /// Pickling: through the record's JSON (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle::by_json(slf.as_any(), &slf.get().inner)
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner = crate::pickle::from_json(py, text)?;

        Ok(Self { inner })
    }

    /// `actuator`: one actuator driving the wheel directly (the PIPTB). `drivetrain` with
    /// `heading_rad`: three omniwheels (MiaPURE), travel at `heading_rad` in the body frame.
    /// `traction`: every omniwheel inside its friction cone (needs `drivetrain`).
    /// `normal_force_margin_n`: the cone becomes `|F_i| <= mu (N_i - margin)` (N, >= 0; a
    /// margin > 0 needs `traction`).
    #[new]
    #[pyo3(signature = (
        *, tilt_rad = None, tilt_rate_rad_per_s = None, ball_speed_m_per_s = None,
        torque_nm = None, actuator = None, drivetrain = None, heading_rad = 0.0, traction = false,
        normal_force_margin_n = 0.0,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        tilt_rad: Option<f64>,
        tilt_rate_rad_per_s: Option<f64>,
        ball_speed_m_per_s: Option<f64>,
        torque_nm: Option<f64>,
        actuator: Option<PyActuatorParams>,
        drivetrain: Option<PyDrivetrainParams>,
        heading_rad: f64,
        traction: bool,
        normal_force_margin_n: f64,
    ) -> PyResult<Self> {
        let drive = match (actuator, drivetrain) {
            (Some(_), Some(_)) => {
                return Err(error(
                    py,
                    Kind::Parameter,
                    "give either `actuator` (direct drive) or `drivetrain` (omniwheels), not both",
                ));
            }
            (Some(a), None) => Some(Drive::Direct(a.inner)),
            (None, Some(d)) => Some(Drive::Omniwheels {
                params: d.inner,
                heading_rad,
            }),
            (None, None) => None,
        };
        let inner = Limits {
            tilt_rad,
            tilt_rate_rad_per_s,
            ball_speed_m_per_s,
            torque_nm,
            drive,
            traction,
            normal_force_margin_n,
        };
        // Validated through a problem, the only public validation entry point.
        BrakingProblem {
            limits: inner,
            ..BrakingProblem::miapure()
        }
        .validate()
        .map_err(|e| trajopt_error(py, e))?;
        Ok(Self { inner })
    }

    /// MiaPURE's actuators for travel at `heading_rad` (no traction limit).
    #[staticmethod]
    fn miapure_actuators(heading_rad: f64) -> Self {
        Self {
            inner: Limits::miapure_actuators(heading_rad),
        }
    }

    /// The PIPTB's actuator driving its wheel directly.
    #[staticmethod]
    fn piptb_actuator() -> Self {
        Self {
            inner: Limits::piptb_actuator(),
        }
    }

    /// `|theta| <=` this (rad).
    #[getter]
    fn tilt_rad(&self) -> Option<f64> {
        self.inner.tilt_rad
    }

    /// `|theta_dot| <=` this (rad/s).
    #[getter]
    fn tilt_rate_rad_per_s(&self) -> Option<f64> {
        self.inner.tilt_rate_rad_per_s
    }

    /// `|r phi_dot| <=` this (m/s).
    #[getter]
    fn ball_speed_m_per_s(&self) -> Option<f64> {
        self.inner.ball_speed_m_per_s
    }

    /// `|tau| <=` this (N m).
    #[getter]
    fn torque_nm(&self) -> Option<f64> {
        self.inner.torque_nm
    }

    /// Whether the friction cones of the omniwheels are enforced.
    #[getter]
    fn traction(&self) -> bool {
        self.inner.traction
    }

    /// Normal-force margin of the traction cones (N).
    #[getter]
    fn normal_force_margin_n(&self) -> f64 {
        self.inner.normal_force_margin_n
    }

    fn __repr__(&self) -> String {
        format!("BrakingLimits({:?})", self.inner)
    }
}

/// Minimum-effort braking of one WIP plane (`ballbot_sim::trajopt::BrakingProblem`).
#[pyclass(
    name = "BrakingProblem",
    module = "ballbot",
    frozen,
    eq,
    from_py_object
)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyBrakingProblem {
    inner: BrakingProblem,
}

#[pymethods]
impl PyBrakingProblem {
    /// Pickling: through the record's JSON (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle::by_json(slf.as_any(), &slf.get().inner)
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner: BrakingProblem = crate::pickle::from_json(py, text)?;
        inner.validate().map_err(|e| trajopt_error(py, e))?;
        Ok(Self { inner })
    }

    /// From cruise at `initial_speed_m_per_s` upright to rest upright in exactly
    /// `duration_secs`, minimising `integral tau^2 dt`; `intervals` collocation intervals
    /// (`method` `"hermite_simpson"` or `"trapezoidal"`). Defaults: the paper's MiaPURE problem.
    #[new]
    #[pyo3(signature = (
        *, plane = None, initial_speed_m_per_s = 1.4, duration_secs = 2.0, intervals = 100,
        method = "hermite_simpson", zero_end_torques = false, limits = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        plane: Option<PyWipParams>,
        initial_speed_m_per_s: f64,
        duration_secs: f64,
        intervals: usize,
        method: &str,
        zero_end_torques: bool,
        limits: Option<PyBrakingLimits>,
    ) -> PyResult<Self> {
        let inner = BrakingProblem {
            plane: plane.map_or_else(|| BrakingProblem::miapure().plane, |p| p.inner),
            initial_speed_m_per_s,
            duration_secs,
            intervals,
            method: parse_method(py, method)?,
            zero_end_torques,
            limits: limits.map_or_else(Limits::none, |l| l.inner),
        };
        inner.validate().map_err(|e| trajopt_error(py, e))?;
        Ok(Self { inner })
    }

    /// The paper's MiaPURE problem: 1.4 m/s to rest in 2 s, 100 Hermite-Simpson intervals.
    #[staticmethod]
    fn miapure() -> Self {
        Self {
            inner: BrakingProblem::miapure(),
        }
    }

    /// The PIPTB braking phase: 1 m/s to rest in 1.4 s.
    #[staticmethod]
    fn piptb() -> Self {
        Self {
            inner: BrakingProblem::piptb(),
        }
    }

    /// A copy with `duration_secs` replaced.
    fn with_duration(&self, py: Python<'_>, duration_secs: f64) -> PyResult<Self> {
        let inner = BrakingProblem {
            duration_secs,
            ..self.inner
        };
        inner.validate().map_err(|e| trajopt_error(py, e))?;
        Ok(Self { inner })
    }

    /// The plant.
    #[getter]
    fn plane(&self) -> PyWipParams {
        PyWipParams {
            inner: self.inner.plane,
        }
    }

    /// Cruise speed at the start (m/s).
    #[getter]
    fn initial_speed_m_per_s(&self) -> f64 {
        self.inner.initial_speed_m_per_s
    }

    /// Braking time (s).
    #[getter]
    fn duration_secs(&self) -> f64 {
        self.inner.duration_secs
    }

    /// Collocation intervals.
    #[getter]
    fn intervals(&self) -> usize {
        self.inner.intervals
    }

    /// `"hermite_simpson"` or `"trapezoidal"`.
    #[getter]
    fn method(&self) -> &'static str {
        method_name(self.inner.method)
    }

    /// Whether `tau = 0` is pinned at both ends.
    #[getter]
    fn zero_end_torques(&self) -> bool {
        self.inner.zero_end_torques
    }

    /// The path limits.
    #[getter]
    fn limits(&self) -> PyBrakingLimits {
        PyBrakingLimits {
            inner: self.inner.limits,
        }
    }

    /// Solves by SQP (without the GIL). `initial_guess`: a previous `BrakingSolution` (any
    /// grid or duration) or `None` for the linear-quadratic optimum. Malformed input raises;
    /// the outcome is the solution's `status`.
    #[pyo3(signature = (
        *, max_iterations = 50, primal_tolerance = 1e-8, dual_tolerance = 1e-6,
        initial_guess = None,
    ))]
    fn solve(
        &self,
        py: Python<'_>,
        max_iterations: usize,
        primal_tolerance: f64,
        dual_tolerance: f64,
        initial_guess: Option<PyRef<'_, PyBrakingSolution>>,
    ) -> PyResult<PyBrakingSolution> {
        let options = options(
            max_iterations,
            primal_tolerance,
            dual_tolerance,
            initial_guess.as_deref(),
        );
        let problem = self.inner;
        let sol = py
            .detach(|| solve(&problem, &options))
            .map_err(|e| trajopt_error(py, e))?;
        Ok(PyBrakingSolution { inner: sol })
    }

    fn __repr__(&self) -> String {
        format!(
            "BrakingProblem(initial_speed_m_per_s={:?}, duration_secs={:?}, intervals={}, \
             method={:?}, zero_end_torques={})",
            self.inner.initial_speed_m_per_s,
            self.inner.duration_secs,
            self.inner.intervals,
            method_name(self.inner.method),
            if self.inner.zero_end_torques {
                "True"
            } else {
                "False"
            }
        )
    }
}

fn options(
    max_iterations: usize,
    primal_tolerance: f64,
    dual_tolerance: f64,
    guess: Option<&PyBrakingSolution>,
) -> SolveOptions {
    SolveOptions {
        max_iterations,
        primal_tolerance,
        dual_tolerance,
        initial_guess: guess.map_or(InitialGuess::LinearQuadratic, |g| {
            InitialGuess::Trajectory(g.inner.trajectory.clone())
        }),
    }
}

/// The result of a braking solve (`ballbot_sim::trajopt::BrakingSolution`).
#[pyclass(name = "BrakingSolution", module = "ballbot", frozen)]
pub struct PyBrakingSolution {
    inner: BrakingSolution,
}

#[pymethods]
impl PyBrakingSolution {
    /// A `SolveStatus`: `SOLVED`, `MAX_ITERATIONS`, `INFEASIBLE`, `LINE_SEARCH_FAILED` or
    /// `NUMERICAL_ERROR`. Only `SOLVED` certifies the trajectory.
    #[getter]
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::enums::solve_status(py, self.inner.status)
    }

    /// Whether the status is `"solved"`.
    fn is_solved(&self) -> bool {
        self.inner.is_solved()
    }

    /// The problem that was solved.
    #[getter]
    fn problem(&self) -> PyBrakingProblem {
        PyBrakingProblem {
            inner: self.inner.problem,
        }
    }

    /// `J = integral tau^2 dt` (N^2 m^2 s).
    #[getter]
    fn cost_n2m2s(&self) -> f64 {
        self.inner.cost_n2m2s
    }

    /// SQP iterations.
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.iterations
    }

    /// Largest constraint violation at the returned point.
    #[getter]
    fn primal_residual(&self) -> f64 {
        self.inner.primal_residual
    }

    /// KKT stationarity residual at the returned point.
    #[getter]
    fn dual_residual(&self) -> f64 {
        self.inner.dual_residual
    }

    /// Wall time of the solve (s).
    #[getter]
    fn solve_time_secs(&self) -> f64 {
        self.inner.solve_time_secs
    }

    /// Peak tilt magnitude over the knots (rad).
    #[getter]
    fn peak_tilt_rad(&self) -> f64 {
        self.inner.peak_tilt_rad()
    }

    /// Knot times (s), shape (N + 1,).
    #[getter]
    fn knot_times_secs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.trajectory.knot_times_secs())
    }

    /// Knot states `[theta, phi, theta_dot, phi_dot]`, shape (N + 1, 4).
    #[getter]
    fn knot_states<'py>(&self, py: Python<'py>) -> Out<'py> {
        let s: Vec<[f64; 4]> = self
            .inner
            .trajectory
            .knot_states()
            .iter()
            .map(|s| (*s).into())
            .collect();
        rows_out(py, s, false)
    }

    /// Knot torques (N m), shape (N + 1,).
    #[getter]
    fn knot_torques_nm<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.trajectory.knot_torques_nm())
    }

    /// Hermite-Simpson midpoint torques (N m), shape (N,); empty for trapezoidal.
    #[getter]
    fn mid_torques_nm<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.trajectory.mid_torques_nm())
    }

    /// Normal forces of the omniwheels at every knot (N), shape (N + 1, 3); empty (0, 3)
    /// unless the limits name an omniwheel drive.
    #[getter]
    fn normal_force_n<'py>(&self, py: Python<'py>) -> Out<'py> {
        rows_out(
            py,
            self.inner.contacts.iter().map(|c| c.normal_n).collect(),
            false,
        )
    }

    /// Traction magnitudes of the omniwheels at every knot (N), shape (N + 1, 3) or (0, 3).
    #[getter]
    fn traction_n<'py>(&self, py: Python<'py>) -> Out<'py> {
        rows_out(
            py,
            self.inner.contacts.iter().map(|c| c.traction_n).collect(),
            false,
        )
    }

    /// The interpolated state `s_c(t)` at times `t_secs` (scalar: (4,), array (n,): (n, 4)).
    fn state_at<'py>(&self, py: Python<'py>, t_secs: Arr<'py>) -> Out<'py> {
        let single = t_secs.shape().is_empty();
        let s: Vec<[f64; 4]> = t_secs
            .as_array()
            .iter()
            .map(|t| self.inner.trajectory.state_at(*t).into())
            .collect();
        rows_out(py, s, single)
    }

    /// The interpolated torque (N m) at times `t_secs` (scalar or (n,)).
    fn torque_at<'py>(&self, py: Python<'py>, t_secs: Arr<'py>) -> Out<'py> {
        let shape = t_secs.shape().to_vec();
        let v: Vec<f64> = t_secs
            .as_array()
            .iter()
            .map(|t| self.inner.trajectory.torque_at(*t))
            .collect();
        array_out(py, v, &shape)
    }

    /// Samples every `dt_secs` from 0 to T: a dict of `time_secs` (n,), `state` (n, 4),
    /// `torque_nm` (n,).
    fn sample<'py>(&self, py: Python<'py>, dt_secs: f64) -> PyResult<Bound<'py, PyDict>> {
        if !(dt_secs.is_finite() && dt_secs > 0.0) {
            return Err(error(
                py,
                Kind::Parameter,
                "invalid parameter `dt_secs`: must be finite and > 0",
            ));
        }
        let samples = self.inner.trajectory.sample(dt_secs);
        let time = PyArray1::from_vec(py, samples.iter().map(|s| s.0).collect());
        let state = rows_out::<4>(py, samples.iter().map(|s| s.1.into()).collect(), false)?;
        let torque = PyArray1::from_vec(py, samples.iter().map(|s| s.2).collect());
        [
            ("time_secs", time.into_any()),
            ("state", state.into_any()),
            ("torque_nm", torque.into_any()),
        ]
        .into_py_dict(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "BrakingSolution(status={:?}, cost_n2m2s={:.6}, iterations={}, solve_time_secs={:.4})",
            self.inner.status.as_str(),
            self.inner.cost_n2m2s,
            self.inner.iterations,
            self.inner.solve_time_secs
        )
    }
}

/// Bisects the braking duration of `problem` (its own duration ignored) for the shortest one
/// that solves under its limits. Returns a `MinBrakingTime`: `min_duration_secs` (None if even
/// `upper_secs` fails), `infeasible_below_secs`, `solution` (at the minimum), `solves`.
#[pyfunction(name = "min_braking_time")]
#[pyo3(signature = (
    problem, *, lower_secs = 0.1, upper_secs = 10.0, resolution_secs = 0.01,
    max_iterations = 50, primal_tolerance = 1e-8, dual_tolerance = 1e-6,
))]
#[allow(clippy::too_many_arguments)]
fn py_min_braking_time<'py>(
    py: Python<'py>,
    problem: PyRef<'py, PyBrakingProblem>,
    lower_secs: f64,
    upper_secs: f64,
    resolution_secs: f64,
    max_iterations: usize,
    primal_tolerance: f64,
    dual_tolerance: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let search = MinTimeOptions {
        lower_secs,
        upper_secs,
        resolution_secs,
    };
    let options = options(max_iterations, primal_tolerance, dual_tolerance, None);
    let p = problem.inner;
    let result = py
        .detach(|| min_braking_time(&p, &options, &search))
        .map_err(|e| trajopt_error(py, e))?;
    let view = MinBrakingTimeView {
        min_duration_secs: result.min_duration_secs,
        infeasible_below_secs: result.infeasible_below_secs,
        solution: Bound::new(
            py,
            PyBrakingSolution {
                inner: result.solution,
            },
        )?,
        solves: result.solves,
    };
    crate::results::build_objects(py, view)
}

/// The shortest feasible braking time (`min_braking_time`).
#[derive(IntoPyObject, JsonSchema)]
#[schemars(rename = "MinBrakingTime")]
pub(crate) struct MinBrakingTimeView<'py> {
    /// Shortest feasible duration (s), `None` if none in the bracket.
    min_duration_secs: Option<f64>,
    /// Longest infeasible duration below it (s).
    infeasible_below_secs: Option<f64>,
    /// The `BrakingSolution` at `min_duration_secs`.
    #[schemars(
        with = "serde_json::Value",
        extend("x-python-type" = "ballbot._core.BrakingSolution")
    )]
    solution: Bound<'py, PyBrakingSolution>,
    /// Solves run.
    solves: usize,
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBrakingLimits>()?;
    m.add_class::<PyBrakingProblem>()?;
    m.add_class::<PyBrakingSolution>()?;
    m.add_function(wrap_pyfunction!(py_min_braking_time, m)?)?;
    Ok(())
}
