//! A run's recording: the per-step columns (`Trace`), how a run records and stops, its MCAP
//! log.

use super::live::PyLiveView;
use super::row_at;
use super::telemetry::PyFailure;
use crate::arrays::reserve;
use crate::errors::{Kind, error};
use crate::log::log_error;
use ballbot_sim::log::{LogSink, McapLogger, WorldLogOptions, WorldLogger};
use ballbot_sim::world::failure::tilt_from_vertical_rad;
use ballbot_sim::world::{Failure, StepTelemetry, WheelTelemetry, WorldParams};
use nalgebra::Vector3;
use numpy::{Element, PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;

/// Per-step records of a run, column by column.
pub(crate) struct Trace {
    time_secs: Vec<f64>,
    input: Vec<[f64; 3]>,
    normal_force_n: Vec<[f64; 3]>,
    traction_n: Vec<[f64; 3]>,
    traction_demand_n: Vec<[f64; 3]>,
    axle_force_n: Vec<[f64; 3]>,
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

impl Trace {
    pub(crate) fn with_capacity(len: usize) -> PyResult<Self> {
        Ok(Self {
            time_secs: reserve(len)?,
            input: reserve(len)?,
            normal_force_n: reserve(len)?,
            traction_n: reserve(len)?,
            traction_demand_n: reserve(len)?,
            axle_force_n: reserve(len)?,
            cone_utilisation: reserve(len)?,
            slip_speed_m_per_s: reserve(len)?,
            slipping: reserve(len)?,
            motor_torque_nm: reserve(len)?,
            wheel_speed_rad_per_s: reserve(len)?,
            wheel_angle_rad: reserve(len)?,
            ball_position_m: reserve(len)?,
            ball_velocity_m_per_s: reserve(len)?,
            ball_angular_velocity_rad_per_s: reserve(len)?,
            body_position_m: reserve(len)?,
            body_orientation: reserve(len)?,
            body_rate_rad_per_s: reserve(len)?,
            tilt_rad: reserve(len)?,
            tilt_from_vertical_rad: reserve(len)?,
            yaw_rad: reserve(len)?,
            floor_force_n: reserve(len)?,
        })
    }

    fn push(&mut self, t: &StepTelemetry, input: [f64; 3]) {
        let wheels = |f: fn(&WheelTelemetry) -> f64| t.wheels.each_ref().map(f);
        let v = |v: &Vector3<f64>| [v.x, v.y, v.z];
        self.time_secs.push(t.time_secs);
        self.input.push(input);
        self.normal_force_n.push(wheels(|w| w.normal_force_n));
        self.traction_n.push(wheels(|w| w.traction_n));
        self.traction_demand_n.push(wheels(|w| w.traction_demand_n));
        self.axle_force_n.push(wheels(|w| w.axle_force_n));
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
        d.set_item("time_secs", PyArray1::from_vec(py, self.time_secs))?;
        d.set_item(input_name, table(py, self.input)?)?;
        d.set_item("normal_force_n", table(py, self.normal_force_n)?)?;
        d.set_item("traction_n", table(py, self.traction_n)?)?;
        d.set_item("traction_demand_n", table(py, self.traction_demand_n)?)?;
        d.set_item("axle_force_n", table(py, self.axle_force_n)?)?;
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
pub(crate) struct RunOptions {
    n_steps: usize,
    record_every: usize,
    stop_on_failure: bool,
}

impl RunOptions {
    /// Checks the counts as Python passed them (any int): `n_steps >= 0`, `record_every >= 1`;
    /// a `ParameterError` (a `ValueError`) naming the argument otherwise, rather than pyo3's
    /// `OverflowError` for a negative int that names nothing.
    pub(crate) fn new(
        py: Python<'_>,
        n_steps: i64,
        record_every: i64,
        stop_on_failure: bool,
    ) -> PyResult<Self> {
        let count = |value: i64, name: &str, min: i64| {
            usize::try_from(value)
                .ok()
                .filter(|_| value >= min)
                .ok_or_else(|| {
                    error(
                        py,
                        Kind::Parameter,
                        format!("invalid parameter `{name}`: must be >= {min}, got {value}"),
                    )
                })
        };
        Ok(Self {
            n_steps: count(n_steps, "n_steps", 0)?,
            record_every: count(record_every, "record_every", 1)?,
            stop_on_failure,
        })
    }

    /// The number of steps asked for.
    pub(crate) fn n_steps(&self) -> usize {
        self.n_steps
    }

    pub(crate) fn records(&self) -> usize {
        self.n_steps.div_ceil(self.record_every)
    }
}

/// Runs `step(k, input)` for the options' steps, recording every `record_every`-th step (the
/// first included) and the failing one. Returns the trace and the number of steps run.
pub(crate) fn run_steps<E>(
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

/// The logger of a run, if `log_path` or `live` is given: the MCAP file, the live view, or
/// both; `compact` writes the telemetry at 1 kHz.
pub(crate) fn logger(
    py: Python<'_>,
    log_path: Option<&Path>,
    live: Option<&PyLiveView>,
    params: &WorldParams,
    compact: bool,
) -> PyResult<Option<WorldLogger>> {
    let options = if compact {
        WorldLogOptions::compact()
    } else {
        WorldLogOptions::default()
    };
    let sink = match (log_path, live) {
        (None, None) => return Ok(None),
        (Some(path), live) => {
            let file =
                McapLogger::create(path, options.logger.clone()).map_err(|e| log_error(py, e))?;
            let sink = LogSink::file(file);
            match live {
                Some(view) => sink.with_live(view.server.clone()),
                None => sink,
            }
        }
        (None, Some(view)) => LogSink::live(view.server.clone()),
    };
    WorldLogger::with_sink(sink, params, options)
        .map(Some)
        .map_err(|e| log_error(py, e))
}

/// Closes the log of a run.
pub(crate) fn finish_log(py: Python<'_>, log: Option<WorldLogger>) -> PyResult<()> {
    if let Some(log) = log {
        py.detach(|| log.finish()).map_err(|e| log_error(py, e))?;
    }
    Ok(())
}

/// The run's dict: the trace's columns plus `steps` and `failure`.
pub(crate) fn finish_run<'py>(
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
