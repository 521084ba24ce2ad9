//! The mechanism study ([`crate::studies::mechanisms`]) as the summary's JSON
//! (`slow_ramp_mechanisms`, `ramp_accel_sweep`, `contact_ripple`) and as comparison tables.

use crate::studies::max_speed::{PAPER_MAX_SPEED, TrialOutcome};
use crate::studies::mechanisms::{MechanismStudy, RippleSpectrum};
use ballbot_world::world::wheel_name;
use serde_json::{Map, Value, json};

/// `{:.0}` of a heading, as the summary's object key.
fn heading_key(heading_deg: f64) -> String {
    format!("{heading_deg:.0}")
}

/// A run as one table cell: `0.55 slip OW2`, `5.70 stop` (the supervisor's controlled stop
/// came first, e.g. at a wheel's speed limit or its tilt limit), `4.49 stop, tilt` (a failure
/// after that stop), `>= 3.00` (censored).
pub fn outcome_cell(t: &TrialOutcome) -> String {
    let what = t.failure.map(|f| match f.kind.wheel_name() {
        Some(w) => format!("{} {w}", f.kind.as_str()),
        None => f.kind.as_str().to_owned(),
    });
    match (t.supervisor_stop_secs, what) {
        (Some(_), None) => format!("{:.2} stop", t.max_speed_m_per_s),
        (Some(_), Some(w)) => format!("{:.2} stop, {w}", t.max_speed_m_per_s),
        (None, None) => format!(">= {:.2}", t.max_speed_m_per_s),
        (None, Some(w)) => format!("{:.2} {w}", t.max_speed_m_per_s),
    }
}

impl MechanismStudy {
    /// `slow_ramp_mechanisms`: per controller, per mechanism, per heading the slow ramp's
    /// record ([`TrialOutcome::to_json`]), with the protocol and the paper's values.
    pub fn slow_ramp_json(&self) -> Value {
        let mut controllers = Map::new();
        for &c in &self.settings.controllers {
            let mut mechanisms = Map::new();
            for &m in &self.settings.mechanisms {
                let mut headings = Map::new();
                for &h in &self.settings.headings_deg {
                    if let Some(r) = self.run(c, m, h) {
                        headings.insert(heading_key(h), r.outcome.to_json());
                    }
                }
                mechanisms.insert(m.as_str().to_owned(), Value::Object(headings));
            }
            controllers.insert(c.as_str().to_owned(), Value::Object(mechanisms));
        }
        let s = &self.settings.protocol.slow_ramp;
        json!({
            "protocol": {
                "accel_m_per_s2": s.accel_m_per_s2,
                "top_m_per_s": s.max_command_m_per_s,
                "settle_secs": s.settle_secs,
                "hold_secs": 1.0,
                "sensor_seed": self.settings.seed,
            },
            "mechanisms": self.settings.mechanisms.iter().map(|m| json!({
                "name": m.as_str(),
                "label": m.label(),
            })).collect::<Vec<_>>(),
            "controllers": Value::Object(controllers),
            "paper": PAPER_MAX_SPEED.iter().map(|p| json!({
                "heading_deg": p.heading_deg,
                "max_speed_m_per_s": p.speed_m_per_s,
                "upper_bound": p.upper_bound,
            })).collect::<Vec<_>>(),
        })
    }

    /// `ramp_accel_sweep`: the default world's ramps by heading, `mu` and acceleration.
    pub fn sweep_json(&self) -> Value {
        Value::Array(
            self.sweep
                .iter()
                .map(|p| {
                    let mut v = p.outcome.to_json();
                    if let Value::Object(m) = &mut v {
                        m.insert("wheel_ball_friction".into(), json!(p.wheel_ball_friction));
                        m.insert("accel_over_mu_g".into(), json!(p.accel_over_mu_g()));
                    }
                    v
                })
                .collect(),
        )
    }

    /// `contact_ripple`: per cruise and wheel the roller-passing frequency, the spectrum's
    /// peak and the amplitude at the roller-passing line (the spectra themselves are drawn,
    /// not stored).
    pub fn ripple_json(&self) -> Value {
        Value::Array(self.ripple.iter().map(ripple_json).collect())
    }

    /// The tables: maximum speed per mechanism and heading for each controller beside the
    /// paper's, the sweep, and the ripple peaks.
    pub fn table(&self) -> String {
        let s = &self.settings.protocol.slow_ramp;
        let mut out = format!(
            "What limits the slow ramp ({} m/s^2 to {} m/s, seed {}): max speed (m/s) and what \
             ended the run\n",
            s.accel_m_per_s2, s.max_command_m_per_s, self.settings.seed
        );
        let headings = &self.settings.headings_deg;
        out.push_str(&format!("{:>22} | {:>24}", "controller", "world"));
        for h in headings {
            out.push_str(&format!(" | {:>26}", format!("{h:.0} deg")));
        }
        out.push('\n');
        for &c in &self.settings.controllers {
            for &m in &self.settings.mechanisms {
                out.push_str(&format!("{:>22} | {:>24}", c.as_str(), m.as_str()));
                for &h in headings {
                    let cell = self
                        .run(c, m, h)
                        .map_or("-".into(), |r| outcome_cell(&r.outcome));
                    out.push_str(&format!(" | {cell:>26}"));
                }
                out.push('\n');
            }
        }
        out.push_str(&format!(
            "{:>22} | {:>24}",
            "MiaPURE hardware", "the paper's Fig. acc"
        ));
        for &h in headings {
            let cell = PAPER_MAX_SPEED
                .iter()
                .find(|p| (p.heading_deg - h).abs() < 1e-9)
                .map_or("-".to_owned(), |p| {
                    format!(
                        "{}{}",
                        if p.upper_bound { "< " } else { "" },
                        p.speed_m_per_s
                    )
                });
            out.push_str(&format!(" | {cell:>26}"));
        }
        out.push('\n');
        if !self.sweep.is_empty() {
            out.push_str("ramp-acceleration sweep, default world, corrected controller:\n");
            out.push_str(&format!(
                "{:>8} | {:>5} | {:>8} | {:>8} | {}\n",
                "heading", "mu", "a m/s^2", "a/(mu g)", "max speed and end"
            ));
            for p in &self.sweep {
                out.push_str(&format!(
                    "{:>8} | {:>5} | {:>8} | {:>8.3} | {}\n",
                    format!("{:.0} deg", p.outcome.heading_deg),
                    p.wheel_ball_friction,
                    p.outcome.accel_m_per_s2,
                    p.accel_over_mu_g(),
                    outcome_cell(&p.outcome)
                ));
            }
        }
        if !self.ripple.is_empty() {
            out.push_str(
                "contact-load ripple, default world (per wheel: roller passing Hz / spectrum peak \
                 Hz / amplitude there N):\n",
            );
            for r in &self.ripple {
                out.push_str(&format!(
                    "  {:.0} deg {:.2} m/s:",
                    r.heading_deg, r.speed_m_per_s
                ));
                if let Some(f) = r.failure {
                    out.push_str(&format!(" failed: {f}\n"));
                    continue;
                }
                for (i, w) in r.wheels.iter().enumerate() {
                    out.push_str(&format!(
                        " {} {} / {:.0} / {:.1}{}",
                        wheel_name(i),
                        w.roller_passing_hz
                            .map_or("-".into(), |f| format!("{f:.1}")),
                        w.peak_hz,
                        w.peak_amplitude_n,
                        if i < 2 { ";" } else { "" }
                    ));
                }
                out.push('\n');
            }
        }
        out
    }
}

fn ripple_json(r: &RippleSpectrum) -> Value {
    json!({
        "heading_deg": r.heading_deg,
        "speed_m_per_s": r.speed_m_per_s,
        "roller_count": r.roller_count,
        "failure": r.failure.map_or(Value::Null, |f| serde_json::to_value(f).unwrap_or(Value::Null)),
        "wheels": r.wheels.iter().enumerate().map(|(i, w)| json!({
            "wheel": wheel_name(i),
            "mean_speed_rad_per_s": w.mean_speed_rad_per_s,
            "mean_normal_force_n": w.mean_normal_force_n,
            "roller_passing_hz": w.roller_passing_hz,
            "peak_hz": w.peak_hz,
            "peak_amplitude_n": w.peak_amplitude_n,
            "amplitude_at_roller_passing_n": w.amplitude_at_roller_passing_n,
        })).collect::<Vec<_>>(),
    })
}
