//! The planar simulator (`ballbot_sim::planar`, `ballbot_sim::studies::scenario`) and the PIPTB
//! controller comparison (`ballbot_sim::studies::piptb`, what `ballbot reproduce` runs).
//! Runs release the GIL; a scenario's run comes back through [`crate::results::build`], the
//! PIPTB comparison too (its trials' series as numpy arrays inside the JSON records).

use crate::errors::{Kind, error};
use crate::results::{Array, Columns};
use ballbot_sim::log::planar::McapRecorder;
use ballbot_sim::log::{LoggerOptions, McapLogger};
use ballbot_sim::planar::{ControllerKind, Fault, Observer, OuterTick};
use ballbot_sim::studies::piptb::{
    self, ControllerResult, ExperimentError, PiptbSettings, TrialSeries,
};
use ballbot_sim::studies::scenario::{Scenario, ScenarioError};
use pyo3::prelude::*;
use schemars::JsonSchema;
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
#[derive(Clone, Copy, Debug, Default, Serialize, JsonSchema)]
struct Tick {
    /// Tick times (s).
    time_secs: f64,
    /// True `[theta, phi, theta_dot, phi_dot]`.
    state: [f64; 4],
    /// `[theta_c, theta_dot_c, phi_dot_c]`.
    command: [f64; 3],
    /// Torque the controller requested (N m).
    requested_torque_nm: f64,
    /// Torque delivered (N m).
    torque_nm: f64,
    /// Transmission friction torque (N m).
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

/// A planar scenario's run (`Scenario.run`), sampled at the main controller's ticks.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "ScenarioRun")]
pub(crate) struct ScenarioRunView<'a> {
    #[serde(flatten)]
    ticks: Columns<'a, Tick>,
    /// When the run ended (s).
    end_time_secs: f64,
    /// Why the run stopped early, or `None`.
    fault: Option<&'a str>,
    /// The MCAP log written, or `None`.
    #[schemars(extend("x-python-type" = "pathlib.Path"))]
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
        crate::results::build(py, &view)
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

/// A JSON object as Python has it (`dict[str, Any]`).
type JsonObject = serde_json::Map<String, serde_json::Value>;

/// The PIPTB controller comparison (`piptb_experiment`).
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "PiptbExperiment")]
pub(crate) struct PiptbExperimentView {
    /// When braking starts (s).
    brake_start_secs: f64,
    /// When braking ends (s).
    brake_end_secs: f64,
    /// The braking reference: effort, peak tilt, duration, source.
    #[schemars(with = "JsonObject")]
    reference: serde_json::Value,
    /// Per controller key: the metrics and the trials (each with `series`), braking phase
    /// `[t2, t2 + 1.4 s]` (the fixed window).
    #[schemars(with = "std::collections::BTreeMap<String, JsonObject>")]
    controllers: ControllersView,
    /// The same shape, braking phase `[t2, t3]` with `t3` when the testbed stopped (the speed
    /// within the stop band for the stop hold; `t3_capped` when it never did).
    #[schemars(with = "std::collections::BTreeMap<String, JsonObject>")]
    controllers_until_stopped: ControllersView,
}

/// Per controller key: its result's JSON record, each trial with its `series` (numpy arrays
/// at the controller's ticks, as [`Array`]s).
struct ControllersView(Vec<(&'static str, serde_json::Value, Vec<SeriesView>)>);

impl ControllersView {
    fn new(py: Python<'_>, controllers: Vec<ControllerResult>) -> PyResult<Self> {
        let mut out = Vec::with_capacity(controllers.len());
        for c in controllers {
            let series = c
                .trials
                .iter()
                .map(|t| SeriesView::from(&t.series))
                .collect();
            let record =
                serde_json::to_value(&c).map_err(|e| error(py, Kind::Other, e.to_string()))?;
            out.push((c.kind.key(), record, series));
        }
        Ok(Self(out))
    }
}

impl Serialize for ControllersView {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(key, record, series)| {
            let entry = ControllerView { record, series };
            (key, entry)
        }))
    }
}

/// One controller's record with `series` added to each of its `trials`.
struct ControllerView<'a> {
    record: &'a serde_json::Value,
    series: &'a [SeriesView],
}

impl Serialize for ControllerView<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let fields = self.record.as_object().into_iter().flatten();
        let mut map = s.serialize_map(None)?;
        for (key, value) in fields {
            match (key.as_str(), value.as_array()) {
                ("trials", Some(trials)) => {
                    let trials: Vec<TrialView<'_>> = trials
                        .iter()
                        .zip(self.series)
                        .map(|(record, series)| TrialView { record, series })
                        .collect();
                    map.serialize_entry(key, &trials)?;
                }
                _ => map.serialize_entry(key, value)?,
            }
        }
        map.end()
    }
}

/// A trial's record and its series.
#[derive(Serialize)]
struct TrialView<'a> {
    #[serde(flatten)]
    record: &'a serde_json::Value,
    series: &'a SeriesView,
}

/// A trial's time series as arrays.
#[derive(Serialize)]
struct SeriesView {
    time_secs: Array,
    tilt_rad: Array,
    speed_m_per_s: Array,
    command_speed_m_per_s: Array,
    torque_nm: Array,
    friction_torque_nm: Array,
    effort_n2m2s: Array,
}

impl From<&TrialSeries> for SeriesView {
    fn from(s: &TrialSeries) -> Self {
        let column = |v: &[f64]| Array::column(v.iter().copied());
        Self {
            time_secs: column(&s.time_secs),
            tilt_rad: column(&s.tilt_rad),
            speed_m_per_s: column(&s.speed_m_per_s),
            command_speed_m_per_s: column(&s.command_speed_m_per_s),
            torque_nm: column(&s.torque_nm),
            friction_torque_nm: column(&s.friction_torque_nm),
            effort_n2m2s: column(&s.effort_n2m2s),
        }
    }
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

    let view = PiptbExperimentView {
        brake_start_secs: settings.brake_start_secs(),
        brake_end_secs: settings.brake_end_secs(),
        reference: serde_json::to_value(&report.reference)
            .map_err(|e| error(py, Kind::Other, e.to_string()))?,
        controllers: ControllersView::new(py, report.controllers)?,
        controllers_until_stopped: ControllersView::new(py, until.controllers)?,
    };
    crate::results::build(py, &view)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScenario>()?;
    m.add_function(wrap_pyfunction!(piptb_experiment, m)?)?;
    Ok(())
}
