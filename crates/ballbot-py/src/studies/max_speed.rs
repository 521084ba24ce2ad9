//! The maximum-speed study (`ballbot_sim::studies::max_speed`, what `ballbot reproduce` runs for
//! the paper's Sec. V): seeded slow-ramp trials per heading, the failing ramp acceleration per
//! heading, the capability map and the mu / COM-height sensitivity.

use super::settings::MaxSpeedSettings;
use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use crate::results::FailureParts;
use crate::world::{RampRunView, params_or_default};
use ballbot_sim::rig::Happened;
use ballbot_sim::studies::max_speed::{
    FailingAccel, MaxSpeedProtocol, MaxSpeedStudySettings, TrialOutcome, failing_acceleration,
    run_study, slow_ramp_trial,
};
use pyo3::prelude::*;
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

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

/// The summary of one slow-ramp or fast-ramp trial of the maximum-speed study.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "TrialOutcome")]
pub(crate) struct TrialOutcomeView<'a> {
    /// Heading (deg).
    heading_deg: f64,
    /// Sensor-noise seed.
    seed: u64,
    /// Ramp acceleration (m/s^2).
    accel_m_per_s2: f64,
    /// Highest ball speed along the heading (m/s).
    max_speed_m_per_s: f64,
    /// No failure: the speed is only a lower bound.
    censored: bool,
    /// The failure, or `None`.
    failure: Option<FailureParts>,
    /// Peak cone utilisation.
    peak_cone_utilisation: f64,
    /// Smallest wheel normal force (N).
    min_normal_force_n: f64,
    /// Peak tilt from the vertical (rad).
    peak_tilt_rad: f64,
    /// When the safety supervisor stopped balancing (s), or `None`.
    supervisor_stop_secs: Option<f64>,
    /// How the run ended and its contact events (`BrakingRun.happened`'s form); a ramp ends
    /// at the world's first failure, so a failed trial's outcome is `ended_by_stop_rule` or
    /// `fell`.
    #[schemars(with = "JsonObject")]
    happened: &'a Happened,
}

impl<'a> From<&'a TrialOutcome> for TrialOutcomeView<'a> {
    fn from(o: &'a TrialOutcome) -> Self {
        Self {
            heading_deg: o.heading_deg,
            seed: o.seed,
            accel_m_per_s2: o.accel_m_per_s2,
            max_speed_m_per_s: o.max_speed_m_per_s,
            censored: o.censored(),
            failure: o.failure.map(FailureParts::from),
            peak_cone_utilisation: o.peak_cone_utilisation,
            min_normal_force_n: o.min_normal_force_n,
            peak_tilt_rad: o.peak_tilt_rad,
            supervisor_stop_secs: o.supervisor_stop_secs,
            happened: &o.happened,
        }
    }
}

/// One slow-ramp trial (`slow_ramp_trial`): the ramp and its outcome.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "SlowRampTrial", extend("x-python-base" = "RampRun"))]
pub(crate) struct SlowRampTrialView<'a> {
    #[serde(flatten)]
    ramp: RampRunView<'a>,
    /// The trial's summary.
    outcome: TrialOutcomeView<'a>,
}

/// The failing-acceleration search at one heading (`failing_acceleration`).
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "FailingAcceleration")]
pub(crate) struct FailingAccelerationView<'a> {
    /// Heading (deg).
    heading_deg: f64,
    /// Largest surviving ramp acceleration, `None` if the bracket's low end failed.
    largest_surviving_m_per_s2: Option<f64>,
    /// Smallest failing ramp acceleration, `None` if the high end survived.
    smallest_failing_m_per_s2: Option<f64>,
    /// The bracket's high end survived.
    censored: bool,
    /// As the table prints it: `1.75`, `>= 3.00`, `< 0.50`.
    text: String,
    /// Ramps run.
    runs: usize,
    /// The failing run's outcome.
    failing: Option<TrialOutcomeView<'a>>,
    /// The surviving run's outcome.
    surviving: Option<TrialOutcomeView<'a>>,
    /// The failing ramp's series.
    failing_run: Option<RampRunView<'a>>,
}

impl<'a> From<&'a FailingAccel> for FailingAccelerationView<'a> {
    fn from(f: &'a FailingAccel) -> Self {
        Self {
            heading_deg: f.heading_deg,
            largest_surviving_m_per_s2: f.largest_surviving_m_per_s2,
            smallest_failing_m_per_s2: f.smallest_failing_m_per_s2,
            censored: f.smallest_failing_m_per_s2.is_none(),
            text: f.text(),
            runs: f.runs,
            failing: f.failing.as_ref().map(TrialOutcomeView::from),
            surviving: f.surviving.as_ref().map(TrialOutcomeView::from),
            failing_run: f.failing_run.as_ref().map(RampRunView::from),
        }
    }
}

/// A JSON object as Python has it (`dict[str, Any]`).
type JsonObject = serde_json::Map<String, serde_json::Value>;

/// The whole maximum-speed study (`max_speed_study`); the JSON-shaped fields are the
/// `max_speed_study` entry of `summary.json`.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "MaxSpeedStudy")]
pub(crate) struct MaxSpeedStudyView<'a> {
    #[serde(flatten)]
    detail: MaxSpeedDetail,
    /// Mean slow-ramp maximum speed per heading.
    max_speed_by_heading: JsonObject,
    /// The text table `reproduce` prints.
    table: String,
    /// Per trial heading, the first trial's ramp.
    first_runs: FirstRuns<'a>,
}

/// The study's record as `detail_json` writes it (the `max_speed_study` entry of
/// `summary.json`), read back field by field so that a field it adds or drops fails here.
#[derive(Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct MaxSpeedDetail {
    /// The protocol (ramps, search).
    protocol: JsonObject,
    /// Wheel-ball friction coefficient.
    wheel_ball_friction: f64,
    /// Centre-of-mass height (m).
    com_height_m: f64,
    /// Per trial heading: mean and spread of the slow-ramp maximum speed, the trials.
    trials: Vec<JsonObject>,
    /// The failing acceleration per heading.
    failing_accel_by_heading: JsonObject,
    /// The capability map.
    map: Vec<JsonObject>,
    /// The mu / COM-height sensitivity.
    sensitivity: Vec<JsonObject>,
    /// The paper's numbers.
    paper: Vec<JsonObject>,
}

/// A JSON record of the study as the field of the view that has it (a bug in the view if it
/// does not fit, as a `BallbotError`).
fn record<T: serde::de::DeserializeOwned>(py: Python<'_>, value: serde_json::Value) -> PyResult<T> {
    serde_json::from_value(value).map_err(|e| {
        error(
            py,
            Kind::Other,
            format!("the study's record does not fit MaxSpeedStudy: {e}"),
        )
    })
}

/// The first ramp of each trial heading, keyed by the heading (deg).
struct FirstRuns<'a>(Vec<(f64, RampRunView<'a>)>);

impl Serialize for FirstRuns<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(k, v)| (k, v)))
    }
}

/// In the mirror's schema, a map from the heading (deg, a float key) to the ramp.
impl JsonSchema for FirstRuns<'_> {
    fn schema_name() -> Cow<'static, str> {
        "FirstRuns".into()
    }

    fn inline_schema() -> bool {
        true
    }

    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        let ramp = generator.subschema_for::<RampRunView<'_>>();
        json_schema!({
            "type": "object",
            "additionalProperties": ramp,
            "x-python-key": "float",
        })
    }
}

/// One slow-ramp trial of the maximum-speed study
/// (`ballbot_sim::studies::max_speed::slow_ramp_trial`): the protocol's slow ramp (0.25 m/s^2 to
/// 6 m/s after 0.5 s, then 1 s hold) at `heading_deg` with the sensor noise seeded by `seed`,
/// the command shaper's caps lifted as in the study. Returns a `SlowRampTrial`: the ramp (as
/// `max_speed_ramp`) plus `outcome`: `max_speed_m_per_s`, `censored` (no failure: the speed is
/// only a lower bound), `failure`, `peak_cone_utilisation`, `min_normal_force_n`,
/// `peak_tilt_rad`, `supervisor_stop_secs`, `seed`, `accel_m_per_s2`, `heading_deg`.
#[pyfunction(name = "slow_ramp_trial")]
#[pyo3(signature = (params = None, *, heading_deg = 0.0, seed = 1))]
pub(crate) fn py_slow_ramp_trial<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let params = params_or_default(params);
    let protocol = MaxSpeedProtocol::default();
    let (run, outcome) = py
        .detach(|| slow_ramp_trial(params, &protocol, heading_deg, seed))
        .map_err(|e| world_error(py, e))?;
    let view = SlowRampTrialView {
        ramp: RampRunView::from(&run),
        outcome: TrialOutcomeView::from(&outcome),
    };
    crate::results::build(py, &view)
}

/// The failing-acceleration search at `heading_deg`
/// (`ballbot_sim::studies::max_speed::failing_acceleration`): bisection on the grid of
/// `accel_resolution_m_per_s2` inside `accel_bracket_m_per_s2` for the largest ramp acceleration
/// whose ramp to `fast_top_m_per_s` (and 1 s hold) survives. Defaults: the study's protocol
/// (3.0 m/s, (0.5, 3.0) m/s^2, 0.05 m/s^2). Returns a `FailingAcceleration`: `largest_surviving_m_per_s2`
/// (`None` if the bracket's low end failed), `smallest_failing_m_per_s2` (`None` if its high end
/// survived: `censored`), `text` (`1.75`, `>= 3.00`, `< 0.50`), `runs`, `failing` and
/// `surviving` (the two runs' outcomes, as in `slow_ramp_trial`), `failing_run` (the failing
/// ramp's series, as `max_speed_ramp` returns them).
#[pyfunction(name = "failing_acceleration")]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, seed = 0, fast_top_m_per_s = None,
    accel_bracket_m_per_s2 = None, accel_resolution_m_per_s2 = None,
))]
pub(crate) fn py_failing_acceleration<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    seed: u64,
    fast_top_m_per_s: Option<f64>,
    accel_bracket_m_per_s2: Option<(f64, f64)>,
    accel_resolution_m_per_s2: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
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
    crate::results::build(py, &FailingAccelerationView::from(&found))
}

/// The study's settings: the paper's or the CI variant's (`quick`), with the settings'
/// overrides.
fn study_settings(py: Python<'_>, s: MaxSpeedSettings) -> PyResult<MaxSpeedStudySettings> {
    let MaxSpeedSettings {
        quick,
        trial_headings_deg,
        seeds,
        map_headings_deg,
        sensitivity_headings_deg,
        sensitivity_wheel_ball_friction,
        sensitivity_com_height_m,
        threads,
        fast_top_m_per_s,
        accel_bracket_m_per_s2,
        accel_resolution_m_per_s2,
    } = s;
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
            &mut settings.sensitivity_wheel_ball_friction,
            sensitivity_wheel_ball_friction,
            "sensitivity_wheel_ball_friction",
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
    Ok(settings)
}

/// The whole maximum-speed study as `ballbot reproduce` runs it
/// (`ballbot_sim::studies::max_speed::run_study`), on Rust worker threads (`threads`, 0: every
/// core) without the GIL. `quick` starts from the CI variant (one trial at 0 and 180 deg, a
/// coarse search, no sensitivity) instead of the paper's (3 seeds at 0, 90, 180 deg, the map
/// every 15 deg, mu 0.4/0.6/0.8 and COM height 0.4/0.5/0.7 m; a few minutes on two cores); the
/// other keywords override its lists and the search.
///
/// Returns a `MaxSpeedStudy`: the study's record (the `max_speed_study` entry of `summary.json`: `protocol`,
/// `wheel_ball_friction`, `com_height_m`, `trials`, `failing_accel_by_heading`, `map`, `sensitivity`, `paper`),
/// plus `max_speed_by_heading` (mean slow-ramp maximum speed per heading), `table` (the text
/// table `reproduce` prints) and `first_runs` (per trial heading, the first trial's series as
/// `max_speed_ramp` returns them, for the paper's Fig. "acc").
#[pyfunction(name = "max_speed_study")]
#[pyo3(signature = (
    params = None, *, quick = false, trial_headings_deg = None, seeds = None,
    map_headings_deg = None, sensitivity_headings_deg = None, sensitivity_wheel_ball_friction = None,
    sensitivity_com_height_m = None, threads = 0, fast_top_m_per_s = None,
    accel_bracket_m_per_s2 = None, accel_resolution_m_per_s2 = None,
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn py_max_speed_study<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    quick: bool,
    trial_headings_deg: Option<Vec<f64>>,
    seeds: Option<Vec<u64>>,
    map_headings_deg: Option<Vec<f64>>,
    sensitivity_headings_deg: Option<Vec<f64>>,
    sensitivity_wheel_ball_friction: Option<Vec<f64>>,
    sensitivity_com_height_m: Option<Vec<f64>>,
    threads: usize,
    fast_top_m_per_s: Option<f64>,
    accel_bracket_m_per_s2: Option<(f64, f64)>,
    accel_resolution_m_per_s2: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let params = params_or_default(params);
    let settings = study_settings(
        py,
        MaxSpeedSettings {
            quick,
            trial_headings_deg,
            seeds,
            map_headings_deg,
            sensitivity_headings_deg,
            sensitivity_wheel_ball_friction,
            sensitivity_com_height_m,
            threads,
            fast_top_m_per_s,
            accel_bracket_m_per_s2,
            accel_resolution_m_per_s2,
        },
    )?;
    let study = py
        .detach(|| run_study(params, &settings, &|_| {}))
        .map_err(|e| world_error(py, e))?;
    let view = MaxSpeedStudyView {
        detail: record(py, study.detail_json())?,
        max_speed_by_heading: record(py, study.max_speed_by_heading_json())?,
        table: study.table(),
        first_runs: FirstRuns(
            study
                .trials
                .iter()
                .map(|h| (h.heading_deg, RampRunView::from(&h.first_run)))
                .collect(),
        ),
    };
    crate::results::build(py, &view)
}
