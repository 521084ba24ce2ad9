//! The paper's braking protocol (descent from 5 s by 0.5 s until failure) and the bisection
//! that refines the limit beyond it: its parameters and its result at one heading (run by
//! [`super::BrakingExperiment`]).

use super::*;

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

    /// Checks the protocol: at least one duration, every duration and the resolution finite
    /// and > 0.
    ///
    /// ```
    /// use ballbot_studies::studies::world_braking::BrakingStudyParams;
    /// assert!(BrakingStudyParams::paper().validate().is_ok());
    /// let none = BrakingStudyParams { durations_secs: Vec::new(), ..BrakingStudyParams::paper() };
    /// assert!(none.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), BrakingError> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if self.durations_secs.is_empty() || !self.durations_secs.iter().all(|&t| ok(t)) {
            return Err(invalid(
                "study.durations_secs",
                "must be non-empty, every duration finite and > 0",
            ));
        }
        if self.bisection_resolution_secs.is_some_and(|r| !ok(r)) {
            return Err(invalid(
                "study.bisection_resolution_secs",
                "must be finite and > 0",
            ));
        }
        Ok(())
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
