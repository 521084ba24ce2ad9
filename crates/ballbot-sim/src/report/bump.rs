//! The bump study ([`crate::studies::bump`]) as the summary's `bump_tolerance` and as a table:
//! the report function of a [`Study`]. It renders; it runs
//! nothing.

use crate::studies::bump::{BumpJob, BumpStudy, BumpTrial};
use crate::studies::driver::{JobRecord, Study};
use serde_json::{Value, json};
use std::fmt::Write;

/// `crossed` (past the bar and following the command again), `failed_after_crossing` (past
/// the bar, then a fall or a stop) or `not_crossed`.
fn verdict(t: &BumpTrial) -> &'static str {
    match (t.passed(), t.crossed) {
        (true, _) => "crossed",
        (false, true) => "failed_after_crossing",
        (false, false) => "not_crossed",
    }
}

fn trial_json(t: &BumpTrial) -> Value {
    let record = json!({
        "height_mm": t.height_m * 1e3,
        "verdict": verdict(t),
        "crossed": t.crossed,
        "peak_tilt_deg": t.peak_tilt_deg,
        "peak_ball_rise_m_per_s": t.peak_ball_rise_m_per_s,
        "peak_ball_lift_mm": t.peak_ball_lift_m * 1e3,
    });
    super::world_suite::with_happened(record, Some(&t.happened))
}

fn cell_json(job: &BumpJob, r: &JobRecord<BumpTrial>) -> Value {
    let bracket = r.bracket;
    json!({
        "speed_m_per_s": job.speed_m_per_s,
        "heading_deg": job.heading_deg,
        "traction_control": job.traction_control,
        "largest_crossed_mm": bracket.and_then(|b| b.passed).map(|h| h * 1e3),
        "smallest_not_crossed_mm": bracket.and_then(|b| b.failed).map(|h| h * 1e3),
        "trials": r.trials.iter().map(|(_, t)| trial_json(t)).collect::<Vec<_>>(),
    })
}

/// `bump_tolerance`: the protocol and, per speed, heading and traction-control setting, the
/// largest bar crossed (mm; 0 when none of the tried heights was), the smallest not crossed
/// (`null` when the search's top was crossed) and every trial with what happened.
pub fn summary_json(study: &BumpStudy, records: &[JobRecord<BumpTrial>]) -> Value {
    let jobs = study.jobs();
    let cells: Vec<Value> = records
        .iter()
        .filter_map(|r| jobs.get(r.index).map(|job| cell_json(job, r)))
        .collect();
    json!({
        "protocol": study.settings,
        "stop_rules": crate::world::StopRules::contact_rules_off().to_string(),
        "floor_contact": "the ball coating's compliant contact (world::floor), the default world",
        "cells": cells,
    })
}

/// The table `ballbot reproduce` prints: one row per speed, heading and traction-control
/// setting, the largest bar crossed, and how the trial at the lowest failing bar ended.
pub fn table(study: &BumpStudy, records: &[JobRecord<BumpTrial>]) -> String {
    let s = &study.settings;
    let jobs = study.jobs();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "bump tolerance (MiaPURE 60 kg, paper controller, a {:.0} mm wide arc across the path, \
         heights to {:.2} mm; crossed = past the bar and following the command again; seed {}):",
        s.width_m * 1e3,
        s.height_search.resolution * 1e3,
        s.seed
    );
    let _ = writeln!(
        out,
        "  {:>7} | {:>7} | {:>8} | {:>16} | what the lowest failing bar did",
        "speed", "heading", "traction", "largest crossed"
    );
    for r in records {
        let Some(job) = jobs.get(r.index) else {
            continue;
        };
        let crossed = r.bracket.map_or_else(
            || "-".to_owned(),
            |b| match (b.passed, b.failed) {
                (Some(h), Some(_)) => format!("{:.2} mm", h * 1e3),
                (Some(h), None) => format!(">= {:.2} mm", h * 1e3),
                (None, _) => "-".to_owned(),
            },
        );
        let failing = r
            .bracket
            .and_then(|b| b.failed)
            .and_then(|h| r.trial_at(h))
            .map_or_else(
                || "-".to_owned(),
                |t| {
                    format!(
                        "{:.2} mm: {}{}, peak tilt {:.1} deg",
                        t.height_m * 1e3,
                        t.happened.outcome.as_str(),
                        if t.crossed { "" } else { ", not past the bar" },
                        t.peak_tilt_deg
                    )
                },
            );
        let _ = writeln!(
            out,
            "  {:>3.1} m/s | {:>6.0}° | {:>8} | {:>16} | {}",
            job.speed_m_per_s,
            job.heading_deg,
            if job.traction_control { "on" } else { "off" },
            crossed,
            failing
        );
    }
    out
}
