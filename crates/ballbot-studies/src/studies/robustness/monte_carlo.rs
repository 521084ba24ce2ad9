//! Monte Carlo robustness: pushes on robots that differ from the controller's model.
//!
//! Each run samples a [`Mismatch`] from its own seed, builds the world of the mismatched robot
//! and drives it with the controller designed for the nominal one, then pushes the body's
//! centre of mass with 40 N s over 0.1 s towards a random heading (the protocol of
//! [`crate::studies::push`], with a longer settle so that a biased robot has found its
//! balance before the push). A subset of the runs also bisects the largest push it recovers
//! from. The runs go to every core through the one job runner; the study times a batch on one
//! thread and the rest on all, and reports both rates.

use super::fault_run::ControllerVariant;
use super::mismatch::Mismatch;
use crate::studies::driver::{self, Bisection, Study};
use crate::studies::push::{
    PushOutcome, PushParams, PushSearch, PushTrial, push_recovery_limit_by, push_trial_with,
};
use ballbot_world::rig::{Happened, WorldRobot};
use ballbot_world::runner::run_jobs;
use ballbot_world::world::{StopRules, WorldError, WorldParams};
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// What the Monte Carlo study runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MonteCarloSettings {
    /// The controller (designed for the nominal robot).
    pub controller: ControllerVariant,
    /// What counts as not staying up: the world's stop rules, or falls only.
    pub count: MonteCarloCount,
    /// Runs at the push impulse.
    pub runs: usize,
    /// Runs (the first ones) that also bisect their largest recovered push.
    pub limit_runs: usize,
    /// The push (N s). 40 in the campaign's presets.
    pub impulse_ns: f64,
    /// Mismatch fraction of every scaled parameter. 0.2 in the campaign's presets.
    pub fraction: f64,
    /// Base seed; run `i` uses [`run_seed`]`(seed, i)`.
    pub seed: u64,
    /// Runs timed on one thread before the rest run on all (the throughput figures).
    pub single_thread_runs: usize,
    /// Standing still before the push (s). 3: the balance-point estimator's 2 s time
    /// constant, and the world's settling.
    pub settle_secs: f64,
    /// Bisection of the largest recovered push: upper end and resolution (N s).
    pub search: PushSearch,
}

/// What a Monte Carlo run counts as not staying up.
///
/// ```
/// use ballbot_studies::studies::robustness::MonteCarloCount;
/// assert_eq!(MonteCarloCount::Falls.as_str(), "falls");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MonteCarloCount {
    /// The world's stop rules ([`ballbot_world::world::FailureParams`]): a wheel slipping for longer
    /// than 0.1 s or off the ball for longer than 20 ms ends the run as a failure, as do the
    /// falls below. A slip or a lift-off is not a fall, so this counts some recoveries as
    /// failures.
    StopRules,
    /// Falls only: the slip and lift-off stop rules relaxed (their durations set beyond any
    /// run), so a run fails only when the body tilts 25 deg from the vertical, touches the
    /// floor, or a motor driver trips ([`ballbot_world::world::FailureParams`]'s other rules).
    Falls,
}

impl MonteCarloCount {
    /// Both, the published protocol first.
    pub const ALL: [Self; 2] = [Self::StopRules, Self::Falls];

    /// The canonical (snake_case) name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::StopRules => "stop_rules",
            Self::Falls => "falls",
        }
    }

    /// Whether `trial` stayed up under this count: with the stop rules, no failure and the
    /// tilt below the push's 15 deg bound ([`PushTrial::stayed_up`]); counting falls, no
    /// failure of the world (a lean beyond 15 deg that the robot recovers from is not a fall).
    pub fn stayed_up(self, trial: &PushTrial) -> bool {
        match self {
            Self::StopRules => trial.stayed_up(),
            Self::Falls => !matches!(trial.outcome, PushOutcome::Failed(_)),
        }
    }

    /// The world's stop rules this count runs with: all of them, or the slip and lift-off
    /// rules off ([`StopRules::contact_rules_off`]).
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::MonteCarloCount;
    /// use ballbot_world::world::StopRules;
    /// assert_eq!(MonteCarloCount::Falls.stop_rules(), StopRules::contact_rules_off());
    /// assert_eq!(MonteCarloCount::StopRules.stop_rules(), StopRules::all());
    /// ```
    pub fn stop_rules(self) -> StopRules {
        match self {
            Self::StopRules => StopRules::all(),
            Self::Falls => StopRules::contact_rules_off(),
        }
    }
}

impl MonteCarloSettings {
    /// The issue's size: 1,000 runs at 40 N s with +-20 % mismatch, 100 of them bisected.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::MonteCarloSettings;
    /// assert_eq!(MonteCarloSettings::full().runs, 1000);
    /// ```
    pub fn full() -> Self {
        Self {
            controller: ControllerVariant::Design,
            count: MonteCarloCount::StopRules,
            runs: 1000,
            limit_runs: 100,
            impulse_ns: 40.0,
            fraction: 0.2,
            seed: 1,
            single_thread_runs: 20,
            settle_secs: 3.0,
            search: PushSearch {
                upper_ns: 120.0,
                resolution_ns: 2.0,
            },
        }
    }

    /// The CI size: 6 runs, 1 bisected.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::MonteCarloSettings;
    /// assert!(MonteCarloSettings::quick().validate().is_ok());
    /// ```
    pub fn quick() -> Self {
        Self {
            runs: 6,
            limit_runs: 1,
            single_thread_runs: 2,
            search: PushSearch {
                upper_ns: 120.0,
                resolution_ns: 8.0,
            },
            ..Self::full()
        }
    }

    /// Checks every field, naming the first out of range.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::MonteCarloSettings;
    /// let bad = MonteCarloSettings { fraction: 1.5, ..MonteCarloSettings::quick() };
    /// assert!(bad.validate().unwrap_err().to_string().contains("fraction"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let check = |ok: bool, field, requirement| {
            if ok {
                Ok(())
            } else {
                Err(WorldError::InvalidParameter { field, requirement })
            }
        };
        check(self.runs >= 1, "runs", "must be >= 1")?;
        check(
            self.limit_runs <= self.runs,
            "limit_runs",
            "must be <= runs",
        )?;
        check(
            self.impulse_ns.is_finite() && self.impulse_ns >= 0.0,
            "impulse_ns",
            "must be finite and >= 0",
        )?;
        check(
            self.fraction.is_finite() && (0.0..0.99).contains(&self.fraction),
            "fraction",
            "must be finite, >= 0 and < 0.99",
        )?;
        check(
            self.settle_secs.is_finite() && self.settle_secs >= 0.0,
            "settle_secs",
            "must be finite and >= 0",
        )?;
        let ok = |v: f64| v.is_finite() && v > 0.0;
        check(
            ok(self.search.upper_ns) && ok(self.search.resolution_ns),
            "search",
            "upper_ns and resolution_ns must be finite and > 0",
        )
    }

    fn push_params(&self) -> PushParams {
        PushParams {
            settle_secs: self.settle_secs,
            stop_rules: self.count.stop_rules(),
            ..PushParams::default()
        }
    }
}

/// The seed of run `index` of a study seeded `seed` (splitmix64 of both: neighbouring runs
/// and neighbouring base seeds give unrelated samples).
///
/// ```
/// use ballbot_studies::studies::robustness::run_seed;
/// assert_eq!(run_seed(1, 0), run_seed(1, 0));
/// assert_ne!(run_seed(1, 0), run_seed(1, 1));
/// ```
pub fn run_seed(seed: u64, index: usize) -> u64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(index as u64)
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One Monte Carlo run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MonteCarloRun {
    /// Index in the study.
    pub index: usize,
    /// The run's seed: [`run_one`] with it gives this run again.
    pub seed: u64,
    /// The sampled mismatch.
    pub mismatch: Mismatch,
    /// The protocol's verdict on the push (`recovered`, `tilt_exceeded`, `failed`,
    /// `not_at_rest`).
    pub verdict: &'static str,
    /// Whether it stayed up ([`MonteCarloCount::stayed_up`]): with the stop rules, no failure
    /// of the world and the tilt below 15 deg (outcome `recovered` or `not_at_rest`); counting
    /// falls, no failure of the world.
    pub stayed_up: bool,
    /// Whether it also came to rest: below 0.1 m/s and 3 deg from 3 s after the push on
    /// (outcome `recovered`).
    pub recovered: bool,
    /// What failed, if the world detected a failure.
    pub failure: Option<String>,
    /// Largest tilt from the vertical after the push (deg).
    pub peak_tilt_deg: f64,
    /// Largest ball speed in the rest window (m/s).
    pub rest_speed_m_per_s: f64,
    /// Largest push it stays up after (N s), for the bisected runs.
    pub largest_recovered_ns: Option<f64>,
    /// How the run ended (fell, ended by a stop rule, at rest...) and its contact events,
    /// whatever the stop rules; in JSON its fields `outcome`, `events` and `events_dropped`
    /// sit in the run's record. For the bisected runs, the trial at the fixed impulse.
    #[serde(flatten)]
    pub happened: Happened,
}

/// Quantiles of the largest push the bisected runs stay up after (N s).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LimitQuantiles {
    /// Smallest.
    pub min: f64,
    /// 5th percentile.
    pub p05: f64,
    /// Median.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest.
    pub max: f64,
}

/// Throughput of the study's own runs (wall clock; not a benchmark).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Throughput {
    /// Runs per second on one thread.
    pub one_thread_runs_per_s: f64,
    /// Runs per second on all threads.
    pub all_threads_runs_per_s: f64,
    /// Threads used for the second figure.
    pub threads: usize,
}

/// The Monte Carlo study's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MonteCarlo {
    /// The settings it ran with.
    pub settings: MonteCarloSettings,
    /// Runs.
    pub runs: usize,
    /// Runs that stayed up (see [`MonteCarloRun::stayed_up`]).
    pub stayed_up: usize,
    /// `stayed_up / runs`: the recovery rate (the robot recovered its balance).
    pub recovery_rate: f64,
    /// 95 % Wilson score interval of the recovery rate.
    pub recovery_rate_ci95: [f64; 2],
    /// Runs that also came to rest (see [`MonteCarloRun::recovered`]).
    pub at_rest: usize,
    /// `at_rest / runs`.
    pub at_rest_rate: f64,
    /// 95 % Wilson score interval of the at-rest rate.
    pub at_rest_rate_ci95: [f64; 2],
    /// Runs by outcome.
    pub outcomes: Vec<(&'static str, usize)>,
    /// The runs that did not stay up (all of them, with their seeds), then the other runs
    /// with the largest peak tilt, up to 10 in all.
    pub worst: Vec<MonteCarloRun>,
    /// Quantiles of the largest recovered push over the bisected runs.
    pub limit_quantiles: Option<LimitQuantiles>,
    /// Wall-clock throughput.
    pub throughput: Throughput,
    /// Every run, in index order.
    pub all_runs: Vec<MonteCarloRun>,
}

/// The 95 % Wilson score interval of `k` successes in `n` trials.
///
/// ```
/// use ballbot_studies::studies::robustness::wilson_interval_95;
/// let [lo, hi] = wilson_interval_95(990, 1000);
/// assert!((lo - 0.9817).abs() < 1e-4 && (hi - 0.9946).abs() < 1e-4);
/// ```
pub fn wilson_interval_95(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054;
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let denominator = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denominator;
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / denominator;
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// Run `index` of `settings` on `nominal`: the same run as in [`run_monte_carlo`].
pub fn run_one(
    nominal: &WorldParams,
    settings: &MonteCarloSettings,
    index: usize,
) -> Result<MonteCarloRun, WorldError> {
    run_one_observed(nominal, settings, index, &mut |_| {})
}

/// [`run_one`] calling `observe` after every physics step of the push at the study's impulse
/// (not of the limit's bisection); the run is the same with or without it.
pub fn run_one_observed(
    nominal: &WorldParams,
    settings: &MonteCarloSettings,
    index: usize,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<MonteCarloRun, WorldError> {
    let seed = run_seed(settings.seed, index);
    let mismatch = Mismatch::sample(seed, settings.fraction);
    let config = settings.controller.config(nominal)?;
    let mut world = mismatch.apply(nominal);
    world.sensors.seed = seed;
    let params = settings.push_params();
    let trial_observed =
        |impulse_ns: f64, observe: &mut dyn FnMut(&WorldRobot)| -> Result<PushTrial, WorldError> {
            let sim = WorldRobot::with_config(world, config)?;
            push_trial_with(
                sim,
                &mut mismatch.sensor_bias(),
                &params,
                mismatch.heading_deg,
                impulse_ns,
                observe,
            )
        };
    let trial = trial_observed(settings.impulse_ns, observe)?;
    let mut trial_at = |impulse_ns: f64| trial_observed(impulse_ns, &mut |_| {});
    let largest_recovered_ns = if index < settings.limit_runs {
        let search = push_recovery_limit_by(
            &settings.search,
            mismatch.heading_deg,
            &mut trial_at,
            &|trial: &PushTrial| settings.count.stayed_up(trial),
            &mut |_| {},
        )?;
        Some(search.largest_recovered_ns)
    } else {
        None
    };
    let failure = match trial.outcome {
        PushOutcome::Failed(f) => Some(f.to_string()),
        _ => None,
    };
    Ok(MonteCarloRun {
        index,
        seed,
        mismatch,
        verdict: trial.outcome.label(),
        stayed_up: settings.count.stayed_up(&trial),
        recovered: trial.recovered(),
        failure,
        peak_tilt_deg: trial.peak_tilt_rad.to_degrees(),
        rest_speed_m_per_s: trial.rest_speed_m_per_s,
        largest_recovered_ns,
        happened: trial.happened,
    })
}

/// Runs the study on `nominal` (MiaPURE's default world in `ballbot robustness`) on `threads`
/// threads (0: every core), except `single_thread_runs` of the runs that are not bisected,
/// which run first on one thread to time it; `progress(done, total)` after each run.
pub fn run_monte_carlo(
    nominal: &WorldParams,
    settings: &MonteCarloSettings,
    threads: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<MonteCarlo, WorldError> {
    settings.validate()?;
    let total = settings.runs;
    let done = AtomicUsize::new(0);
    let tick = |_| progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
    // One push trial each: the bisected runs are left out of the timed batches.
    let plain: Vec<usize> = (settings.limit_runs..total).collect();
    let split = settings.single_thread_runs.min(plain.len());
    let (single, multi) = plain.split_at(split);
    let bisected: Vec<usize> = (0..settings.limit_runs).collect();
    let study = MonteCarloStudy { nominal, settings };
    let run = |&i: &usize| {
        driver::run_job(&study, i, &i, &mut |_, _| {})
            .map(|r| r.trials.into_iter().map(|(_, run)| run))
    };
    let start = Instant::now();
    let mut all_runs: Vec<MonteCarloRun> = run_jobs(single, 1, run, &tick)?
        .into_iter()
        .flatten()
        .collect();
    let one_secs = start.elapsed().as_secs_f64();
    let start = Instant::now();
    all_runs.extend(run_jobs(multi, threads, run, &tick)?.into_iter().flatten());
    let all_secs = start.elapsed().as_secs_f64();
    all_runs.extend(
        run_jobs(&bisected, threads, run, &tick)?
            .into_iter()
            .flatten(),
    );
    all_runs.sort_by_key(|r| r.index);
    let rate = |n: usize, secs: f64| if secs > 0.0 { n as f64 / secs } else { 0.0 };
    let throughput = Throughput {
        one_thread_runs_per_s: rate(single.len(), one_secs),
        all_threads_runs_per_s: rate(multi.len(), all_secs),
        threads: ballbot_world::runner::thread_count(threads, multi.len()),
    };
    Ok(summarise(*settings, all_runs, throughput))
}

/// The Monte Carlo as a [`Study`]: one job per run index (its seed draws the mismatch, the
/// push's heading and the sensors' noise), one trial each ([`run_one_observed`]: the push at
/// the study's impulse, and for the first `limit_runs` the largest push it stays up after),
/// passing when the robot stayed up ([`MonteCarloCount::stayed_up`]). [`run_monte_carlo`] runs
/// the jobs in its timed batches through [`driver::run_job`]; [`driver::replay`] runs one
/// again with an observer, e.g. the worst run of a table by its index.
pub struct MonteCarloStudy<'a> {
    /// The nominal world the mismatches perturb.
    pub nominal: &'a WorldParams,
    /// The study.
    pub settings: &'a MonteCarloSettings,
}

impl Study for MonteCarloStudy<'_> {
    type Job = usize;
    type Trial = MonteCarloRun;
    type Error = WorldError;

    fn jobs(&self) -> Vec<usize> {
        (0..self.settings.runs).collect()
    }

    fn bisection(&self, _index: &usize) -> Option<Bisection> {
        None
    }

    fn trial(
        &self,
        index: &usize,
        _value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<MonteCarloRun, WorldError> {
        run_one_observed(self.nominal, self.settings, *index, observe)
    }

    fn passed(&self, run: &MonteCarloRun) -> bool {
        run.stayed_up
    }

    fn describe(&self, index: &usize, _value: Option<f64>, run: &MonteCarloRun) -> String {
        format!("monte carlo run {index} seed {}: {}", run.seed, run.verdict)
    }
}

fn summarise(
    settings: MonteCarloSettings,
    all_runs: Vec<MonteCarloRun>,
    throughput: Throughput,
) -> MonteCarlo {
    let runs = all_runs.len();
    let stayed_up = all_runs.iter().filter(|r| r.stayed_up).count();
    let at_rest = all_runs.iter().filter(|r| r.recovered).count();
    let mut outcomes: Vec<(&'static str, usize)> = Vec::new();
    for r in &all_runs {
        match outcomes.iter_mut().find(|(o, _)| *o == r.verdict) {
            Some((_, n)) => *n += 1,
            None => outcomes.push((r.verdict, 1)),
        }
    }
    let mut worst: Vec<MonteCarloRun> = all_runs.iter().filter(|r| !r.stayed_up).cloned().collect();
    let mut near: Vec<&MonteCarloRun> = all_runs.iter().filter(|r| r.stayed_up).collect();
    near.sort_by(|a, b| b.peak_tilt_deg.total_cmp(&a.peak_tilt_deg));
    worst.extend(
        near.into_iter()
            .take(10_usize.saturating_sub(worst.len()))
            .cloned(),
    );
    let mut limits: Vec<f64> = all_runs
        .iter()
        .filter_map(|r| r.largest_recovered_ns)
        .collect();
    limits.sort_by(f64::total_cmp);
    let quantile = |q: f64| {
        let i = (q * (limits.len() - 1) as f64).round() as usize;
        limits[i.min(limits.len() - 1)]
    };
    let limit_quantiles = (!limits.is_empty()).then(|| LimitQuantiles {
        min: limits[0],
        p05: quantile(0.05),
        p50: quantile(0.5),
        p95: quantile(0.95),
        max: limits[limits.len() - 1],
    });
    MonteCarlo {
        settings,
        runs,
        stayed_up,
        recovery_rate: fraction(stayed_up, runs),
        recovery_rate_ci95: wilson_interval_95(stayed_up, runs),
        at_rest,
        at_rest_rate: fraction(at_rest, runs),
        at_rest_rate_ci95: wilson_interval_95(at_rest, runs),
        outcomes,
        worst,
        limit_quantiles,
        throughput,
        all_runs,
    }
}

fn fraction(k: usize, n: usize) -> f64 {
    if n > 0 { k as f64 / n as f64 } else { 0.0 }
}
