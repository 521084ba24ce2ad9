//! `ballbot brake`: JSON and CSV output, bad flags named in the error.

#[test]
fn brake_command_prints_the_result_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("brake.csv");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args([
            "brake",
            "--preset",
            "piptb",
            "--intervals",
            "50",
            "--json",
            "--csv",
        ])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["status"], "solved");
    assert!((v["cost"].as_f64().unwrap() - 0.8301).abs() < 1e-3, "{v}");
    assert!(v["iterations"].as_u64().unwrap() >= 1);
    assert!(v["solve_ms"].as_f64().unwrap() > 0.0);
    assert_eq!(v["intervals"], 50);
    // 1.4 s sampled every 10 ms, plus the header.
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 142);

    // A parameter file replaces the preset's plane; limits and methods are flags.
    let params = dir.path().join("plane.toml");
    std::fs::write(
        &params,
        "ball_radius_m = 0.1145\nball_mass_kg = 3.6\nball_inertia_kg_m2 = 0.047\n\
         body_mass_kg = 74.3\ncom_height_m = 0.5\nbody_inertia_kg_m2 = 4.0\n\
         wheel_inertia_kg_m2 = 0.0\nball_damping_nm_s_per_rad = 0.0\n\
         drive_damping_nm_s_per_rad = 0.0\ngravity_m_per_s2 = 9.81\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["brake", "--preset", "piptb", "--params"])
        .arg(&params)
        .args([
            "--v0",
            "1.4",
            "--duration",
            "2",
            "--method",
            "trapezoidal",
            "--json",
        ])
        .args(["--max-torque", "7"])
        .output()
        .unwrap();
    // Not solved: the record still comes, and the exit status says it failed.
    assert!(!out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["method"], "trapezoidal");
    assert_eq!(
        v["status"], "infeasible",
        "7 N m cannot brake MiaPURE in 2 s: {v}"
    );

    // Malformed input fails with a message and a non-zero exit.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["brake", "--duration", "0"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("duration_secs"));
}

#[test]
fn a_failed_solve_prints_its_record_and_exits_non_zero() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["brake", "--v0", "1e300", "--json"])
        .output()
        .unwrap();
    assert!(!out.status.success(), "a failed solve must exit non-zero");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_ne!(v["status"], "solved");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("not solved"), "{stderr}");
    assert!(stderr.contains(v["status"].as_str().unwrap()), "{stderr}");
}
