//! The "until stopped" reading of the PIPTB braking test: the measured braking phase
//! `[t2, t3]` ends when the testbed has stopped, not at the fixed `t2 + 1.4 s`.
//!
//! The paper (Sec. IV-C) integrates `J_P = integral_{t2}^{t3} tau^2 dt` over "the measured
//! braking phase" and explains PI-PD's highest `J_P` by its failure to stop within 1.4 s. That
//! explanation holds when `t3` is when the testbed stopped: a controller that lags keeps
//! braking (and spending) after 1.4 s. This module computes that reading from a trial's
//! time series, so both readings come from the same runs.
//!
//! **Stop criterion** ([`StopCriterion`]): `t3` is the first controller tick at or after `t2`
//! from which the ball speed stays within `speed_band_m_per_s` for at least `hold_secs`
//! (every tick of that window). A speed that only passes through the band does not count: at
//! a deceleration `a` it spends `2 band / a` inside, 0.14 s at the braking's mean deceleration
//! `1 m/s / 1.4 s` for the 0.05 m/s band, so the default hold is 0.2 s. **Cap**: the run's last
//! tick (`t2 + brake_secs + settle_secs`, less one controller period); a trial whose stop is
//! not confirmed by then gets `t3` = the cap and `t3_capped` set.

use super::trial::{ControllerResult, TrialResult, TrialSeries, rms};
use super::{ExperimentError, PiptbReport};
use ballbot_world::planar::PlanarError;

/// When the testbed counts as stopped.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct StopCriterion {
    /// The ball speed must be at most this (m/s). Default: the experiment's
    /// `stop_speed_m_per_s`, 0.05.
    pub speed_band_m_per_s: f64,
    /// ... at every tick for at least this long (s). Default 0.2 (see the module doc).
    pub hold_secs: f64,
}

impl StopCriterion {
    /// The default hold (s): longer than the 0.14 s a speed crossing zero at the braking's
    /// mean deceleration (1 m/s in 1.4 s) spends inside the 0.05 m/s band.
    pub const DEFAULT_HOLD_SECS: f64 = 0.2;

    /// Checks both fields.
    pub fn validate(&self) -> Result<(), ExperimentError> {
        if !(self.speed_band_m_per_s.is_finite() && self.speed_band_m_per_s > 0.0) {
            return Err(invalid("stop.speed_band_m_per_s", "must be finite and > 0"));
        }
        if !(self.hold_secs.is_finite() && self.hold_secs >= 0.0) {
            return Err(invalid("stop.hold_secs", "must be finite and >= 0"));
        }
        Ok(())
    }
}

fn invalid(field: &'static str, requirement: &'static str) -> ExperimentError {
    ExperimentError::Planar(PlanarError::invalid(field, requirement))
}

/// When the testbed stopped: `(t3_secs, capped)`.
///
/// `t3` is the first tick at or after `start_secs` from which `|speed|` stays within the band
/// for `hold_secs` (ticks of `time_secs`, equal lengths); if no such tick is confirmed before
/// the last tick, `t3` is the last tick and `capped` is true.
///
/// ```
/// use ballbot_studies::studies::piptb::{StopCriterion, stop_time};
/// // 1 m/s falling by 1 m/s per second, sampled every 10 ms: inside 0.05 m/s from 0.95 s.
/// let t: Vec<f64> = (0..300).map(|k| 0.01 * k as f64).collect();
/// let v: Vec<f64> = t.iter().map(|&t| (1.0 - t).max(0.0)).collect();
/// let c = StopCriterion { speed_band_m_per_s: 0.05, hold_secs: 0.2 };
/// let (t3, capped) = stop_time(&t, &v, 0.0, &c);
/// approx::assert_abs_diff_eq!(t3, 0.95, epsilon = 1e-9);
/// assert!(!capped);
/// ```
pub fn stop_time(
    time_secs: &[f64],
    speed_m_per_s: &[f64],
    start_secs: f64,
    criterion: &StopCriterion,
) -> (f64, bool) {
    // Tick times are multiples of the controller period: half a nanosecond absorbs rounding.
    let eps = 1e-9;
    let mut since: Option<f64> = None;
    for (&t, &v) in time_secs.iter().zip(speed_m_per_s) {
        if t < start_secs - eps {
            continue;
        }
        if v.abs() <= criterion.speed_band_m_per_s {
            let t0 = *since.get_or_insert(t);
            if t - t0 >= criterion.hold_secs - eps {
                return (t0, false);
            }
        } else {
            since = None;
        }
    }
    (time_secs.last().copied().unwrap_or(start_secs), true)
}

/// Metrics of one trial over the braking phase `[t2, t3)` from its series: `(J_P, speed RMS
/// error, torque jitter, speed at t3)`. With the fixed `t3` they are the trial's own
/// (bit-identical: the same terms summed in the same order).
fn window_metrics(s: &TrialSeries, t2: f64, t3: f64) -> (f64, f64, f64, f64) {
    let inside = |t: f64| t >= t2 - 0.5e-9 && t < t3 - 0.5e-9;
    let (mut err_sq, mut err_n, mut jit_sq, mut jit_n) = (0.0, 0_u64, 0.0, 0_u64);
    let mut last: Option<f64> = None;
    let mut j_p = 0.0;
    let mut end_speed = f64::NAN;
    for k in 0..s.time_secs.len() {
        let t = s.time_secs[k];
        if (t - t3).abs() <= 0.5e-9 || (t >= t3 && end_speed.is_nan()) {
            j_p = s.effort_n2m2s[k];
            end_speed = s.speed_m_per_s[k];
        }
        if inside(t) {
            err_sq += (s.speed_m_per_s[k] - s.command_speed_m_per_s[k]).powi(2);
            err_n += 1;
            if let Some(prev) = last {
                jit_sq += (s.torque_nm[k] - prev).powi(2);
                jit_n += 1;
            }
            last = Some(s.torque_nm[k]);
        }
    }
    if end_speed.is_nan()
        && let (Some(&e), Some(&v)) = (s.effort_n2m2s.last(), s.speed_m_per_s.last())
    {
        j_p = e;
        end_speed = v;
    }
    (j_p, rms(err_sq, err_n), rms(jit_sq, jit_n), end_speed)
}

impl TrialResult {
    /// This trial read until stopped: `t3` from [`stop_time`] on its series after `t2 =
    /// brake_start_secs`, and `j_p`, `speed_rmse`, `torque_jitter_nm`, `end_speed_m_per_s`
    /// over `[t2, t3)`; `stopped` means stopped before the cap (and no fault). Every other
    /// field is the trial's own.
    pub fn until_stopped(&self, brake_start_secs: f64, criterion: &StopCriterion) -> Self {
        let s = &self.series;
        let (t3, capped) = stop_time(&s.time_secs, &s.speed_m_per_s, brake_start_secs, criterion);
        self.over_window(brake_start_secs, t3, capped)
    }

    /// This trial's metrics over the braking phase `[t2, t3)` (s since the start of the run),
    /// from its series: `j_p`, `speed_rmse`, `torque_jitter_nm`, `end_speed_m_per_s` (at the
    /// tick `t3`), `t3_secs`, `t3_capped = capped`, and `stopped` = no fault and not capped.
    /// With the fixed `t3` the first three are bit-identical to the trial's own.
    pub fn over_window(&self, t2: f64, t3: f64, capped: bool) -> Self {
        let (j_p, speed_rmse, torque_jitter_nm, end_speed) = window_metrics(&self.series, t2, t3);
        Self {
            j_p,
            j_p_n2mm2s: j_p * 1e6,
            stopped: self.fault.is_none() && !capped,
            t3_secs: t3,
            t3_capped: capped,
            speed_rmse,
            torque_jitter_nm,
            end_speed_m_per_s: end_speed,
            ..self.clone()
        }
    }
}

impl PiptbReport {
    /// The until-stopped reading of this (fixed-window) report: every trial through
    /// [`TrialResult::until_stopped`], the statistics recomputed; `stop` records the
    /// criterion.
    pub fn until_stopped(&self, criterion: &StopCriterion) -> Result<Self, ExperimentError> {
        criterion.validate()?;
        let t2 = self.settings.brake_start_secs();
        let controllers = self
            .controllers
            .iter()
            .map(|c| {
                let trials = c
                    .trials
                    .iter()
                    .map(|t| t.until_stopped(t2, criterion))
                    .collect();
                ControllerResult::new(c.kind, trials)
            })
            .collect();
        Ok(Self {
            controllers,
            reference: self.reference.clone(),
            settings: self.settings.clone(),
            stop: Some(*criterion),
        })
    }

    /// The stop criterion's sensitivity: the until-stopped reading for every pair of
    /// `bands_m_per_s` and `holds_secs`.
    pub fn stop_sensitivity(
        &self,
        bands_m_per_s: &[f64],
        holds_secs: &[f64],
    ) -> Result<Vec<Self>, ExperimentError> {
        let mut out = Vec::new();
        for &speed_band_m_per_s in bands_m_per_s {
            for &hold_secs in holds_secs {
                out.push(self.until_stopped(&StopCriterion {
                    speed_band_m_per_s,
                    hold_secs,
                })?);
            }
        }
        Ok(out)
    }

    /// The controllers' keys from the lowest mean `j_p` to the highest.
    pub fn j_p_order(&self) -> Vec<&'static str> {
        let mut c: Vec<&ControllerResult> = self.controllers.iter().collect();
        c.sort_by(|a, b| a.j_p.total_cmp(&b.j_p));
        c.iter().map(|c| c.kind.key()).collect()
    }

    /// Whether the mean `j_p` ranks as the paper's: LQR-PI lowest and PI-PD highest (the
    /// paper gives no `J_P` for the LQR). `None` without both.
    pub fn matches_paper_order(&self) -> Option<bool> {
        let order = self.j_p_order();
        if !(order.contains(&"lqr_pi") && order.contains(&"pi_pd")) {
            return None;
        }
        Some(order.first() == Some(&"lqr_pi") && order.last() == Some(&"pi_pd"))
    }
}
