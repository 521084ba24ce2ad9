//! The braking protocol as a type on the experiment driver ([`crate::studies::driver`]): one
//! job per heading, the protocol's descent as the job's scan, the bisection to its resolution
//! after it, and every trial one [`braking_run`] from a cold start.

use super::fly::braking_run_observed;
use super::study::{BrakingStudy, BrakingStudyParams};
use super::*;
use crate::studies::driver::{self, Bisection, JobRecord, Study};
use ballbot_world::rig::WorldRobot;

/// The braking study as a [`Study`]: one job per heading (deg, body frame), the descent of
/// [`BrakingStudyParams::durations_secs`] as its scan, then the bisection to
/// [`BrakingStudyParams::bisection_resolution_secs`]; a trial passes when the robot stopped
/// ([`BrakingOutcome::is_success`]).
///
/// Every trial solves its trajectory from the solver's cold start: a trial at `T` is exactly
/// `braking_run(world, params, heading, T, None)`, whatever was tried before it, so any
/// record of the study is what a single run at that `T` gives (and [`driver::replay`]
/// reproduces it bit for bit).
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingExperiment {
    /// The world (its sensor seed is the runs').
    pub world: WorldParams,
    /// One run's protocol and success criterion.
    pub params: BrakingParams,
    /// The descent and the bisection's resolution.
    pub study: BrakingStudyParams,
    /// The headings, one job each.
    pub headings_deg: Vec<f64>,
}

impl Study for BrakingExperiment {
    type Job = f64;
    type Trial = BrakingRun;
    type Error = BrakingError;

    fn jobs(&self) -> Vec<f64> {
        self.headings_deg.clone()
    }

    fn bisection(&self, _heading_deg: &f64) -> Option<Bisection> {
        let durations = &self.study.durations_secs;
        let longest = durations.iter().copied().reduce(f64::max)?;
        let shortest = durations.iter().copied().reduce(f64::min)?;
        // Widened by 1e-9 s (as the protocol always was): a bracket as wide as the resolution
        // up to rounding is not halved once more.
        self.study
            .bisection_resolution_secs
            .map(|r| Bisection::new(longest, shortest, r + 1e-9))
    }

    fn scan(&self, _heading_deg: &f64) -> Vec<f64> {
        self.study.durations_secs.clone()
    }

    fn trial(
        &self,
        heading_deg: &f64,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<BrakingRun, BrakingError> {
        self.study.validate()?;
        let duration_secs = value
            .or_else(|| self.study.durations_secs.first().copied())
            .ok_or_else(|| invalid("study.durations_secs", "must be non-empty"))?;
        braking_run_observed(
            self.world,
            &self.params,
            *heading_deg,
            duration_secs,
            None,
            &mut |sim, _| observe(sim),
        )
    }

    fn passed(&self, run: &BrakingRun) -> bool {
        run.outcome.is_success()
    }

    fn describe(&self, heading_deg: &f64, _value: Option<f64>, run: &BrakingRun) -> String {
        format!(
            "brake {heading_deg:.0} deg T {:.2} s: {}",
            run.duration_secs,
            run.outcome.label()
        )
    }
}

impl BrakingStudy {
    /// A job's record as the study at `heading_deg`: the scanned trials are the descent, the
    /// rest the bisection; the descent's shortest success and first failure, and the
    /// bracket's ends as the limits.
    pub fn from_record(heading_deg: f64, record: JobRecord<BrakingRun>) -> Self {
        let mut descent: Vec<BrakingRun> = record.trials.into_iter().map(|(_, r)| r).collect();
        let bisection = descent.split_off(record.scanned.min(descent.len()));
        let shortest_success_secs = descent
            .iter()
            .rev()
            .find(|r| r.outcome.is_success())
            .map(|r| r.duration_secs);
        let first_failure_secs = descent
            .iter()
            .find(|r| !r.outcome.is_success())
            .map(|r| r.duration_secs);
        Self {
            heading_deg,
            descent,
            bisection,
            shortest_success_secs,
            first_failure_secs,
            limit_secs: record.bracket.and_then(|b| b.passed),
            limit_failure_secs: record.bracket.and_then(|b| b.failed),
        }
    }
}

/// The paper's protocol at one heading: the durations of `study` in order (the paper: 5 s,
/// then 0.5 s shorter per success) until a run fails; then, beyond the paper, bisection
/// between the shortest success and the first failure to the study's resolution. Every run
/// solves its trajectory from a cold start, so each is exactly what [`braking_run`] gives at
/// its `T` with no warm start. Assumes success is monotone in `T` within the bracket (each
/// bisection run is reported, so a non-monotone outcome is visible). `on_run` sees every run
/// as it finishes.
///
/// This is [`BrakingExperiment`]'s job at one heading, run by the experiment driver
/// ([`driver::run_job`]).
pub fn braking_study(
    world_params: WorldParams,
    params: &BrakingParams,
    study: &BrakingStudyParams,
    heading_deg: f64,
    on_run: &mut dyn FnMut(&BrakingRun),
) -> Result<BrakingStudy, BrakingError> {
    study.validate()?;
    let experiment = BrakingExperiment {
        world: world_params,
        params: *params,
        study: study.clone(),
        headings_deg: vec![heading_deg],
    };
    let record = driver::run_job(&experiment, 0, &heading_deg, &mut |_, run| on_run(run))?;
    Ok(BrakingStudy::from_record(heading_deg, record))
}
