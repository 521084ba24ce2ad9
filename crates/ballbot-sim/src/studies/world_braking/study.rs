//! The paper's braking protocol (descent from 5 s by 0.5 s until failure) and the bisection
//! that refines the limit beyond it.

use super::*;
use crate::studies::driver::halve;

/// The paper's protocol and the refinement beyond it.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingStudyParams {
    /// Braking times of the descent, tried in order until one fails (s).
    pub durations_secs: Vec<f64>,
    /// Bisect between the shortest success and the first failure down to this bracket (s);
    /// `None` skips the bisection.
    pub bisection_resolution_secs: Option<f64>,
}

impl BrakingStudyParams {
    /// The paper's descent, `T = 5, 4.5, ..., 0.5 s`, and a bisection to 0.05 s.
    pub fn paper() -> Self {
        Self {
            durations_secs: (0..10).map(|k| 5.0 - 0.5 * f64::from(k)).collect(),
            bisection_resolution_secs: Some(0.05),
        }
    }
}

/// The result of [`braking_study`] at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingStudy {
    /// Heading of travel (deg).
    pub heading_deg: f64,
    /// The descending runs of the paper's protocol, in order (the last one failed unless the
    /// descent ran out of durations).
    pub descent: Vec<BrakingRun>,
    /// The bisection's runs, in order.
    pub bisection: Vec<BrakingRun>,
    /// Shortest successful `T` of the descent (s), the paper's figure; `None` if the first
    /// already failed.
    pub shortest_success_secs: Option<f64>,
    /// First failing `T` of the descent (s); `None` if none failed.
    pub first_failure_secs: Option<f64>,
    /// Shortest successful `T` after the bisection (s).
    pub limit_secs: Option<f64>,
    /// Longest failing `T` after the bisection (s).
    pub limit_failure_secs: Option<f64>,
}

impl BrakingStudy {
    /// The run of the descent at its shortest success.
    pub fn shortest_success(&self) -> Option<&BrakingRun> {
        let t = self.shortest_success_secs?;
        self.descent.iter().find(|r| r.duration_secs == t)
    }

    /// The descent's first failing run.
    pub fn first_failure(&self) -> Option<&BrakingRun> {
        let t = self.first_failure_secs?;
        self.descent.iter().find(|r| r.duration_secs == t)
    }
}

/// The paper's protocol at one heading: the durations of `study` in order (the paper: 5 s,
/// then 0.5 s shorter per success) until a run fails; then, beyond the paper, bisection
/// between the shortest success and the first failure. Each trajectory is warm-started from
/// the last solved one. Assumes success is monotone in `T` within the bracket (each
/// bisection run is reported, so a non-monotone outcome is visible). `on_run` sees every run
/// as it finishes.
pub fn braking_study(
    world_params: WorldParams,
    params: &BrakingParams,
    study: &BrakingStudyParams,
    heading_deg: f64,
    on_run: &mut dyn FnMut(&BrakingRun),
) -> Result<BrakingStudy, BrakingError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if study.durations_secs.is_empty() || !study.durations_secs.iter().all(|&t| ok(t)) {
        return Err(invalid(
            "study.durations_secs",
            "must be non-empty, every duration finite and > 0",
        ));
    }
    if study.bisection_resolution_secs.is_some_and(|r| !ok(r)) {
        return Err(invalid(
            "study.bisection_resolution_secs",
            "must be finite and > 0",
        ));
    }
    let mut out = BrakingStudy {
        heading_deg,
        descent: Vec::new(),
        bisection: Vec::new(),
        shortest_success_secs: None,
        first_failure_secs: None,
        limit_secs: None,
        limit_failure_secs: None,
    };
    let mut warm: Option<Trajectory> = None;
    for &t in &study.durations_secs {
        let run = braking_run(world_params, params, heading_deg, t, warm.as_ref())?;
        on_run(&run);
        if run.plan.is_some() {
            warm.clone_from(&run.plan);
        }
        let success = run.outcome.is_success();
        out.descent.push(run);
        if success {
            out.shortest_success_secs = Some(t);
        } else {
            out.first_failure_secs = Some(t);
            break;
        }
    }
    out.limit_secs = out.shortest_success_secs;
    out.limit_failure_secs = out.first_failure_secs;
    if let (Some(resolution), Some(lo), Some(hi)) = (
        study.bisection_resolution_secs,
        out.first_failure_secs,
        out.shortest_success_secs,
    ) && lo < hi
    {
        let mut bisection = Vec::new();
        let bracket = halve(
            hi,
            lo,
            resolution + 1e-9,
            |t| {
                let run = braking_run(world_params, params, heading_deg, t, warm.as_ref())?;
                if run.plan.is_some() {
                    warm.clone_from(&run.plan);
                }
                Ok::<_, BrakingError>(run)
            },
            |run| run.outcome.is_success(),
            |_, run| {
                on_run(&run);
                bisection.push(run);
            },
        )?;
        out.bisection = bisection;
        out.limit_secs = Some(bracket.passed);
        out.limit_failure_secs = bracket.failed;
    }
    Ok(out)
}
