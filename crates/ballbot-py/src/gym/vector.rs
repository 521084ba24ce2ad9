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
        Bound<'py, PyDict>,
    )> {
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
            .map_err(|e| gym_error(py, e))?;
        let out = &self.out;
        let mut time = Vec::with_capacity(n);
        let mut reset = Vec::with_capacity(n);
        let mut seed = Vec::with_capacity(n);
        let mut dropped = Vec::with_capacity(n);
        let failure = PyList::empty(py);
        let termination = PyList::empty(py);
        let events = PyList::empty(py);
        let ended_events = PyList::empty(py);
        for (i, (info, env)) in out.infos.iter().zip(self.inner.envs()).enumerate() {
            // An environment's events stay on it until its next step (VecInfo's docs).
            events.append(step_events(py, env)?)?;
            match info {
                VecInfo::Step(s) => {
                    time.push(s.time_secs);
                    reset.push(false);
                    seed.push(0_u64);
                    failure.append(s.failure.map(PyFailure::from))?;
                    termination.append(s.termination.map(|t| t.as_str()))?;
                }
                VecInfo::Reset(r) => {
                    time.push(0.0);
                    reset.push(true);
                    seed.push(r.draw.seed);
                    failure.append(py.None())?;
                    termination.append(py.None())?;
                }
            }
            if out.terminated[i] || out.truncated[i] {
                let (list, count) = episode_events(py, env)?;
                ended_events.append(list)?;
                dropped.push(count);
            } else {
                ended_events.append(py.None())?;
                dropped.push(0);
            }
        }
        let infos = VecInfoView {
            time_secs: PyArray1::from_vec(py, time),
            reset: PyArray1::from_vec(py, reset),
            episode_seed: PyArray1::from_vec(py, seed),
            failure,
            termination,
            events,
            episode_events: ended_events,
            events_dropped: PyArray1::from_vec(py, dropped),
        }
        .into_pyobject(py)?;
        Ok((
            rows(py, out.obs.clone(), n)?,
            PyArray1::from_slice(py, &out.rewards),
            PyArray1::from_slice(py, &out.terminated),
            PyArray1::from_slice(py, &out.truncated),
            infos,
        ))
    }
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
