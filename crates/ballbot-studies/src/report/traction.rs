//! The traction study ([`crate::studies::traction`]) as the summary's JSON (`traction_aware`)
//! and as comparison tables.

use crate::studies::traction::{HeadingResult, RunRecord, TractionStudy};
use ballbot_world::world::Failure;
use serde_json::{Map, Value, json};

fn failure_json(failure: Option<Failure>) -> Value {
    failure.map_or(Value::Null, |f| {
        serde_json::to_value(f).unwrap_or(Value::Null)
    })
}

fn failure_cell(failure: Option<Failure>) -> String {
    failure.map_or_else(|| "-".to_owned(), |f| f.to_string())
}

fn optional(value: Option<f64>, digits: usize) -> String {
    value.map_or("-".to_owned(), |v| format!("{v:.digits$}"))
}

/// One run's JSON record: failure, accelerations, slip detection, limiting.
fn run_json(r: &RunRecord) -> Value {
    let record = json!({
        "failed": r.failure.is_some(),
        "failure": failure_json(r.failure),
        "max_accel_m_per_s2": r.max_accel_m_per_s2,
        "max_decel_m_per_s2": r.max_decel_m_per_s2,
        "reached_1_4_m_per_s_secs": r.reached_1_4_secs,
        "mean_accel_0_2_to_1_4_m_per_s2": r.mean_accel_m_per_s2(),
        "first_world_slip_secs": r.first_world_slip_secs,
        "first_detection_secs": r.first_detection_secs,
        "slip_events": r.slip_events,
        "limited_steps": r.limited_steps,
        "min_friction_estimate": r.min_friction_estimate,
        "supervisor_stop_secs": r.supervisor_stop_secs,
        "peak_cone_utilisation": r.peak_cone_utilisation,
        "max_floor_slip_m_per_s": r.max_floor_slip_m_per_s,
        "max_tilt_deg": r.max_tilt_rad.to_degrees(),
    });
    super::world_suite::with_happened(record, Some(&r.happened))
}

/// The ramps start after 0.5 s at rest.
const RAMP_START_SECS: f64 = 0.5;

impl HeadingResult {
    /// Whether any ramp with traction control on failed at this heading.
    pub fn failed_on(&self) -> bool {
        self.on_top.failure.is_some()
            || self.on_top_other_seeds.iter().any(|r| r.failure.is_some())
            || self
                .on_at_off_failing
                .as_ref()
                .is_some_and(|r| r.failure.is_some())
    }

    /// Time from the ramp's start to 1.4 m/s with traction control on (s).
    pub fn time_to_1_4_on_secs(&self) -> Option<f64> {
        self.on_top.reached_1_4_secs.map(|t| t - RAMP_START_SECS)
    }

    fn to_json(&self) -> Value {
        let off = &self.off;
        json!({
            "heading_deg": self.heading_deg,
            "failing_accel_off_m_per_s2": off.largest_surviving_m_per_s2,
            "off_smallest_failing_m_per_s2": off.smallest_failing_m_per_s2,
            "off_censored": off.smallest_failing_m_per_s2.is_none(),
            "off_failure": failure_json(off.failing.as_ref().and_then(|f| f.failure)),
            "max_accel_on_m_per_s2": self.on_top.max_accel_m_per_s2,
            "mean_accel_on_m_per_s2": self.on_top.mean_accel_m_per_s2(),
            "envelope_accel_m_per_s2": self.envelope_m_per_s2,
            "quasi_static_accel_m_per_s2": self.quasi_static_m_per_s2,
            "time_to_1_4_m_per_s_on_secs": self.time_to_1_4_on_secs(),
            "failed_on": self.failed_on(),
            "on": run_json(&self.on_top),
            "on_at_off_failing": self.on_at_off_failing.as_ref().map(run_json),
            "on_other_seeds": self.on_top_other_seeds.iter().map(run_json).collect::<Vec<_>>(),
        })
    }
}

impl TractionStudy {
    /// `traction_aware` of the summary: `by_heading` (one record per heading: the failing
    /// acceleration off, the largest acceleration reached on, the envelope, time to 1.4 m/s,
    /// `failed_on`), `braking_s` (heading -> seconds from 1.4 m/s to rest, traction control
    /// on), `slip_detection_latency_ms` (the wet patch, on), and every run's record.
    pub fn summary_json(&self) -> Value {
        let s = &self.settings;
        let mut braking = Map::new();
        for st in self.stops.iter().filter(|st| st.control.as_str() == "on") {
            braking.insert(format!("{:.0}", st.heading_deg), json!(st.stop_secs));
        }
        let latency = self
            .patches
            .iter()
            .find(|p| p.variant.as_str() == "wet_mu_0.3" && p.control.as_str() == "on")
            .and_then(|p| p.detection_latency_ms());
        json!({
            "protocol": {
                "world": "default (realistic)",
                "robot": "MiaPURE 60 kg",
                "sensor_seed": s.seed,
                "extra_on_seeds": s.extra_on_seeds,
                "ramp_top_m_per_s": s.protocol.fast_top_m_per_s,
                "search_m_per_s2": s.protocol.accel_bracket_m_per_s2,
                "search_resolution_m_per_s2": s.protocol.accel_resolution_m_per_s2,
                "on_request_m_per_s2": s.protocol.accel_bracket_m_per_s2[1],
                "shaper_caps": {
                    "max_speed_m_per_s": s.protocol.shaper.max_speed_m_per_s,
                    "max_accel_m_per_s2": s.protocol.shaper.max_accel_m_per_s2,
                },
                "max_accel_definition": "largest 0.1 s mean of the ball's acceleration along the heading",
                "mean_accel_definition": "the ball's mean acceleration from 0.2 to 1.4 m/s along the heading",
            },
            "by_heading": self.headings.iter().map(HeadingResult::to_json).collect::<Vec<_>>(),
            "braking_s": Value::Object(braking),
            "stops": self.stops.iter().map(|st| {
                let mut v = run_json(&st.record);
                v["heading_deg"] = json!(st.heading_deg);
                v["control"] = json!(st.control.as_str());
                v["stop_secs"] = json!(st.stop_secs);
                v
            }).collect::<Vec<_>>(),
            "slip_detection_latency_ms": latency,
            "patches": self.patches.iter().map(|p| {
                let mut v = run_json(&p.record);
                v["patch"] = json!(p.variant.as_str());
                v["control"] = json!(p.control.as_str());
                v["entered_patch_secs"] = json!(p.on_patch.map(|c| c.entered_secs));
                v["left_patch_secs"] = json!(p.on_patch.and_then(|c| c.left_secs));
                v["detection_latency_ms"] = json!(p.detection_latency_ms());
                v["stayed_up"] = json!(p.stayed_up(self.fall_tilt_rad()));
                v
            }).collect::<Vec<_>>(),
            "rider": {
                "lean_rad": s.rider_lean_rad,
                "max_speed_m_per_s": s.rider.max_speed_m_per_s,
                "max_accel_m_per_s2": s.rider.max_accel_m_per_s2,
                "runs": self.riders.iter().map(|r| {
                    let mut v = run_json(&r.record);
                    v["heading_deg"] = json!(r.heading_deg);
                    v["control"] = json!(r.control.as_str());
                    v
                }).collect::<Vec<_>>(),
            },
        })
    }

    /// The comparison tables (per heading; stops; patches; rider).
    pub fn table(&self) -> String {
        let mut out = format!(
            "Traction-aware control, default world, MiaPURE 60 kg (seed {}; on also seeds {:?}): \
             failing ramp acceleration off against the acceleration reached on (request {} m/s^2 \
             to {} m/s)\n",
            self.settings.seed,
            self.settings.extra_on_seeds,
            self.settings.protocol.accel_bracket_m_per_s2[1],
            self.settings.protocol.fast_top_m_per_s
        );
        out.push_str(&format!(
            "{:>8} | {:>14} | {:>30} | {:>9} | {:>15} | {:>15} | {:>14} | {:>10}\n",
            "heading",
            "off: survives",
            "off: fails",
            "envelope",
            "on: mean 0.2-1.4",
            "on: peak 0.1 s",
            "on: to 1.4 m/s",
            "on: failed"
        ));
        for h in &self.headings {
            let fails = match h.off.smallest_failing_m_per_s2 {
                Some(a) => format!(
                    "{a:.2}: {}",
                    failure_cell(h.off.failing.as_ref().and_then(|f| f.failure))
                ),
                None => "none in the search".to_owned(),
            };
            out.push_str(&format!(
                "{:>8} | {:>14} | {:>30} | {:>9.2} | {:>15} | {:>15.2} | {:>14} | {:>10}\n",
                format!("{:.0} deg", h.heading_deg),
                optional(h.off.largest_surviving_m_per_s2, 2),
                fails,
                h.envelope_m_per_s2,
                optional(h.on_top.mean_accel_m_per_s2(), 2),
                h.on_top.max_accel_m_per_s2,
                optional(h.time_to_1_4_on_secs(), 2),
                if h.failed_on() { "FAILED" } else { "no" },
            ));
        }
        out.push_str("\nStop from 1.4 m/s (command 0): time to below 0.05 m/s\n");
        for st in &self.stops {
            out.push_str(&format!(
                "  {:>3.0} deg {:>8}: {:>6} s, peak decel {:.2} m/s^2, {}\n",
                st.heading_deg,
                st.control.as_str(),
                optional(st.stop_secs, 2),
                st.record.max_decel_m_per_s2,
                failure_cell(st.record.failure)
            ));
        }
        out.push_str("\nFriction patch, 0.5 m at 1.4 m/s towards OW1\n");
        for p in &self.patches {
            let r = &p.record;
            out.push_str(&format!(
                "  {:>12} {:>4}: world slip at {} s, flagged at {} s (latency {} ms), slip events {}, \
                 friction estimate >= {}, stop {}, {}, max tilt {:.1} deg, {}\n",
                p.variant.as_str(),
                p.control.as_str(),
                optional(r.first_world_slip_secs, 3),
                optional(r.first_detection_secs, 3),
                optional(p.detection_latency_ms(), 1),
                r.slip_events,
                optional(r.min_friction_estimate, 2),
                optional(r.supervisor_stop_secs, 2),
                failure_cell(r.failure),
                r.max_tilt_rad.to_degrees(),
                if p.stayed_up(self.fall_tilt_rad()) {
                    "stayed up"
                } else {
                    "FELL"
                }
            ));
        }
        out.push_str("\nRider leaning 0.3 rad (lean-to-drive, 2 m/s, 2 m/s^2)\n");
        for r in &self.riders {
            let rec = &r.record;
            out.push_str(&format!(
                "  towards {:>3.0} deg {:>4}: peak accel {:.2} m/s^2, 1.4 m/s at {} s, limited {} steps, {}\n",
                r.heading_deg,
                r.control.as_str(),
                rec.max_accel_m_per_s2,
                optional(rec.reached_1_4_secs.map(|t| t - RAMP_START_SECS), 2),
                rec.limited_steps,
                failure_cell(rec.failure)
            ));
        }
        out
    }
}
