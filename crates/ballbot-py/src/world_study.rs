//! The maximum-speed study of the 3D world (`ballbot_sim::world::max_speed`, what `ballbot
//! reproduce` runs for the paper's Sec. V): seeded slow-ramp trials per heading, the failing
//! ramp acceleration per heading, the capability map and the mu / COM-height sensitivity.
//! The braking (`braking_run`, `braking_study`) and push-recovery (`push_trial`,
//! `push_recovery_limit`) experiments. Everything runs in Rust without the GIL.

use crate::errors::{Kind, error};
use crate::log::json_to_py;
use crate::params::PyWorldParams;
use crate::world::{PyFailure, ramp_dict, world_error};
use ballbot_sim::studies::max_speed::{
    FailingAccel, MaxSpeedProtocol, MaxSpeedStudySettings, TrialOutcome, failing_acceleration,
    run_study, slow_ramp_trial,
};
use ballbot_sim::studies::push::{
    PushOutcome, PushParams, PushSample, PushSearch, PushTrial, push_recovery_limit, push_trial,
};
use ballbot_sim::studies::world_braking::{
    BrakingError, BrakingOutcome, BrakingParams, BrakingRun, BrakingSample, BrakingStudyParams,
    TrajectoryFeedforward, braking_run, braking_study,
};
use ballbot_sim::world::WorldParams;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn params_or_default(params: Option<PyWorldParams>) -> WorldParams {
    params.map_or_else(WorldParams::miapure_60kg, |p| p.inner)
}

/// The study's protocol with the search overrides, checked (the search divides by the
/// resolution and assumes `0 < low < high`).
fn protocol(
    py: Python<'_>,
    base: MaxSpeedProtocol,
    fast_top_m_per_s: Option<f64>,
    accel_bracket_m_per_s2: Option<(f64, f64)>,
    accel_resolution_m_per_s2: Option<f64>,
) -> PyResult<MaxSpeedProtocol> {
    let mut p = base;
    if let Some(v) = fast_top_m_per_s {
        p.fast_top_m_per_s = v;
    }
    if let Some((low, high)) = accel_bracket_m_per_s2 {
        p.accel_bracket_m_per_s2 = [low, high];
    }
    if let Some(v) = accel_resolution_m_per_s2 {
        p.accel_resolution_m_per_s2 = v;
    }
    let [low, high] = p.accel_bracket_m_per_s2;
    let res = p.accel_resolution_m_per_s2;
    if !(low.is_finite() && high.is_finite() && low > 0.0 && high > low) {
        return Err(error(
            py,
            Kind::Parameter,
            format!(
                "invalid parameter `accel_bracket_m_per_s2`: need 0 < low < high, got ({low}, {high})"
            ),
        ));
    }
    if !(res.is_finite() && res > 0.0 && (high - low) / res <= 1e6) {
        return Err(error(
            py,
            Kind::Parameter,
            format!(
                "invalid parameter `accel_resolution_m_per_s2`: must be > 0 and leave at most \
                 1e6 grid points in the bracket, got {res}"
            ),
        ));
    }
    if !(p.fast_top_m_per_s.is_finite() && p.fast_top_m_per_s > 0.0) {
        return Err(error(
            py,
            Kind::Parameter,
            format!(
                "invalid parameter `fast_top_m_per_s`: must be finite and > 0, got {}",
                p.fast_top_m_per_s
            ),
        ));
    }
    Ok(p)
}

fn outcome_dict<'py>(py: Python<'py>, o: &TrialOutcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("heading_deg", o.heading_deg)?;
    d.set_item("seed", o.seed)?;
    d.set_item("accel_m_per_s2", o.accel_m_per_s2)?;
    d.set_item("max_speed_m_per_s", o.max_speed_m_per_s)?;
    d.set_item("censored", o.censored())?;
    d.set_item("failure", o.failure.map(PyFailure::from))?;
    d.set_item("peak_cone_utilisation", o.peak_cone_utilisation)?;
    d.set_item("min_normal_force_n", o.min_normal_force_n)?;
    d.set_item("peak_tilt_rad", o.peak_tilt_rad)?;
    d.set_item("supervisor_stop_s", o.supervisor_stop_s)?;
    Ok(d)
}

fn failing_dict<'py>(py: Python<'py>, f: FailingAccel) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("heading_deg", f.heading_deg)?;
    d.set_item("largest_surviving_m_per_s2", f.largest_surviving_m_per_s2)?;
    d.set_item("smallest_failing_m_per_s2", f.smallest_failing_m_per_s2)?;
    d.set_item("censored", f.smallest_failing_m_per_s2.is_none())?;
    d.set_item("text", f.text())?;
    d.set_item("runs", f.runs)?;
    let failing = f.failing.map(|o| outcome_dict(py, &o)).transpose()?;
    d.set_item("failing", failing)?;
    let surviving = f.surviving.map(|o| outcome_dict(py, &o)).transpose()?;
    d.set_item("surviving", surviving)?;
    let run = f.failing_run.map(|r| ramp_dict(py, r)).transpose()?;
    d.set_item("failing_run", run)?;
    Ok(d)
}

/// One slow-ramp trial of the maximum-speed study
/// (`ballbot_sim::world::max_speed::slow_ramp_trial`): the protocol's slow ramp (0.25 m/s^2 to
/// 6 m/s after 0.5 s, then 1 s hold) at `heading_deg` with the sensor noise seeded by `seed`,
/// the command shaper's caps lifted as in the study. Returns the ramp's dict (as
/// `max_speed_ramp`) plus `outcome`: `max_speed_m_per_s`, `censored` (no failure: the speed is
/// only a lower bound), `failure`, `peak_cone_utilisation`, `min_normal_force_n`,
/// `peak_tilt_rad`, `supervisor_stop_s`, `seed`, `accel_m_per_s2`, `heading_deg`.
#[pyfunction(name = "slow_ramp_trial")]
#[pyo3(signature = (params = None, *, heading_deg = 0.0, seed = 1))]
fn py_slow_ramp_trial<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_or_default(params);
    let protocol = MaxSpeedProtocol::default();
    let (run, outcome) = py
        .detach(|| slow_ramp_trial(params, &protocol, heading_deg, seed))
        .map_err(|e| world_error(py, e))?;
    let d = ramp_dict(py, run)?;
    d.set_item("outcome", outcome_dict(py, &outcome)?)?;
    Ok(d)
}

/// The failing-acceleration search at `heading_deg`
/// (`ballbot_sim::world::max_speed::failing_acceleration`): bisection on the grid of
/// `accel_resolution_m_per_s2` inside `accel_bracket_m_per_s2` for the largest ramp acceleration
/// whose ramp to `fast_top_m_per_s` (and 1 s hold) survives. Defaults: the study's protocol
/// (3.0 m/s, (0.5, 3.0) m/s^2, 0.05 m/s^2). Returns a dict: `largest_surviving_m_per_s2`
/// (`None` if the bracket's low end failed), `smallest_failing_m_per_s2` (`None` if its high end
/// survived: `censored`), `text` (`1.75`, `>= 3.00`, `< 0.50`), `runs`, `failing` and
/// `surviving` (the two runs' outcomes, as in `slow_ramp_trial`), `failing_run` (the failing
/// ramp's series, as `max_speed_ramp` returns them).
#[pyfunction(name = "failing_acceleration")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, seed = 0, fast_top_m_per_s = None,
    accel_bracket_m_per_s2 = None, accel_resolution_m_per_s2 = None,
))]
fn py_failing_acceleration<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    seed: u64,
    fast_top_m_per_s: Option<f64>,
    accel_bracket_m_per_s2: Option<(f64, f64)>,
    accel_resolution_m_per_s2: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_or_default(params);
    let protocol = protocol(
        py,
        MaxSpeedProtocol::default(),
        fast_top_m_per_s,
        accel_bracket_m_per_s2,
        accel_resolution_m_per_s2,
    )?;
    let found = py
        .detach(|| failing_acceleration(params, &protocol, heading_deg, seed))
        .map_err(|e| world_error(py, e))?;
    failing_dict(py, found)
}

/// The whole maximum-speed study as `ballbot reproduce` runs it
/// (`ballbot_sim::world::max_speed::run_study`), on Rust worker threads (`threads`, 0: every
/// core) without the GIL. `quick` starts from the CI variant (one trial at 0 and 180 deg, a
/// coarse search, no sensitivity) instead of the paper's (3 seeds at 0, 90, 180 deg, the map
/// every 15 deg, mu 0.4/0.6/0.8 and COM height 0.4/0.5/0.7 m; a few minutes on two cores); the
/// other keywords override its lists and the search.
///
/// Returns the study's record (the `max_speed_study` entry of `summary.json`: `protocol`,
/// `mu`, `com_height_m`, `trials`, `failing_accel_by_heading`, `map`, `sensitivity`, `paper`),
/// plus `max_speed_by_heading` (mean slow-ramp maximum speed per heading), `table` (the text
/// table `reproduce` prints) and `first_runs` (per trial heading, the first trial's series as
/// `max_speed_ramp` returns them, for the paper's Fig. "acc").
#[pyfunction(name = "max_speed_study")]
#[pyo3(signature = (
    params = None, *, quick = false, trial_headings_deg = None, seeds = None,
    map_headings_deg = None, sensitivity_headings_deg = None, sensitivity_mu = None,
    sensitivity_com_height_m = None, threads = 0, fast_top_m_per_s = None,
    accel_bracket_m_per_s2 = None, accel_resolution_m_per_s2 = None,
))]
#[allow(clippy::too_many_arguments)]
fn py_max_speed_study<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    quick: bool,
    trial_headings_deg: Option<Vec<f64>>,
    seeds: Option<Vec<u64>>,
    map_headings_deg: Option<Vec<f64>>,
    sensitivity_headings_deg: Option<Vec<f64>>,
    sensitivity_mu: Option<Vec<f64>>,
    sensitivity_com_height_m: Option<Vec<f64>>,
    threads: usize,
    fast_top_m_per_s: Option<f64>,
    accel_bracket_m_per_s2: Option<(f64, f64)>,
    accel_resolution_m_per_s2: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_or_default(params);
    let mut settings = if quick {
        MaxSpeedStudySettings::quick()
    } else {
        MaxSpeedStudySettings::paper()
    };
    settings.protocol = protocol(
        py,
        settings.protocol,
        fast_top_m_per_s,
        accel_bracket_m_per_s2,
        accel_resolution_m_per_s2,
    )?;
    for (list, value, name) in [
        (
            &mut settings.trial_headings_deg,
            trial_headings_deg,
            "trial_headings_deg",
        ),
        (
            &mut settings.map_headings_deg,
            map_headings_deg,
            "map_headings_deg",
        ),
        (
            &mut settings.sensitivity_headings_deg,
            sensitivity_headings_deg,
            "sensitivity_headings_deg",
        ),
        (
            &mut settings.sensitivity_mu,
            sensitivity_mu,
            "sensitivity_mu",
        ),
        (
            &mut settings.sensitivity_com_height_m,
            sensitivity_com_height_m,
            "sensitivity_com_height_m",
        ),
    ] {
        if let Some(values) = value {
            if !values.iter().all(|x| x.is_finite()) {
                return Err(error(
                    py,
                    Kind::Parameter,
                    format!("invalid parameter `{name}`: must be finite, got {values:?}"),
                ));
            }
            *list = values;
        }
    }
    if let Some(seeds) = seeds {
        settings.seeds = seeds;
    }
    settings.threads = threads;
    let study = py
        .detach(|| run_study(params, &settings, &|_| {}))
        .map_err(|e| world_error(py, e))?;
    let detail = json_to_py(py, &study.detail_json())?;
    let d = detail.cast_into::<PyDict>().map_err(PyErr::from)?;
    d.set_item(
        "max_speed_by_heading",
        json_to_py(py, &study.max_speed_by_heading_json())?,
    )?;
    d.set_item("table", study.table())?;
    let first = PyDict::new(py);
    for h in study.trials {
        first.set_item(h.heading_deg, ramp_dict(py, h.first_run)?)?;
    }
    d.set_item("first_runs", first)?;
    Ok(d)
}

fn braking_error(py: Python<'_>, e: BrakingError) -> PyErr {
    match e {
        BrakingError::World(e) => world_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// The braking protocol with keyword overrides (validated by the run).
#[allow(clippy::too_many_arguments)]
fn braking_params(
    py: Python<'_>,
    cruise_speed_m_per_s: Option<f64>,
    approach_accel_m_per_s2: Option<f64>,
    settle_s: Option<f64>,
    cruise_s: Option<f64>,
    trajectory_tilt_limit_rad: Option<f64>,
    intervals: Option<usize>,
    sample_every_s: Option<f64>,
    feedforward: &str,
) -> PyResult<BrakingParams> {
    let mut p = BrakingParams::default();
    if let Some(v) = settle_s {
        p.settle_s = v;
    }
    if let Some(v) = cruise_speed_m_per_s {
        p.cruise_speed_m_per_s = v;
    }
    if let Some(v) = approach_accel_m_per_s2 {
        p.approach_accel_m_per_s2 = v;
    }
    if let Some(v) = cruise_s {
        p.cruise_s = v;
    }
    if let Some(v) = trajectory_tilt_limit_rad {
        p.trajectory_tilt_limit_rad = v;
    }
    if let Some(v) = intervals {
        p.intervals = v;
    }
    if let Some(v) = sample_every_s {
        p.sample_every_s = v;
    }
    p.feedforward = match feedforward {
        "full" => TrajectoryFeedforward::Full,
        "core" => TrajectoryFeedforward::Core,
        _ => {
            return Err(error(
                py,
                Kind::Parameter,
                format!("unknown feedforward `{feedforward}`; known: full, core"),
            ));
        }
    };
    p.validate().map_err(|e| braking_error(py, e))?;
    Ok(p)
}

fn triples<'py>(
    py: Python<'py>,
    samples: &[BrakingSample],
    f: fn(&BrakingSample) -> [f64; 3],
) -> PyResult<Bound<'py, numpy::PyArrayDyn<f64>>> {
    crate::world::table(py, samples.iter().map(f).collect())
}

fn braking_run_dict<'py>(py: Python<'py>, run: &BrakingRun) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("heading_deg", run.heading_deg)?;
    d.set_item("duration_s", run.duration_s)?;
    d.set_item("outcome", run.outcome.label())?;
    d.set_item("success", run.outcome.is_success())?;
    let (failure, rest_speed, status) = match run.outcome {
        BrakingOutcome::Stopped { rest_speed_m_per_s } => (None, Some(rest_speed_m_per_s), None),
        BrakingOutcome::NotAtRest {
            rest_speed_m_per_s, ..
        } => (None, Some(rest_speed_m_per_s), None),
        BrakingOutcome::Failed(f) => (Some(PyFailure::from(f)), None, None),
        BrakingOutcome::NoTrajectory { status } => (None, None, Some(format!("{status:?}"))),
    };
    d.set_item("failure", failure)?;
    d.set_item("rest_speed_m_per_s", rest_speed)?;
    d.set_item("solve_status", status)?;
    d.set_item("brake_start_s", run.brake_start_s)?;
    d.set_item("plan_peak_tilt_rad", run.plan_peak_tilt_rad)?;
    d.set_item("plan_cost_n2m2s", run.plan_cost_n2m2s)?;
    let peaks = PyDict::new(py);
    let p = &run.peaks;
    peaks.set_item("cone_utilisation", p.cone_utilisation.to_vec())?;
    peaks.set_item("min_normal_force_n", p.min_normal_force_n.to_vec())?;
    peaks.set_item("actuator_utilisation", p.actuator_utilisation.to_vec())?;
    peaks.set_item("tilt_rad", p.tilt_rad)?;
    peaks.set_item("speed_error_m_per_s", p.speed_error_m_per_s)?;
    peaks.set_item("slip_s", p.slip_s)?;
    d.set_item("peaks", peaks)?;
    let s = &run.samples;
    let column = |f: fn(&BrakingSample) -> f64| PyArray1::from_vec(py, s.iter().map(f).collect());
    d.set_item("time_s", column(|x| x.time_s))?;
    d.set_item("command_m_per_s", column(|x| x.command_m_per_s))?;
    d.set_item("speed_m_per_s", column(|x| x.speed_m_per_s))?;
    d.set_item("command_tilt_rad", column(|x| x.command_tilt_rad))?;
    d.set_item("tilt_rad", column(|x| x.tilt_rad))?;
    d.set_item("cone_utilisation", triples(py, s, |x| x.cone_utilisation)?)?;
    d.set_item("normal_force_n", triples(py, s, |x| x.normal_force_n)?)?;
    d.set_item(
        "actuator_utilisation",
        triples(py, s, |x| x.actuator_utilisation)?,
    )?;
    d.set_item("telemetry_hash", run.telemetry_hash)?;
    Ok(d)
}

/// One braking run of the paper's Sec. V in the 3D world
/// (`ballbot_sim::world::braking::braking_run`): settle, a jerk-limited ramp to
/// `cruise_speed_m_per_s` along `heading_deg`, cruise for `cruise_s`, then the optimal braking
/// trajectory to rest in `duration_s` (solved here under the actuator, traction and tilt
/// limits), flown through the core's trajectory command. `feedforward` is `"full"` (the
/// trajectory's whole torque) or `"core"` (ablation: the equilibrium-lean feedforward only). Runs
/// without the GIL.
///
/// Returns a dict: `outcome` (`"stopped"`, `"no_trajectory"`, `"failed"`, `"not_at_rest"`),
/// `success`, `failure`, `rest_speed_m_per_s`, `solve_status` (for `no_trajectory`),
/// `brake_start_s`, `plan_peak_tilt_rad`, `plan_cost_n2m2s`, `peaks` (braking-phase extremes),
/// `telemetry_hash` (equal for bit-identical runs) and samples every `sample_every_s`:
/// `time_s`, `command_m_per_s`, `speed_m_per_s`, `command_tilt_rad`, `tilt_rad` (n,);
/// `cone_utilisation`, `normal_force_n`, `actuator_utilisation` (n, 3).
#[pyfunction(name = "braking_run")]
#[pyo3(signature = (
    params = None, *, duration_s, heading_deg = 0.0, cruise_speed_m_per_s = None,
    approach_accel_m_per_s2 = None, settle_s = None, cruise_s = None,
    trajectory_tilt_limit_rad = None, intervals = None, sample_every_s = None,
    feedforward = "full",
))]
#[allow(clippy::too_many_arguments)]
fn py_braking_run<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    duration_s: f64,
    heading_deg: f64,
    cruise_speed_m_per_s: Option<f64>,
    approach_accel_m_per_s2: Option<f64>,
    settle_s: Option<f64>,
    cruise_s: Option<f64>,
    trajectory_tilt_limit_rad: Option<f64>,
    intervals: Option<usize>,
    sample_every_s: Option<f64>,
    feedforward: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let world = params_or_default(params);
    let protocol = braking_params(
        py,
        cruise_speed_m_per_s,
        approach_accel_m_per_s2,
        settle_s,
        cruise_s,
        trajectory_tilt_limit_rad,
        intervals,
        sample_every_s,
        feedforward,
    )?;
    let run = py
        .detach(|| braking_run(world, &protocol, heading_deg, duration_s, None))
        .map_err(|e| braking_error(py, e))?;
    braking_run_dict(py, &run)
}

/// The paper's minimum-braking-time protocol at one heading
/// (`ballbot_sim::world::braking::braking_study`): braking times `durations_s` (default 5.0,
/// 4.5, ..., 0.5 s) in order until a run fails, then (beyond the paper) bisection between the
/// shortest success and the first failure down to `bisection_resolution_s` (`None` skips it).
/// The protocol keywords are `braking_run`'s. Runs without the GIL.
///
/// Returns a dict: `shortest_success_s` (the paper's figure), `first_failure_s`, `limit_s`,
/// `limit_failure_s` (after the bisection), and `descent`, `bisection`: lists of runs as
/// `braking_run` returns them.
#[pyfunction(name = "braking_study")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, durations_s = None, bisection_resolution_s = Some(0.05),
    cruise_speed_m_per_s = None, approach_accel_m_per_s2 = None, settle_s = None,
    cruise_s = None, trajectory_tilt_limit_rad = None, intervals = None, sample_every_s = None,
    feedforward = "full",
))]
#[allow(clippy::too_many_arguments)]
fn py_braking_study<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    durations_s: Option<Vec<f64>>,
    bisection_resolution_s: Option<f64>,
    cruise_speed_m_per_s: Option<f64>,
    approach_accel_m_per_s2: Option<f64>,
    settle_s: Option<f64>,
    cruise_s: Option<f64>,
    trajectory_tilt_limit_rad: Option<f64>,
    intervals: Option<usize>,
    sample_every_s: Option<f64>,
    feedforward: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let world = params_or_default(params);
    let protocol = braking_params(
        py,
        cruise_speed_m_per_s,
        approach_accel_m_per_s2,
        settle_s,
        cruise_s,
        trajectory_tilt_limit_rad,
        intervals,
        sample_every_s,
        feedforward,
    )?;
    let mut study = BrakingStudyParams::paper();
    if let Some(d) = durations_s {
        study.durations_s = d;
    }
    study.bisection_resolution_s = bisection_resolution_s;
    let result = py
        .detach(|| braking_study(world, &protocol, &study, heading_deg, &mut |_| {}))
        .map_err(|e| braking_error(py, e))?;
    let d = PyDict::new(py);
    d.set_item("heading_deg", result.heading_deg)?;
    d.set_item("shortest_success_s", result.shortest_success_s)?;
    d.set_item("first_failure_s", result.first_failure_s)?;
    d.set_item("limit_s", result.limit_s)?;
    d.set_item("limit_failure_s", result.limit_failure_s)?;
    let runs = |runs: &[BrakingRun]| -> PyResult<Vec<Bound<'py, PyDict>>> {
        runs.iter().map(|r| braking_run_dict(py, r)).collect()
    };
    d.set_item("descent", runs(&result.descent)?)?;
    d.set_item("bisection", runs(&result.bisection)?)?;
    Ok(d)
}

fn push_params(
    push_duration_s: Option<f64>,
    settle_s: Option<f64>,
    observe_s: Option<f64>,
    rest_within_s: Option<f64>,
    sample_every_s: Option<f64>,
) -> PushParams {
    let mut p = PushParams::default();
    if let Some(v) = rest_within_s {
        p.rest_within_s = v;
    }
    if let Some(v) = push_duration_s {
        p.push_duration_s = v;
    }
    if let Some(v) = settle_s {
        p.settle_s = v;
    }
    if let Some(v) = observe_s {
        p.observe_s = v;
    }
    if let Some(v) = sample_every_s {
        p.sample_every_s = v;
    }
    p
}

fn push_trial_dict<'py>(py: Python<'py>, t: &PushTrial) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("heading_deg", t.heading_deg)?;
    d.set_item("impulse_ns", t.impulse_ns)?;
    d.set_item("outcome", t.outcome.label())?;
    d.set_item("recovered", t.recovered())?;
    let failure = match t.outcome {
        PushOutcome::Failed(f) => Some(PyFailure::from(f)),
        _ => None,
    };
    d.set_item("failure", failure)?;
    d.set_item("peak_tilt_rad", t.peak_tilt_rad)?;
    d.set_item("peak_speed_m_per_s", t.peak_speed_m_per_s)?;
    d.set_item("rest_speed_m_per_s", t.rest_speed_m_per_s)?;
    let s = &t.samples;
    let column = |f: fn(&PushSample) -> f64| PyArray1::from_vec(py, s.iter().map(f).collect());
    d.set_item("time_s", column(|x| x.time_s))?;
    d.set_item("tilt_rad", column(|x| x.tilt_rad))?;
    d.set_item("speed_m_per_s", column(|x| x.speed_m_per_s))?;
    d.set_item("max_cone_utilisation", column(|x| x.max_cone_utilisation))?;
    let v: Vec<[f64; 2]> = s.iter().map(|x| x.ball_velocity_m_per_s).collect();
    d.set_item("ball_velocity_m_per_s", crate::world::table(py, v)?)?;
    d.set_item("telemetry_hash", t.telemetry_hash)?;
    Ok(d)
}

/// One push-recovery trial (`ballbot_sim::world::push::push_trial`): the robot stands still
/// under the core's controller for `settle_s`, a horizontal impulse `impulse_ns` towards
/// `heading_deg` (body frame) spread over `push_duration_s` hits the body's centre of mass,
/// and the run is watched for `observe_s` (defaults 1.0, 0.1, 4.0 s); recovered means no
/// failure, tilt below 15 deg, and at rest (ball under 0.1 m/s, tilt under 3 deg) from
/// `rest_within_s` (default 3.0 s) after the push on. Runs without the GIL.
/// Returns a dict: `outcome` (`"recovered"`, `"tilt_exceeded"`, `"failed"`, `"not_at_rest"`),
/// `recovered`, `failure`, `peak_tilt_rad`, `peak_speed_m_per_s`, `rest_speed_m_per_s`,
/// `telemetry_hash`, and samples: `time_s` (since the push), `tilt_rad`, `speed_m_per_s`,
/// `max_cone_utilisation` (n,), `ball_velocity_m_per_s` (n, 2).
#[pyfunction(name = "push_trial")]
#[pyo3(signature = (
    params = None, *, impulse_ns, heading_deg = 0.0, push_duration_s = None, settle_s = None,
    observe_s = None, rest_within_s = None, sample_every_s = None,
))]
#[allow(clippy::too_many_arguments)]
fn py_push_trial<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    impulse_ns: f64,
    heading_deg: f64,
    push_duration_s: Option<f64>,
    settle_s: Option<f64>,
    observe_s: Option<f64>,
    rest_within_s: Option<f64>,
    sample_every_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let world = params_or_default(params);
    let protocol = push_params(
        push_duration_s,
        settle_s,
        observe_s,
        rest_within_s,
        sample_every_s,
    );
    protocol.validate().map_err(|e| world_error(py, e))?;
    if !(impulse_ns.is_finite() && heading_deg.is_finite()) {
        return Err(error(
            py,
            Kind::Parameter,
            "invalid parameter `impulse_ns`/`heading_deg`: must be finite",
        ));
    }
    let trial = py
        .detach(|| push_trial(world, &protocol, heading_deg, impulse_ns))
        .map_err(|e| world_error(py, e))?;
    push_trial_dict(py, &trial)
}

/// The largest push recovered at `heading_deg` (`ballbot_sim::world::push::push_recovery_limit`):
/// tries `upper_ns` first, then bisects `[0, upper_ns]` down to `resolution_ns` (defaults 100
/// and 0.5 N s). Trial keywords as `push_trial`. Returns a dict: `largest_recovered_ns`,
/// `smallest_failing_ns` (`None` if `upper_ns` was recovered) and `trials`, each as
/// `push_trial` returns it.
#[pyfunction(name = "push_recovery_limit")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, upper_ns = 100.0, resolution_ns = 0.5,
    push_duration_s = None, settle_s = None, observe_s = None, rest_within_s = None,
    sample_every_s = None,
))]
#[allow(clippy::too_many_arguments)]
fn py_push_recovery_limit<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    upper_ns: f64,
    resolution_ns: f64,
    push_duration_s: Option<f64>,
    settle_s: Option<f64>,
    observe_s: Option<f64>,
    rest_within_s: Option<f64>,
    sample_every_s: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let world = params_or_default(params);
    let protocol = push_params(
        push_duration_s,
        settle_s,
        observe_s,
        rest_within_s,
        sample_every_s,
    );
    protocol.validate().map_err(|e| world_error(py, e))?;
    if !(resolution_ns.is_finite() && resolution_ns > 0.0 && upper_ns / resolution_ns <= 1e9) {
        return Err(error(
            py,
            Kind::Parameter,
            format!(
                "invalid parameter `resolution_ns`: must be > 0 and >= upper_ns / 1e9, got {resolution_ns}"
            ),
        ));
    }
    let search = PushSearch {
        upper_ns,
        resolution_ns,
    };
    let found = py
        .detach(|| push_recovery_limit(world, &protocol, &search, heading_deg, &mut |_| {}))
        .map_err(|e| world_error(py, e))?;
    let d = PyDict::new(py);
    d.set_item("heading_deg", found.heading_deg)?;
    d.set_item("largest_recovered_ns", found.largest_recovered_ns)?;
    d.set_item("smallest_failing_ns", found.smallest_failing_ns)?;
    let trials: Vec<Bound<'py, PyDict>> = found
        .trials
        .iter()
        .map(|t| push_trial_dict(py, t))
        .collect::<PyResult<_>>()?;
    d.set_item("trials", trials)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(py_braking_run, m)?)?;
    m.add_function(wrap_pyfunction!(py_braking_study, m)?)?;
    m.add_function(wrap_pyfunction!(py_push_trial, m)?)?;
    m.add_function(wrap_pyfunction!(py_push_recovery_limit, m)?)?;
    m.add_function(wrap_pyfunction!(py_slow_ramp_trial, m)?)?;
    m.add_function(wrap_pyfunction!(py_failing_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(py_max_speed_study, m)?)?;
    Ok(())
}
