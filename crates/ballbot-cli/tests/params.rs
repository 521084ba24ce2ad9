//! `ballbot params`: valid files pass with one OK line, a value out of bounds names its key
//! and the bound, an unknown key is named, every preset's `show` passes `check` and reads back
//! as the preset, `diff` lists exactly the changed keys, every bound the schema states is one
//! that `validate()` enforces, and the committed schemas are the ones the types generate.

use ballbot_sim::params_file::{FileKind, PRESETS, ParamsFile, preset, schema_json, schema_text};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn ballbot(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

fn check(path: &Path) -> Output {
    ballbot(&["params", "check", path.to_str().unwrap()])
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn the_shipped_files_are_valid_and_say_ok_in_one_line() {
    let files = [
        "examples/params/miapure_60kg.toml",
        "examples/params/traction_study_on.toml",
        "scenarios/piptb_lqr_pi.toml",
        "scenarios/balance_stiction_lqr.toml",
        "scenarios/trapezoid_pi_pd.toml",
    ];
    for file in files {
        let out = check(&repo().join(file));
        assert!(out.status.success(), "{file}: {}", text(&out.stderr));
        let stdout = text(&out.stdout);
        assert_eq!(stdout.lines().count(), 1, "{stdout}");
        assert!(stdout.starts_with("OK: "), "{stdout}");
    }
}

/// Writes `text` into `dir/name` and checks it; returns (success, stderr).
fn check_text(dir: &Path, name: &str, text_in: &str) -> (bool, String) {
    let path = dir.join(name);
    std::fs::write(&path, text_in).unwrap();
    let out = check(&path);
    (out.status.success(), text(&out.stderr))
}

#[test]
fn a_value_out_of_bounds_names_the_dotted_key_and_the_bound() {
    let dir = tempfile::tempdir().unwrap();
    let robot = std::fs::read_to_string(repo().join("examples/params/miapure_60kg.toml")).unwrap();
    let scenario = std::fs::read_to_string(repo().join("scenarios/piptb_lqr_pi.toml")).unwrap();
    let world = text(&ballbot(&["params", "show", "--kind", "world"]).stdout);
    for (name, bad, key, bound) in [
        (
            "robot.toml",
            robot.replacen("ball_mass_kg = 3.6", "ball_mass_kg = -1.0", 1),
            "`sagittal.ball_mass_kg`",
            "must be finite and > 0",
        ),
        (
            "robot.toml",
            robot.replace("peak_torque_nm = 43.2", "peak_torque_nm = 0.0"),
            "`drivetrain.actuator.peak_torque_nm`",
            "> 0",
        ),
        (
            "scenario.toml",
            scenario.replace("coulomb_torque_nm = 0.35", "coulomb_torque_nm = 0.7"),
            "`friction.coulomb_torque_nm`",
            "must not exceed friction.stiction_torque_nm",
        ),
        (
            "world.toml",
            world.replace(
                "kinetic_friction_ratio = 0.85",
                "kinetic_friction_ratio = 1.5",
            ),
            "`contact.kinetic_friction_ratio`",
            "must be in (0, 1]",
        ),
        (
            "world.toml",
            world.replacen("com_height_m = 0.5", "com_height_m = 0.0", 1),
            "`robot.sagittal.com_height_m`",
            "> 0",
        ),
    ] {
        let (ok, err) = check_text(dir.path(), name, &bad);
        assert!(!ok, "{name} {key} passed");
        assert!(err.contains(key) && err.contains(bound), "{key}: {err}");
    }
}

#[test]
fn an_unknown_or_mistyped_key_is_named_with_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let robot = std::fs::read_to_string(repo().join("examples/params/miapure_60kg.toml")).unwrap();
    let scenario = std::fs::read_to_string(repo().join("scenarios/piptb_lqr_pi.toml")).unwrap();
    for (name, bad, expected) in [
        (
            "robot.toml",
            robot.replace("gear_ratio", "gear_ration"),
            "`drivetrain.actuator.gear_ration`: unknown field",
        ),
        (
            "scenario.toml",
            scenario.replace("stiction_torque_nm", "stiction_nm"),
            "`friction.stiction_nm`: unknown field",
        ),
        (
            "scenario.toml",
            scenario.replace("hold_secs = 2.0", "hold_sec = 2.0"),
            "`command.hold_sec`: unknown field",
        ),
        (
            "robot.toml",
            robot.replacen("body_mass_kg = 74.3", "body_mass_kg = \"heavy\"", 1),
            "`sagittal.body_mass_kg`: invalid type",
        ),
        (
            "scenario.toml",
            scenario.replace("kind = \"lqr_pi\"", ""),
            "`controller.kind`: missing field",
        ),
    ] {
        let (ok, err) = check_text(dir.path(), name, &bad);
        assert!(!ok, "{expected} passed");
        assert!(err.contains(expected), "{expected}: {err}");
    }
    // Without a kind to go by, the error says how to give one.
    let (ok, err) = check_text(dir.path(), "bare.toml", "seed = 1\n");
    assert!(!ok && err.contains("--kind"), "{err}");
}

#[test]
fn every_preset_shown_passes_check_and_reads_back_as_the_preset() {
    let dir = tempfile::tempdir().unwrap();
    for p in PRESETS {
        let out = ballbot(&[
            "params",
            "show",
            "--kind",
            p.kind.as_str(),
            "--preset",
            p.name,
        ]);
        assert!(out.status.success(), "{p:?}: {}", text(&out.stderr));
        let shown = text(&out.stdout);
        assert!(shown.starts_with("# "), "{shown}");
        let path = dir.path().join(format!("{}-{}.toml", p.kind, p.name));
        std::fs::write(&path, &shown).unwrap();
        // No --kind: the kind is inferred from the keys.
        let checked = check(&path);
        assert!(checked.status.success(), "{p:?}: {}", text(&checked.stderr));
        assert!(text(&checked.stdout).contains(p.kind.as_str()));
        let (_, expected) = preset(p.name, Some(p.kind)).unwrap();
        assert_eq!(
            ParamsFile::check(&shown, p.kind).unwrap(),
            expected,
            "{p:?}"
        );
    }
    // `miapure` alone is the robot.
    let out = ballbot(&["params", "show", "--preset", "miapure"]);
    assert!(text(&out.stdout).contains("robot file (BallbotParams)"));
    let out = ballbot(&["params", "show", "--kind", "world", "--preset", "piptb"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("scenario/piptb"));
}

#[test]
fn the_piptb_scenario_preset_is_the_shipped_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let shown = dir.path().join("piptb.toml");
    std::fs::write(
        &shown,
        ballbot(&["params", "show", "--preset", "piptb"]).stdout,
    )
    .unwrap();
    let shipped = repo().join("scenarios/piptb_lqr_pi.toml");
    let out = ballbot(&[
        "params",
        "diff",
        shipped.to_str().unwrap(),
        shown.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    assert!(out.stdout.is_empty());
}

#[test]
fn diff_lists_exactly_the_changed_keys_and_exits_like_diff() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.toml");
    let b = dir.path().join("b.toml");
    let robot = std::fs::read_to_string(repo().join("examples/params/miapure_60kg.toml")).unwrap();
    std::fs::write(&a, &robot).unwrap();
    let changed = robot
        .replacen("body_mass_kg = 74.3", "body_mass_kg = 80.0", 1)
        .replace("peak_torque_nm = 43.2", "peak_torque_nm = 40.0");
    std::fs::write(&b, changed).unwrap();
    let (pa, pb) = (a.to_str().unwrap(), b.to_str().unwrap());
    let out = ballbot(&["params", "diff", pa, pb]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(
        rows,
        [
            vec!["sagittal.body_mass_kg", "74.3", "80.0"],
            vec!["drivetrain.actuator.peak_torque_nm", "43.2", "40.0"],
        ],
        "{stdout}"
    );
    // Equal files: no output, exit 0; an error (a missing file, two kinds): exit 2.
    let same = ballbot(&["params", "diff", pa, pa]);
    assert_eq!(same.status.code(), Some(0));
    assert!(same.stdout.is_empty());
    let missing = ballbot(&["params", "diff", pa, "/nonexistent/file.toml"]);
    assert_eq!(missing.status.code(), Some(2));
    let scenario = repo().join("scenarios/piptb_lqr_pi.toml");
    let kinds = ballbot(&["params", "diff", pa, scenario.to_str().unwrap()]);
    assert_eq!(kinds.status.code(), Some(2));
    assert!(text(&kinds.stderr).contains("different kinds"));
}

/// Every numeric key of `value` (a file as JSON) with its schema, by dotted path.
fn numeric_leaves<'a>(
    root: &'a Value,
    schema: &'a Value,
    value: &Value,
    path: &str,
    out: &mut Vec<(String, &'a Value)>,
) {
    let resolve = |mut node: &'a Value| {
        loop {
            let reference = node
                .get("$ref")
                .or_else(|| node["allOf"].get(0)?.get("$ref"));
            match reference.and_then(Value::as_str) {
                Some(r) => node = &root["definitions"][&r["#/definitions/".len()..]],
                None => return node,
            }
        }
    };
    let schema = resolve(schema);
    if let Value::Object(map) = value {
        for (key, child) in map {
            let branches = schema["oneOf"].as_array().into_iter().flatten();
            let property = std::iter::once(schema)
                .chain(branches)
                .map(|s| &resolve(s)["properties"][key.as_str()])
                .find(|p| !p.is_null());
            if let Some(property) = property {
                let key = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                numeric_leaves(root, property, child, &key, out);
            }
        }
    } else if value.is_number() {
        out.push((path.to_owned(), schema));
    }
}

/// Sets the value at dotted `path` of a TOML table.
fn set(table: &mut toml::Table, path: &str, value: toml::Value) {
    let (head, last) = path.rsplit_once('.').map_or(("", path), |(h, l)| (h, l));
    let mut node = table;
    for part in head.split('.').filter(|p| !p.is_empty()) {
        node = node.get_mut(part).unwrap().as_table_mut().unwrap();
    }
    node.insert(last.to_owned(), value);
}

#[test]
fn every_bound_in_the_schema_is_enforced_by_validate_and_named() {
    let mut bounds = 0;
    for p in PRESETS {
        let (_, file) = preset(p.name, Some(p.kind)).unwrap();
        let toml_text = file.to_toml().unwrap();
        let json: Value =
            serde_json::to_value(toml::from_str::<toml::Table>(&toml_text).unwrap()).unwrap();
        let schema = schema_json(p.kind);
        let mut leaves = Vec::new();
        numeric_leaves(&schema, &schema, &json, "", &mut leaves);
        assert!(leaves.len() > 10, "{p:?}");
        for (path, node) in leaves {
            let integer = node["type"] == "integer";
            // At an exclusive bound, or half a unit below an inclusive one (the integer types'
            // own minimum 0 is not a field's bound).
            let just_outside = node["exclusiveMinimum"].as_f64().or_else(|| {
                node["minimum"]
                    .as_f64()
                    .filter(|lo| !(integer && *lo == 0.0))
                    .map(|lo| lo - 0.5)
            });
            let Some(bad) = just_outside else { continue };
            bounds += 1;
            let mut table: toml::Table = toml::from_str(&toml_text).unwrap();
            let value = if integer {
                toml::Value::Integer(bad.floor() as i64)
            } else {
                toml::Value::Float(bad)
            };
            set(&mut table, &path, value);
            let bad_text = toml::to_string(&table).unwrap();
            let err = ParamsFile::check(&bad_text, p.kind)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(&format!("`{path}`")),
                "{p:?} {path} = {bad}: {err}"
            );
        }
    }
    assert!(bounds > 60, "{bounds}");
}

#[test]
fn the_committed_schemas_are_the_ones_the_types_generate() {
    for kind in FileKind::ALL {
        let path = repo().join("schemas").join(kind.schema_file_name());
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == schema_text(kind),
            "schemas/{} is out of date with the Rust types (or missing); regenerate the \
             schemas with `cargo run -p ballbot-cli --bin ballbot -- params schema --out \
             schemas` and commit them",
            kind.schema_file_name()
        );
    }
}
