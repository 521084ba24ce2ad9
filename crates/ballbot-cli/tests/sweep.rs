//! `ballbot sweep`: a grid file runs every point on the threads asked for, with the same
//! table on one thread and two; bad keys exit non-zero naming the key.

use std::path::Path;
use std::process::{Command, Output};

fn sweep(dir: &Path, grid: &str, threads: &str) -> Output {
    let file = dir.join("grid.toml");
    std::fs::write(&file, grid).unwrap();
    Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args([
            "sweep",
            file.to_str().unwrap(),
            "--threads",
            threads,
            "--out",
        ])
        .arg(dir.join(format!("out-{threads}")))
        .output()
        .unwrap()
}

const GRID: &str = r#"
study = "push_recovery"
seed = 2
[grid]
heading_deg = [90.0]
"robot.{sagittal,frontal}.com_height_m" = [0.4, 0.7]
"#;

#[test]
fn a_grid_runs_every_point_and_the_thread_count_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let one = sweep(dir.path(), GRID, "1");
    assert!(
        one.status.success(),
        "{}",
        String::from_utf8_lossy(&one.stderr)
    );
    let two = sweep(dir.path(), GRID, "2");
    assert!(two.status.success());
    let csv1 = std::fs::read_to_string(dir.path().join("out-1/sweep.csv")).unwrap();
    let csv2 = std::fs::read_to_string(dir.path().join("out-2/sweep.csv")).unwrap();
    assert_eq!(csv1, csv2);
    let lines: Vec<&str> = csv1.lines().collect();
    assert_eq!(lines.len(), 3, "header and two points:\n{csv1}");
    // The brace key holds a comma, so it is quoted: every line has the header's column count.
    assert!(lines[0].starts_with("heading_deg,\"robot.{sagittal,frontal}.com_height_m\","));
    let columns = |line: &str| {
        let mut quoted = false;
        1 + line
            .chars()
            .filter(|c| {
                if *c == '"' {
                    quoted = !quoted;
                }
                *c == ',' && !quoted
            })
            .count()
    };
    assert!(
        lines.iter().all(|l| columns(l) == columns(lines[0])),
        "{csv1}"
    );
    assert_eq!(columns(lines[0]), 6, "{}", lines[0]);
    assert!(lines[0].ends_with(",failing_outcome"), "{}", lines[0]);
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out-1/sweep.json")).unwrap(),
    )
    .unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    // A higher COM recovers a different push: the field reached the world.
    let push = |i: usize| rows[i]["values"]["largest_recovered_ns"].as_f64().unwrap();
    assert_ne!(push(0), push(1));
    assert!(push(0) > 10.0, "{}", push(0));
    // The low COM fails below 100 N s and the high one recovers 100 N s (censored): a row
    // says how the run at the failing end ended, and the CSV's last cell is that outcome;
    // a censored row has none.
    assert!(
        rows[0]["values"]["smallest_failing_ns"].is_number(),
        "{json}"
    );
    assert!(rows[1]["values"]["smallest_failing_ns"].is_null(), "{json}");
    for (i, line) in lines[1..].iter().enumerate() {
        let failing = &rows[i]["failing_run"];
        let cell = line.rsplit(',').next().unwrap();
        if rows[i]["values"]["smallest_failing_ns"].is_null() {
            assert!(failing.is_null() && cell.is_empty(), "{failing} {line}");
            continue;
        }
        assert_eq!(
            failing["value"].as_f64(),
            rows[i]["values"]["smallest_failing_ns"].as_f64(),
            "{failing}"
        );
        let kind = failing["outcome"]["kind"].as_str().unwrap();
        assert!(
            ["fell", "ended_by_stop_rule", "stopped", "unsettled"].contains(&kind),
            "{kind}"
        );
        assert!(failing["events"].is_array(), "{failing}");
        assert!(cell.starts_with(kind), "{cell} against {kind}");
    }
}

/// The failing-acceleration study's rows: a censored point (no ramp on the quick grid fails
/// towards 180 deg) has no failing run, an empty last cell and `null` in the JSON.
#[test]
fn a_censored_point_has_no_failing_run() {
    let dir = tempfile::tempdir().unwrap();
    let grid = "study = \"failing_acceleration\"\nquick = true\n[grid]\nheading_deg = [180.0]";
    let out = sweep(dir.path(), grid, "1");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("out-1/sweep.csv")).unwrap();
    let row = csv.lines().nth(1).unwrap();
    assert!(row.ends_with(','), "{csv}");
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out-1/sweep.json")).unwrap(),
    )
    .unwrap();
    let r = &json["rows"][0];
    assert!(r["values"]["smallest_failing_m_per_s2"].is_null(), "{r}");
    assert!(r["failing_run"].is_null(), "{r}");
}

#[test]
fn bad_grid_keys_and_values_exit_non_zero_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (grid, expected) in [
        (
            "study = \"push_recovery\"\n[grid]\n\"robot.nope\" = [1.0]",
            "robot.nope",
        ),
        (
            "study = \"push_recovery\"\n[grid]\n\"dt_secs\" = [-1.0]",
            "dt_secs",
        ),
        (
            "study = \"push_recovery\"\n[grid]\nheading_deg = []",
            "heading_deg",
        ),
        ("study = \"sprint\"\n[grid]\nheading_deg = [0.0]", "sprint"),
        (
            "study = \"push_recovery\"\nseeds = 1\n[grid]\nheading_deg = [0.0]",
            "seeds",
        ),
    ] {
        let out = sweep(dir.path(), grid, "1");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{grid}");
        assert!(err.contains(expected), "{grid}: {err}");
    }
}
