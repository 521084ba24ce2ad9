//! The result of a failing-acceleration search (bisection on a grid of ramp accelerations for
//! the largest one whose ramp survives); the search itself is a job of
//! [`super::MaxSpeedExperiment`] ([`super::failing_acceleration`]).

use super::trial::TrialOutcome;
use crate::studies::ramp::RampResult;

/// The result of a failing-acceleration search at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct FailingAccel {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Largest acceleration on the grid whose ramp survived (m/s^2); `None` if even the
    /// bracket's low end failed.
    pub largest_surviving_m_per_s2: Option<f64>,
    /// Smallest acceleration on the grid whose ramp failed (m/s^2); `None` if the bracket's
    /// high end survived (censored: the limit is above the bracket).
    pub smallest_failing_m_per_s2: Option<f64>,
    /// The run at `smallest_failing_m_per_s2` (reduced), if any.
    pub failing: Option<TrialOutcome>,
    /// The run at `largest_surviving_m_per_s2` (reduced), if any.
    pub surviving: Option<TrialOutcome>,
    /// The failing run's time series (for plots), if any.
    pub failing_run: Option<RampResult>,
    /// Ramps simulated by the search.
    pub runs: usize,
}

impl FailingAccel {
    /// Whether the failing run failed while its shaped command was still rising (below 98 % of
    /// the ramp's top `top_m_per_s`): a failure of acceleration; `Some(false)` is a failure at
    /// cruise (during the hold), `None` if no run failed.
    pub fn failed_during_ramp(&self, top_m_per_s: f64) -> Option<bool> {
        let run = self.failing_run.as_ref()?;
        let last = run.samples.last()?;
        Some(last.shaped_command_m_per_s < 0.98 * top_m_per_s)
    }

    /// The limit as text: `1.75` (largest surviving), `>= 4.00` if the bracket's top survived,
    /// `< 0.50` if its bottom failed.
    pub fn text(&self) -> String {
        match (
            self.largest_surviving_m_per_s2,
            self.smallest_failing_m_per_s2,
        ) {
            (Some(a), Some(_)) => format!("{a:.2}"),
            (Some(a), None) => format!(">= {a:.2}"),
            (None, Some(a)) => format!("< {a:.2}"),
            (None, None) => "-".to_owned(),
        }
    }
}
