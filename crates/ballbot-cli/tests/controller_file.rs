//! The controller configuration as data: `ballbot params show --kind controller` writes a file
//! that reads back as the designed controller, `ballbot world --controller FILE` runs what the
//! file says (its traction safety factor included), `--traction-safety-factor` overrides it, and
//! a bad value is an error naming the key.

use ballbot_cli::world::{ControllerChoice, WorldArgs, simulate};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_sim::params_file::{FileKind, ParamsFile, commented_toml, preset};
use std::path::Path;
use std::process::Command;

/// The design preset's commented file with `friction_safety_factor` set to `factor`.
fn design_file_with_factor(dir: &Path, factor: &str) -> std::path::PathBuf {
    let (_, design) = preset("design", Some(FileKind::Controller)).unwrap();
    let text = commented_toml(&design, &[]).unwrap();
    let line = "friction_safety_factor = 2.0\n";
    assert_eq!(text.matches(line).count(), 1, "{text}");
    let path = dir.join(format!("factor_{factor}.toml"));
    std::fs::write(
        &path,
        text.replace(line, &format!("friction_safety_factor = {factor}\n")),
    )
    .unwrap();
    path
}

/// A 2 m/s^2 ramp towards OW2 (120 deg) with the designed controller, no log.
fn ramp(controller: ControllerChoice) -> WorldArgs {
    WorldArgs {
        controller,
        heading_deg: 120.0,
        accel_m_per_s2: 2.0,
        top_speed_m_per_s: 2.0,
        duration_secs: 2.5,
        no_log: true,
        ..WorldArgs::default()
    }
}

#[test]
fn the_design_preset_file_is_the_designed_controller_and_runs_as_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = design_file_with_factor(dir.path(), "2.0");
    let from_file = ramp(ControllerChoice::File(path.clone()));
    let designed = ramp(ControllerChoice::Design);
    let params = designed.world_params().unwrap();
    let config = from_file.controller_config(&params).unwrap();
    assert_eq!(config, designed.controller_config(&params).unwrap());
    // The file's text reads back to the same value, and TOML written from it to the same text.
    let text = std::fs::read_to_string(&path).unwrap();
    let file = ParamsFile::check(&text, FileKind::Controller).unwrap();
    let again = ParamsFile::check(&file.to_toml().unwrap(), FileKind::Controller).unwrap();
    assert_eq!(file, again);
    let ParamsFile::Controller(read) = file else {
        panic!("not a controller file")
    };
    let robot = &params.robot;
    assert_eq!(*read, BallbotControllerConfig::design(robot).unwrap());
    // The kind is inferred from the keys.
    assert_eq!(FileKind::infer(&text).unwrap(), FileKind::Controller);
    assert_eq!(
        simulate(&from_file).unwrap().max_speed_m_per_s,
        simulate(&designed).unwrap().max_speed_m_per_s
    );
}

#[test]
fn the_traction_safety_factor_comes_from_the_file_or_the_flag_and_changes_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let cautious = ramp(ControllerChoice::File(design_file_with_factor(
        dir.path(),
        "6.0",
    )));
    let params = cautious.world_params().unwrap();
    let config = cautious.controller_config(&params).unwrap();
    assert_eq!(config.traction.friction_safety_factor, 6.0);
    let flagged = WorldArgs {
        traction_safety_factor: Some(6.0),
        ..ramp(ControllerChoice::Design)
    };
    assert_eq!(flagged.controller_config(&params).unwrap(), config);
    // Planning with a sixth of the friction instead of half holds the ramp back.
    let (slow, nominal) = (
        simulate(&cautious).unwrap(),
        simulate(&ramp(ControllerChoice::Design)).unwrap(),
    );
    assert!(
        slow.max_speed_m_per_s < nominal.max_speed_m_per_s - 0.05,
        "factor 6: {} m/s, factor 2: {} m/s",
        slow.max_speed_m_per_s,
        nominal.max_speed_m_per_s
    );
}

#[test]
fn a_bad_factor_in_the_file_or_the_flag_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let bad = design_file_with_factor(dir.path(), "0.5");
    let err = simulate(&ramp(ControllerChoice::File(bad.clone()))).unwrap_err();
    let text = format!("{err:#}");
    assert!(
        text.contains("`traction.friction_safety_factor`") && text.contains(">= 1"),
        "{text}"
    );
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_ballbot"))
            .args(args)
            .env("RUST_BACKTRACE", "0")
            .output()
            .unwrap()
    };
    let out = run(&["world", "--no-log", "--traction-safety-factor", "0.9"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("friction_safety_factor"),
        "{stderr}"
    );
    let out = run(&["world", "--no-log", "--controller", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("traction.friction_safety_factor"),
        "{stderr}"
    );
    let out = run(&[
        "world",
        "--no-log",
        "--controller",
        "/no/such/controller.toml",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("/no/such/controller.toml"),
        "{stderr}"
    );
}
