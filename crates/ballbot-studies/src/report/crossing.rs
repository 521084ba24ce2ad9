//! The crossing studies ([`crate::studies::crossing`]) as the summary's `bump_tolerance` and
//! `step_tolerance` and as tables: the report function of a [`Study`]. It renders; it runs
//! nothing.

use crate::studies::crossing::{CrossingJob, CrossingStudy, CrossingTrial, Obstacle};
use crate::studies::driver::{JobRecord, Study};
use serde_json::{Value, json};
use std::fmt::Write;

/// `crossed` (past the obstacle and following the command again), `failed_after_crossing`
/// (past it, then a fall or a stop) or `not_crossed`.
fn verdict(t: &CrossingTrial) -> &'static str {
    match (t.passed(), t.crossed) {
        (true, _) => "crossed",
        (false, true) => "failed_after_crossing",
        (false, false) => "not_crossed",
    }
}

fn trial_json(t: &CrossingTrial) -> Value {
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

fn cell_json(job: &CrossingJob, r: &JobRecord<CrossingTrial>) -> Value {
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

/// `bump_tolerance` or `step_tolerance`: the protocol (the obstacle's `width_m` or
/// `edge_radius_m` among its fields) and, per speed, heading and traction-control setting, the
/// largest obstacle crossed (mm; 0 when none of the tried heights was), the smallest not
/// crossed (`null` when the search's top was crossed) and every trial with what happened.
pub fn summary_json(study: &CrossingStudy, records: &[JobRecord<CrossingTrial>]) -> Value {
    let jobs = study.jobs();
    let cells: Vec<Value> = records
        .iter()
        .filter_map(|r| jobs.get(r.index).map(|job| cell_json(job, r)))
        .collect();
    json!({
        "protocol": study.settings,
        "stop_rules": ballbot_world::world::StopRules::contact_rules_off().to_string(),
        "floor_contact": "the ball coating's compliant contact (world::floor), the default world",
        "cells": cells,
    })
}

/// The obstacle in the table's title, and what crossing it is.
fn obstacle_text(obstacle: &Obstacle) -> (String, &'static str) {
    match *obstacle {
        Obstacle::Bump { width_m } => (
            format!("a {:.0} mm wide arc across the path", width_m * 1e3),
            "past the bar",
        ),
        Obstacle::Step { edge_radius_m } => (
            format!(
                "a step up across the path, its edge rounded with {:.0} mm (with its height \
                 when lower)",
                edge_radius_m * 1e3
            ),
            "onto the step",
        ),
    }
}

/// The table `ballbot reproduce` prints: one row per speed, heading and traction-control
/// setting, the largest obstacle crossed, and how the trial at the lowest failing one ended.
pub fn table(study: &CrossingStudy, records: &[JobRecord<CrossingTrial>]) -> String {
    let s = &study.settings;
    let (what, past) = obstacle_text(&s.obstacle);
    let name = s.obstacle.name();
    let jobs = study.jobs();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{name} tolerance (MiaPURE 60 kg, paper controller, {what}, heights to {:.2} mm; \
         crossed = {past} and following the command again; seed {}):",
        s.height_search.resolution * 1e3,
        s.seed
    );
    let _ = writeln!(
        out,
        "  {:>7} | {:>7} | {:>8} | {:>16} | what the lowest failing {name} did",
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
                        if t.crossed {
                            String::new()
                        } else {
                            format!(", not {past}")
                        },
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::crossing::CrossingSettings;

    /// The obstacle is flattened into the protocol: a bump's protocol has the keys it had
    /// before steps joined the study (`bump_tolerance` unchanged), a step's has
    /// `edge_radius_m` in place of `width_m`.
    #[test]
    fn the_protocol_names_the_obstacle_by_its_field() {
        let keys = |obstacle| {
            let study = CrossingStudy {
                settings: CrossingSettings::quick(obstacle),
                world: ballbot_world::world::WorldParams::miapure_60kg(),
            };
            let json = summary_json(&study, &[]);
            let protocol = json["protocol"].as_object().cloned().unwrap_or_default();
            protocol.keys().cloned().collect::<Vec<_>>().join(",")
        };
        // The keys, sorted (serde_json's map).
        assert_eq!(
            keys(Obstacle::BUMP),
            "after_secs,ahead_m,cruise_secs,headings_deg,height_search,ramp_accel_m_per_s2,seed,\
             settle_secs,speeds_m_per_s,traction_control,width_m"
        );
        assert_eq!(
            keys(Obstacle::STEP),
            "after_secs,ahead_m,cruise_secs,edge_radius_m,headings_deg,height_search,\
             ramp_accel_m_per_s2,seed,settle_secs,speeds_m_per_s,traction_control"
        );
    }
}
