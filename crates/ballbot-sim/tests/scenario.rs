//! Scenario files: every example parses, errors name the key.

use ballbot_sim::studies::scenario::{Scenario, ScenarioError};
use std::path::{Path, PathBuf};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}

#[test]
fn every_example_scenario_parses() {
    let mut n = 0;
    for entry in std::fs::read_dir(scenarios_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            Scenario::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            n += 1;
        }
    }
    assert!(n >= 3, "{n} scenarios");
}

fn error_of(text: &str) -> String {
    Scenario::from_toml_str(text).unwrap_err().to_string()
}

#[test]
fn scenario_errors_name_the_key() {
    let base = "[controller]\nkind = \"lqr\"\n";
    // Unknown keys, in any section.
    assert!(error_of(&format!("{base}[friction]\nstiction = 1.0")).contains("stiction"));
    assert!(error_of(&format!("{base}speed = 1.0")).contains("speed"));
    assert!(error_of(&format!("{base}[sim]\nplant_hz = 1.0")).contains("plant_hz"));
    // Wrong types and missing keys.
    assert!(error_of(&format!("{base}seed = \"one\"")).contains("seed"));
    assert!(error_of("seed = 1").contains("controller"));
    assert!(error_of("[controller]\nkind = \"pid\"").contains("pid"));
    assert!(
        error_of(&format!(
            "{base}[command]\nkind = \"trapezoid\"\nspeed_m_per_s = 1.0"
        ))
        .contains("ramp_secs")
    );
    // Values out of range, named with their section.
    let e = error_of(&format!(
        "{base}[friction]\nstiction_torque_nm = 0.1\ncoulomb_torque_nm = 0.3"
    ));
    assert!(e.contains("friction.coulomb_torque_nm"), "{e}");
    let e = error_of(&format!("{base}[sim]\nouter_rate_hz = 300.0"));
    assert!(e.contains("sim.outer_rate_hz"), "{e}");
    let e = error_of(&format!("{base}[sensors]\ntilt_noise_rad = -1.0"));
    assert!(e.contains("sensors.tilt_noise_rad"), "{e}");
    let e = error_of(&format!("{base}duration_secs = 0.0"));
    assert!(e.contains("duration_secs"), "{e}");
    let plane = "[robot.plane]\nball_radius_m = 0.05\nball_mass_kg = 1.0\nball_inertia_kg_m2 = 0.001\n\
                 body_mass_kg = -3.0\ncom_height_m = 0.2\nbody_inertia_kg_m2 = 0.1\n\
                 wheel_inertia_kg_m2 = 0.0\nball_damping_nm_s_per_rad = 0.0\n\
                 drive_damping_nm_s_per_rad = 0.0\ngravity_m_per_s2 = 9.81\n";
    let e = error_of(&format!("{base}{plane}"));
    assert!(e.contains("robot.plane.body_mass_kg"), "{e}");
    assert!(matches!(
        Scenario::from_path(Path::new("/nonexistent.toml")),
        Err(ScenarioError::Read { .. })
    ));
}
