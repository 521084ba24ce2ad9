//! The push-recovery experiments (`ballbot_sim::studies::push`): one trial and the recovery
//! limit.

use super::settings::PushSettings;
use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use crate::results::{Columns, FailureParts};
use crate::world::params_or_default;
use ballbot_sim::rig::Happened;
use ballbot_sim::studies::push::{
    PushOutcome, PushParams, PushSample, PushSearch, PushTrial, push_recovery_limit, push_trial,
};
use pyo3::prelude::*;
use schemars::JsonSchema;
use serde::Serialize;

/// The push protocol with the settings' overrides and the world's stop rules (parsed from
/// `settings.stop_on`).
fn push_params(py: Python<'_>, settings: &PushSettings) -> PyResult<PushParams> {
    let PushSettings {
        push_duration_secs,
        settle_secs,
        observe_secs,
        rest_within_secs,
        sample_every_secs,
        ref stop_on,
    } = *settings;
    let stop_rules = super::stop_rules(py, stop_on)?;
    let mut p = PushParams {
        stop_rules,
        ..PushParams::default()
    };
    if let Some(v) = rest_within_secs {
        p.rest_within_secs = v;
    }
    if let Some(v) = push_duration_secs {
        p.push_duration_secs = v;
    }
    if let Some(v) = settle_secs {
        p.settle_secs = v;
    }
    if let Some(v) = observe_secs {
        p.observe_secs = v;
    }
    if let Some(v) = sample_every_secs {
        p.sample_every_secs = v;
    }
    Ok(p)
}

/// One push-recovery trial (`push_trial`).
// The failure lifted out of the outcome, the samples as columns.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "PushTrial")]
pub(crate) struct PushTrialView<'a> {
    /// Push heading (deg).
    heading_deg: f64,
    /// Impulse (N s).
    impulse_ns: f64,
    /// How the trial ended.
    // `PushOutcome::label`, a `ballbot.PushOutcome`'s value.
    #[schemars(extend("x-python-type" = "ballbot._enums.PushOutcome"))]
    outcome: &'static str,
    /// Whether it recovered.
    recovered: bool,
    /// The failure, for `PushOutcome.FAILED`.
    failure: Option<FailureParts>,
    /// Peak tilt (rad).
    peak_tilt_rad: f64,
    /// Peak ball speed (m/s).
    peak_speed_m_per_s: f64,
    /// Ball speed at the end (m/s).
    rest_speed_m_per_s: f64,
    #[serde(flatten)]
    samples: Columns<'a, PushSample>,
    /// Hash of the run's telemetry (determinism checks).
    telemetry_hash: u64,
    /// How the run ended and its contact events, whatever the stop rules (the form of
    /// `BrakingRun.happened`).
    #[schemars(with = "serde_json::Map<String, serde_json::Value>")]
    happened: &'a Happened,
}

impl<'a> From<&'a PushTrial> for PushTrialView<'a> {
    fn from(t: &'a PushTrial) -> Self {
        Self {
            heading_deg: t.heading_deg,
            impulse_ns: t.impulse_ns,
            outcome: t.outcome.label(),
            recovered: t.recovered(),
            failure: match t.outcome {
                PushOutcome::Failed(f) => Some(f.into()),
                _ => None,
            },
            peak_tilt_rad: t.peak_tilt_rad,
            peak_speed_m_per_s: t.peak_speed_m_per_s,
            rest_speed_m_per_s: t.rest_speed_m_per_s,
            samples: Columns(&t.samples),
            telemetry_hash: t.telemetry_hash,
            happened: &t.happened,
        }
    }
}

/// The push-recovery limit at one heading (`push_recovery_limit`).
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "PushRecovery")]
pub(crate) struct PushRecoveryView<'a> {
    /// Heading (deg).
    heading_deg: f64,
    /// Largest impulse recovered (N s).
    largest_recovered_ns: f64,
    /// Smallest impulse not recovered (N s), `None` if the upper end recovered.
    smallest_failing_ns: Option<f64>,
    /// The trials of the search.
    trials: Vec<PushTrialView<'a>>,
}

/// One push-recovery trial (`ballbot_sim::studies::push::push_trial`): the robot stands still
/// under the core's controller for `settle_secs`, a horizontal impulse `impulse_ns` towards
/// `heading_deg` (body frame) spread over `push_duration_secs` hits the body's centre of mass,
/// and the run is watched for `observe_secs` (defaults 1.0, 0.1, 4.0 s); recovered means no
/// failure, tilt below 15 deg, and at rest (ball under 0.1 m/s, tilt under 3 deg) from
/// `rest_within_secs` (default 3.0 s) after the push on. `stop_on` names the world's stop rules
/// (`"all"`, the default; `"none"`; or some of `tilt,slip,lift-off,driver-trip`). Runs without
/// the GIL.
/// Returns a `PushTrial`: `outcome` (a `PushOutcome`),
/// `recovered`, `failure`, `peak_tilt_rad`, `peak_speed_m_per_s`, `rest_speed_m_per_s`,
/// `telemetry_hash`, `happened` (how the run ended and its contact events), and samples: `time_secs` (since the push), `tilt_rad`, `speed_m_per_s`,
/// `max_cone_utilisation` (n,), `ball_velocity_m_per_s` (n, 2).
#[pyfunction(name = "push_trial")]
#[pyo3(signature = (
    params = None, *, impulse_ns, heading_deg = 0.0, push_duration_secs = None, settle_secs = None,
    observe_secs = None, rest_within_secs = None, sample_every_secs = None, stop_on = "all",
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn py_push_trial<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    impulse_ns: f64,
    heading_deg: f64,
    push_duration_secs: Option<f64>,
    settle_secs: Option<f64>,
    observe_secs: Option<f64>,
    rest_within_secs: Option<f64>,
    sample_every_secs: Option<f64>,
    stop_on: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let world = params_or_default(params);
    let settings = PushSettings {
        push_duration_secs,
        settle_secs,
        observe_secs,
        rest_within_secs,
        sample_every_secs,
        stop_on: stop_on.to_owned(),
    };
    let protocol = push_params(py, &settings)?;
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
    crate::results::build(py, &PushTrialView::from(&trial))
}

/// The largest push recovered at `heading_deg` (`ballbot_sim::studies::push::push_recovery_limit`):
/// tries `upper_ns` first, then bisects `[0, upper_ns]` down to `resolution_ns` (defaults 100
/// and 0.5 N s). Trial keywords as `push_trial`. Returns a `PushRecovery`: `largest_recovered_ns`,
/// `smallest_failing_ns` (`None` if `upper_ns` was recovered) and `trials`, each as
/// `push_trial` returns it.
#[pyfunction(name = "push_recovery_limit")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, upper_ns = 100.0, resolution_ns = 0.5,
    push_duration_secs = None, settle_secs = None, observe_secs = None, rest_within_secs = None,
    sample_every_secs = None, stop_on = "all",
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn py_push_recovery_limit<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    upper_ns: f64,
    resolution_ns: f64,
    push_duration_secs: Option<f64>,
    settle_secs: Option<f64>,
    observe_secs: Option<f64>,
    rest_within_secs: Option<f64>,
    sample_every_secs: Option<f64>,
    stop_on: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let world = params_or_default(params);
    let settings = PushSettings {
        push_duration_secs,
        settle_secs,
        observe_secs,
        rest_within_secs,
        sample_every_secs,
        stop_on: stop_on.to_owned(),
    };
    let protocol = push_params(py, &settings)?;
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
    let view = PushRecoveryView {
        heading_deg: found.heading_deg,
        largest_recovered_ns: found.largest_recovered_ns,
        smallest_failing_ns: found.smallest_failing_ns,
        trials: found.trials.iter().map(PushTrialView::from).collect(),
    };
    crate::results::build(py, &view)
}
