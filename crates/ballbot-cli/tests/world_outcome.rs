//! `ballbot world`'s outcome and events, and its stop rules (`--stop-on`): with the rules a
//! slipping robot's run ends at the slip; without them the same run shows what the slip led
//! to, the events are the same record either way, and a run the robot survives says so.

use ballbot_cli::Cli;
use ballbot_cli::world::{ControllerChoice, WorldArgs, simulate};
use ballbot_sim::rig::{EventKind, Outcome};
use ballbot_sim::world::{FailureKind, StopRules};
use clap::Parser;
use std::path::Path;

/// The paper's controller ramped at 2 m/s^2 towards OW1: it slips at about 0.57 m/s (the
/// failing acceleration at 0 deg is 1.35 m/s^2).
fn slipping(out: &Path, stop_on: StopRules) -> WorldArgs {
    WorldArgs {
        controller: ControllerChoice::Paper,
        heading_deg: 0.0,
        accel_m_per_s2: 2.0,
        top_speed_m_per_s: 2.0,
        duration_secs: 4.0,
        decimate: 80,
        stop_on,
        out: out.to_owned(),
        ..WorldArgs::default()
    }
}

/// The first slip event's onset (s).
fn first_slip(events: &[ballbot_sim::rig::Event]) -> f64 {
    events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::Slip { .. }))
        .map(|e| e.onset_secs)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn with_the_stop_rules_a_slip_ends_the_run_and_without_them_the_fall_that_follows_is_seen() {
    let dir = tempfile::tempdir().unwrap();
    let ruled = simulate(&slipping(&dir.path().join("a.mcap"), StopRules::all())).unwrap();
    let free = simulate(&slipping(&dir.path().join("b.mcap"), StopRules::none())).unwrap();
    println!("with the rules: {:?}", ruled.outcome);
    println!("without: {:?}, {} events", free.outcome, free.events.len());
    // With the rules: the slip rule ends it.
    let Outcome::EndedByStopRule { rule, time_secs } = ruled.outcome else {
        panic!("{:?}", ruled.outcome);
    };
    assert!(
        matches!(rule, FailureKind::SustainedSlip { .. }),
        "{rule:?}"
    );
    assert_eq!(ruled.stop_rules, "tilt,slip,lift-off,driver-trip");
    // Without: the robot falls after it slipped (the body reaches the floor).
    let Outcome::Fell { time_secs: fell } = free.outcome else {
        panic!("{:?}", free.outcome);
    };
    assert_eq!(free.stop_rules, "none");
    let slip = first_slip(&free.events);
    assert!(
        slip < time_secs && time_secs < fell,
        "slip {slip}, rule {time_secs}, fell {fell}"
    );
    assert!(
        fell - slip < 1.0,
        "fell {fell} s, {} s after the slip",
        fell - slip
    );
    // The events up to the rule's end are the same record either way.
    let until = |events: &[ballbot_sim::rig::Event]| {
        events
            .iter()
            .filter(|e| e.onset_secs <= time_secs)
            .map(|e| (e.kind.as_str(), e.onset_secs))
            .collect::<Vec<_>>()
    };
    assert_eq!(until(&ruled.events), until(&free.events));
    // Some rules only: the slip rule alone ends it as all did.
    let slip_only = StopRules {
        slip: true,
        ..StopRules::none()
    };
    let only = simulate(&slipping(&dir.path().join("c.mcap"), slip_only)).unwrap();
    assert_eq!(only.outcome, ruled.outcome);
}

#[test]
fn a_run_the_shipped_controller_survives_recovers_and_reports_its_traction_limit() {
    let dir = tempfile::tempdir().unwrap();
    let args = WorldArgs {
        heading_deg: 180.0,
        accel_m_per_s2: 3.0,
        top_speed_m_per_s: 2.0,
        duration_secs: 4.0,
        decimate: 80,
        out: dir.path().join("w.mcap"),
        ..WorldArgs::default()
    };
    let o = simulate(&args).unwrap();
    let Outcome::Recovered { time_secs } = o.outcome else {
        panic!("{:?}", o.outcome);
    };
    assert!(time_secs < 4.0, "{time_secs}");
    let limited = o
        .events
        .iter()
        .find_map(|e| match e.kind {
            EventKind::TractionLimit {
                min_accel_limit_m_per_s2,
            } => Some(min_accel_limit_m_per_s2),
            _ => None,
        })
        .expect("no traction limit at 3 m/s^2");
    assert!(limited < 3.0, "{limited}");
    // The JSON names the outcome and every event's kind and onset.
    let json = serde_json::to_value(&o).unwrap();
    assert_eq!(json["outcome"]["kind"], "recovered");
    assert_eq!(json["events"][0]["kind"], "traction_limit");
    assert!(json["events"][0]["onset_secs"].as_f64().is_some());
}

#[test]
fn stop_on_takes_all_none_or_rule_names_and_names_an_unknown_one() {
    let parse = |v: &str| Cli::try_parse_from(["ballbot", "world", "--stop-on", v]);
    assert!(parse("none").is_ok() && parse("all").is_ok() && parse("slip,lift-off").is_ok());
    let e = parse("slip,wobble").unwrap_err().to_string();
    assert!(e.contains("wobble") && e.contains("lift-off"), "{e}");
}
