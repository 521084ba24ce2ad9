//! A run's recording: the per-step columns (`Trace`), how a run records and stops, its MCAP
//! log.

use super::live::PyLiveView;
use super::row_at;
use crate::arrays::reserve;
use crate::errors::{Kind, error};
use crate::log::log_error;
use crate::results::{Columns, FailureParts};
use ballbot_sim::log::{LogSink, McapLogger, WorldLogOptions, WorldLogger};
use ballbot_sim::world::failure::tilt_from_vertical_rad;
use ballbot_sim::world::{Failure, StepTelemetry, WheelTelemetry, WorldParams};
use nalgebra::Vector3;
use pyo3::prelude::*;
use schemars::JsonSchema;
use serde::Serialize;
use std::path::Path;

/// One recorded step of a run as Python has it: each field is a column of the run's result
/// (`(n,)` or `(n, k)`, through [`Columns`]), named as the field; the doc comments are the
/// columns' docstrings.
#[derive(Clone, Copy, Debug, Default, Serialize, JsonSchema)]
pub(crate) struct TraceRow {
    /// Simulated time (s).
    time_secs: f64,
    /// Wheel normal forces (N).
    normal_force_n: [f64; 3],
    /// Wheel tractions along the rolling direction (N).
    traction_n: [f64; 3],
    /// Traction each contact needed to stick (N).
    traction_demand_n: [f64; 3],
    /// Roller losses along each wheel's axle (N); 0 with free rollers.
    axle_force_n: [f64; 3],
    /// `|(F, F_a)| / (mu N)` per wheel.
    cone_utilisation: [f64; 3],
    /// Slip speed per wheel (m/s).
    slip_speed_m_per_s: [f64; 3],
    /// Whether each contact slides.
    slipping: [bool; 3],
    /// Torque each actuator delivered (N m).
    motor_torque_nm: [f64; 3],
    /// Wheel speeds relative to the body (rad/s).
    wheel_speed_rad_per_s: [f64; 3],
    /// Wheel angles relative to the body (rad).
    wheel_angle_rad: [f64; 3],
    /// Ball centre (m).
    ball_position_m: [f64; 3],
    /// Ball velocity (m/s).
    ball_velocity_m_per_s: [f64; 3],
    /// Ball angular velocity (rad/s).
    ball_angular_velocity_rad_per_s: [f64; 3],
    /// Body frame origin (m).
    body_position_m: [f64; 3],
    /// Body orientation `(x, y, z, w)`.
    body_orientation: [f64; 4],
    /// Body angular velocity in the body frame (rad/s).
    body_rate_rad_per_s: [f64; 3],
    /// Body tilt `(theta_x, theta_y)` (rad).
    tilt_rad: [f64; 2],
    /// Angle between the body axis and the vertical (rad).
    tilt_from_vertical_rad: f64,
    /// Body yaw (rad).
    yaw_rad: f64,
    /// Normal force of the floor on the ball (N).
    floor_force_n: f64,
}

impl From<&StepTelemetry> for TraceRow {
    fn from(t: &StepTelemetry) -> Self {
        let wheels = |f: fn(&WheelTelemetry) -> f64| t.wheels.each_ref().map(f);
        let v = |v: &Vector3<f64>| [v.x, v.y, v.z];
        let q = &t.body_orientation.coords;
        Self {
            time_secs: t.time_secs,
            normal_force_n: wheels(|w| w.normal_force_n),
            traction_n: wheels(|w| w.traction_n),
            traction_demand_n: wheels(|w| w.traction_demand_n),
            axle_force_n: wheels(|w| w.axle_force_n),
            cone_utilisation: wheels(|w| w.cone_utilisation),
            slip_speed_m_per_s: wheels(|w| w.slip_speed_m_per_s),
            slipping: t.wheels.map(|w| w.slipping),
            motor_torque_nm: wheels(|w| w.motor_torque_nm),
            wheel_speed_rad_per_s: wheels(|w| w.speed_rad_per_s),
            wheel_angle_rad: wheels(|w| w.angle_rad),
            ball_position_m: v(&t.ball_position_m),
            ball_velocity_m_per_s: v(&t.ball_velocity_m_per_s),
            ball_angular_velocity_rad_per_s: v(&t.ball_angular_velocity_rad_per_s),
            body_position_m: v(&t.body_position_m),
            body_orientation: [q.x, q.y, q.z, q.w],
            body_rate_rad_per_s: v(&t.body_rate_rad_per_s),
            tilt_rad: t.tilt_rad,
            tilt_from_vertical_rad: tilt_from_vertical_rad(t),
            yaw_rad: t.body_orientation.euler_angles().2,
            floor_force_n: t.floor_force_n,
        }
    }
}

/// `World.run`'s input column.
#[derive(Clone, Copy, Debug, Default, Serialize, JsonSchema)]
pub(crate) struct TorqueInput {
    /// Wheel torque commands (N m).
    torque_nm: [f64; 3],
}

impl From<[f64; 3]> for TorqueInput {
    fn from(torque_nm: [f64; 3]) -> Self {
        Self { torque_nm }
    }
}

/// `WorldLoop.run`'s input column.
#[derive(Clone, Copy, Debug, Default, Serialize, JsonSchema)]
pub(crate) struct CommandInput {
    /// Velocity commands `(vx_m_per_s, vy_m_per_s, yaw_rate_rad_per_s)`.
    command: [f64; 3],
}

impl From<[f64; 3]> for CommandInput {
    fn from(command: [f64; 3]) -> Self {
        Self { command }
    }
}

/// Per-step records of a run, with the input column `I` ([`TorqueInput`], [`CommandInput`]).
pub(crate) struct Trace<I> {
    rows: Vec<TraceRow>,
    inputs: Vec<I>,
}

impl<I: From<[f64; 3]>> Trace<I> {
    pub(crate) fn with_capacity(len: usize) -> PyResult<Self> {
        Ok(Self {
            rows: reserve(len)?,
            inputs: reserve(len)?,
        })
    }

    fn push(&mut self, t: &StepTelemetry, input: [f64; 3]) {
        self.rows.push(TraceRow::from(t));
        self.inputs.push(I::from(input));
    }
}

/// A run's trace as `WorldRun` and `WorldLoopRun` have it: the trace's columns, `steps`,
/// `failure` and `log_path` (beside the input column, in [`WorldRunView`] and
/// [`WorldLoopRunView`]).
#[derive(Serialize, JsonSchema)]
pub(crate) struct RunView<'a> {
    #[serde(flatten)]
    trace: Columns<'a, TraceRow>,
    /// Steps run (fewer than asked when stopped on a failure).
    steps: usize,
    /// The first failure detected, or `None`.
    failure: Option<FailureParts>,
    /// The MCAP log written, or `None`.
    #[schemars(extend("x-python-type" = "pathlib.Path"))]
    log_path: Option<&'a Path>,
}

/// A `World.run`: the trace plus the wheel torque commands.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "WorldRun")]
pub(crate) struct WorldRunView<'a> {
    #[serde(flatten)]
    run: RunView<'a>,
    #[serde(flatten)]
    input: Columns<'a, TorqueInput>,
}

/// A `WorldLoop.run`: the trace plus the velocity commands.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "WorldLoopRun")]
pub(crate) struct WorldLoopRunView<'a> {
    #[serde(flatten)]
    run: RunView<'a>,
    #[serde(flatten)]
    input: Columns<'a, CommandInput>,
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
pub(crate) fn run_steps<I: From<[f64; 3]>, E>(
    options: RunOptions,
    inputs: &[[f64; 3]],
    mut trace: Trace<I>,
    mut step: impl FnMut([f64; 3]) -> Result<(StepTelemetry, bool), E>,
) -> Result<(Trace<I>, usize), E> {
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

/// The run's result: `WorldRun` for a [`TorqueInput`] trace, `WorldLoopRun` for a
/// [`CommandInput`] one.
pub(crate) fn finish_run<'py, I: RunInput>(
    py: Python<'py>,
    trace: Trace<I>,
    steps: usize,
    failure: Option<Failure>,
    log_path: Option<&Path>,
) -> PyResult<Bound<'py, PyAny>> {
    let run = RunView {
        trace: Columns(&trace.rows),
        steps,
        failure: failure.map(FailureParts::from),
        log_path,
    };
    I::build(py, run, &trace.inputs)
}

/// An input column and the result class of a run with it.
pub(crate) trait RunInput: Sized {
    /// The result of a run with this input column.
    fn build<'py>(
        py: Python<'py>,
        run: RunView<'_>,
        inputs: &[Self],
    ) -> PyResult<Bound<'py, PyAny>>;
}

impl RunInput for TorqueInput {
    fn build<'py>(
        py: Python<'py>,
        run: RunView<'_>,
        inputs: &[Self],
    ) -> PyResult<Bound<'py, PyAny>> {
        let input = Columns(inputs);
        crate::results::build(py, &WorldRunView { run, input })
    }
}

impl RunInput for CommandInput {
    fn build<'py>(
        py: Python<'py>,
        run: RunView<'_>,
        inputs: &[Self],
    ) -> PyResult<Bound<'py, PyAny>> {
        let input = Columns(inputs);
        crate::results::build(py, &WorldLoopRunView { run, input })
    }
}
