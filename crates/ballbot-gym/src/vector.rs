//! [`VecEnv`]: N environments stepped in one call, spread over a thread pool, with
//! Gymnasium 1.x's next-step autoreset.

use super::config::EnvConfig;
use super::env::{BallbotEnv, ResetInfo, ResetOptions, StepInfo};
use super::error::GymError;

/// What one environment of a vector step reports. Its events are on the environment until the
/// next vector step: `envs()[i].step_events()` and `envs()[i].events()` (an environment that was
/// reset has a new episode, without events).
#[derive(Clone, Debug, PartialEq)]
pub enum VecInfo {
    /// The environment stepped (its termination, if it ended, in [`StepInfo::termination`]).
    Step(StepInfo),
    /// The environment had ended at the previous step and was reset instead (its action was
    /// ignored; reward 0, neither terminated nor truncated).
    Reset(Box<ResetInfo>),
}

/// The outputs of a vector step, one row per environment.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VecStep {
    /// Observations, row-major `(n, observation_len)`.
    pub obs: Vec<f32>,
    /// Rewards.
    pub rewards: Vec<f64>,
    /// Terminated flags.
    pub terminated: Vec<bool>,
    /// Truncated flags.
    pub truncated: Vec<bool>,
    /// Per environment: its step's or its reset's report.
    pub infos: Vec<VecInfo>,
}

/// N independent environments of one configuration, stepped together on a thread pool.
///
/// Autoreset is Gymnasium 1.x's default, `AutoresetMode.NEXT_STEP`: an environment that
/// ended (terminated or truncated) is reset at its next step, which ignores its action and
/// returns the first observation of the new episode. Environment `i` then behaves exactly like
/// a single [`BallbotEnv`] stepped and reset in that order: the results do not depend on the
/// number of threads.
///
/// ```
/// use ballbot_gym::{EnvConfig, Task, VecEnv, VecStep};
/// let mut envs = VecEnv::new(EnvConfig::new(Task::Balance), 4, 2)?;
/// let mut obs = vec![0.0_f32; 4 * envs.observation_len()];
/// envs.reset(&[Some(0), Some(1), Some(2), Some(3)], None, &mut obs)?;
/// let mut out = VecStep::default();
/// envs.step(&[[0.0; 3]; 4], &mut out)?;
/// assert_eq!(out.rewards.len(), 4);
/// # Ok::<(), ballbot_gym::GymError>(())
/// ```
pub struct VecEnv {
    envs: Vec<BallbotEnv>,
    /// `threads - 1` workers (the calling thread steps the first share itself); `None` with
    /// one thread.
    pool: Option<rayon::ThreadPool>,
    threads: usize,
    obs_len: usize,
}

/// One environment's share of a vector call.
struct Job<'a, R> {
    index: usize,
    env: &'a mut BallbotEnv,
    row: &'a mut [f32],
    action: [f64; 3],
    out: Option<Result<R, GymError>>,
}

/// Runs `work` on every job: the first share on the calling thread, the others on the pool
/// (so a call wakes `threads - 1` workers, and none with one thread).
fn run_split<R: Send>(
    pool: Option<&rayon::ThreadPool>,
    threads: usize,
    jobs: &mut [Job<'_, R>],
    work: &(dyn Fn(&mut Job<'_, R>) + Sync),
) {
    let share = jobs.len().div_ceil(threads.max(1)).max(1);
    match pool {
        Some(pool) if jobs.len() > share => pool.in_place_scope(|scope| {
            let mut chunks = jobs.chunks_mut(share);
            let first = chunks.next();
            for chunk in chunks {
                scope.spawn(move |_| chunk.iter_mut().for_each(work));
            }
            if let Some(first) = first {
                first.iter_mut().for_each(work);
            }
        }),
        _ => jobs.iter_mut().for_each(work),
    }
}

impl VecEnv {
    /// `n` environments (n >= 1) on `threads` worker threads (0: one per core).
    pub fn new(config: EnvConfig, n: usize, threads: usize) -> Result<Self, GymError> {
        if n == 0 {
            return Err(GymError::invalid("num_envs", "must be >= 1", n));
        }
        let envs = (0..n)
            .map(|_| BallbotEnv::new(config))
            .collect::<Result<Vec<_>, _>>()?;
        let threads = ballbot_world::runner::thread_count(threads, n);
        let pool = if threads > 1 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads - 1)
                .thread_name(|i| format!("ballbot-vec-env-{i}"))
                .build()
                .map_err(|e| GymError::invalid("threads", "could not start the pool", e))?;
            Some(pool)
        } else {
            None
        };
        Ok(Self {
            obs_len: envs[0].observation_len(),
            envs,
            pool,
            threads,
        })
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.envs.len()
    }

    /// Always false (a vector env has at least one environment).
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    /// Threads stepping the environments (the caller's included).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Length of one observation.
    pub fn observation_len(&self) -> usize {
        self.obs_len
    }

    /// The environments (e.g. to draw environment `i`).
    pub fn envs(&self) -> &[BallbotEnv] {
        &self.envs
    }

    /// Resets every environment, environment `i` with `seeds[i]` (see [`BallbotEnv::reset`]),
    /// writing the observations row-major into `obs`.
    pub fn reset(
        &mut self,
        seeds: &[Option<u64>],
        options: Option<&ResetOptions>,
        obs: &mut [f32],
    ) -> Result<Vec<ResetInfo>, GymError> {
        let n = self.envs.len();
        if seeds.len() != n {
            return Err(GymError::invalid(
                "seeds",
                "must have one entry per environment",
                seeds.len(),
            ));
        }
        if obs.len() != n * self.obs_len {
            return Err(GymError::invalid(
                "obs",
                "the buffer must have len() * observation_len() entries",
                obs.len(),
            ));
        }
        let no_actions = vec![[0.0; 3]; n];
        let mut jobs = jobs(&mut self.envs, obs, self.obs_len, &no_actions);
        let work = |job: &mut Job<'_, ResetInfo>| {
            job.out = Some(job.env.reset(seeds[job.index], options, job.row));
        };
        run_split(self.pool.as_ref(), self.threads, &mut jobs, &work);
        let results: Vec<Result<ResetInfo, GymError>> = jobs
            .into_iter()
            .map(|j| j.out.unwrap_or(Err(GymError::NeedsReset("not reset"))))
            .collect();
        results.into_iter().collect()
    }

    /// Steps every environment with its action (one row per environment), autoresetting the
    /// ones that ended at the previous step; `out` is resized and overwritten.
    pub fn step(&mut self, actions: &[[f64; 3]], out: &mut VecStep) -> Result<(), GymError> {
        let n = self.envs.len();
        if actions.len() != n {
            return Err(GymError::invalid(
                "actions",
                "must have one row per environment",
                actions.len(),
            ));
        }
        if let Some(a) = actions.iter().find(|a| !a.iter().all(|x| x.is_finite())) {
            return Err(GymError::NonFiniteAction(*a));
        }
        out.obs.resize(n * self.obs_len, 0.0);
        type Row = (f64, bool, bool, VecInfo);
        let work = |job: &mut Job<'_, Row>| {
            // The environment's own record says whether its episode ended at the last step.
            job.out = Some(if job.env.episode_ended() == Some(true) {
                job.env
                    .reset(None, None, job.row)
                    .map(|info| (0.0, false, false, VecInfo::Reset(Box::new(info))))
            } else {
                job.env
                    .step(job.action, job.row)
                    .map(|o| (o.reward, o.terminated, o.truncated, VecInfo::Step(o.info)))
            });
        };
        let mut jobs = jobs(&mut self.envs, &mut out.obs, self.obs_len, actions);
        run_split(self.pool.as_ref(), self.threads, &mut jobs, &work);
        let results: Vec<Result<Row, GymError>> = jobs
            .into_iter()
            .map(|j| j.out.unwrap_or(Err(GymError::NeedsReset("not stepped"))))
            .collect();
        out.rewards.clear();
        out.terminated.clear();
        out.truncated.clear();
        out.infos.clear();
        for r in results {
            let (reward, terminated, truncated, info) = r?;
            out.rewards.push(reward);
            out.terminated.push(terminated);
            out.truncated.push(truncated);
            out.infos.push(info);
        }
        Ok(())
    }
}

/// One job per environment over `obs`'s rows (`obs_len` each) and `actions`.
fn jobs<'a, R>(
    envs: &'a mut [BallbotEnv],
    obs: &'a mut [f32],
    obs_len: usize,
    actions: &[[f64; 3]],
) -> Vec<Job<'a, R>> {
    envs.iter_mut()
        .zip(obs.chunks_mut(obs_len))
        .zip(actions)
        .enumerate()
        .map(|(index, ((env, row), action))| Job {
            index,
            env,
            row,
            action: *action,
            out: None,
        })
        .collect()
}
