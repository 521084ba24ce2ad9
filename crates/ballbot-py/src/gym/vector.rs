//! `GymVecEnv`: N environments stepped in Rust on a thread pool without the GIL
//! (`ballbot_sim::gym::VecEnv`).

use super::{config, episode_events, gym_error, reset_info, reset_options, step_events};
use crate::errors::{Kind, error};
use crate::params::PyWorldParams;
use crate::world::{PyFailure, PyStepTelemetry};
use ballbot_sim::gym::{VecEnv, VecInfo, VecStep};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// N ballbot environments stepped in one call (`ballbot_sim::gym::VecEnv`), the engine of
/// `ballbot.gym.BallbotVectorEnv`: the worlds run on `threads` Rust threads (0: one per core)
/// while the GIL is released. Autoreset is Gymnasium's next-step mode.
#[pyclass(name = "GymVecEnv", module = "ballbot")]
pub struct PyGymVecEnv {
    inner: VecEnv,
    out: VecStep,
}

#[pymethods]
impl PyGymVecEnv {
    #[new]
    #[pyo3(signature = (
        task, num_envs, params = None, *, threads = 0, control_hz = 400.0,
        max_episode_secs = None, last_action_in_observation = false, residual = true,
        residual_fraction = 0.2, randomization = None, commands = None, reward = None,
        stop_on = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        task: &str,
        num_envs: usize,
        params: Option<PyWorldParams>,
        threads: usize,
        control_hz: f64,
        max_episode_secs: Option<f64>,
        last_action_in_observation: bool,
        residual: bool,
        residual_fraction: f64,
        randomization: Option<&Bound<'_, PyAny>>,
        commands: Option<&Bound<'_, PyAny>>,
        reward: Option<&Bound<'_, PyAny>>,
        stop_on: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let config = config(
            py,
            task,
            params,
            control_hz,
            max_episode_secs,
            last_action_in_observation,
            residual,
            residual_fraction,
            randomization,
            commands,
            reward,
            stop_on,
        )?;
        let inner = VecEnv::new(config, num_envs, threads).map_err(|e| gym_error(py, e))?;
        Ok(Self {
            inner,
            out: VecStep::default(),
        })
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.inner.len()
    }

    /// Worker threads.
    #[getter]
    fn threads(&self) -> usize {
        self.inner.threads()
    }

    /// The observation box's upper bounds of one environment, float32.
    #[getter]
    fn observation_high<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        PyArray1::from_slice(py, self.inner.envs()[0].observation_high())
    }

    /// The nominal world.
    #[getter]
    fn params(&self) -> PyWorldParams {
        PyWorldParams {
            inner: self.inner.envs()[0].config().world,
        }
    }

    /// Agent steps per second.
    #[getter]
    fn control_hz(&self) -> f64 {
        self.inner.envs()[0].config().control_hz
    }

    /// The stop rules in force, as `stop_on=` takes them (`"tilt,driver-trip"` by default).
    #[getter]
    fn stop_on(&self) -> String {
        self.inner.envs()[0].config().stop_rules.to_string()
    }

    /// Environment `index`'s last step record (`None` before the first reset).
    fn telemetry(&self, py: Python<'_>, index: usize) -> PyResult<Option<PyStepTelemetry>> {
        let env = self.inner.envs().get(index).ok_or_else(|| {
            error(
                py,
                Kind::Parameter,
                format!("no environment {index} of {}", self.inner.len()),
            )
        })?;
        Ok(env.telemetry().map(|t| PyStepTelemetry { inner: *t }))
    }

    /// Resets every environment, environment `i` with `seeds[i]` (an int or `None`). Returns
    /// `(observations (n, d) float32, infos)`, `infos` a list of per-environment reset dicts.
    #[pyo3(signature = (seeds, options = None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seeds: Vec<Option<u64>>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<(Bound<'py, PyArray2<f32>>, Bound<'py, PyList>)> {
        let n = self.inner.len();
        if seeds.len() != n {
            return Err(error(
                py,
                Kind::Shape,
                format!("`seeds` must have {n} entries, got {}", seeds.len()),
            ));
        }
        let options = reset_options(py, options)?;
        let mut obs = vec![0.0_f32; n * self.inner.observation_len()];
        let env = &mut self.inner;
        let infos = py
            .detach(|| env.reset(&seeds, options.as_ref(), &mut obs))
            .map_err(|e| gym_error(py, e))?;
        let list = PyList::empty(py);
        for info in &infos {
            list.append(reset_info(py, info)?)?;
        }
        Ok((rows(py, obs, n)?, list))
    }

    /// Steps every environment (`actions`: shape (n, 3)), autoresetting those that ended at the
    /// previous step. Returns `(observations, rewards, terminated, truncated, infos)`; `infos`
    /// is a dict of arrays and lists, one entry per environment: `time_secs` (n,), `reset` (n,)
    /// bool (the environment was reset this step), `episode_seed` (n,) uint64 (0 where not
    /// reset), `failure` (`Failure` or `None`), `termination` (its name or `None`), `events`
    /// (the events in progress during the step, as `GymEnv.step` gives them; empty where
    /// reset), `episode_events` (the episode's events where it ended this step, else `None`),
    /// `events_dropped` (n,) uint64 (0 where it did not end).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyAny>,
    )> {
        self.advance(py, &actions)?;
        let c = Collected::of(py, &self.inner, &self.out)?;
        let infos = VecInfoView {
            time_secs: PyArray1::from_vec(py, c.time),
            reset: PyArray1::from_vec(py, c.reset),
            episode_seed: PyArray1::from_vec(py, c.seed),
            failure: PyList::new(py, c.failure)?,
            termination: PyList::new(py, c.termination)?,
            events: PyList::new(py, c.events)?,
            episode_events: PyList::new(py, c.episode_events)?,
            events_dropped: PyArray1::from_vec(py, c.dropped),
        }
        .into_pyobject(py)?
        .into_any();
        self.outputs(py, infos)
    }

    /// `step` with its infos in Gymnasium's vector form, built here rather than in Python
    /// (what `BallbotVectorEnv.step` returns): each key as a (n,) array, object arrays for
    /// `failure`, `termination`, `events` and `episode_events`, int64 for `episode_seed` and
    /// `events_dropped`, and beside each its mask `_key`, where it is set: `time_secs` and
    /// `events` where the environment stepped, `episode_seed` where it was reset, `failure`
    /// and `termination` where one ended the episode, `episode_events` and `events_dropped`
    /// where the episode ended.
    #[allow(clippy::type_complexity)]
    fn step_gym<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyAny>,
    )> {
        self.advance(py, &actions)?;
        let c = Collected::of(py, &self.inner, &self.out)?;
        let stepped: Vec<bool> = c.reset.iter().map(|r| !r).collect();
        let infos = GymInfoView {
            time_secs_mask: PyArray1::from_slice(py, &stepped),
            time_secs: PyArray1::from_vec(py, c.time),
            episode_seed_mask: PyArray1::from_slice(py, &c.reset),
            // Seeds are drawn below 2^63; as the Python wrapper's int64 cast did.
            episode_seed: PyArray1::from_vec(py, c.seed.iter().map(|&s| s as i64).collect()),
            failure_mask: PyArray1::from_vec(py, c.has_failure),
            failure: PyArray1::from_vec(py, c.failure),
            termination_mask: PyArray1::from_vec(py, c.has_termination),
            termination: PyArray1::from_vec(py, c.termination),
            events_mask: PyArray1::from_vec(py, stepped),
            events: PyArray1::from_vec(py, c.events),
            episode_events_mask: PyArray1::from_slice(py, &c.ended),
            episode_events: PyArray1::from_vec(py, c.episode_events),
            events_dropped_mask: PyArray1::from_vec(py, c.ended),
            events_dropped: PyArray1::from_vec(py, c.dropped.iter().map(|&d| d as i64).collect()),
        }
        .into_pyobject(py)?
        .into_any();
        self.outputs(py, infos)
    }
}

impl PyGymVecEnv {
    /// Checks `actions` against the environments and steps them all without the GIL.
    fn advance(&mut self, py: Python<'_>, actions: &PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let n = self.inner.len();
        if actions.shape() != [n, 3] {
            return Err(error(
                py,
                Kind::Shape,
                format!(
                    "`actions` must have shape ({n}, 3), got {:?}",
                    actions.shape()
                ),
            ));
        }
        let a: Vec<[f64; 3]> = actions
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect();
        let (env, out) = (&mut self.inner, &mut self.out);
        py.detach(|| env.step(&a, out))
            .map_err(|e| gym_error(py, e))
    }

    /// The step's observations, rewards, terminated and truncated flags, with `infos`.
    #[allow(clippy::type_complexity)]
    fn outputs<'py>(
        &self,
        py: Python<'py>,
        infos: Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyAny>,
    )> {
        let out = &self.out;
        Ok((
            rows(py, out.obs.clone(), self.inner.len())?,
            PyArray1::from_slice(py, &out.rewards),
            PyArray1::from_slice(py, &out.terminated),
            PyArray1::from_slice(py, &out.truncated),
            infos,
        ))
    }
}

/// One step's per-environment values, taken from the Rust outputs once for both forms of
/// the infos.
struct Collected {
    time: Vec<f64>,
    reset: Vec<bool>,
    seed: Vec<u64>,
    dropped: Vec<u64>,
    ended: Vec<bool>,
    has_failure: Vec<bool>,
    has_termination: Vec<bool>,
    failure: Vec<Py<PyAny>>,
    termination: Vec<Py<PyAny>>,
    events: Vec<Py<PyAny>>,
    episode_events: Vec<Py<PyAny>>,
}

impl Collected {
    fn of(py: Python<'_>, envs: &VecEnv, out: &VecStep) -> PyResult<Self> {
        let n = envs.len();
        let mut c = Self {
            time: Vec::with_capacity(n),
            reset: Vec::with_capacity(n),
            seed: Vec::with_capacity(n),
            dropped: Vec::with_capacity(n),
            ended: Vec::with_capacity(n),
            has_failure: Vec::with_capacity(n),
            has_termination: Vec::with_capacity(n),
            failure: Vec::with_capacity(n),
            termination: Vec::with_capacity(n),
            events: Vec::with_capacity(n),
            episode_events: Vec::with_capacity(n),
        };
        for (i, (info, env)) in out.infos.iter().zip(envs.envs()).enumerate() {
            // An environment's events stay on it until its next step (VecInfo's docs).
            c.events.push(step_events(py, env)?.into_any().unbind());
            let (failure, termination) = match info {
                VecInfo::Step(s) => {
                    c.time.push(s.time_secs);
                    c.reset.push(false);
                    c.seed.push(0);
                    (
                        s.failure.map(PyFailure::from),
                        s.termination.map(|t| t.as_str()),
                    )
                }
                VecInfo::Reset(r) => {
                    c.time.push(0.0);
                    c.reset.push(true);
                    c.seed.push(r.draw.seed);
                    (None, None)
                }
            };
            c.has_failure.push(failure.is_some());
            c.has_termination.push(termination.is_some());
            c.failure
                .push(failure.into_pyobject(py)?.into_any().unbind());
            c.termination
                .push(termination.into_pyobject(py)?.into_any().unbind());
            let ended = out.terminated[i] || out.truncated[i];
            c.ended.push(ended);
            if ended {
                let (list, count) = episode_events(py, env)?;
                c.episode_events.push(list.into_any().unbind());
                c.dropped.push(count);
            } else {
                c.episode_events.push(py.None());
                c.dropped.push(0);
            }
        }
        Ok(c)
    }
}

/// The infos in Gymnasium's vector form (`step_gym`): each value with its mask `_key`.
#[derive(IntoPyObject)]
struct GymInfoView<'py> {
    time_secs: Bound<'py, PyArray1<f64>>,
    #[pyo3(item("_time_secs"))]
    time_secs_mask: Bound<'py, PyArray1<bool>>,
    episode_seed: Bound<'py, PyArray1<i64>>,
    #[pyo3(item("_episode_seed"))]
    episode_seed_mask: Bound<'py, PyArray1<bool>>,
    failure: Bound<'py, PyArray1<Py<PyAny>>>,
    #[pyo3(item("_failure"))]
    failure_mask: Bound<'py, PyArray1<bool>>,
    termination: Bound<'py, PyArray1<Py<PyAny>>>,
    #[pyo3(item("_termination"))]
    termination_mask: Bound<'py, PyArray1<bool>>,
    events: Bound<'py, PyArray1<Py<PyAny>>>,
    #[pyo3(item("_events"))]
    events_mask: Bound<'py, PyArray1<bool>>,
    episode_events: Bound<'py, PyArray1<Py<PyAny>>>,
    #[pyo3(item("_episode_events"))]
    episode_events_mask: Bound<'py, PyArray1<bool>>,
    events_dropped: Bound<'py, PyArray1<i64>>,
    #[pyo3(item("_events_dropped"))]
    events_dropped_mask: Bound<'py, PyArray1<bool>>,
}

/// The vector env's step infos as Python has them: one entry per environment in each.
#[derive(IntoPyObject)]
struct VecInfoView<'py> {
    time_secs: Bound<'py, PyArray1<f64>>,
    reset: Bound<'py, PyArray1<bool>>,
    episode_seed: Bound<'py, PyArray1<u64>>,
    failure: Bound<'py, PyList>,
    termination: Bound<'py, PyList>,
    events: Bound<'py, PyList>,
    episode_events: Bound<'py, PyList>,
    events_dropped: Bound<'py, PyArray1<u64>>,
}

/// A row-major buffer of `n` rows as a 2-D array.
fn rows(py: Python<'_>, values: Vec<f32>, n: usize) -> PyResult<Bound<'_, PyArray2<f32>>> {
    let d = values.len() / n.max(1);
    PyArray1::from_vec(py, values).reshape([n, d])
}
