//! The maximum-speed study ([`crate::studies::max_speed`]) as the summary's JSON
//! (`max_speed_by_heading`, `max_speed_study`) and as a comparison table.

use crate::studies::max_speed::{
    FailingAccel, MaxSpeedStudy, PAPER_MAX_SPEED, TrialOutcome, quasi_static_failing_accel_m_per_s2,
};
use ballbot_world::world::Failure;
use serde_json::{Value, json};

fn same(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// The failure's canonical JSON (`Failure`'s `Serialize`); `null` for none.
fn failure_json(failure: Option<Failure>) -> Value {
    failure.map_or(Value::Null, |f| {
        serde_json::to_value(f).unwrap_or(Value::Null)
    })
}

/// A failure as text ([`Failure`]'s `Display`, e.g. `slip OW3 at 13.090 s`); `-` for none.
fn failure_text(failure: Option<Failure>) -> String {
    failure.map_or_else(|| "-".to_owned(), |f| f.to_string())
}

impl TrialOutcome {
    /// The JSON record of a trial (summary `max_speed_study.trials[].trials[]`).
    pub fn to_json(&self) -> Value {
        let record = json!({
            "heading_deg": self.heading_deg,
            "seed": self.seed,
            "accel_m_per_s2": self.accel_m_per_s2,
            "max_speed_m_per_s": self.max_speed_m_per_s,
            "censored": self.censored(),
            "failure": failure_json(self.failure),
            "supervisor_stop_secs": self.supervisor_stop_secs,
            "peak_cone_utilisation": self.peak_cone_utilisation,
            "min_normal_force_n": self.min_normal_force_n,
            "peak_tilt_deg": self.peak_tilt_rad.to_degrees(),
        });
        super::world_suite::with_happened(record, Some(&self.happened))
    }
}

impl FailingAccel {
    /// The JSON record of a search (summary `max_speed_study.failing_accel_by_heading`);
    /// `top_m_per_s` is the searched ramps' top speed.
    pub fn to_json(&self, top_m_per_s: f64) -> Value {
        json!({
            "heading_deg": self.heading_deg,
            "failed_during_ramp": self.failed_during_ramp(top_m_per_s),
            "largest_surviving_m_per_s2": self.largest_surviving_m_per_s2,
            "smallest_failing_m_per_s2": self.smallest_failing_m_per_s2,
            "censored": self.smallest_failing_m_per_s2.is_none(),
            "failure": failure_json(self.failing.as_ref().and_then(|f| f.failure)),
            "speed_at_failure_m_per_s": self.failing.as_ref().map(|f| f.max_speed_m_per_s),
            "surviving_peak_cone_utilisation": self.surviving.as_ref().map(|s| s.peak_cone_utilisation),
            "runs": self.runs,
        })
    }
}

/// `{:.2}` of a value, `-` for none.
fn optional(value: Option<f64>) -> String {
    value.map_or("-".to_owned(), |v| format!("{v:.2}"))
}

/// `{:.0}` of a heading, as the summary's object key.
fn heading_key(heading_deg: f64) -> String {
    format!("{heading_deg:.0}")
}

impl MaxSpeedStudy {
    /// `max_speed_by_heading`: heading (deg, as text) to the mean slow-ramp maximum speed
    /// (m/s) over the seeded trials.
    pub fn max_speed_by_heading_json(&self) -> Value {
        let mut m = serde_json::Map::new();
        for h in &self.trials {
            m.insert(
                heading_key(h.heading_deg),
                json!(h.mean_max_speed_m_per_s()),
            );
        }
        Value::Object(m)
    }

    /// The detailed record (summary key `max_speed_study`): protocol, mu and COM height, the
    /// trials with failures and censoring, the failing acceleration by heading, the map, the
    /// sensitivity and the paper's values.
    pub fn detail_json(&self) -> Value {
        let p = &self.settings.protocol;
        let s = &p.slow_ramp;
        let robot = &self.params.robot;
        let trials: Vec<Value> = self
            .trials
            .iter()
            .map(|h| {
                json!({
                    "heading_deg": h.heading_deg,
                    "mean_max_speed_m_per_s": h.mean_max_speed_m_per_s(),
                    "std_max_speed_m_per_s": h.std_max_speed_m_per_s(),
                    "censored_trials": h.censored_count(),
                    "mean_is_lower_bound": h.censored_count() > 0,
                    "trials": h.trials.iter().map(|t| t.to_json()).collect::<Vec<_>>(),
                })
            })
            .collect();
        let mut failing = serde_json::Map::new();
        for h in &self.trials {
            if let Some(f) = self.failing_at(h.heading_deg) {
                failing.insert(heading_key(h.heading_deg), f.to_json(p.fast_top_m_per_s));
            }
        }
        let map: Vec<Value> = self
            .map
            .iter()
            .map(|m| {
                json!({
                    "heading_deg": m.heading_deg,
                    "quasi_static_failing_accel_m_per_s2":
                        quasi_static_failing_accel_m_per_s2(robot, m.heading_deg),
                    "slow_ramp": m.slow.to_json(),
                    "failing_accel": m.failing.to_json(p.fast_top_m_per_s),
                })
            })
            .collect();
        let sensitivity: Vec<Value> = self
            .sensitivity
            .iter()
            .map(|r| {
                json!({
                    "parameter": r.parameter,
                    "value": r.value,
                    "heading_deg": r.heading_deg,
                    "quasi_static_failing_accel_m_per_s2": quasi_static_failing_accel_m_per_s2(
                        &r.variant.apply(self.params).robot,
                        r.heading_deg,
                    ),
                    "slow_ramp": r.slow.to_json(),
                    "failing_accel": r.failing.to_json(p.fast_top_m_per_s),
                })
            })
            .collect();
        json!({
            "protocol": {
                "slow_ramp": {
                    "accel_m_per_s2": s.accel_m_per_s2,
                    "top_m_per_s": s.max_command_m_per_s,
                    "settle_secs": s.settle_secs,
                    "hold_secs": 1.0,
                },
                "failing_accel_search": {
                    "top_m_per_s": p.fast_top_m_per_s,
                    "hold_secs": 1.0,
                    "bracket_m_per_s2": p.accel_bracket_m_per_s2,
                    "resolution_m_per_s2": p.accel_resolution_m_per_s2,
                    "sensor_seed": 0,
                    "command_accel_ceiling_m_per_s2": self.command_accel_ceiling_m_per_s2(),
                },
                "shaper": {
                    "max_speed_m_per_s": p.shaper.max_speed_m_per_s,
                    "max_accel_m_per_s2": p.shaper.max_accel_m_per_s2,
                    "max_jerk_m_per_s3": self.jerk_limit_m_per_s3,
                    "max_tilt_command_rad": p.shaper.max_tilt_command_rad,
                    "max_tilt_rate_command_rad_per_s": p.shaper.max_tilt_rate_command_rad_per_s,
                },
                "seeds": self.settings.seeds,
                "seed_drives": "sensor noise (IMU tilt and gyro)",
            },
            "wheel_ball_friction": robot.drivetrain.wheel_ball_friction,
            "com_height_m": robot.sagittal.com_height_m,
            "trials": trials,
            "failing_accel_by_heading": Value::Object(failing),
            "map": map,
            "sensitivity": sensitivity,
            "paper": PAPER_MAX_SPEED.iter().map(|p| json!({
                "heading_deg": p.heading_deg,
                "max_speed_m_per_s": p.speed_m_per_s,
                "upper_bound": p.upper_bound,
            })).collect::<Vec<_>>(),
        })
    }

    /// The comparison table: per heading, our trials and mean beside the paper's value, and
    /// the failing acceleration.
    pub fn table(&self) -> String {
        let mut out = format!(
            "MiaPURE maximum speed per heading (3D world, slow ramp {} m/s^2 to {} m/s, mu {}, l {} m)\n",
            self.settings.protocol.slow_ramp.accel_m_per_s2,
            self.settings.protocol.slow_ramp.max_command_m_per_s,
            self.params.robot.drivetrain.wheel_ball_friction,
            self.params.robot.sagittal.com_height_m,
        );
        let p = &self.settings.protocol;
        out.push_str(&format!(
            "fail accel: largest surviving ramp acceleration to {} m/s on a {} m/s^2 grid in \
             [{}, {}]; the jerk limit {} m/s^3 caps the shaped command at {:.2} m/s^2\n",
            p.fast_top_m_per_s,
            p.accel_resolution_m_per_s2,
            p.accel_bracket_m_per_s2[0],
            p.accel_bracket_m_per_s2[1],
            self.jerk_limit_m_per_s3,
            self.command_accel_ceiling_m_per_s2(),
        ));
        out.push_str(&format!(
            "{:>8} | {:>30} | {:>12} | {:>10} | {:>16} | {:>12} | {}\n",
            "heading",
            "trials max speed (m/s)",
            "mean (m/s)",
            "paper",
            "fail accel m/s^2",
            "quasi-static",
            "failure at the next grid step"
        ));
        for h in &self.trials {
            let speeds: Vec<String> = h.trials.iter().map(TrialOutcome::speed_text).collect();
            let mean = if h.censored_count() > 0 {
                format!(">= {:.2}", h.mean_max_speed_m_per_s())
            } else {
                format!("{:.2}", h.mean_max_speed_m_per_s())
            };
            let paper = PAPER_MAX_SPEED
                .iter()
                .find(|p| same(p.heading_deg, h.heading_deg))
                .map_or("-".to_owned(), |p| {
                    format!(
                        "{}{}",
                        if p.upper_bound { "< " } else { "" },
                        p.speed_m_per_s
                    )
                });
            let f = self.failing_at(h.heading_deg);
            out.push_str(&format!(
                "{:>8} | {:>30} | {:>12} | {:>10} | {:>16} | {:>12} | {}\n",
                format!("{:.0} deg", h.heading_deg),
                speeds.join(", "),
                mean,
                paper,
                f.map_or("-".to_owned(), FailingAccel::text),
                optional(quasi_static_failing_accel_m_per_s2(
                    &self.params.robot,
                    h.heading_deg
                )),
                f.map_or("-".to_owned(), |f| f.failing.as_ref().map_or(
                    "-".to_owned(),
                    |o| format!(
                        "{} ({:.2} m/s, {})",
                        failure_text(o.failure),
                        o.max_speed_m_per_s,
                        match f.failed_during_ramp(p.fast_top_m_per_s) {
                            Some(false) => "at cruise",
                            _ => "accelerating",
                        }
                    )
                )),
            ));
        }
        for h in &self.trials {
            for t in &h.trials {
                if let Some(f) = t.failure {
                    let stop = t.supervisor_stop_secs.map_or(String::new(), |s| {
                        format!(", after the supervisor's controlled stop at {s:.2} s")
                    });
                    out.push_str(&format!(
                        "  {:.0} deg seed {}: {}{stop}\n",
                        h.heading_deg,
                        t.seed,
                        failure_text(Some(f))
                    ));
                }
            }
        }
        if !self.sensitivity.is_empty() {
            out.push_str("sensitivity (first seed):\n");
            out.push_str(&format!(
                "{:>14} | {:>6} | {:>8} | {:>14} | {:>16} | {:>12}\n",
                "parameter",
                "value",
                "heading",
                "max speed m/s",
                "fail accel m/s^2",
                "quasi-static"
            ));
            for r in &self.sensitivity {
                out.push_str(&format!(
                    "{:>14} | {:>6} | {:>8} | {:>14} | {:>16} | {:>12}\n",
                    r.parameter,
                    r.value,
                    format!("{:.0} deg", r.heading_deg),
                    r.slow.speed_text(),
                    r.failing.text(),
                    optional(quasi_static_failing_accel_m_per_s2(
                        &r.variant.apply(self.params).robot,
                        r.heading_deg
                    )),
                ));
            }
        }
        out
    }
}
