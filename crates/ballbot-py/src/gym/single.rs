//! `GymEnv`: one environment (`ballbot_sim::gym::BallbotEnv`).

use super::{config, gym_error, reset_info, reset_options, step_info};
use crate::params::PyWorldParams;
use crate::world::PyStepTelemetry;
use ballbot_sim::gym::BallbotEnv;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One ballbot environment on the rapier3d world (`ballbot_sim::gym::BallbotEnv`), the engine
/// of `ballbot.gym.BallbotEnv`. `task` is `"balance"` or `"velocity"`; see `ballbot.gym` for
/// the keyword arguments. Observations are float32 arrays; `reset` and `step` follow
/// Gymnasium's protocol.
#[pyclass(name = "GymEnv", module = "ballbot")]
pub struct PyGymEnv {
    inner: BallbotEnv,
    obs: Vec<f32>,
}

#[pymethods]
impl PyGymEnv {
    #[new]
    #[pyo3(signature = (
        task, params = None, *, control_hz = 400.0, max_episode_secs = None,
        last_action_in_observation = false, residual = true, residual_fraction = 0.2,
        randomization = None, commands = None, reward = None, stop_on = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
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
        let inner = BallbotEnv::new(config).map_err(|e| gym_error(py, e))?;
        Ok(Self {
            obs: vec![0.0; inner.observation_len()],
            inner,
        })
    }

    /// The observation box's upper bounds, float32 (the lower ones are their negatives).
    #[getter]
    fn observation_high<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        PyArray1::from_slice(py, self.inner.observation_high())
    }

    /// Physics steps per agent step.
    #[getter]
    fn steps_per_action(&self) -> u32 {
        self.inner.steps_per_action()
    }

    /// Agent steps per second.
    #[getter]
    fn control_hz(&self) -> f64 {
        self.inner.config().control_hz
    }

    /// The time limit (s).
    #[getter]
    fn max_episode_secs(&self) -> f64 {
        self.inner.config().max_episode_secs
    }

    /// The stop rules in force, as `stop_on=` takes them (`"tilt,driver-trip"` by default).
    #[getter]
    fn stop_on(&self) -> String {
        self.inner.config().stop_rules.to_string()
    }

    /// The nominal world.
    #[getter]
    fn params(&self) -> PyWorldParams {
        PyWorldParams {
            inner: self.inner.config().world,
        }
    }

    /// The world's last step record (`None` before the first reset).
    #[getter]
    fn telemetry(&self) -> Option<PyStepTelemetry> {
        self.inner
            .telemetry()
            .map(|t| PyStepTelemetry { inner: *t })
    }

    /// Starts an episode: `seed` starts it (and the stream of later episodes' seeds), `None`
    /// draws the next seed from that stream. Returns `(observation, info)`; `info` has
    /// `episode_seed`, `draw` (the randomised values) and `params` (the episode's world).
    #[pyo3(signature = (seed = None, options = None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: Option<u64>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        let options = reset_options(py, options)?;
        let (env, obs) = (&mut self.inner, &mut self.obs);
        let info = py
            .detach(|| env.reset(seed, options.as_ref(), obs))
            .map_err(|e| gym_error(py, e))?;
        Ok((PyArray1::from_slice(py, &self.obs), reset_info(py, &info)?))
    }

    /// One agent step with `action` (3 numbers, clipped to [-1, 1]). Returns `(observation,
    /// reward, terminated, truncated, info)`; `info` has `time_secs`, `termination`, `failure`,
    /// `controller_off`, `push_ns`, `command`, `events`, and at the episode's end
    /// `episode_events` and `events_dropped`.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f32>>,
        f64,
        bool,
        bool,
        Bound<'py, PyDict>,
    )> {
        let a = super::action(py, action)?;
        let (env, obs) = (&mut self.inner, &mut self.obs);
        let out = py
            .detach(|| env.step(a, obs))
            .map_err(|e| gym_error(py, e))?;
        Ok((
            PyArray1::from_slice(py, &self.obs),
            out.reward,
            out.terminated,
            out.truncated,
            step_info(py, &out.info, &self.inner, out.terminated || out.truncated)?,
        ))
    }
}
