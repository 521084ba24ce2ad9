//! The failing-acceleration search: bisection on a grid of ramp accelerations for the largest
//! one whose ramp survives.

use super::protocol::MaxSpeedProtocol;
use super::trial::{TrialOutcome, controller};
use crate::studies::ramp::{RampParams, RampResult, max_speed_ramp_with_config};
use crate::world::{WorldError, WorldParams};

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

/// The failing-acceleration search at `heading_deg`: bisection on the grid of
/// [`MaxSpeedProtocol::accel_resolution_m_per_s2`] inside
/// [`MaxSpeedProtocol::accel_bracket_m_per_s2`] for the largest ramp acceleration whose ramp to
/// [`MaxSpeedProtocol::fast_top_m_per_s`] (and 1 s hold) survives. Assumes that failure is
/// monotonic in the acceleration (it checks both ends of the bracket first).
pub fn failing_acceleration(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
) -> Result<FailingAccel, WorldError> {
    protocol.validate()?;
    let mut p = params;
    p.sensors.seed = seed;
    let config = controller(&p, protocol)?;
    let res = protocol.accel_resolution_m_per_s2;
    let [low, high] = protocol.accel_bracket_m_per_s2;
    let mut runs = 0;
    let mut run = |k: i64| -> Result<(RampResult, TrialOutcome), WorldError> {
        runs += 1;
        // On the grid, without the product's rounding noise (1.95, not 1.9500000000000002).
        let accel_m_per_s2 = (k as f64 * res * 1e9).round() / 1e9;
        let ramp = RampParams {
            accel_m_per_s2,
            max_command_m_per_s: protocol.fast_top_m_per_s,
            ..protocol.slow_ramp
        };
        let r = max_speed_ramp_with_config(p, config, heading_deg, &ramp)?;
        let o = TrialOutcome::from_run(&r, seed, accel_m_per_s2);
        Ok((r, o))
    };
    let mut lo = ((low / res).round() as i64).max(1);
    let mut hi = ((high / res).round() as i64).max(lo + 1);
    let (lo_run, lo_out) = run(lo)?;
    if !lo_out.censored() {
        return Ok(FailingAccel {
            heading_deg,
            largest_surviving_m_per_s2: None,
            smallest_failing_m_per_s2: Some(lo_out.accel_m_per_s2),
            failing: Some(lo_out),
            surviving: None,
            failing_run: Some(lo_run),
            runs: 1,
        });
    }
    let (hi_run, hi_out) = run(hi)?;
    if hi_out.censored() {
        return Ok(FailingAccel {
            heading_deg,
            largest_surviving_m_per_s2: Some(hi_out.accel_m_per_s2),
            smallest_failing_m_per_s2: None,
            failing: None,
            surviving: Some(hi_out),
            failing_run: None,
            runs: 2,
        });
    }
    let (mut surviving, mut failing, mut failing_run) = (lo_out, hi_out, hi_run);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let (r, o) = run(mid)?;
        if o.censored() {
            lo = mid;
            surviving = o;
        } else {
            hi = mid;
            failing = o;
            failing_run = r;
        }
    }
    Ok(FailingAccel {
        heading_deg,
        largest_surviving_m_per_s2: Some(surviving.accel_m_per_s2),
        smallest_failing_m_per_s2: Some(failing.accel_m_per_s2),
        failing: Some(failing),
        surviving: Some(surviving),
        failing_run: Some(failing_run),
        runs,
    })
}
