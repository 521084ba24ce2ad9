//! The planar simulator (`ballbot_sim::planar`, `ballbot_sim::studies::scenario`) and the PIPTB
//! controller comparison (`ballbot_sim::studies::piptb`, what `ballbot reproduce` runs).
//! Runs release the GIL; a scenario's run comes back through [`crate::results::build`], the
//! PIPTB comparison as a hand-filled dict.

use crate::errors::{Kind, error};
use crate::log::json_to_py;
use crate::results::Columns;
use ballbot_sim::log::planar::McapRecorder;
use ballbot_sim::log::{LoggerOptions, McapLogger};
use ballbot_sim::planar::{ControllerKind, Fault, Observer, OuterTick};
use ballbot_sim::studies::piptb::{
    self, ControllerResult, ExperimentError, PiptbSettings, TrialSeries,
};
use ballbot_sim::studies::scenario::{Scenario, ScenarioError};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;
use std::path::{Path, PathBuf};

fn scenario_error(py: Python<'_>, e: ScenarioError) -> PyErr {
    let kind = match e {
        ScenarioError::Read { .. } => Kind::File,
        _ => Kind::Parameter,
    };
    error(py, kind, e.to_string())
}

fn experiment_error(py: Python<'_>, e: ExperimentError) -> PyErr {
    let kind = match e {
        ExperimentError::Log(_) => Kind::File,
        ExperimentError::Braking(_) => Kind::Solver,
        _ => Kind::Parameter,
    };
    error(py, kind, e.to_string())
}

/// What a run records at every tick of the main controller: one [`Tick`] per tick and the
/// fault that stopped it.
#[derive(Default)]
struct Recorder {
    ticks: Vec<Tick>,
    fault: Option<String>,
}

/// One tick as `ScenarioRun`'s columns have it (through [`Columns`], named as the fields).
#[derive(Clone, Copy, Debug, Default, Serialize)]
struct Tick {
    time_secs: f64,
    /// True `[theta, phi, theta_dot, phi_dot]`.
    state: [f64; 4],
    /// `[theta_c, theta_dot_c, phi_dot_c]`.
    command: [f64; 3],
    requested_torque_nm: f64,
    /// Delivered.
    torque_nm: f64,
    friction_torque_nm: f64,
    /// 1.0 when saturated, else 0.0.
    saturated: f64,
}

impl Observer for Recorder {
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        self.ticks.push(Tick {
            time_secs: tick.time_secs,
            state: tick.state.into(),
            command: [
                tick.command.tilt_rad,
                tick.command.tilt_rate_rad_per_s,
                tick.command.ball_rate_rad_per_s,
            ],
            requested_torque_nm: tick.step.requested_torque_nm,
            torque_nm: tick.step.applied_torque_nm,
            friction_torque_nm: tick.step.friction_torque_nm,
            saturated: if tick.step.saturated { 1.0 } else { 0.0 },
        });
    }

    fn fault(&mut self, fault: &Fault) {
        self.fault = Some(format!("{:?} at {:.4} s", fault.kind, fault.time_secs));
    }
}

/// A scenario's run as `ballbot._results.ScenarioRun` has it.
#[derive(Serialize)]
struct ScenarioRunView<'a> {
    #[serde(flatten)]
    ticks: Columns<'a, Tick>,
    end_time_secs: f64,
    fault: Option<&'a str>,
    log_path: Option<&'a Path>,
}

/// Why a scenario run failed after it was validated.
enum RunError {
    Scenario(ScenarioError),
    Log(String),
}

/// A planar simulation scenario (`ballbot_sim::studies::scenario::Scenario`): robot, friction,
/// sensors, rates, controller, command profile, seed and duration, as in a scenario TOML file.
#[pyclass(name = "Scenario", module = "ballbot", frozen)]
pub struct PyScenario {
    inner: Scenario,
}

#[pymethods]
impl PyScenario {
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

    /// Parses a scenario from TOML text (unknown keys are errors naming the key).
    #[staticmethod]
    fn from_toml(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner = Scenario::from_toml_str(text).map_err(|e| scenario_error(py, e))?;
        Ok(Self { inner })
    }

    /// Reads a scenario file.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let inner = Scenario::from_path(&path).map_err(|e| scenario_error(py, e))?;
        Ok(Self { inner })
    }

    /// The noise seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }

    /// Simulated time (s).
    #[getter]
    fn duration_secs(&self) -> f64 {
        self.inner.duration_secs
    }

    /// The controller: `"lqr"`, `"pi_pd"` or `"lqr_pi"`.
    #[getter]
    fn controller(&self) -> &'static str {
        self.inner.controller.kind.key()
    }

    /// Runs the scenario without the GIL, writing every channel to the MCAP file `log_path`
    /// when given. Returns a `ScenarioRun` sampled at the main controller's ticks: `time_secs` (n,),
    /// `state` (n, 4) true `[theta, phi, theta_dot, phi_dot]`, `command` (n, 3)
    /// `[theta_c, theta_dot_c, phi_dot_c]`, `requested_torque_nm`, `torque_nm` (delivered),
    /// `friction_torque_nm`, `saturated` (1.0 / 0.0) (n,); and `end_time_secs`, `fault` (None
    /// or why the run stopped), `log_path` (None or the MCAP file).
    #[pyo3(signature = (log_path = None))]
    fn run<'py>(&self, py: Python<'py>, log_path: Option<PathBuf>) -> PyResult<Bound<'py, PyAny>> {
        let scenario = &self.inner;
        let result = py.detach(|| run_scenario(scenario, log_path.as_deref()));
        let (rec, end_time_secs) = match result {
            Ok(r) => r,
            Err(RunError::Scenario(e)) => return Err(scenario_error(py, e)),
            Err(RunError::Log(m)) => return Err(error(py, Kind::File, m)),
        };
        let view = ScenarioRunView {
            ticks: Columns(&rec.ticks),
            end_time_secs,
            fault: rec.fault.as_deref(),
            log_path: log_path.as_deref(),
        };
        crate::results::build(py, "ScenarioRun", &view)
    }
}

fn run_scenario(scenario: &Scenario, log_path: Option<&Path>) -> Result<(Recorder, f64), RunError> {
    let robot = scenario.robot.params().map_err(RunError::Scenario)?;
    let mut sim = scenario.simulator().map_err(RunError::Scenario)?;
    let mut controller = scenario
        .controller
        .build(&robot, sim.plant().joint_gain(0.0))
        .map_err(|e| RunError::Scenario(e.into()))?;
    let profile = scenario.command_profile().map_err(RunError::Scenario)?;
    let mut rec = Recorder::default();
    let outcome = match log_path {
        Some(path) => {
            let log_err = |e: ballbot_sim::log::LogError| RunError::Log(e.to_string());
            let mut log = McapLogger::create(path, LoggerOptions::default()).map_err(log_err)?;
            let mut recorder =
                McapRecorder::new(&mut log, robot.plane.ball_radius_m).map_err(log_err)?;
            let outcome = sim.run(
                &mut controller,
                &profile,
                scenario.duration_secs,
                &mut (&mut rec, &mut recorder),
            );
            recorder.finish().map_err(log_err)?;
            log.finish().map_err(log_err)?;
            outcome
        }
        None => sim.run(&mut controller, &profile, scenario.duration_secs, &mut rec),
    };
    Ok((rec, outcome.end_time_secs))
}

fn parse_kind(py: Python<'_>, key: &str) -> PyResult<ControllerKind> {
    ControllerKind::ALL
        .into_iter()
        .find(|k| k.key() == key)
        .ok_or_else(|| {
            error(
                py,
                Kind::Parameter,
                format!("unknown controller `{key}`; known: lqr, pi_pd, lqr_pi"),
            )
        })
}

fn series_dict<'py>(py: Python<'py>, s: TrialSeries) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time_secs", PyArray1::from_vec(py, s.time_secs))?;
    d.set_item("tilt_rad", PyArray1::from_vec(py, s.tilt_rad))?;
    d.set_item("speed_m_per_s", PyArray1::from_vec(py, s.speed_m_per_s))?;
    d.set_item(
        "command_speed_m_per_s",
        PyArray1::from_vec(py, s.command_speed_m_per_s),
    )?;
    d.set_item("torque_nm", PyArray1::from_vec(py, s.torque_nm))?;
    d.set_item(
        "friction_torque_nm",
        PyArray1::from_vec(py, s.friction_torque_nm),
    )?;
    d.set_item("effort_n2m2s", PyArray1::from_vec(py, s.effort_n2m2s))?;
    Ok(d)
}

/// Per controller key: its result as a dict, each trial with its `series`.
fn controllers_dict<'py>(
    py: Python<'py>,
    controllers: Vec<ControllerResult>,
) -> PyResult<Bound<'py, PyDict>> {
    let by_kind = PyDict::new(py);
    for c in controllers {
        let series: Vec<TrialSeries> = c.trials.iter().map(|t| t.series.clone()).collect();
        let value = serde_json::to_value(&c).map_err(|e| error(py, Kind::Other, e.to_string()))?;
        let entry = json_to_py(py, &value)?;
        if let Ok(list) = entry.get_item("trials") {
            for (i, s) in series.into_iter().enumerate() {
                list.get_item(i)?.set_item("series", series_dict(py, s)?)?;
            }
        }
        by_kind.set_item(c.kind.key(), entry)?;
    }
    Ok(by_kind)
}

/// The PIPTB controller comparison of the paper (Sec. IV-C), as `ballbot reproduce` runs it:
/// 0 -> 1 m/s in 2 s, hold, then track the braking reference to rest in 1.4 s, on the PIPTB
/// with transmission stiction and sensor noise, seeded trials per controller.
///
/// `quick` runs the CI variant (one trial, shorter hold). `trials` and `base_seed` override the
/// settings; `controllers` picks from `"lqr"`, `"pi_pd"`, `"lqr_pi"`; `log_dir` writes one MCAP
/// log per trial there. Returns a `PiptbExperiment`: `brake_start_secs`, `brake_end_secs`, `reference`
/// (its effort, peak tilt, duration, source) and `controllers`, keyed by controller: `j_p`
/// (mean braking effort, N^2 m^2 s), `j_p_std`, `j_p_n2mm2s`, `stopped_all`, `speed_rmse`,
/// `torque_jitter_nm`, the paper's `paper_j_p_n2mm2s` and `paper_stopped`, and `trials`, each
/// with its metrics (`t3_secs`, the end of the measured braking phase, among them), `log_path`
/// and `series` (numpy arrays at the controller's ticks, `effort_n2m2s` the running braking
/// effort). `controllers_until_stopped` has the same shape for the reading "t3 = when the
/// testbed stopped": the speed within `stop_speed_m_per_s` (default 0.05) for
/// `stop_hold_secs` (default 0.2), capped at the end of the run (`t3_capped`).
#[pyfunction]
#[pyo3(signature = (
    *, quick = false, trials = None, base_seed = None, controllers = None, log_dir = None,
    stop_speed_m_per_s = None, stop_hold_secs = None,
))]
#[allow(clippy::too_many_arguments)]
fn piptb_experiment<'py>(
    py: Python<'py>,
    quick: bool,
    trials: Option<usize>,
    base_seed: Option<u64>,
    controllers: Option<Vec<String>>,
    log_dir: Option<PathBuf>,
    stop_speed_m_per_s: Option<f64>,
    stop_hold_secs: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut settings = if quick {
        PiptbSettings::quick()
    } else {
        PiptbSettings::paper()
    };
    if let Some(t) = trials {
        if t == 0 {
            return Err(error(
                py,
                Kind::Parameter,
                "invalid parameter `trials`: must be >= 1",
            ));
        }
        settings.trials = t;
    }
    if let Some(seed) = base_seed {
        settings.base_seed = seed;
    }
    if let Some(v) = stop_speed_m_per_s {
        settings.stop_speed_m_per_s = v;
    }
    if let Some(v) = stop_hold_secs {
        settings.stop_hold_secs = v;
    }
    settings
        .stop_criterion()
        .validate()
        .map_err(|e| experiment_error(py, e))?;
    let kinds: Vec<ControllerKind> = match controllers {
        Some(keys) => keys
            .iter()
            .map(|k| parse_kind(py, k))
            .collect::<PyResult<_>>()?,
        None => ControllerKind::ALL.to_vec(),
    };
    if let Some(dir) = &log_dir {
        std::fs::create_dir_all(dir)
            .map_err(|e| error(py, Kind::File, format!("{}: {e}", dir.display())))?;
    }
    let (report, until) = py
        .detach(|| {
            let brake = piptb::braking_reference(&settings)?;
            let report = piptb::run(&settings, brake, &kinds, log_dir.as_deref(), &mut |_, _| {})?;
            let until = report.until_stopped(&settings.stop_criterion())?;
            Ok::<_, ExperimentError>((report, until))
        })
        .map_err(|e| experiment_error(py, e))?;

    let out = PyDict::new(py);
    out.set_item("brake_start_secs", settings.brake_start_secs())?;
    out.set_item("brake_end_secs", settings.brake_end_secs())?;
    let reference = serde_json::to_value(&report.reference)
        .map_err(|e| error(py, Kind::Other, e.to_string()))?;
    out.set_item("reference", json_to_py(py, &reference)?)?;
    out.set_item("controllers", controllers_dict(py, report.controllers)?)?;
    out.set_item(
        "controllers_until_stopped",
        controllers_dict(py, until.controllers)?,
    )?;
    crate::results::make(py, "PiptbExperiment", out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScenario>()?;
    m.add_function(wrap_pyfunction!(piptb_experiment, m)?)?;
    Ok(())
}
