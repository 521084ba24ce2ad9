//! The engine of `ballbot.gym` (`ballbot_sim::gym`): `GymEnv`, one environment, and
//! `GymVecEnv`, N of them stepped in Rust without the GIL. The Gymnasium classes in
//! `python/ballbot/gym/` wrap them.

mod single;
mod vector;

use crate::errors::{Kind, error, world_error};
use crate::params::PyWorldParams;
use ballbot_sim::gym::{
    BallbotEnv, CommandRanges, EnvConfig, EpisodeDraw, GymError, Randomization, ResetInfo,
    ResetOptions, RewardWeights, StepInfo, Task,
};
use ballbot_sim::rig::Event;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::de::DeserializeOwned;

pub(crate) use single::PyGymEnv;
pub(crate) use vector::PyGymVecEnv;

/// Maps an environment error: parameters and options to `ballbot.ParameterError` (the message
/// names the field), protocol misuse to `ballbot.BallbotError`.
pub(crate) fn gym_error(py: Python<'_>, e: GymError) -> PyErr {
    match e {
        GymError::World(e) => world_error(py, e),
        GymError::NeedsReset(_) => error(py, Kind::Other, e.to_string()),
        other => error(py, Kind::Parameter, other.to_string()),
    }
}

/// A serde struct from a Python dict of plain values (through JSON: unknown keys and wrong
/// types are rejected with serde's message, which names the key).
fn from_dict<T: DeserializeOwned>(
    py: Python<'_>,
    value: &Bound<'_, PyAny>,
    field: &str,
) -> PyResult<T> {
    let json = py.import("json")?.call_method1("dumps", (value,))?;
    let text: String = json.extract()?;
    serde_json::from_str(&text).map_err(|e| {
        error(
            py,
            Kind::Parameter,
            format!("invalid parameter `{field}`: {e}"),
        )
    })
}

/// The keyword arguments both classes take, as an `EnvConfig`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn config(
    py: Python<'_>,
    task: &str,
    params: Option<PyWorldParams>,
    control_hz: f64,
    max_episode_secs: Option<f64>,
    last_action_in_observation: bool,
    residual: bool,
    residual_fraction: f64,
    randomization: Option<&Bound<'_, PyAny>>,
    commands: Option<&Bound<'_, PyAny>>,
    reward: Option<&Bound<'_, PyAny>>,
    stop_on: Option<&Bound<'_, PyAny>>,
) -> PyResult<EnvConfig> {
    let task: Task = task.parse().map_err(|e| gym_error(py, e))?;
    let mut config = EnvConfig::new(task);
    if let Some(p) = params {
        config.world = p.inner;
    }
    config.control_hz = control_hz;
    if let Some(secs) = max_episode_secs {
        config.max_episode_secs = secs;
    }
    config.last_action_in_observation = last_action_in_observation;
    config.residual = residual;
    config.residual_fraction = residual_fraction;
    if let Some(r) = randomization {
        // A name: "recommended" adds the campaign's ranges to the task's defaults, "none"
        // removes every range (the initial tilt too); a dict overrides the task's ranges.
        config.randomization = match r.extract::<String>().ok().as_deref() {
            Some("recommended") => config.randomization.merged(&Randomization::recommended()),
            Some("none") => Randomization::default(),
            Some(name) => {
                return Err(error(
                    py,
                    Kind::Parameter,
                    format!(
                        "invalid parameter `randomization`: a dict of ranges, \
                         \"recommended\" or \"none\", got {name:?}"
                    ),
                ));
            }
            None => {
                config
                    .randomization
                    .merged(&from_dict::<Randomization>(py, r, "randomization")?)
            }
        };
    }
    if let Some(c) = commands {
        config.commands = from_dict::<CommandRanges>(py, c, "commands")?;
    }
    if let Some(w) = reward {
        config.reward = from_dict::<RewardWeights>(py, w, "reward")?;
    }
    if let Some(rules) = stop_on {
        config.stop_rules = crate::world::stop_rules(py, rules)?;
    }
    config.validate().map_err(|e| gym_error(py, e))?;
    Ok(config)
}

/// `reset(options=...)`: `randomization` (a dict of ranges overriding the environment's),
/// `initial_tilt_rad` (2 numbers), `command` (3 numbers); any other key is an error.
pub(crate) fn reset_options(
    py: Python<'_>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Option<ResetOptions>> {
    let Some(options) = options else {
        return Ok(None);
    };
    let mut out = ResetOptions::default();
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        match key.as_str() {
            "randomization" => out.randomization = Some(from_dict(py, &value, "randomization")?),
            "initial_tilt_rad" => {
                out.initial_tilt_rad =
                    Some(value.extract().map_err(|_| {
                        error(py, Kind::Shape, "`initial_tilt_rad` must be 2 numbers")
                    })?);
            }
            "command" => {
                out.command = Some(value.extract().map_err(|_| {
                    error(
                        py,
                        Kind::Shape,
                        "`command` must be 3 numbers (vx, vy, yaw rate)",
                    )
                })?);
            }
            _ => {
                return Err(error(
                    py,
                    Kind::Parameter,
                    format!(
                        "unknown reset option `{key}`; known: randomization, \
                         initial_tilt_rad, command"
                    ),
                ));
            }
        }
    }
    Ok(Some(out))
}

/// The reset's info dict: `episode_seed`, `draw` (the drawn values), `params` (the world).
pub(crate) fn reset_info<'py>(py: Python<'py>, info: &ResetInfo) -> PyResult<Bound<'py, PyDict>> {
    ResetInfoView {
        episode_seed: info.draw.seed,
        draw: draw_dict(py, &info.draw)?,
        params: PyWorldParams { inner: info.params },
    }
    .into_pyobject(py)
}

/// The reset's info dict as Python has it (`#[derive(IntoPyObject)]`: a dict keyed by the
/// fields).
#[derive(IntoPyObject)]
struct ResetInfoView<'py> {
    episode_seed: u64,
    draw: Bound<'py, PyAny>,
    params: PyWorldParams,
}

/// The step's info dict as Python has it, every step (the hot path: the derive fills the
/// dict as a hand-written one would).
#[derive(IntoPyObject)]
struct StepInfoView<'py> {
    time_secs: f64,
    termination: Option<&'static str>,
    failure: Option<crate::world::PyFailure>,
    controller_off: bool,
    push_ns: Option<(f64, f64)>,
    command: Bound<'py, PyList>,
    events: Bound<'py, PyList>,
}

/// What the step's info dict adds at the episode's end.
#[derive(IntoPyObject)]
struct EpisodeEndView<'py> {
    episode_events: Bound<'py, PyList>,
    events_dropped: u64,
}

/// The draw through its JSON text, as `json.loads` reads it: its `[f64; 2]` stays a list
/// (`pythonize` would make a fixed-size array a tuple) and Python's dict is plain.
fn draw_dict<'py>(py: Python<'py>, draw: &EpisodeDraw) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(draw)
        .map_err(|e| error(py, Kind::Other, format!("episode draw: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The step's info dict: `time_secs`, `termination` (its name or `None`), `failure`
/// (`Failure` or `None`), `controller_off`, `push_ns` (a tuple or `None`), `command`, `events`
/// (the events in progress during the step, [`step_events`]); at the episode's end
/// (`ended`: terminated or truncated) also `episode_events` and `events_dropped`
/// ([`episode_events`]).
pub(crate) fn step_info<'py>(
    py: Python<'py>,
    info: &StepInfo,
    env: &BallbotEnv,
    ended: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = StepInfoView {
        time_secs: info.time_secs,
        termination: info.termination.map(|t| t.as_str()),
        failure: info.failure.map(crate::world::PyFailure::from),
        controller_off: info.controller_off,
        push_ns: info.push_ns.map(|j| (j[0], j[1])),
        command: PyList::new(py, info.command)?,
        events: step_events(py, env)?,
    }
    .into_pyobject(py)?;
    if ended {
        let (episode_events, events_dropped) = episode_events(py, env)?;
        let end = EpisodeEndView {
            episode_events,
            events_dropped,
        };
        d.update(end.into_pyobject(py)?.as_mapping())?;
    }
    Ok(d)
}

/// Events as a list of dicts, the keys of their serde form (`ballbot world --json`): `kind`
/// (`slip`, `lift_off`, `driver_trip`, `controller_fault`, `traction_limit`), `wheel`
/// (`"OW1"`..) for the wheel events, `fault` for a controller fault, the peak under a key
/// naming its unit (`peak_slip_m_per_s`, `min_normal_force_n`, `min_accel_limit_m_per_s2`),
/// `onset_secs`, `duration_secs`, `ongoing`.
fn events_list<'py>(py: Python<'py>, events: &[&Event]) -> PyResult<Bound<'py, PyList>> {
    pythonize::pythonize(py, events)?
        .cast_into::<PyList>()
        .map_err(PyErr::from)
}

/// The events in progress during `env`'s last step (`BallbotEnv::step_events`), as dicts.
pub(crate) fn step_events<'py>(py: Python<'py>, env: &BallbotEnv) -> PyResult<Bound<'py, PyList>> {
    let events: Vec<&Event> = env.step_events().collect();
    events_list(py, &events)
}

/// The episode's events so far (`BallbotEnv::events`) as dicts, and how many were not kept
/// (beyond `EventLog::MAX_EVENTS`).
pub(crate) fn episode_events<'py>(
    py: Python<'py>,
    env: &BallbotEnv,
) -> PyResult<(Bound<'py, PyList>, u64)> {
    let Some(log) = env.events() else {
        return Ok((PyList::empty(py), 0));
    };
    let events: Vec<&Event> = log.events().iter().collect();
    Ok((events_list(py, &events)?, log.dropped()))
}

/// A finite action of three numbers.
pub(crate) fn action(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    let a: [f64; 3] = value
        .extract()
        .map_err(|_| error(py, Kind::Shape, "an action is 3 numbers, shape (3,)"))?;
    Ok(a)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyGymEnv>()?;
    m.add_class::<PyGymVecEnv>()?;
    Ok(())
}
