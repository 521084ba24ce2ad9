//! The PIPTB controller comparison ([`crate::studies::piptb`]) as the summary's JSON (`piptb`,
//! `piptb_ablation`) and as comparison tables.

use crate::studies::piptb::{AblationVariant, PiptbReport};

impl PiptbReport {
    /// The summary's `piptb` value: `{"lqr": {...}, "pi_pd": {...}, "lqr_pi": {...},
    /// "reference": {...}}`, each controller with `trials` (`j_p` N^2 m^2 s, `stopped`,
    /// `speed_rmse` m/s, ...) and the mean `j_p`.
    pub fn summary_json(&self) -> serde_json::Value {
        let mut map = serde_json::Map::new();
        for c in &self.controllers {
            map.insert(
                c.kind.key().to_owned(),
                serde_json::to_value(c).unwrap_or(serde_json::Value::Null),
            );
        }
        map.insert(
            "reference".to_owned(),
            serde_json::to_value(&self.reference).unwrap_or(serde_json::Value::Null),
        );
        let s = &self.settings;
        map.insert(
            "settings".to_owned(),
            serde_json::json!({
                "trials": s.trials,
                "base_seed": s.base_seed,
                "cruise_speed_m_per_s": s.cruise_speed_m_per_s,
                "accel_secs": s.accel_secs,
                "hold_secs": s.hold_secs,
                "brake_secs": s.brake_secs,
                "stop_speed_m_per_s": s.stop_speed_m_per_s,
                "friction": s.friction,
                "sensors": s.sensors,
                "sim": s.sim,
            }),
        );
        serde_json::Value::Object(map)
    }

    /// A plain-text comparison table, ours beside the paper's.
    pub fn table(&self) -> String {
        let mut out = String::new();
        out.push_str(&format!(
            "PIPTB braking, 1 m/s to rest in {:.1} s ({} trial(s) per controller; reference: {:?}, \
             its own effort {:.3} N^2 m^2 s)\n",
            self.settings.brake_secs,
            self.settings.trials,
            self.reference.source,
            self.reference.effort_n2m2s
        ));
        out.push_str(
            "controller |  J_P (N^2 m^2 s)  | J_P (N^2 mm^2 s) | paper J_P (N^2 mm^2 s) | stopped | paper | speed RMSE (m/s) | jitter (N m)\n",
        );
        out.push_str(
            "-----------|-------------------|------------------|------------------------|---------|-------|------------------|-------------\n",
        );
        for c in &self.controllers {
            let paper = c
                .paper_j_p_n2mm2s
                .map_or("(not given)".to_owned(), |(m, s)| {
                    format!("{m:.2e} +- {s:.1e}")
                });
            let stopped = format!(
                "{}/{}",
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len()
            );
            let paper_stopped = match c.paper_stopped {
                Some(true) => "yes",
                Some(false) => "no",
                None => "-",
            };
            out.push_str(&format!(
                "{:<10} | {:>7.3} +- {:<6.3} | {:>16.3e} | {:>22} | {:>7} | {:>5} | {:>16.4} | {:>11.4}\n",
                c.kind.label(),
                c.j_p,
                c.j_p_std,
                c.j_p_n2mm2s,
                paper,
                stopped,
                paper_stopped,
                c.speed_rmse,
                c.torque_jitter_nm,
            ));
        }
        out
    }
}

/// The ablation as the summary's `piptb_ablation` value: per variant, per controller, the mean
/// `j_p`, the number of trials that stopped, and the mean torque jitter.
pub fn ablation_json(variants: &[AblationVariant]) -> serde_json::Value {
    let mut map = serde_json::Map::new();
    for v in variants {
        let mut per = serde_json::Map::new();
        for c in &v.report.controllers {
            per.insert(
                c.kind.key().to_owned(),
                serde_json::json!({
                    "j_p": c.j_p,
                    "stopped": c.trials.iter().filter(|t| t.stopped).count(),
                    "trials": c.trials.len(),
                    "torque_jitter_nm": c.torque_jitter_nm,
                    "speed_rmse": c.speed_rmse,
                }),
            );
        }
        map.insert(v.name.to_owned(), serde_json::Value::Object(per));
    }
    serde_json::Value::Object(map)
}

/// The ablation as a plain-text table: mean `J_P` (N^2 m^2 s) / stopped / jitter (N m).
pub fn ablation_table(variants: &[AblationVariant]) -> String {
    let mut out = String::from(
        "PIPTB ablation: mean J_P (N^2 m^2 s), trials stopped, torque jitter (N m)\n\
         variant            | LQR                   | PI-PD                 | LQR-PI\n\
         -------------------|-----------------------|-----------------------|----------------------\n",
    );
    for v in variants {
        out.push_str(&format!("{:<18}", v.name));
        for c in &v.report.controllers {
            let cell = format!(
                "{:.3} {}/{} {:.3}",
                c.j_p,
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len(),
                c.torque_jitter_nm
            );
            out.push_str(&format!(" | {cell:<21}"));
        }
        out.push('\n');
    }
    out
}
