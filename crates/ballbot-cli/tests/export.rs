//! `ballbot export`: the files equal the library's export of the same world, a world file is
//! read and checked like `ballbot params check`, and a bad one fails naming the key.

use ballbot_sim::export::{ExportFormat, export};
use ballbot_sim::world::WorldParams;
use std::process::{Command, Output};

fn ballbot(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn export_writes_the_default_world_and_a_world_file() {
    let dir = tempfile::tempdir().unwrap();
    let xml = dir.path().join("sub/ballbot.xml");
    let out = ballbot(&["export", "--format", "mjcf", "--out", xml.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let want = export(&WorldParams::miapure_60kg(), ExportFormat::Mjcf).unwrap();
    assert_eq!(std::fs::read_to_string(&xml).unwrap(), want);

    // A world file: the default world with a lighter body.
    let mut world = WorldParams::miapure_60kg();
    world.robot.sagittal.body_mass_kg = 50.0;
    world.robot.frontal.body_mass_kg = 50.0;
    let file = dir.path().join("world.toml");
    std::fs::write(&file, toml::to_string(&world).unwrap()).unwrap();
    let urdf = dir.path().join("ballbot.urdf");
    let out = ballbot(&[
        "export",
        "--format",
        "urdf",
        "--world",
        file.to_str().unwrap(),
        "--out",
        urdf.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&urdf).unwrap();
    assert_eq!(text, export(&world, ExportFormat::Urdf).unwrap());
    assert_ne!(
        text,
        export(&WorldParams::miapure_60kg(), ExportFormat::Urdf).unwrap()
    );
}

#[test]
fn export_rejects_a_bad_world_file_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let mut world = WorldParams::miapure_60kg();
    world.wheel_inertia_kg_m2 = -1.0;
    let file = dir.path().join("world.toml");
    std::fs::write(&file, toml::to_string(&world).unwrap()).unwrap();
    let out = ballbot(&[
        "export",
        "--format",
        "mjcf",
        "--world",
        file.to_str().unwrap(),
        "--out",
        dir.path().join("x.xml").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("wheel_inertia_kg_m2"), "{err}");
    let out = ballbot(&["export", "--format", "sdf", "--out", "x"]);
    assert!(!out.status.success());
}
