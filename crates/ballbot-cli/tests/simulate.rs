//! `ballbot simulate`: a scenario's MCAP log and summary, a killed run still readable.

use ballbot_sim::log::{McapLog, topics};
use std::path::{Path, PathBuf};
use std::process::Command;

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}

#[test]
fn simulate_writes_a_log_and_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .arg("simulate")
        .arg(scenarios_dir().join("balance_stiction_lqr.toml"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("balance_stiction_lqr.json")).unwrap(),
    )
    .unwrap();
    assert!(summary["fault"].is_null(), "{summary}");
    assert!(summary["peak_tilt_rad"].as_f64().unwrap() >= 0.05);
    assert!(
        summary["final_tilt_rad"].as_f64().unwrap().abs() < 0.02,
        "{summary}"
    );
    let log = McapLog::open(dir.path().join("balance_stiction_lqr.mcap")).unwrap();
    assert!(log.is_complete());
    assert_eq!(
        log.channel(topics::PLANAR_STATE).unwrap().message_count,
        2000
    );
    // A bad file fails with the key in the message and a non-zero exit.
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[controller]\nkind = \"lqr\"\n[friction]\nstictoin = 1",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .arg("simulate")
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("stictoin"));
}

#[test]
fn a_run_killed_midway_leaves_a_readable_log() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("long.toml");
    std::fs::write(
        &scenario,
        "duration_secs = 100000.0\n[controller]\nkind = \"lqr_pi\"\n[command]\nkind = \"balance\"\n",
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(dir.path())
        .spawn()
        .unwrap();
    let log_path = dir.path().join("long.mcap");
    // Wait until a few chunks (flushed every simulated second) are on disk, then kill.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while std::fs::metadata(&log_path).map_or(0, |m| m.len()) < 200_000 {
        assert!(
            std::time::Instant::now() < deadline,
            "the run wrote nothing"
        );
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let log = McapLog::open(&log_path).unwrap();
    assert!(!log.is_complete());
    let count = |t: &str| log.channel(t).map_or(0, |c| c.message_count);
    let states = count(topics::PLANAR_STATE);
    assert!(states >= 400, "{states} state messages recovered");
    for t in [topics::PLANAR_COMMAND, topics::PLANAR_CONTROL] {
        assert!(
            count(t).abs_diff(states) <= 1,
            "{t}: {} vs {states}",
            count(t)
        );
    }
    let series = log.numeric_series(topics::PLANAR_STATE).unwrap();
    assert!(
        series
            .column("tilt_rad")
            .unwrap()
            .iter()
            .all(|x| x.is_finite())
    );
}
