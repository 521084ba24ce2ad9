//! The 3D world (`ballbot_sim::world`): `World` (the rapier3d ballbot driven by wheel torques),
//! `WorldLoop` (the core's 3D controller in the loop), their per-step records, and the
//! maximum-speed ramp. `run` and the experiments execute entirely in Rust without the GIL and
//! return dicts of numpy arrays, so Python threads run several worlds in parallel.

use crate::errors::{Kind, core_error, error};
use crate::log::log_error;
use crate::params::PyWorldParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::Mode;
use ballbot_sim::log::{WorldLogOptions, WorldLogger};
use ballbot_sim::world::experiments::{RampParams, RampResult, max_speed_ramp_with_config};
use ballbot_sim::world::failure::tilt_from_vertical_rad;
use ballbot_sim::world::{
    BallbotWorld, CoreLoop, Failure, FailureKind, Measurement, StepTelemetry, WheelTelemetry,
    WorldError, WorldParams,
};
use nalgebra::Vector3;
use numpy::{
    AllowTypeChange, Element, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Maps a world error: a robot or world parameter out of range to `ballbot.ParameterError`
/// (the message names the field), a failed controller design to `ballbot.SolverError`.
pub fn world_error(py: Python<'_>, e: WorldError) -> PyErr {
    match e {
        WorldError::Robot(e) => core_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// A finite 3-vector from a sequence of three numbers or a numpy array of shape (3,).
fn vec3(py: Python<'_>, value: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    let v: [f64; 3] = value.extract().map_err(|_| {
        error(
            py,
            Kind::Shape,
            format!("`{name}` must be 3 numbers (a sequence or an array of shape (3,))"),
        )
    })?;
    finite(py, &v, name)?;
    Ok(v)
}

fn finite(py: Python<'_>, values: &[f64], name: &str) -> PyResult<()> {
    if values.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(error(
            py,
            Kind::Parameter,
            format!("`{name}` must be finite, got {values:?}"),
        ))
    }
}

/// Per-step rows for a run of `n_steps`: an array of shape (3,) (held for every step) or
/// (n_steps, 3), all finite. `None` gives zeros.
fn step_rows(
    py: Python<'_>,
    array: Option<Arr<'_>>,
    n_steps: usize,
    name: &str,
) -> PyResult<Vec<[f64; 3]>> {
    let Some(array) = array else {
        return Ok(vec![[0.0; 3]]);
    };
    let shape = array.shape().to_vec();
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    let rows: Vec<[f64; 3]> = match shape.as_slice() {
        [3] => vec![[values[0], values[1], values[2]]],
        [n, 3] if *n == n_steps => values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        _ => {
            return Err(error(
                py,
                Kind::Shape,
                format!(
                    "`{name}` must have shape (3,) or (n_steps, 3) = ({n_steps}, 3), got {shape:?}"
                ),
            ));
        }
    };
    if let Some((k, row)) = rows
        .iter()
        .enumerate()
        .find(|(_, r)| !r.iter().all(|x| x.is_finite()))
    {
        return Err(error(
            py,
            Kind::Parameter,
            format!("`{name}` must be finite; row {k} is {row:?}"),
        ));
    }
    Ok(rows)
}

/// The row used at step `k`: the only row, or row `k`.
fn row_at(rows: &[[f64; 3]], k: usize) -> [f64; 3] {
    if rows.len() == 1 { rows[0] } else { rows[k] }
}

/// One omniwheel in one step (`ballbot_sim::world::WheelTelemetry`).
#[pyclass(name = "WheelTelemetry", module = "ballbot", frozen, get_all)]
#[derive(Clone, Debug)]
pub struct PyWheelTelemetry {
    /// Normal force `N_i` (N), from the compliant contact.
    normal_force_n: f64,
    /// Traction `F_i` the wheel applies to the ball along its rolling direction (N).
    traction_n: f64,
    /// Traction the contact would need to keep sticking (N).
    traction_demand_n: f64,
    /// `|F_i| / (mu N_i)`, 0 when lifted off.
    cone_utilisation: f64,
    /// Slip speed along the rolling direction, ball surface minus wheel rim (m/s).
    slip_speed_m_per_s: f64,
    /// Whether the demand exceeded the friction cone (the contact slides).
    slipping: bool,
    /// Torque the actuator delivered at the wheel after its torque-speed limit (N m).
    motor_torque_nm: f64,
    /// Wheel speed relative to the body (rad/s).
    speed_rad_per_s: f64,
    /// Wheel angle relative to the body (rad).
    angle_rad: f64,
}

impl From<&WheelTelemetry> for PyWheelTelemetry {
    fn from(w: &WheelTelemetry) -> Self {
        Self {
            normal_force_n: w.normal_force_n,
            traction_n: w.traction_n,
            traction_demand_n: w.traction_demand_n,
            cone_utilisation: w.cone_utilisation,
            slip_speed_m_per_s: w.slip_speed_m_per_s,
            slipping: w.slipping,
            motor_torque_nm: w.motor_torque_nm,
            speed_rad_per_s: w.speed_rad_per_s,
            angle_rad: w.angle_rad,
        }
    }
}

#[pymethods]
impl PyWheelTelemetry {
    fn __repr__(&self) -> String {
        format!(
            "WheelTelemetry(normal_force_n={:.3}, traction_n={:.3}, cone_utilisation={:.3}, \
             slip_speed_m_per_s={:.4}, slipping={}, motor_torque_nm={:.3}, speed_rad_per_s={:.3})",
            self.normal_force_n,
            self.traction_n,
            self.cone_utilisation,
            self.slip_speed_m_per_s,
            if self.slipping { "True" } else { "False" },
            self.motor_torque_nm,
            self.speed_rad_per_s
        )
    }
}

fn vec_out<'py>(py: Python<'py>, v: &Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

/// Everything the world reports after one step, in world coordinates, z up
/// (`ballbot_sim::world::StepTelemetry`). Vectors are numpy arrays of shape (3,);
/// orientations are unit quaternions `(x, y, z, w)` (scalar last, as scipy's `Rotation`).
#[pyclass(name = "StepTelemetry", module = "ballbot", frozen)]
pub struct PyStepTelemetry {
    inner: StepTelemetry,
}

#[pymethods]
impl PyStepTelemetry {
    /// Simulated time at the end of the step (s).
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time_s
    }

    /// The three omniwheels (OW1, OW2, OW3).
    #[getter]
    fn wheels(&self) -> Vec<PyWheelTelemetry> {
        self.inner
            .wheels
            .iter()
            .map(PyWheelTelemetry::from)
            .collect()
    }

    /// Ball centre (m).
    #[getter]
    fn ball_position_m<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_position_m)
    }

    /// Ball orientation, world from ball, `(x, y, z, w)`.
    #[getter]
    fn ball_orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.ball_orientation.coords.as_slice())
    }

    /// Ball velocity (m/s).
    #[getter]
    fn ball_velocity_m_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_velocity_m_per_s)
    }

    /// Ball angular velocity (rad/s).
    #[getter]
    fn ball_angular_velocity_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_angular_velocity_rad_per_s)
    }

    /// Body frame origin, the nominal ball centre in the body (m).
    #[getter]
    fn body_position_m<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.body_position_m)
    }

    /// Body orientation, world from body, `(x, y, z, w)`.
    #[getter]
    fn body_orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.body_orientation.coords.as_slice())
    }

    /// Body angular velocity in the body frame (rad/s).
    #[getter]
    fn body_rate_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.body_rate_rad_per_s)
    }

    /// Body tilt about the body-aligned horizontal axes, `(theta_x, theta_y)` (rad).
    #[getter]
    fn tilt_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.tilt_rad)
    }

    /// Angle between the body axis and the vertical (rad).
    #[getter]
    fn tilt_from_vertical_rad(&self) -> f64 {
        tilt_from_vertical_rad(&self.inner)
    }

    /// Normal force of the floor on the ball (N).
    #[getter]
    fn floor_force_n(&self) -> f64 {
        self.inner.floor_force_n
    }

    fn __repr__(&self) -> String {
        let t = &self.inner;
        format!(
            "StepTelemetry(time_s={:.6}, normal_force_n={:?}, ball_velocity_m_per_s={:?}, \
             tilt_rad={:?})",
            t.time_s,
            t.wheels.map(|w| w.normal_force_n),
            [
                t.ball_velocity_m_per_s.x,
                t.ball_velocity_m_per_s.y,
                t.ball_velocity_m_per_s.z
            ],
            t.tilt_rad
        )
    }
}

/// One sample of every sensor (`ballbot_sim::world::Measurement`): IMU tilt as ZYX Euler
/// angles (as the core's `ImuSample`), gyro, quantised encoders and their windowed speeds.
#[pyclass(name = "Measurement", module = "ballbot", frozen)]
pub struct PyMeasurement {
    inner: Measurement,
}

#[pymethods]
impl PyMeasurement {
    /// Time of the sample (s).
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time_s
    }

    /// IMU `(roll, pitch)` (rad); pitch > 0 leans towards +x (OW1).
    #[getter]
    fn tilt_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.tilt_rad)
    }

    /// IMU yaw (rad).
    #[getter]
    fn yaw_rad(&self) -> f64 {
        self.inner.yaw_rad
    }

    /// Gyro: body angular velocity in the body frame (rad/s).
    #[getter]
    fn body_rate_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.body_rate_rad_per_s)
    }

    /// Encoder angles of the three wheels relative to the body, quantised (rad).
    #[getter]
    fn wheel_angle_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.wheel_angle_rad)
    }

    /// Wheel speeds as a motor driver measures them, over the encoder window (rad/s).
    #[getter]
    fn wheel_speed_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.wheel_speed_rad_per_s)
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "Measurement(time_s={:.6}, tilt_rad={:?}, yaw_rad={:?}, body_rate_rad_per_s={:?}, \
             wheel_speed_rad_per_s={:?})",
            m.time_s, m.tilt_rad, m.yaw_rad, m.body_rate_rad_per_s, m.wheel_speed_rad_per_s
        )
    }
}

/// A detected failure of a world run (`ballbot_sim::world::Failure`): `kind` is `"tilt"`,
/// `"body_touched_floor"`, `"sustained_slip"` or `"lift_off"`; `wheel` (0-based, OW1 is 0)
/// for slip and lift-off, `tilt_rad` for a tilt failure.
#[pyclass(name = "Failure", module = "ballbot", frozen, eq, get_all)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyFailure {
    /// What failed: `"tilt"`, `"body_touched_floor"`, `"sustained_slip"`, `"lift_off"`.
    kind: &'static str,
    /// Simulated time of detection (s).
    time_s: f64,
    /// The wheel, 0-based, for `"sustained_slip"` and `"lift_off"`.
    wheel: Option<usize>,
    /// Tilt from the vertical when detected (rad), for `"tilt"`.
    tilt_rad: Option<f64>,
}

impl From<Failure> for PyFailure {
    fn from(f: Failure) -> Self {
        let (kind, wheel, tilt_rad) = match f.kind {
            FailureKind::Tilt { tilt_rad } => ("tilt", None, Some(tilt_rad)),
            FailureKind::BodyTouchedFloor => ("body_touched_floor", None, None),
            FailureKind::SustainedSlip { wheel } => ("sustained_slip", Some(wheel), None),
            FailureKind::LiftOff { wheel } => ("lift_off", Some(wheel), None),
        };
        Self {
            kind,
            time_s: f.time_s,
            wheel,
            tilt_rad,
        }
    }
}

#[pymethods]
impl PyFailure {
    fn __repr__(&self) -> String {
        let detail = match (self.wheel, self.tilt_rad) {
            (Some(w), _) => format!(", wheel={w}"),
            (_, Some(t)) => format!(", tilt_rad={t:.4}"),
            _ => String::new(),
        };
        format!(
            "Failure(kind={:?}, time_s={:.4}{detail})",
            self.kind, self.time_s
        )
    }
}

/// Per-step records of a run, column by column.
#[derive(Default)]
struct Trace {
    time_s: Vec<f64>,
    input: Vec<[f64; 3]>,
    normal_force_n: Vec<[f64; 3]>,
    traction_n: Vec<[f64; 3]>,
    traction_demand_n: Vec<[f64; 3]>,
    cone_utilisation: Vec<[f64; 3]>,
    slip_speed_m_per_s: Vec<[f64; 3]>,
    slipping: Vec<[bool; 3]>,
    motor_torque_nm: Vec<[f64; 3]>,
    wheel_speed_rad_per_s: Vec<[f64; 3]>,
    wheel_angle_rad: Vec<[f64; 3]>,
    ball_position_m: Vec<[f64; 3]>,
    ball_velocity_m_per_s: Vec<[f64; 3]>,
    ball_angular_velocity_rad_per_s: Vec<[f64; 3]>,
    body_position_m: Vec<[f64; 3]>,
    body_orientation: Vec<[f64; 4]>,
    body_rate_rad_per_s: Vec<[f64; 3]>,
    tilt_rad: Vec<[f64; 2]>,
    tilt_from_vertical_rad: Vec<f64>,
    yaw_rad: Vec<f64>,
    floor_force_n: Vec<f64>,
}

/// Reserves `len` elements or raises `MemoryError` (before the GIL is released).
fn reserved<T>(len: usize) -> PyResult<Vec<T>> {
    crate::arrays::reserve(len)
}

impl Trace {
    fn with_capacity(len: usize) -> PyResult<Self> {
        Ok(Self {
            time_s: reserved(len)?,
            input: reserved(len)?,
            normal_force_n: reserved(len)?,
            traction_n: reserved(len)?,
            traction_demand_n: reserved(len)?,
            cone_utilisation: reserved(len)?,
            slip_speed_m_per_s: reserved(len)?,
            slipping: reserved(len)?,
            motor_torque_nm: reserved(len)?,
            wheel_speed_rad_per_s: reserved(len)?,
            wheel_angle_rad: reserved(len)?,
            ball_position_m: reserved(len)?,
            ball_velocity_m_per_s: reserved(len)?,
            ball_angular_velocity_rad_per_s: reserved(len)?,
            body_position_m: reserved(len)?,
            body_orientation: reserved(len)?,
            body_rate_rad_per_s: reserved(len)?,
            tilt_rad: reserved(len)?,
            tilt_from_vertical_rad: reserved(len)?,
            yaw_rad: reserved(len)?,
            floor_force_n: reserved(len)?,
        })
    }

    fn push(&mut self, t: &StepTelemetry, input: [f64; 3]) {
        let wheels = |f: fn(&WheelTelemetry) -> f64| t.wheels.each_ref().map(f);
        let v = |v: &Vector3<f64>| [v.x, v.y, v.z];
        self.time_s.push(t.time_s);
        self.input.push(input);
        self.normal_force_n.push(wheels(|w| w.normal_force_n));
        self.traction_n.push(wheels(|w| w.traction_n));
        self.traction_demand_n.push(wheels(|w| w.traction_demand_n));
        self.cone_utilisation.push(wheels(|w| w.cone_utilisation));
        self.slip_speed_m_per_s
            .push(wheels(|w| w.slip_speed_m_per_s));
        self.slipping.push(t.wheels.map(|w| w.slipping));
        self.motor_torque_nm.push(wheels(|w| w.motor_torque_nm));
        self.wheel_speed_rad_per_s
            .push(wheels(|w| w.speed_rad_per_s));
        self.wheel_angle_rad.push(wheels(|w| w.angle_rad));
        self.ball_position_m.push(v(&t.ball_position_m));
        self.ball_velocity_m_per_s.push(v(&t.ball_velocity_m_per_s));
        self.ball_angular_velocity_rad_per_s
            .push(v(&t.ball_angular_velocity_rad_per_s));
        self.body_position_m.push(v(&t.body_position_m));
        let q = &t.body_orientation.coords;
        self.body_orientation.push([q.x, q.y, q.z, q.w]);
        self.body_rate_rad_per_s.push(v(&t.body_rate_rad_per_s));
        self.tilt_rad.push(t.tilt_rad);
        self.tilt_from_vertical_rad.push(tilt_from_vertical_rad(t));
        self.yaw_rad.push(t.body_orientation.euler_angles().2);
        self.floor_force_n.push(t.floor_force_n);
    }

    /// The columns as a dict; the input column is named `input_name`.
    fn into_dict<'py>(self, py: Python<'py>, input_name: &str) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("time_s", PyArray1::from_vec(py, self.time_s))?;
        d.set_item(input_name, table(py, self.input)?)?;
        d.set_item("normal_force_n", table(py, self.normal_force_n)?)?;
        d.set_item("traction_n", table(py, self.traction_n)?)?;
        d.set_item("traction_demand_n", table(py, self.traction_demand_n)?)?;
        d.set_item("cone_utilisation", table(py, self.cone_utilisation)?)?;
        d.set_item("slip_speed_m_per_s", table(py, self.slip_speed_m_per_s)?)?;
        d.set_item("slipping", table(py, self.slipping)?)?;
        d.set_item("motor_torque_nm", table(py, self.motor_torque_nm)?)?;
        d.set_item(
            "wheel_speed_rad_per_s",
            table(py, self.wheel_speed_rad_per_s)?,
        )?;
        d.set_item("wheel_angle_rad", table(py, self.wheel_angle_rad)?)?;
        d.set_item("ball_position_m", table(py, self.ball_position_m)?)?;
        d.set_item(
            "ball_velocity_m_per_s",
            table(py, self.ball_velocity_m_per_s)?,
        )?;
        d.set_item(
            "ball_angular_velocity_rad_per_s",
            table(py, self.ball_angular_velocity_rad_per_s)?,
        )?;
        d.set_item("body_position_m", table(py, self.body_position_m)?)?;
        d.set_item("body_orientation", table(py, self.body_orientation)?)?;
        d.set_item("body_rate_rad_per_s", table(py, self.body_rate_rad_per_s)?)?;
        d.set_item("tilt_rad", table(py, self.tilt_rad)?)?;
        d.set_item(
            "tilt_from_vertical_rad",
            PyArray1::from_vec(py, self.tilt_from_vertical_rad),
        )?;
        d.set_item("yaw_rad", PyArray1::from_vec(py, self.yaw_rad))?;
        d.set_item("floor_force_n", PyArray1::from_vec(py, self.floor_force_n))?;
        Ok(d)
    }
}

/// Rows of length `N` as an `(n, N)` numpy array.
pub fn table<'py, T: Element + Copy, const N: usize>(
    py: Python<'py>,
    rows: Vec<[T; N]>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let n = rows.len();
    let flat: Vec<T> = rows.into_iter().flatten().collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([n, N])?
        .to_dyn()
        .clone())
}

/// How a run is recorded and when it stops.
#[derive(Clone, Copy)]
struct RunOptions {
    n_steps: usize,
    record_every: usize,
    stop_on_failure: bool,
}

impl RunOptions {
    fn new(
        py: Python<'_>,
        n_steps: usize,
        record_every: usize,
        stop_on_failure: bool,
    ) -> PyResult<Self> {
        if record_every == 0 {
            return Err(error(
                py,
                Kind::Parameter,
                "invalid parameter `record_every`: must be >= 1",
            ));
        }
        Ok(Self {
            n_steps,
            record_every,
            stop_on_failure,
        })
    }

    fn records(&self) -> usize {
        self.n_steps.div_ceil(self.record_every)
    }
}

/// Runs `step(k, input)` for the options' steps, recording every `record_every`-th step (the
/// first included) and the failing one. Returns the trace and the number of steps run.
fn run_steps<E>(
    options: RunOptions,
    inputs: &[[f64; 3]],
    mut trace: Trace,
    mut step: impl FnMut([f64; 3]) -> Result<(StepTelemetry, bool), E>,
) -> Result<(Trace, usize), E> {
    let mut steps = 0;
    for k in 0..options.n_steps {
        let input = row_at(inputs, k);
        let (telemetry, failed) = step(input)?;
        steps += 1;
        let stop = failed && options.stop_on_failure;
        if k % options.record_every == 0 || stop {
            trace.push(&telemetry, input);
        }
        if stop {
            break;
        }
    }
    Ok((trace, steps))
}

/// The MCAP logger of a run, if `log_path` is given: `compact` writes the telemetry at 1 kHz.
fn logger(
    py: Python<'_>,
    log_path: Option<&Path>,
    params: &WorldParams,
    compact: bool,
) -> PyResult<Option<WorldLogger>> {
    let Some(path) = log_path else {
        return Ok(None);
    };
    let options = if compact {
        WorldLogOptions::compact()
    } else {
        WorldLogOptions::default()
    };
    WorldLogger::with_options(path, params, options)
        .map(Some)
        .map_err(|e| log_error(py, e))
}

/// Closes the log of a run.
fn finish_log(py: Python<'_>, log: Option<WorldLogger>) -> PyResult<()> {
    if let Some(log) = log {
        py.detach(|| log.finish()).map_err(|e| log_error(py, e))?;
    }
    Ok(())
}

/// The world methods both `World` and `WorldLoop` have: what `BallbotWorld` offers besides
/// `step`. `$world` and `$world_mut` are expressions on `self` giving the world.
macro_rules! world_class {
    (
        $(#[$meta:meta])*
        $py_ty:ident($name:literal) {
            inner: $inner:ty,
            world: |$this:ident| $world:expr,
            world_mut: |$this_mut:ident| $world_mut:expr,
        }
        methods { $($extra:item)* }
    ) => {
        $(#[$meta])*
        #[pyclass(name = $name, module = "ballbot")]
        pub struct $py_ty {
            inner: $inner,
        }

        impl $py_ty {
            fn world(&self) -> &BallbotWorld {
                let $this = self;
                $world
            }

            fn world_mut(&mut self) -> &mut BallbotWorld {
                let $this_mut = self;
                $world_mut
            }
        }

        #[pymethods]
        impl $py_ty {
            /// The parameters the world was built with.
            #[getter]
            fn params(&self) -> PyWorldParams {
                PyWorldParams { inner: *self.world().params() }
            }

            /// Simulated time (s).
            #[getter]
            fn time_s(&self) -> f64 {
                self.world().time_s()
            }

            /// The record of the last step (before the first step: the initial poses).
            #[getter]
            fn telemetry(&self) -> PyStepTelemetry {
                PyStepTelemetry { inner: *self.world().telemetry() }
            }

            /// The first failure detected, or `None` (the simulation keeps running after it).
            #[getter]
            fn failure(&self) -> Option<PyFailure> {
                self.world().failure().map(PyFailure::from)
            }

            /// Samples the sensors (IMU, encoders) at the current state; draws from the
            /// seeded noise generator.
            fn measure(&mut self) -> PyMeasurement {
                PyMeasurement { inner: self.world_mut().measure() }
            }

            /// The encoders' wheel speed estimate (rad/s), as the motor drivers read it.
            fn encoder_speeds_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                PyArray1::from_slice(py, &self.world().encoder_speeds_rad_per_s())
            }

            /// Applies an impulse `impulse_ns` (N s, 3 numbers, world frame) at the body's
            /// centre of mass, e.g. a push.
            fn push_body(&mut self, py: Python<'_>, impulse_ns: &Bound<'_, PyAny>) -> PyResult<()> {
                let j = vec3(py, impulse_ns, "impulse_ns")?;
                self.world_mut().push_body(Vector3::from(j));
                Ok(())
            }

            /// Sets the body's centre-of-mass velocity (m/s) and angular velocity (rad/s,
            /// world frame).
            #[pyo3(signature = (linear_m_per_s, angular_rad_per_s = None))]
            fn set_body_velocity(
                &mut self,
                py: Python<'_>,
                linear_m_per_s: &Bound<'_, PyAny>,
                angular_rad_per_s: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<()> {
                let v = vec3(py, linear_m_per_s, "linear_m_per_s")?;
                let w = match angular_rad_per_s {
                    Some(w) => vec3(py, w, "angular_rad_per_s")?,
                    None => [0.0; 3],
                };
                self.world_mut().set_body_velocity(Vector3::from(v), Vector3::from(w));
                Ok(())
            }

            /// Sets the ball's linear (m/s) and angular (rad/s) velocity.
            #[pyo3(signature = (linear_m_per_s, angular_rad_per_s = None))]
            fn set_ball_velocity(
                &mut self,
                py: Python<'_>,
                linear_m_per_s: &Bound<'_, PyAny>,
                angular_rad_per_s: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<()> {
                let v = vec3(py, linear_m_per_s, "linear_m_per_s")?;
                let w = match angular_rad_per_s {
                    Some(w) => vec3(py, w, "angular_rad_per_s")?,
                    None => [0.0; 3],
                };
                self.world_mut().set_ball_velocity(Vector3::from(v), Vector3::from(w));
                Ok(())
            }

            /// Rotates the body about the ball centre by `tilt_rad = (theta_x, theta_y)`
            /// (about world x, then y), keeping the contacts' penetration.
            fn tilt_body(&mut self, py: Python<'_>, tilt_rad: (f64, f64)) -> PyResult<()> {
                finite(py, &[tilt_rad.0, tilt_rad.1], "tilt_rad")?;
                self.world_mut().tilt_body([tilt_rad.0, tilt_rad.1]);
                Ok(())
            }

            /// Moves the whole robot (ball and body) by `offset_m` (3 numbers), e.g. into
            /// the air.
            fn translate_robot(&mut self, py: Python<'_>, offset_m: &Bound<'_, PyAny>) -> PyResult<()> {
                let d = vec3(py, offset_m, "offset_m")?;
                self.world_mut().translate_robot(Vector3::from(d));
                Ok(())
            }

            /// Sets gravity along -z (m/s^2, >= 0); 0 gives free flight.
            fn set_gravity_m_per_s2(&mut self, py: Python<'_>, gravity_m_per_s2: f64) -> PyResult<()> {
                finite(py, &[gravity_m_per_s2], "gravity_m_per_s2")?;
                self.world_mut()
                    .set_gravity_m_per_s2(gravity_m_per_s2)
                    .map_err(|e| world_error(py, e))?;
                Ok(())
            }

            /// Sets the ball-floor friction coefficient (>= 0; 0 is a frictionless floor).
            fn set_floor_friction(&mut self, py: Python<'_>, friction: f64) -> PyResult<()> {
                non_negative(py, friction, "friction")?;
                self.world_mut()
                    .set_floor_friction(friction)
                    .map_err(|e| world_error(py, e))?;
                Ok(())
            }

            /// Sets the omniwheel-ball static friction coefficient `mu` (>= 0); the kinetic
            /// one follows with the configured ratio.
            fn set_wheel_friction(&mut self, py: Python<'_>, friction: f64) -> PyResult<()> {
                non_negative(py, friction, "friction")?;
                self.world_mut()
                    .set_wheel_friction(friction)
                    .map_err(|e| world_error(py, e))?;
                Ok(())
            }

            /// Test rig: clamps the ball in place (`True`) or releases it.
            fn set_ball_fixed(&mut self, fixed: bool) {
                self.world_mut().set_ball_fixed(fixed);
            }

            /// Test rig: clamps the body in place (`True`) or releases it.
            fn set_body_fixed(&mut self, fixed: bool) {
                self.world_mut().set_body_fixed(fixed);
            }

            /// Total kinetic energy of ball, body and wheels (J).
            fn kinetic_energy_j(&self) -> f64 {
                self.world().kinetic_energy_j()
            }

            /// Gravitational potential energy of ball and body above the floor (J).
            fn potential_energy_j(&self) -> f64 {
                self.world().potential_energy_j()
            }

            /// Elastic energy stored in the three omniwheel contacts' normal springs (J).
            fn contact_energy_j(&self) -> f64 {
                self.world().contact_energy_j()
            }

            /// Total linear momentum of ball and body (N s), shape (3,).
            fn linear_momentum_ns<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                vec_out(py, &self.world().linear_momentum_ns())
            }

            /// Total angular momentum of ball, body and wheel spins about the world origin
            /// (N m s), shape (3,).
            fn angular_momentum_nms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                vec_out(py, &self.world().angular_momentum_nms())
            }

            /// Height of the chassis' lowest corner above the floor (m).
            fn chassis_clearance_m(&self) -> f64 {
                self.world().chassis_clearance_m()
            }

            $($extra)*
        }
    };
}

fn non_negative(py: Python<'_>, value: f64, name: &str) -> PyResult<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(error(
            py,
            Kind::Parameter,
            format!("invalid parameter `{name}`: must be finite and >= 0, got {value}"),
        ))
    }
}

fn params_or_default(params: Option<PyWorldParams>) -> WorldParams {
    params.map_or_else(WorldParams::miapure_60kg, |p| p.inner)
}

world_class! {
    /// The simulated 3D ballbot (`ballbot_sim::world::BallbotWorld`) driven directly by wheel
    /// torques: rapier3d integrates ball and body, the omniwheel contacts carry compliant
    /// normal forces and friction-cone-bounded traction along their rolling directions.
    ///
    /// Frames: world z up, floor at z = 0; the body frame's x points towards OW1.
    ///
    /// A world is stepped by one thread at a time (a call while another thread's `run` holds
    /// it raises `RuntimeError`); run several worlds to use several cores.
    PyWorld("World") {
        inner: BallbotWorld,
        world: |this| &this.inner,
        world_mut: |this| &mut this.inner,
    }
    methods {
        /// The world with the robot at rest, upright, the ball on the floor at the origin and
        /// the contacts pre-loaded (default parameters: `WorldParams.preset("miapure_60kg")`).
        #[new]
        #[pyo3(signature = (params = None))]
        fn py_new(py: Python<'_>, params: Option<PyWorldParams>) -> PyResult<Self> {
            let inner = BallbotWorld::new(params_or_default(params)).map_err(|e| world_error(py, e))?;
            Ok(Self { inner })
        }

        /// One physics step of `params.dt_secs` with the wheel torque commands `torque_nm`
        /// (3 numbers, N m at the wheels; each clamped to the actuator's torque-speed limit).
        fn step(&mut self, py: Python<'_>, torque_nm: &Bound<'_, PyAny>) -> PyResult<PyStepTelemetry> {
            let tau = vec3(py, torque_nm, "torque_nm")?;
            Ok(PyStepTelemetry { inner: *self.inner.step(tau) })
        }

        /// Runs `n_steps` physics steps in Rust without the GIL. `torque_nm`: wheel torques
        /// (N m), shape (3,) held for every step or (n_steps, 3), default zeros. Records every
        /// `record_every`-th step (the first one included); `stop_on_failure` ends the run at
        /// the step that detects a failure (recorded too). Returns a dict of numpy arrays, one
        /// row per recorded step: `time_s` (n,), `torque_nm` (n, 3) (the commands),
        /// per wheel (n, 3) `normal_force_n`, `traction_n`, `traction_demand_n`,
        /// `cone_utilisation`, `slip_speed_m_per_s`, `slipping` (bool), `motor_torque_nm`,
        /// `wheel_speed_rad_per_s`, `wheel_angle_rad`; `ball_position_m`,
        /// `ball_velocity_m_per_s`, `ball_angular_velocity_rad_per_s`, `body_position_m`,
        /// `body_rate_rad_per_s` (n, 3); `body_orientation` (n, 4) `(x, y, z, w)`; `tilt_rad`
        /// (n, 2); `tilt_from_vertical_rad`, `yaw_rad`, `floor_force_n` (n,); and `steps`
        /// (steps run), `failure` (`Failure` or `None`), `log_path`. With `log_path` every step
        /// is also written to that MCAP file (`ballbot_sim::log::WorldLogger`: telemetry,
        /// the Foxglove 3D scene and transforms, failure events; `log_compact` writes the
        /// telemetry at 1 kHz instead of every step), readable with `McapLog`.
        #[pyo3(signature = (
            n_steps, torque_nm = None, *, record_every = 1, stop_on_failure = false,
            log_path = None, log_compact = false,
        ))]
        #[allow(clippy::too_many_arguments)]
        fn run<'py>(
            &mut self,
            py: Python<'py>,
            n_steps: usize,
            torque_nm: Option<Arr<'py>>,
            record_every: usize,
            stop_on_failure: bool,
            log_path: Option<PathBuf>,
            log_compact: bool,
        ) -> PyResult<Bound<'py, PyDict>> {
            let options = RunOptions::new(py, n_steps, record_every, stop_on_failure)?;
            let inputs = step_rows(py, torque_nm, n_steps, "torque_nm")?;
            let trace = Trace::with_capacity(options.records())?;
            let mut log = logger(py, log_path.as_deref(), self.inner.params(), log_compact)?;
            let world = &mut self.inner;
            let result = py.detach(|| {
                run_steps(options, &inputs, trace, |tau| {
                    let telemetry = *world.step(tau);
                    if let Some(log) = log.as_mut() {
                        log.record(world, None)?;
                    }
                    Ok((telemetry, world.failure().is_some()))
                })
            });
            let (trace, steps) = result.map_err(|e| log_error(py, e))?;
            finish_log(py, log)?;
            let d = finish_run(py, trace, "torque_nm", steps, self.inner.failure())?;
            d.set_item("log_path", log_path)?;
            Ok(d)
        }
    }
}

/// The run's dict: the trace's columns plus `steps` and `failure`.
fn finish_run<'py>(
    py: Python<'py>,
    trace: Trace,
    input_name: &str,
    steps: usize,
    failure: Option<Failure>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = trace.into_dict(py, input_name)?;
    d.set_item("steps", steps)?;
    d.set_item("failure", failure.map(PyFailure::from))?;
    Ok(d)
}

/// Overrides of the controller's command shaping (`BallbotControllerConfig.shaping`), e.g. to
/// lift the translation caps so that a ramp, not the shaper, sets the command.
#[derive(Clone, Copy, Default)]
struct Shaping {
    max_speed_m_per_s: Option<f64>,
    max_accel_m_per_s2: Option<f64>,
    max_jerk_m_per_s3: Option<f64>,
    max_tilt_command_rad: Option<f64>,
    max_tilt_rate_command_rad_per_s: Option<f64>,
}

impl Shaping {
    /// The controller designed from the robot with these overrides.
    fn config(
        &self,
        py: Python<'_>,
        params: &WorldParams,
    ) -> PyResult<BallbotControllerConfig<f64>> {
        let mut config =
            BallbotControllerConfig::design(&params.robot).map_err(|e| core_error(py, e))?;
        let shaping = &mut config.shaping;
        for (value, name, slot) in [
            (
                self.max_speed_m_per_s,
                "max_speed_m_per_s",
                &mut shaping.translation.max_value,
            ),
            (
                self.max_accel_m_per_s2,
                "max_accel_m_per_s2",
                &mut shaping.translation.max_rate_per_s,
            ),
            (
                self.max_jerk_m_per_s3,
                "max_jerk_m_per_s3",
                &mut shaping.translation.max_jerk_per_s2,
            ),
            (
                self.max_tilt_command_rad,
                "max_tilt_command_rad",
                &mut shaping.max_tilt_command_rad,
            ),
            (
                self.max_tilt_rate_command_rad_per_s,
                "max_tilt_rate_command_rad_per_s",
                &mut shaping.max_tilt_rate_command_rad_per_s,
            ),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && v > 0.0) {
                    return Err(error(
                        py,
                        Kind::Parameter,
                        format!("invalid parameter `{name}`: must be finite and > 0, got {v}"),
                    ));
                }
                *slot = v;
            }
        }
        Ok(config)
    }
}

fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Idle => "idle",
        Mode::Balancing => "balancing",
        Mode::ControlledStop => "controlled_stop",
        Mode::Fault => "fault",
    }
}

fn velocity(command: [f64; 3]) -> VelocityCommand<f64> {
    VelocityCommand {
        vx_m_per_s: command[0],
        vy_m_per_s: command[1],
        yaw_rate_rad_per_s: command[2],
    }
}

world_class! {
    /// The 3D world driven by the core's controller at its two rates
    /// (`ballbot_sim::world::CoreLoop`): the cascaded LQR-PI outer loop (400 Hz) reads the
    /// simulated IMU and encoders, the per-motor speed PIs (8 kHz) drive the wheels. Every
    /// `World` method that inspects or disturbs the world is here too.
    ///
    /// The controller is designed from the robot (`BallbotControllerConfig::design`); the
    /// keyword arguments `max_speed_m_per_s`, `max_accel_m_per_s2`, `max_jerk_m_per_s3`,
    /// `max_tilt_command_rad`, `max_tilt_rate_command_rad_per_s` override its command
    /// shaping (defaults 2.0 m/s, 1.0 m/s^2, 2.0 m/s^3, 0.2 rad, 1.0 rad/s).
    PyWorldLoop("WorldLoop") {
        inner: CoreLoop,
        world: |this| this.inner.world(),
        world_mut: |this| this.inner.world_mut(),
    }
    methods {
        #[new]
        #[pyo3(signature = (
            params = None, *, max_speed_m_per_s = None, max_accel_m_per_s2 = None,
            max_jerk_m_per_s3 = None, max_tilt_command_rad = None,
            max_tilt_rate_command_rad_per_s = None,
        ))]
        fn py_new(
            py: Python<'_>,
            params: Option<PyWorldParams>,
            max_speed_m_per_s: Option<f64>,
            max_accel_m_per_s2: Option<f64>,
            max_jerk_m_per_s3: Option<f64>,
            max_tilt_command_rad: Option<f64>,
            max_tilt_rate_command_rad_per_s: Option<f64>,
        ) -> PyResult<Self> {
            let params = params_or_default(params);
            let config = Shaping {
                max_speed_m_per_s,
                max_accel_m_per_s2,
                max_jerk_m_per_s3,
                max_tilt_command_rad,
                max_tilt_rate_command_rad_per_s,
            }
            .config(py, &params)?;
            let inner = CoreLoop::with_config(params, config).map_err(|e| world_error(py, e))?;
            Ok(Self { inner })
        }

        /// The controller's mode: `"idle"` (before the first step arms it), `"balancing"`,
        /// `"controlled_stop"` or `"fault"`.
        #[getter]
        fn mode(&self) -> &'static str {
            mode_name(self.inner.mode())
        }

        /// One physics step (8 kHz) with the velocity command (m/s, m/s, rad/s; body frame);
        /// every outer period the controller first runs on a fresh sensor sample.
        #[pyo3(signature = (vx_m_per_s = 0.0, vy_m_per_s = 0.0, yaw_rate_rad_per_s = 0.0))]
        fn step(
            &mut self,
            py: Python<'_>,
            vx_m_per_s: f64,
            vy_m_per_s: f64,
            yaw_rate_rad_per_s: f64,
        ) -> PyResult<PyStepTelemetry> {
            let command = [vx_m_per_s, vy_m_per_s, yaw_rate_rad_per_s];
            finite(py, &command, "velocity command")?;
            let inner = *self.inner.step(Command::Velocity(velocity(command)));
            Ok(PyStepTelemetry { inner })
        }

        /// Runs `n_steps` physics steps in Rust without the GIL under the velocity command
        /// `command` = `(vx_m_per_s, vy_m_per_s, yaw_rate_rad_per_s)` (body frame), shape (3,)
        /// held for every step or (n_steps, 3) one row per step (a ramp, a profile), default
        /// zeros. Records every `record_every`-th step (the first one included);
        /// `stop_on_failure` ends the run at the step that detects a failure (recorded too).
        /// Returns the dict of `World.run` with `command` (n, 3) instead of `torque_nm`
        /// (`motor_torque_nm` holds what the controller drove). `log_path` and `log_compact`
        /// as in `World.run`; the log also carries the controller's outer loop and the
        /// commands (what `ballbot world` writes).
        #[pyo3(signature = (
            n_steps, command = None, *, record_every = 1, stop_on_failure = false,
            log_path = None, log_compact = false,
        ))]
        #[allow(clippy::too_many_arguments)]
        fn run<'py>(
            &mut self,
            py: Python<'py>,
            n_steps: usize,
            command: Option<Arr<'py>>,
            record_every: usize,
            stop_on_failure: bool,
            log_path: Option<PathBuf>,
            log_compact: bool,
        ) -> PyResult<Bound<'py, PyDict>> {
            let options = RunOptions::new(py, n_steps, record_every, stop_on_failure)?;
            let inputs = step_rows(py, command, n_steps, "command")?;
            let trace = Trace::with_capacity(options.records())?;
            let params = *self.inner.world().params();
            let mut log = logger(py, log_path.as_deref(), &params, log_compact)?;
            let sim = &mut self.inner;
            let result = py.detach(|| {
                run_steps(options, &inputs, trace, |cmd| {
                    let command = velocity(cmd);
                    if let Some(log) = log.as_mut() {
                        log.record_command(sim.world().time_s(), &command)?;
                    }
                    let telemetry = *sim.step(Command::Velocity(command));
                    if let Some(log) = log.as_mut() {
                        log.record_core(sim)?;
                    }
                    Ok((telemetry, sim.world().failure().is_some()))
                })
            });
            let (trace, steps) = result.map_err(|e| log_error(py, e))?;
            finish_log(py, log)?;
            let d = finish_run(py, trace, "command", steps, self.inner.world().failure())?;
            d.set_item("log_path", log_path)?;
            Ok(d)
        }
    }
}

pub fn ramp_dict<'py>(py: Python<'py>, r: RampResult) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("heading_deg", r.heading_deg)?;
    d.set_item("max_speed_m_per_s", r.max_speed_m_per_s)?;
    d.set_item("failure", r.failure.map(PyFailure::from))?;
    d.set_item("supervisor_stop_s", r.supervisor_stop_s)?;
    let column = |f: fn(&ballbot_sim::world::experiments::RampSample) -> f64| {
        r.samples.iter().map(f).collect::<Vec<f64>>()
    };
    d.set_item("time_s", PyArray1::from_vec(py, column(|s| s.time_s)))?;
    d.set_item(
        "command_m_per_s",
        PyArray1::from_vec(py, column(|s| s.command_m_per_s)),
    )?;
    d.set_item(
        "shaped_command_m_per_s",
        PyArray1::from_vec(py, column(|s| s.shaped_command_m_per_s)),
    )?;
    d.set_item(
        "speed_m_per_s",
        PyArray1::from_vec(py, column(|s| s.speed_m_per_s)),
    )?;
    d.set_item("tilt_rad", PyArray1::from_vec(py, column(|s| s.tilt_rad)))?;
    d.set_item(
        "max_cone_utilisation",
        PyArray1::from_vec(py, column(|s| s.max_cone_utilisation)),
    )?;
    let normal: Vec<[f64; 3]> = r.samples.iter().map(|s| s.normal_force_n).collect();
    d.set_item("normal_force_n", table(py, normal)?)?;
    let cone: Vec<[f64; 3]> = r.samples.iter().map(|s| s.cone_utilisation).collect();
    d.set_item("cone_utilisation", table(py, cone)?)?;
    Ok(d)
}

/// The maximum-speed experiment of the paper's Sec. V in the 3D world
/// (`ballbot_sim::world::experiments::max_speed_ramp`): the core's controller follows a
/// velocity ramp towards `heading_deg` (body frame; 0 is towards OW1) after `settle_s`, rising
/// at `accel_m_per_s2` to `max_command_m_per_s`, until the world detects a failure or the top
/// speed has been held for 1 s. Runs in Rust without the GIL. The shaping keywords lift the
/// controller's caps as in `WorldLoop` (by default the shaper caps the command at 2.0 m/s
/// and 1.0 m/s^2).
///
/// Returns a dict: `heading_deg`, `max_speed_m_per_s` (highest ball speed along the heading
/// before failure), `failure` (`Failure` or `None` if the ramp ended first),
/// `supervisor_stop_s` (when the core's safety supervisor stopped balancing, e.g. at its
/// wheel-speed limit, or `None`), and samples every
/// `sample_every_s`: `time_s`, `command_m_per_s` (the ramp), `shaped_command_m_per_s` (after
/// the controller's command shaper), `speed_m_per_s`, `tilt_rad` (from the vertical),
/// `max_cone_utilisation` (n,); `normal_force_n`, `cone_utilisation` (n, 3).
#[pyfunction]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, accel_m_per_s2 = 0.25, max_command_m_per_s = 3.5,
    settle_s = 0.5, sample_every_s = 0.01, max_speed_m_per_s = None, max_accel_m_per_s2 = None,
    max_jerk_m_per_s3 = None, max_tilt_command_rad = None, max_tilt_rate_command_rad_per_s = None,
))]
#[allow(clippy::too_many_arguments)]
fn max_speed_ramp<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    max_command_m_per_s: f64,
    settle_s: f64,
    sample_every_s: f64,
    max_speed_m_per_s: Option<f64>,
    max_accel_m_per_s2: Option<f64>,
    max_jerk_m_per_s3: Option<f64>,
    max_tilt_command_rad: Option<f64>,
    max_tilt_rate_command_rad_per_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_or_default(params);
    let config = Shaping {
        max_speed_m_per_s,
        max_accel_m_per_s2,
        max_jerk_m_per_s3,
        max_tilt_command_rad,
        max_tilt_rate_command_rad_per_s,
    }
    .config(py, &params)?;
    finite(py, &[heading_deg], "heading_deg")?;
    for (value, name) in [
        (accel_m_per_s2, "accel_m_per_s2"),
        (max_command_m_per_s, "max_command_m_per_s"),
        (sample_every_s, "sample_every_s"),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(error(
                py,
                Kind::Parameter,
                format!("invalid parameter `{name}`: must be finite and > 0, got {value}"),
            ));
        }
    }
    non_negative(py, settle_s, "settle_s")?;
    let ramp = RampParams {
        accel_m_per_s2,
        max_command_m_per_s,
        settle_s,
        sample_every_s,
    };
    let result = py
        .detach(|| max_speed_ramp_with_config(params, config, heading_deg, &ramp))
        .map_err(|e| world_error(py, e))?;
    ramp_dict(py, result)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWheelTelemetry>()?;
    m.add_class::<PyStepTelemetry>()?;
    m.add_class::<PyMeasurement>()?;
    m.add_class::<PyFailure>()?;
    m.add_class::<PyWorld>()?;
    m.add_class::<PyWorldLoop>()?;
    m.add_function(wrap_pyfunction!(max_speed_ramp, m)?)?;
    Ok(())
}
