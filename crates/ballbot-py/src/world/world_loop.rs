//! `WorldLoop`: the world with the core's controller in the loop, and its command-shaping
//! overrides.

use super::class::world_class;
use super::live::PyLiveView;
use super::telemetry::{PyFailure, PyMeasurement, PyStepTelemetry, vec_out};
use super::trace::{CommandInput, RunOptions, Trace, finish_log, finish_run, logger, run_steps};
use super::{Arr, finite, non_negative, params_or_default, step_rows, vec3};
use crate::errors::world_error;
use crate::errors::{Kind, core_error, error};
use crate::log::log_error;
use crate::params::{PyControllerConfig, PyWorldParams};
use ballbot_core::ballbot::{BallbotControllerConfig, WheelMapping};
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::{BallbotWorld, WorldParams};
use nalgebra::Vector3;
use numpy::PyArray1;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Overrides of the controller's command shaping (`BallbotControllerConfig.shaping`), e.g. to
/// lift the translation caps so that a ramp, not the shaper, sets the command.
#[derive(Clone, Copy, Default)]
pub(crate) struct Shaping {
    /// The controller to start from (`controller=`, a `ControllerConfig`): replaces the
    /// designed one; the overrides below still apply on top, except `traction_control` and
    /// `balance_point`, which only choose the designed controller (the caller refuses them
    /// with a controller, see [`Shaping::layers`]).
    pub(crate) controller: Option<BallbotControllerConfig<f64>>,
    pub(crate) max_speed_m_per_s: Option<f64>,
    pub(crate) max_accel_m_per_s2: Option<f64>,
    pub(crate) max_jerk_m_per_s3: Option<f64>,
    pub(crate) max_tilt_command_rad: Option<f64>,
    pub(crate) max_tilt_rate_command_rad_per_s: Option<f64>,
    /// The wheel mapping by its canonical name (`"rolling_ball"`, `"upright"`); `None`: the
    /// designed default.
    pub(crate) wheel_mapping: Option<WheelMapping>,
    /// Traction-aware control on (`BallbotControllerConfig::with_traction_control`).
    pub(crate) traction_control: bool,
    /// Balance-point estimation on
    /// (`BallbotControllerConfig::with_balance_point_estimation`).
    pub(crate) balance_point: bool,
    /// The IMU filter's time constant to correct the tilt for
    /// (`BallbotControllerConfig::with_imu_lean_correction`); `None`: no correction.
    pub(crate) imu_lean_time_constant_secs: Option<f64>,
}

impl Shaping {
    /// The `traction_control` and `balance_point` keywords (`None`: not given) as the layers
    /// of the designed controller (`None` is on); with a `controller` they are an error, as
    /// its own `traction.enabled` and `balance_point.enabled` say which layers run.
    pub(crate) fn layers(
        py: Python<'_>,
        controller: Option<&PyControllerConfig>,
        traction_control: Option<bool>,
        balance_point: Option<bool>,
    ) -> PyResult<(bool, bool)> {
        if controller.is_some() && (traction_control.is_some() || balance_point.is_some()) {
            return Err(error(
                py,
                Kind::Parameter,
                "`traction_control` and `balance_point` choose the layers of the designed \
                 controller; with `controller=` its own `traction.enabled` and \
                 `balance_point.enabled` decide (set them with `ControllerConfig.replace`)",
            ));
        }
        Ok((
            traction_control.unwrap_or(true),
            balance_point.unwrap_or(true),
        ))
    }

    /// The controller with these overrides: `controller` if given, else the one designed from
    /// the robot, the paper's configuration (`BallbotControllerConfig::paper`) with the layers
    /// asked for (with both on, the shipped default, `BallbotControllerConfig::design`); then
    /// the shaping caps, the wheel mapping and the IMU-lean correction given.
    pub(crate) fn config(
        &self,
        py: Python<'_>,
        params: &WorldParams,
    ) -> PyResult<BallbotControllerConfig<f64>> {
        let mut config = match self.controller {
            Some(config) => config,
            None => BallbotControllerConfig::paper(&params.robot).map_err(|e| core_error(py, e))?,
        };
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
                // An infinite jerk limit means none (`AxisLimits::unlimited_jerk_per_s2`).
                let unlimited = name == "max_jerk_m_per_s3" && v == f64::INFINITY;
                if !(unlimited || v.is_finite() && v > 0.0) {
                    return Err(error(
                        py,
                        Kind::Parameter,
                        format!(
                            "invalid parameter `{name}`: must be finite and > 0 \
                             (max_jerk_m_per_s3 also inf: no jerk limit), got {v}"
                        ),
                    ));
                }
                *slot = v;
            }
        }
        if let Some(mapping) = self.wheel_mapping {
            config.wheel_mapping = mapping;
        }
        if self.controller.is_none() {
            if self.traction_control {
                config = config.with_traction_control();
            }
            if self.balance_point {
                config = config.with_balance_point_estimation();
            }
        }
        if let Some(tau) = self.imu_lean_time_constant_secs {
            config = config.with_imu_lean_correction(tau);
        }
        Ok(config)
    }
}

pub(crate) fn velocity(command: [f64; 3]) -> VelocityCommand<f64> {
    VelocityCommand {
        vx_m_per_s: command[0],
        vy_m_per_s: command[1],
        yaw_rate_rad_per_s: command[2],
    }
}

world_class! {
    /// The 3D world driven by the core's controller at its two rates
    /// (`ballbot_sim::rig::WorldRobot`): the cascaded LQR-PI outer loop (400 Hz) reads the
    /// simulated IMU and encoders, the per-motor speed PIs (8 kHz) drive the wheels. Every
    /// `World` method that inspects or disturbs the world is here too.
    ///
    /// The controller is designed from the robot (`BallbotControllerConfig::design`, the
    /// shipped default); the
    /// keyword arguments `max_speed_m_per_s`, `max_accel_m_per_s2`, `max_jerk_m_per_s3`,
    /// `max_tilt_command_rad`, `max_tilt_rate_command_rad_per_s` override its command
    /// shaping (defaults 2.0 m/s, 1.0 m/s^2, 2.0 m/s^3, 0.2 rad, 1.0 rad/s; `max_jerk_m_per_s3 =
    /// math.inf` removes the jerk limit). `wheel_mapping` chooses how the reference rates map to
    /// the wheels: `"rolling_ball"` (default) or `"upright"`, the paper's mapping, an ablation
    /// (`WheelMapping` in the core; with `max_jerk_m_per_s3 = math.inf` this is
    /// `BallbotControllerConfig::with_paper_ablation`). `traction_control` (default `True`)
    /// is traction-aware control (`BallbotControllerConfig::with_traction_control`: the
    /// direction-dependent acceleration envelope, slip and lift-off detection); `traction`
    /// then reports each outer step and `traction_envelope()` gives the envelope.
    /// `balance_point` (default `True`) is balance-point estimation
    /// (`BallbotControllerConfig::with_balance_point_estimation`). With both `False` the
    /// controller is the paper's configuration (`BallbotControllerConfig::paper`).
    /// `imu_lean_time_constant_secs` corrects the measured tilt for an IMU attitude filter of
    /// that time constant (`BallbotControllerConfig::with_imu_lean_correction`; for the world's
    /// `SensorParams.preset("miapure")`, its `imu.filter_time_constant_secs`); default `None`.
    ///
    /// `controller` (a `ControllerConfig`, e.g. read from a controller file) replaces the
    /// designed controller, its own robot model included (designed for another robot than the
    /// world's, it runs as a model mismatch); the shaping keywords, `wheel_mapping` and
    /// `imu_lean_time_constant_secs` still apply on top of it, while `traction_control` and
    /// `balance_point` are then an error (the controller's `traction.enabled` and
    /// `balance_point.enabled` decide).
    PyWorldLoop("WorldLoop") {
        inner: WorldRobot,
        world: |this| this.inner.world(),
        world_mut: |this| this.inner.world_mut(),
    }
    methods {
        #[new]
        #[pyo3(signature = (
            params = None, *, max_speed_m_per_s = None, max_accel_m_per_s2 = None,
            max_jerk_m_per_s3 = None, max_tilt_command_rad = None,
            max_tilt_rate_command_rad_per_s = None, wheel_mapping = None,
            traction_control = None, balance_point = None, imu_lean_time_constant_secs = None,
            controller = None,
        ))]
        #[allow(clippy::too_many_arguments)]
        fn py_new(
            py: Python<'_>,
            params: Option<PyWorldParams>,
            max_speed_m_per_s: Option<f64>,
            max_accel_m_per_s2: Option<f64>,
            max_jerk_m_per_s3: Option<f64>,
            max_tilt_command_rad: Option<f64>,
            max_tilt_rate_command_rad_per_s: Option<f64>,
            wheel_mapping: Option<&str>,
            traction_control: Option<bool>,
            balance_point: Option<bool>,
            imu_lean_time_constant_secs: Option<f64>,
            controller: Option<PyControllerConfig>,
        ) -> PyResult<Self> {
            let params = params_or_default(params);
            let (traction_control, balance_point) =
                Shaping::layers(py, controller.as_ref(), traction_control, balance_point)?;
            let wheel_mapping = wheel_mapping
                .map(|name| {
                    name.parse::<WheelMapping>().map_err(|e| {
                        error(
                            py,
                            Kind::Parameter,
                            format!("invalid parameter `wheel_mapping`: {e}: {name:?}"),
                        )
                    })
                })
                .transpose()?;
            let config = Shaping {
                controller: controller.map(|c| c.inner),
                max_speed_m_per_s,
                max_accel_m_per_s2,
                max_jerk_m_per_s3,
                max_tilt_command_rad,
                max_tilt_rate_command_rad_per_s,
                wheel_mapping,
                traction_control,
                balance_point,
                imu_lean_time_constant_secs,
            }
            .config(py, &params)?;
            let inner = WorldRobot::with_config(params, config).map_err(|e| world_error(py, e))?;
            Ok(Self { inner })
        }

        /// The controller's mode: `Mode.IDLE` (before the first step arms it),
        /// `BALANCING`, `CONTROLLED_STOP` or `FAULT`.
        #[getter]
        fn mode<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            crate::enums::mode(py, self.inner.mode())
        }

        /// Traction-aware control's report of the last outer step (`TractionStatus`): the
        /// acceleration limit along the command's direction, whether it limited the command,
        /// each wheel's estimated slip speed and slip flag, the predicted normal forces, the
        /// envelope scale and the friction estimate. `None` when traction control is off or
        /// before the first outer step.
        #[getter]
        fn traction<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
            let status = self.inner.last_outer().and_then(|out| out.traction);
            status.map(|s| super::traction::status(py, &s)).transpose()
        }

        /// The controller's traction envelope (`TractionEnvelope`): the largest acceleration
        /// (m/s^2) at each of its 96 table headings (rad, body frame, 0 towards OW1), with the
        /// recommended margins; `None` when traction control is off.
        fn traction_envelope<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
            let control = self.inner.robot().controller().traction();
            control.map(|c| super::traction::envelope(py, c)).transpose()
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
        /// Returns a `WorldLoopRun`, the columns of `World.run` with `command` (n, 3) instead
        /// of `torque_nm` (`motor_torque_nm` holds what the controller drove). `log_path` and `log_compact`
        /// as in `World.run`; the log also carries the controller's outer loop and the
        /// commands (what `ballbot world` writes). `live`: a `LiveView` to serve the run to
        /// Foxglove as it goes (`ballbot world --live`).
        #[pyo3(signature = (
            n_steps, command = None, *, record_every = 1, stop_on_failure = false,
            log_path = None, log_compact = false, live = None,
        ))]
        #[allow(clippy::too_many_arguments)]
        fn run<'py>(
            &mut self,
            py: Python<'py>,
            n_steps: i64,
            command: Option<Arr<'py>>,
            record_every: i64,
            stop_on_failure: bool,
            log_path: Option<PathBuf>,
            log_compact: bool,
            live: Option<PyRef<'py, PyLiveView>>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let options = RunOptions::new(py, n_steps, record_every, stop_on_failure)?;
            let inputs = step_rows(py, command, options.n_steps(), "command")?;
            let trace = Trace::<CommandInput>::with_capacity(options.records())?;
            let params = *self.inner.world().params();
            let mut log = logger(py, log_path.as_deref(), live.as_deref(), &params, log_compact)?;
            let sim = &mut self.inner;
            let result = py.detach(|| {
                run_steps(options, &inputs, trace, |cmd| {
                    let command = velocity(cmd);
                    if let Some(log) = log.as_mut() {
                        log.record_command(sim.world().time_secs(), &command)?;
                    }
                    let telemetry = *sim.step(Command::Velocity(command));
                    if let Some(log) = log.as_mut() {
                        log.record_robot(sim)?;
                    }
                    Ok((telemetry, sim.world().failure().is_some()))
                })
            });
            let (trace, steps) = result.map_err(|e| log_error(py, e))?;
            finish_log(py, log)?;
            finish_run(py, trace, steps, self.inner.world().failure(), log_path.as_deref())
        }
    }
}
