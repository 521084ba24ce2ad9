//! The PIPTB controller comparison ([`crate::studies::piptb`]) as the summary's JSON (`piptb`,
//! `piptb_until_stopped`, `piptb_stop_sensitivity`, `piptb_ablation`) and as comparison
//! tables.

use crate::studies::piptb::{AblationVariant, PiptbReport};

/// Stop bands of the stop criterion's sensitivity (m/s): the default 0.05 and 40 % tighter
/// and 60 % looser, enough to move a trial that ends 4 mm/s outside 0.05 m/s across it.
pub const SENSITIVITY_BANDS_M_PER_S: [f64; 3] = [0.03, 0.05, 0.08];

/// Stop holds of the sensitivity (s): none (the first tick in the band), half, once and
/// twice the default 0.2 s.
pub const SENSITIVITY_HOLDS_SECS: [f64; 4] = [0.0, 0.1, 0.2, 0.4];

impl PiptbReport {
    /// The summary's `piptb` value: `{"lqr": {...}, "pi_pd": {...}, "lqr_pi": {...},
    /// "reference": {...}}`, each controller with `trials` (`j_p` N^2 m^2 s, `stopped`,
    /// `speed_rmse` m/s, `t3_secs`, ...) and the mean `j_p`. The until-stopped reading
    /// (`piptb_until_stopped`) has the same shape, its `settings` also with `stop_hold_secs`.
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
        if let (Some(stop), Some(serde_json::Value::Object(settings))) =
            (self.stop, map.get_mut("settings"))
        {
            settings.insert(
                "stop_speed_m_per_s".to_owned(),
                stop.speed_band_m_per_s.into(),
            );
            settings.insert("stop_hold_secs".to_owned(), stop.hold_secs.into());
        }
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

/// The two readings of `t3` side by side (fixed window and until stopped, same trials): mean
/// `J_P`, mean braking-phase length `t3 - t2`, trials stopped, and which ranking each gives.
pub fn readings_table(fixed: &PiptbReport, until: &PiptbReport) -> String {
    let t2 = fixed.settings.brake_start_secs();
    let stop = until
        .stop
        .unwrap_or_else(|| fixed.settings.stop_criterion());
    let mut out = format!(
        "PIPTB J_P by reading of t3: fixed t2 + {:.1} s | until stopped (|v| <= {} m/s held {} s, \
         cap = end of run)\n\
         controller | J_P fixed (N^2 m^2 s) | stopped | J_P until stopped | t3 - t2 (s) | stopped before cap\n\
         -----------|-----------------------|---------|-------------------|-------------|-------------------\n",
        fixed.settings.brake_secs, stop.speed_band_m_per_s, stop.hold_secs
    );
    for (f, u) in fixed.controllers.iter().zip(&until.controllers) {
        let n = u.trials.len().max(1) as f64;
        let span = u.trials.iter().map(|t| t.t3_secs - t2).sum::<f64>() / n;
        let count = |c: &crate::studies::piptb::ControllerResult| {
            format!(
                "{}/{}",
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len()
            )
        };
        out.push_str(&format!(
            "{:<10} | {:>8.3} +- {:<10.3} | {:>7} | {:>7.3} +- {:<6.3} | {:>11.3} | {:>18}\n",
            f.kind.label(),
            f.j_p,
            f.j_p_std,
            count(f),
            u.j_p,
            u.j_p_std,
            span,
            count(u),
        ));
    }
    let verdict = |r: &PiptbReport| match r.matches_paper_order() {
        Some(true) => "matches the paper (LQR-PI lowest, PI-PD highest)",
        Some(false) => "differs from the paper (LQR-PI lowest, PI-PD highest)",
        None => "not comparable (needs LQR-PI and PI-PD)",
    };
    out.push_str(&format!(
        "order (lowest J_P first): fixed {:?}: {}; until stopped {:?}: {}\n",
        fixed.j_p_order(),
        verdict(fixed),
        until.j_p_order(),
        verdict(until)
    ));
    out
}

/// The summary's `piptb_stop_sensitivity`: one record per (band, hold) of the until-stopped
/// reading, with the mean `j_p` (N^2 m^2 s), trials stopped before the cap, mean `t3 - t2`
/// (s) per controller, the order and whether it matches the paper's.
pub fn stop_sensitivity_json(readings: &[PiptbReport]) -> serde_json::Value {
    let rows = readings
        .iter()
        .filter_map(|r| {
            let stop = r.stop?;
            let t2 = r.settings.brake_start_secs();
            let mut per = serde_json::Map::new();
            for c in &r.controllers {
                let n = c.trials.len().max(1) as f64;
                per.insert(
                    c.kind.key().to_owned(),
                    serde_json::json!({
                        "j_p": c.j_p,
                        "j_p_std": c.j_p_std,
                        "stopped": c.trials.iter().filter(|t| t.stopped).count(),
                        "trials": c.trials.len(),
                        "mean_brake_secs": c.trials.iter().map(|t| t.t3_secs - t2).sum::<f64>() / n,
                    }),
                );
            }
            Some(serde_json::json!({
                "stop_speed_m_per_s": stop.speed_band_m_per_s,
                "stop_hold_secs": stop.hold_secs,
                "order": r.j_p_order(),
                "matches_paper_order": r.matches_paper_order(),
                "controllers": per,
            }))
        })
        .collect();
    serde_json::Value::Array(rows)
}

/// The sensitivity as a plain-text table: per (band, hold), mean `J_P` and trials stopped per
/// controller, and whether the order matches the paper's.
pub fn stop_sensitivity_table(readings: &[PiptbReport]) -> String {
    let mut out = String::from(
        "PIPTB until-stopped J_P (N^2 m^2 s) and trials stopped before the cap, by stop criterion\n\
         band (m/s) | hold (s) | LQR          | PI-PD        | LQR-PI       | paper order\n\
         -----------|----------|--------------|--------------|--------------|------------\n",
    );
    for r in readings {
        let Some(stop) = r.stop else { continue };
        out.push_str(&format!(
            "{:>10.3} | {:>8.2}",
            stop.speed_band_m_per_s, stop.hold_secs
        ));
        for c in &r.controllers {
            let cell = format!(
                "{:.3} {}/{}",
                c.j_p,
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len()
            );
            out.push_str(&format!(" | {cell:<12}"));
        }
        let m = match r.matches_paper_order() {
            Some(true) => "yes",
            Some(false) => "no",
            None => "-",
        };
        out.push_str(&format!(" | {m}\n"));
    }
    out
}
