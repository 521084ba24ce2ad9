//! The braking experiments (`ballbot_sim::studies::world_braking`): one braking run and the
//! minimum-braking-time study.

use super::settings::BrakingSettings;
use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use crate::results::{Columns, FailureParts};
use crate::world::params_or_default;
use ballbot_sim::rig::Happened;
use ballbot_sim::studies::world_braking::{
    BrakingError, BrakingOutcome, BrakingParams, BrakingPeaks, BrakingRun, BrakingSample,
    BrakingStudyParams, TrajectoryFeedforward, braking_run, braking_study,
};
use pyo3::prelude::*;
use schemars::JsonSchema;
use serde::Serialize;

fn braking_error(py: Python<'_>, e: BrakingError) -> PyErr {
    match e {
        BrakingError::World(e) => world_error(py, e),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// The braking protocol with the settings' overrides (validated by the run).
fn braking_params(py: Python<'_>, settings: &BrakingSettings) -> PyResult<BrakingParams> {
    let BrakingSettings {
        cruise_speed_m_per_s,
        approach_accel_m_per_s2,
        settle_secs,
        cruise_secs,
        trajectory_tilt_limit_rad,
        intervals,
        sample_every_secs,
        ref feedforward,
        ref stop_on,
    } = *settings;
    let mut p = BrakingParams::default();
    if let Some(v) = settle_secs {
        p.settle_secs = v;
    }
    if let Some(v) = cruise_speed_m_per_s {
        p.cruise_speed_m_per_s = v;
    }
    if let Some(v) = approach_accel_m_per_s2 {
        p.approach_accel_m_per_s2 = v;
    }
    if let Some(v) = cruise_secs {
        p.cruise_secs = v;
    }
    if let Some(v) = trajectory_tilt_limit_rad {
        p.trajectory_tilt_limit_rad = v;
    }
    if let Some(v) = intervals {
        p.intervals = v;
    }
    if let Some(v) = sample_every_secs {
        p.sample_every_secs = v;
    }
    p.feedforward = match feedforward.as_str() {
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
    p.stop_rules = super::stop_rules(py, stop_on)?;
    p.validate().map_err(|e| braking_error(py, e))?;
    Ok(p)
}

/// One braking run in the 3D world (`braking_run`).
// The outcome's fields lifted to the top (`failure`, `rest_speed_m_per_s`, `solve_status`),
// the samples as columns.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "BrakingRun")]
pub(crate) struct BrakingRunView<'a> {
    /// Heading (deg).
    heading_deg: f64,
    /// Planned braking duration (s).
    duration_secs: f64,
    /// How the run ended.
    // `BrakingOutcome::label`, a `ballbot.BrakingOutcome`'s value.
    #[schemars(extend("x-python-type" = "ballbot._enums.BrakingOutcome"))]
    outcome: &'static str,
    /// Stopped within the criterion.
    success: bool,
    /// The failure, for `BrakingOutcome.FAILED`.
    failure: Option<FailureParts>,
    /// Speed at the end (m/s), when the run survived.
    rest_speed_m_per_s: Option<f64>,
    /// The optimiser's status, for `BrakingOutcome.NO_TRAJECTORY`.
    // `SolveStatus::as_str`, a `ballbot.SolveStatus`'s value.
    #[schemars(extend("x-python-type" = "ballbot._enums.SolveStatus"))]
    solve_status: Option<&'static str>,
    /// When braking started (s).
    brake_start_secs: f64,
    /// Peak tilt of the plan (rad).
    plan_peak_tilt_rad: Option<f64>,
    /// Cost of the plan (N^2 m^2 s).
    plan_cost_n2m2s: Option<f64>,
    /// Peaks over the run.
    peaks: &'a BrakingPeaks,
    #[serde(flatten)]
    samples: Columns<'a, BrakingSample>,
    /// Hash of the run's telemetry (determinism checks).
    telemetry_hash: u64,
    /// How the flown run ended and its contact events, whatever the stop rules:
    /// `{"outcome": {"kind": "at_rest", "time_secs": ...}, "events": [...], "events_dropped": 0}`
    /// (kinds `fell`, `ended_by_stop_rule`, `stopped`, `at_rest`, `recovered`, `unsettled`);
    /// `None` when no trajectory was flown.
    #[schemars(with = "Option<serde_json::Map<String, serde_json::Value>>")]
    happened: Option<&'a Happened>,
}

impl<'a> From<&'a BrakingRun> for BrakingRunView<'a> {
    fn from(run: &'a BrakingRun) -> Self {
        let (failure, rest_speed_m_per_s, solve_status) = match run.outcome {
            BrakingOutcome::Stopped { rest_speed_m_per_s }
            | BrakingOutcome::NotAtRest {
                rest_speed_m_per_s, ..
            } => (None, Some(rest_speed_m_per_s), None),
            BrakingOutcome::Failed(f) => (Some(f.into()), None, None),
            BrakingOutcome::NoTrajectory { status } => (None, None, Some(status.as_str())),
        };
        Self {
            heading_deg: run.heading_deg,
            duration_secs: run.duration_secs,
            outcome: run.outcome.label(),
            success: run.outcome.is_success(),
            failure,
            rest_speed_m_per_s,
            solve_status,
            brake_start_secs: run.brake_start_secs,
            plan_peak_tilt_rad: run.plan_peak_tilt_rad,
            plan_cost_n2m2s: run.plan_cost_n2m2s,
            peaks: &run.peaks,
            samples: Columns(&run.samples),
            telemetry_hash: run.telemetry_hash,
            happened: run.happened.as_ref(),
        }
    }
}

/// The braking-time study at one heading (`braking_study`).
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "BrakingStudy")]
pub(crate) struct BrakingStudyView<'a> {
    /// Heading (deg).
    heading_deg: f64,
    /// Shortest successful duration of the descent (s).
    shortest_success_secs: Option<f64>,
    /// First failing duration of the descent (s).
    first_failure_secs: Option<f64>,
    /// The bisected limit (s).
    limit_secs: Option<f64>,
    /// The failing duration next to the limit (s).
    limit_failure_secs: Option<f64>,
    /// The runs of the descent.
    descent: Vec<BrakingRunView<'a>>,
    /// The runs of the bisection.
    bisection: Vec<BrakingRunView<'a>>,
}

/// One braking run of the paper's Sec. V in the 3D world
/// (`ballbot_sim::studies::world_braking::braking_run`): settle, a jerk-limited ramp to
/// `cruise_speed_m_per_s` along `heading_deg`, cruise for `cruise_secs`, then the optimal braking
/// trajectory to rest in `duration_secs` (solved here under the actuator, traction and tilt
/// limits), flown through the core's trajectory command. `feedforward` is `"full"` (the
/// trajectory's whole torque) or `"core"` (ablation: the equilibrium-lean feedforward only).
/// `stop_on` names the world's stop rules (`"all"`, the default and the paper protocol's;
/// `"none"`; or some of `tilt,slip,lift-off,driver-trip`). Runs without the GIL.
///
/// Returns a `BrakingRun`: `outcome` (a `BrakingOutcome`),
/// `success`, `failure`, `rest_speed_m_per_s`, `solve_status` (for `no_trajectory`),
/// `brake_start_secs`, `plan_peak_tilt_rad`, `plan_cost_n2m2s`, `peaks` (braking-phase extremes),
/// `telemetry_hash` (equal for bit-identical runs), `happened` (how the run ended: fell, ended
/// by a stop rule, at rest...; and its contact events) and samples every `sample_every_secs`:
/// `time_secs`, `command_m_per_s`, `speed_m_per_s`, `command_tilt_rad`, `tilt_rad` (n,);
/// `cone_utilisation`, `normal_force_n`, `actuator_utilisation` (n, 3).
#[pyfunction(name = "braking_run")]
#[pyo3(signature = (
    params = None, *, duration_secs, heading_deg = 0.0, cruise_speed_m_per_s = None,
    approach_accel_m_per_s2 = None, settle_secs = None, cruise_secs = None,
    trajectory_tilt_limit_rad = None, intervals = None, sample_every_secs = None,
    feedforward = "full", stop_on = "all",
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn py_braking_run<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    duration_secs: f64,
    heading_deg: f64,
    cruise_speed_m_per_s: Option<f64>,
    approach_accel_m_per_s2: Option<f64>,
    settle_secs: Option<f64>,
    cruise_secs: Option<f64>,
    trajectory_tilt_limit_rad: Option<f64>,
    intervals: Option<usize>,
    sample_every_secs: Option<f64>,
    feedforward: &str,
    stop_on: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let world = params_or_default(params);
    let settings = BrakingSettings {
        cruise_speed_m_per_s,
        approach_accel_m_per_s2,
        settle_secs,
        cruise_secs,
        trajectory_tilt_limit_rad,
        intervals,
        sample_every_secs,
        feedforward: feedforward.to_owned(),
        stop_on: stop_on.to_owned(),
    };
    let protocol = braking_params(py, &settings)?;
    let run = py
        .detach(|| braking_run(world, &protocol, heading_deg, duration_secs, None))
        .map_err(|e| braking_error(py, e))?;
    crate::results::build(py, &BrakingRunView::from(&run))
}

/// The paper's minimum-braking-time protocol at one heading
/// (`ballbot_sim::studies::world_braking::braking_study`): braking times `durations_secs` (default 5.0,
/// 4.5, ..., 0.5 s) in order until a run fails, then (beyond the paper) bisection between the
/// shortest success and the first failure down to `bisection_resolution_secs` (`None` skips it).
/// Every run solves its trajectory from a cold start, so each is the run `braking_run` gives at
/// its `duration_secs` with the same keywords. The protocol keywords are `braking_run`'s. Runs
/// without the GIL.
///
/// Returns a `BrakingStudy`: `shortest_success_secs` (the paper's figure), `first_failure_secs`, `limit_secs`,
/// `limit_failure_secs` (after the bisection), and `descent`, `bisection`: lists of runs as
/// `braking_run` returns them.
#[pyfunction(name = "braking_study")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, durations_secs = None, bisection_resolution_secs = Some(0.05),
    cruise_speed_m_per_s = None, approach_accel_m_per_s2 = None, settle_secs = None,
    cruise_secs = None, trajectory_tilt_limit_rad = None, intervals = None, sample_every_secs = None,
    feedforward = "full", stop_on = "all",
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn py_braking_study<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    durations_secs: Option<Vec<f64>>,
    bisection_resolution_secs: Option<f64>,
    cruise_speed_m_per_s: Option<f64>,
    approach_accel_m_per_s2: Option<f64>,
    settle_secs: Option<f64>,
    cruise_secs: Option<f64>,
    trajectory_tilt_limit_rad: Option<f64>,
    intervals: Option<usize>,
    sample_every_secs: Option<f64>,
    feedforward: &str,
    stop_on: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let world = params_or_default(params);
    let settings = BrakingSettings {
        cruise_speed_m_per_s,
        approach_accel_m_per_s2,
        settle_secs,
        cruise_secs,
        trajectory_tilt_limit_rad,
        intervals,
        sample_every_secs,
        feedforward: feedforward.to_owned(),
        stop_on: stop_on.to_owned(),
    };
    let protocol = braking_params(py, &settings)?;
    let mut study = BrakingStudyParams::paper();
    if let Some(d) = durations_secs {
        study.durations_secs = d;
    }
    study.bisection_resolution_secs = bisection_resolution_secs;
    let result = py
        .detach(|| braking_study(world, &protocol, &study, heading_deg, &mut |_| {}))
        .map_err(|e| braking_error(py, e))?;
    let view = BrakingStudyView {
        heading_deg: result.heading_deg,
        shortest_success_secs: result.shortest_success_secs,
        first_failure_secs: result.first_failure_secs,
        limit_secs: result.limit_secs,
        limit_failure_secs: result.limit_failure_secs,
        descent: result.descent.iter().map(BrakingRunView::from).collect(),
        bisection: result.bisection.iter().map(BrakingRunView::from).collect(),
    };
    crate::results::build(py, &view)
}
