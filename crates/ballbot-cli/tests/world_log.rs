//! MCAP logs of the 3D world and `ballbot world`: channels and counts, schemas, transforms that
//! match the telemetry, bit-identical files for a seed, decimation that thins every channel of
//! the same run, the same run without a log, a killed run still readable, and the committed
//! Foxglove world layout.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use ballbot_cli::world::{ControllerChoice, WorldArgs, simulate};
use ballbot_sim::log::foxglove::{
    BallbotScene, FrameTransforms, JointStates, Log, LogLevel, Pose, SceneUpdate, pose,
    position_of, rotation_of,
};
use ballbot_sim::log::world::{WorldControllerMsg, WorldEventMsg, WorldTelemetryMsg};
use ballbot_sim::log::{McapLog, check_message, check_schema, schema_for, topics};
use ballbot_sim::world::{BallbotWorld, StepTelemetry, WheelTelemetry, WorldParams, wheel_name};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde_json::Value;

fn args(out: &Path) -> WorldArgs {
    WorldArgs {
        duration_secs: 0.6,
        accel_m_per_s2: 1.0,
        top_speed_m_per_s: 0.3,
        push_ns: 20.0,
        push_at_secs: 0.3,
        push_heading_deg: 0.0,
        out: out.to_owned(),
        ..WorldArgs::default()
    }
}

/// The pose a frame transform carries.
fn pose_of(f: &ballbot_sim::log::foxglove::FrameTransform) -> Pose {
    Pose {
        position: f.translation,
        orientation: f.rotation,
    }
}

/// The pose logged for a position and orientation of the telemetry.
fn logged(position: Vector3<f64>, orientation: UnitQuaternion<f64>) -> Pose {
    pose(&Isometry3::from_parts(
        Translation3::from(position),
        orientation,
    ))
}

#[test]
fn world_command_writes_every_channel_and_transforms_match_the_telemetry() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sub").join("world.mcap");
    let outcome = simulate(&args(&path)).unwrap();
    assert_eq!(outcome.failure, None);
    assert!(
        outcome.max_speed_m_per_s > 0.05,
        "{}",
        outcome.max_speed_m_per_s
    );
    assert!(outcome.peak_cone_utilisation > 0.0 && outcome.peak_cone_utilisation < 1.0);

    let log = McapLog::open(&path).unwrap();
    assert!(log.is_complete());
    assert_eq!(outcome.log_bytes, std::fs::metadata(&path).unwrap().len());
    let count = |t: &str| log.channel(t).map(|c| c.message_count);
    // 0.6 s at 8 kHz; the outer loop at 400 Hz; transforms at 100 Hz and the scene at 50 Hz
    // (plus the first step each).
    assert_eq!(count(topics::WORLD_TELEMETRY), Some(4800));
    assert_eq!(count(topics::WORLD_CONTROLLER), Some(240));
    assert_eq!(count(topics::WORLD_COMMAND), Some(240));
    assert_eq!(count(topics::TRANSFORMS), Some(61));
    assert_eq!(count(topics::JOINT_STATES), Some(61));
    assert_eq!(count(topics::SCENE), Some(31));
    let schema_names: BTreeMap<&str, (&str, &str)> = log
        .channels()
        .iter()
        .map(|c| {
            let encodings = (c.schema_name.as_str(), c.message_encoding.as_str());
            (c.topic.as_str(), encodings)
        })
        .collect();
    for (topic, name) in [
        (topics::TRANSFORMS, "foxglove.FrameTransforms"),
        (topics::SCENE, "foxglove.SceneUpdate"),
        (topics::JOINT_STATES, "foxglove.JointStates"),
        (topics::LOG, "foxglove.Log"),
    ] {
        assert_eq!(schema_names[topic], (name, "protobuf"), "{topic}");
    }

    // Every JSON message matches its channel's schema (what Foxglove reads the fields by);
    // every protobuf message decodes with the SDK's type of its schema.
    for channel in log.channels() {
        let series = log.json_series(&channel.topic).unwrap();
        assert_eq!(series.values.len() as u64, channel.message_count);
        let Some(text) = channel.schema_text() else {
            assert_eq!(channel.schema_encoding, "protobuf", "{}", channel.topic);
            continue;
        };
        let schema: Value = serde_json::from_str(text).unwrap();
        check_schema(&schema).unwrap();
        for value in &series.values {
            check_message(&schema, value)
                .unwrap_or_else(|e| panic!("{}: {e}: {value}", channel.topic));
        }
    }
    // The events again as text for the Log panel, at the same times.
    let text = log.decode_protobuf::<Log>(topics::LOG).unwrap();
    let levels: Vec<i32> = text.iter().map(|(_, l)| l.level).collect();
    assert_eq!(levels, [LogLevel::Info as i32, LogLevel::Info as i32]);
    assert!(text[1].1.message.starts_with("push: "), "{:?}", text[1].1);

    // Events: the controller armed, the push, no failure.
    let events = log.decode::<WorldEventMsg>(topics::FAULTS).unwrap();
    let kinds: Vec<&str> = events.iter().map(|(_, e)| e.kind.as_str()).collect();
    assert_eq!(kinds, ["mode", "push"], "{events:?}");
    assert!((events[1].0 - 0.3).abs() < 1e-9);
    let controller = log
        .decode::<WorldControllerMsg>(topics::WORLD_CONTROLLER)
        .unwrap();
    assert!(controller.iter().all(|(_, c)| c.mode == "balancing"));
    assert_eq!(controller[1].0, 1.0 / 400.0, "stamped when computed");

    // The transforms are the telemetry's poses at the same time.
    let telemetry = log
        .decode::<WorldTelemetryMsg>(topics::WORLD_TELEMETRY)
        .unwrap();
    let by_time: BTreeMap<u64, &WorldTelemetryMsg> = telemetry
        .iter()
        .map(|(t, m)| ((t * 1e9).round() as u64, m))
        .collect();
    let robot = BallbotScene::from_params(&WorldParams::miapure_60kg().robot);
    let frames = log
        .decode_protobuf::<FrameTransforms>(topics::TRANSFORMS)
        .unwrap();
    let joints = log
        .decode_protobuf::<JointStates>(topics::JOINT_STATES)
        .unwrap();
    assert_eq!(joints.len(), frames.len());
    let mut ball_angles = Vec::new();
    for (time_secs, frames) in &frames {
        let t = by_time[&((time_secs * 1e9).round() as u64)];
        let find = |parent: &str, child: &str| {
            frames
                .transforms
                .iter()
                .find(|f| f.parent_frame_id == parent && f.child_frame_id == child)
                .unwrap_or_else(|| panic!("no {parent} -> {child}"))
        };
        let ball = pose_of(find("world", "ball"));
        let step = &t.step;
        assert_eq!(ball, logged(step.ball_position_m, step.ball_orientation));
        ball_angles.push(rotation_of(Some(&ball)).angle());
        let body = pose_of(find("world", "body"));
        assert_eq!(body, logged(step.body_position_m, step.body_orientation));
        let (joint_secs, joint_states) = &joints[ball_angles.len() - 1];
        assert_eq!(joint_secs, time_secs);
        for (i, name) in ["ow1", "ow2", "ow3"].into_iter().enumerate() {
            let wheel = pose_of(find("body", name));
            let nominal = robot.body_from_wheels[i];
            let at = position_of(Some(&wheel));
            assert!((at - nominal.translation.vector).norm() < 1e-12);
            // The joint state is the wheel's angle, speed and motor torque.
            let joint = &joint_states.joints[i];
            let w = &step.wheels[i];
            assert_eq!(joint.name, name);
            assert_eq!(joint.position, Some(w.angle_rad));
            assert_eq!(joint.velocity, Some(w.speed_rad_per_s));
            assert_eq!(joint.effort, Some(w.motor_torque_nm));
            // The wheel frame is the mounting pose turned by the wheel's angle about its axle.
            let spin = nominal.rotation.inverse() * rotation_of(Some(&wheel));
            let expected =
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), t.step.wheels[i].angle_rad);
            assert!(
                spin.angle_to(&expected) < 1e-9,
                "{name} at {time_secs}: {} vs {}",
                spin.angle(),
                expected.angle()
            );
        }
        assert_eq!(frames.transforms.len(), 5);
    }
    // The ball rolled: its rotation shows in the transforms.
    let last = *ball_angles.last().unwrap();
    assert!(last > 0.2, "ball turned by {last} rad");

    // The scene: floor, ball, body, three wheels, contact forces.
    let scenes = log.decode::<SceneUpdate>(topics::SCENE).unwrap();
    let ids: BTreeSet<&str> = scenes[0].1.entities.iter().map(|e| e.id.as_str()).collect();
    let expected: BTreeSet<&str> = [
        "floor",
        "ball",
        "body",
        "ow1",
        "ow2",
        "ow3",
        "contact_forces",
        "labels",
    ]
    .into();
    assert_eq!(ids, expected);
    let forces = scenes[20]
        .1
        .entities
        .iter()
        .find(|e| e.id == "contact_forces")
        .unwrap();
    assert_eq!(forces.arrows.len(), 3);
    // Arrow length = contact force magnitude * 0.5 mm/N (the normal force dominates).
    let t = by_time[&((scenes[20].0 * 1e9).round() as u64)];
    for (arrow, wheel) in forces.arrows.iter().zip(&t.step.wheels) {
        let length = arrow.shaft_length + arrow.head_length;
        let force = wheel.normal_force_n.hypot(wheel.traction_n);
        assert!((length - 5e-4 * force).abs() < 1e-9, "{length} vs {force}");
    }
}

#[test]
fn a_failure_is_logged_once_and_the_run_stops_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slip.mcap");
    // mu = 0.05: the wheels cannot carry the traction of the first acceleration.
    let a = WorldArgs {
        wheel_ball_friction: Some(0.05),
        push_ns: 0.0,
        duration_secs: 1.5,
        ..args(&path)
    };
    let outcome = simulate(&a).unwrap();
    assert_eq!(outcome.failure.as_deref(), Some("sustained_slip"));
    let failure_secs = outcome.failure_time_secs.unwrap();
    let wheel = outcome.failure_wheel.unwrap();
    assert!((1..=3).contains(&wheel));
    assert!((outcome.end_time_secs - failure_secs - a.after_failure_secs).abs() < 2e-4);

    let log = McapLog::open(&path).unwrap();
    let events = log.decode::<WorldEventMsg>(topics::FAULTS).unwrap();
    let failures: Vec<_> = events.iter().filter(|(_, e)| e.kind != "mode").collect();
    assert_eq!(failures.len(), 1, "{events:?}");
    let (time_secs, event) = failures[0];
    assert_eq!(event.kind, "sustained_slip");
    assert_eq!(event.wheel.as_deref(), Some(wheel_name(wheel - 1)));
    assert!((time_secs - failure_secs).abs() < 1e-9);
    assert!(event.description.contains(&format!("OW{wheel}")));

    let telemetry = log
        .decode::<WorldTelemetryMsg>(topics::WORLD_TELEMETRY)
        .unwrap();
    for (t, msg) in &telemetry {
        assert_eq!(msg.failed, *t >= failure_secs - 1e-9, "at {t}");
    }
    // While a wheel slips, its contact-force arrow is red.
    let by_time: BTreeMap<u64, &WorldTelemetryMsg> = telemetry
        .iter()
        .map(|(t, m)| ((t * 1e9).round() as u64, m))
        .collect();
    let mut red = 0;
    for (time_secs, update) in log.decode_protobuf::<SceneUpdate>(topics::SCENE).unwrap() {
        let t = by_time[&((time_secs * 1e9).round() as u64)];
        let forces = update
            .entities
            .iter()
            .find(|e| e.id == "contact_forces")
            .unwrap();
        for (arrow, w) in forces.arrows.iter().zip(&t.step.wheels) {
            let colour = arrow.color.unwrap_or_default();
            let is_red = colour.r > 0.8 && colour.g < 0.1;
            assert_eq!(is_red, w.slipping, "at {time_secs}");
            red += usize::from(is_red);
        }
    }
    assert!(red > 0, "no slipping wheel drawn");
}

#[test]
fn same_seed_gives_a_bit_identical_log_and_another_seed_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, seed: u64| {
        let path = dir.path().join(name);
        let mut a = args(&path);
        a.duration_secs = 0.2;
        a.seed = seed;
        simulate(&a).unwrap();
        std::fs::read(path).unwrap()
    };
    let first = run("a.mcap", 3);
    let again = run("b.mcap", 3);
    let other = run("c.mcap", 4);
    assert!(first == again, "same seed, different bytes");
    assert!(first != other, "the seed must matter (sensor noise)");
}

#[test]
fn bad_flags_are_named_in_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let base = args(&dir.path().join("x.mcap"));
    let cases: [(&str, WorldArgs); 6] = [
        (
            "--accel-m-per-s2",
            WorldArgs {
                accel_m_per_s2: 0.0,
                ..base.clone()
            },
        ),
        (
            "--duration-secs",
            WorldArgs {
                duration_secs: f64::NAN,
                ..base.clone()
            },
        ),
        (
            "--wheel-ball-friction",
            WorldArgs {
                wheel_ball_friction: Some(-0.1),
                ..base.clone()
            },
        ),
        (
            "--com-height-m",
            WorldArgs {
                com_height_m: Some(0.0),
                ..base.clone()
            },
        ),
        (
            "--push-ns",
            WorldArgs {
                push_ns: -1.0,
                ..base.clone()
            },
        ),
        (
            "--reference-filter-secs",
            WorldArgs {
                reference_filter_secs: Some(-0.1),
                ..base.clone()
            },
        ),
    ];
    for (flag, bad) in cases {
        let message = format!("{:#}", simulate(&bad).unwrap_err());
        assert!(message.contains(flag), "{flag}: {message}");
    }
    // clap rejects a zero decimation by name.
    let out = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["world", "--decimate", "0"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--decimate"));
}

#[test]
fn decimation_to_1_khz_thins_the_telemetry_only() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.mcap");
    let mut a = args(&path);
    a.duration_secs = 0.2;
    a.decimate = 8;
    a.scene_hz = 10.0;
    simulate(&a).unwrap();
    let log = McapLog::open(&path).unwrap();
    let count = |t: &str| log.channel(t).map(|c| c.message_count);
    assert_eq!(count(topics::WORLD_TELEMETRY), Some(200));
    assert_eq!(count(topics::WORLD_CONTROLLER), Some(80));
    assert_eq!(count(topics::TRANSFORMS), Some(5));
    assert_eq!(count(topics::SCENE), Some(3));
    let series = log.numeric_series(topics::WORLD_TELEMETRY).unwrap();
    let dt = 1.0 / 8000.0;
    assert!((series.time_secs[1] - series.time_secs[0] - 8.0 * dt).abs() < 1e-9);
}

#[test]
fn a_log_decimated_below_the_outer_rate_thins_every_channel_of_the_same_run() {
    let dir = tempfile::tempdir().unwrap();
    let full_path = dir.path().join("full.mcap");
    let full_outcome = simulate(&args(&full_path)).unwrap();
    let full = McapLog::open(&full_path).unwrap();
    let thin_path = dir.path().join("thin.mcap");
    let mut a = args(&thin_path);
    a.decimate = 400; // 20 Hz: every 20th outer step, transforms and scene at 20 Hz
    let thin_outcome = simulate(&a).unwrap();
    let thin = McapLog::open(&thin_path).unwrap();
    assert_eq!(
        WorldOutcomeFigures::of(&thin_outcome),
        WorldOutcomeFigures::of(&full_outcome)
    );
    let every_nth = |topic: &str, n: usize| -> Vec<(f64, Value)> {
        let all = full.decode::<Value>(topic).unwrap();
        all.into_iter().step_by(n).collect()
    };
    let thin_of = |topic: &str| thin.decode::<Value>(topic).unwrap();
    // The same run: the written telemetry and controller output are the full log's, thinned.
    assert_eq!(
        thin_of(topics::WORLD_TELEMETRY),
        every_nth(topics::WORLD_TELEMETRY, 400)
    );
    assert_eq!(
        thin_of(topics::WORLD_CONTROLLER),
        every_nth(topics::WORLD_CONTROLLER, 20)
    );
    // Mode changes and the push are events, written whatever the rates.
    assert_eq!(
        thin_of(topics::FAULTS),
        full.decode::<Value>(topics::FAULTS).unwrap()
    );
    let count = |t: &str| thin.channel(t).map(|c| c.message_count);
    // 0.6 s on a 0.05 s grid: the first step, then 0.05, ..., 0.6 s (commands from t = 0 to
    // the last step's start).
    assert_eq!(count(topics::TRANSFORMS), Some(13));
    assert_eq!(count(topics::JOINT_STATES), Some(13));
    assert_eq!(count(topics::SCENE), Some(13));
    assert_eq!(count(topics::WORLD_COMMAND), Some(12));
}

/// The figures of a run's outcome, without its log.
#[derive(Debug, PartialEq)]
struct WorldOutcomeFigures(String);

impl WorldOutcomeFigures {
    fn of(outcome: &ballbot_cli::world::WorldOutcome) -> Self {
        let mut value = serde_json::to_value(outcome).unwrap();
        let fields = value.as_object_mut().unwrap();
        fields.remove("log");
        fields.remove("log_bytes");
        Self(value.to_string())
    }
}

#[test]
fn without_a_log_the_run_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let logged = simulate(&args(&dir.path().join("w.mcap"))).unwrap();
    let mut a = args(&dir.path().join("none.mcap"));
    a.no_log = true;
    let unlogged = simulate(&a).unwrap();
    assert_eq!(
        WorldOutcomeFigures::of(&unlogged),
        WorldOutcomeFigures::of(&logged)
    );
    assert_eq!((unlogged.log.as_str(), unlogged.log_bytes), ("", 0));
    assert!(!dir.path().join("none.mcap").exists());
    // --no-log refuses the flags of a log.
    for flags in [["--no-log", "--live"], ["--no-log", "--decimate=8"]] {
        let out = Command::new(env!("CARGO_BIN_EXE_ballbot"))
            .arg("world")
            .args(flags)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{flags:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--no-log"));
    }
}

#[test]
fn a_killed_world_run_leaves_a_readable_log() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("killed.mcap");
    /// Kills the child if the test fails before it does.
    struct KillOnDrop(std::process::Child);
    impl Drop for KillOnDrop {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
    let mut guard = KillOnDrop(
        Command::new(env!("CARGO_BIN_EXE_ballbot"))
            .args(["world", "--duration-secs", "600", "--out"])
            .arg(&path)
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap(),
    );
    let child = &mut guard.0;
    // A few closed chunks (256 KiB uncompressed each, about 25 ms of telemetry) on disk.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while std::fs::metadata(&path).map_or(0, |m| m.len()) < 300_000 {
        assert!(
            std::time::Instant::now() < deadline,
            "the run wrote nothing"
        );
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // SIGKILL: no summary, no footer.
    child.kill().unwrap();
    child.wait().unwrap();
    let log = McapLog::open(&path).unwrap();
    assert!(!log.is_complete());
    let telemetry = log
        .decode::<WorldTelemetryMsg>(topics::WORLD_TELEMETRY)
        .unwrap();
    assert!(telemetry.len() >= 200, "{} recovered", telemetry.len());
    // A prefix of the run, in order, one message per step.
    let dt = 1.0 / 8000.0;
    for (k, (time_secs, msg)) in telemetry.iter().enumerate() {
        assert!((time_secs - (k + 1) as f64 * dt).abs() < 1e-9);
        assert!((time_secs - msg.step.time_secs).abs() < 1e-9);
    }
    assert!(log.channel(topics::TRANSFORMS).unwrap().message_count >= 1);
}

/// Splits a Foxglove message path `/topic.field[0].sub` into topic and field path.
fn split_message_path(path: &str) -> (&str, &str) {
    match path.find('.') {
        Some(dot) => (&path[..dot], &path[dot..]),
        None => (path, ""),
    }
}

/// Whether a field path `.a[0].b` leads to a number or boolean in a JSON schema.
fn schema_has_numeric_field(schema: &Value, fields: &str) -> bool {
    let mut node = schema;
    for part in fields.split('.').skip(1) {
        let name = part.split('[').next().unwrap_or("");
        node = &node["properties"][name];
        for _ in part.matches('[') {
            node = &node["items"];
        }
    }
    let numeric = |t: &Value| ["number", "integer", "boolean"].contains(&t.as_str().unwrap_or(""));
    match &node["type"] {
        Value::Array(types) => types.iter().any(numeric),
        other => numeric(other),
    }
}

/// Panel ids placed in a layout tree (a panel id, or a split with `first` and `second`).
fn placed_panels(node: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => out.push(id.clone()),
        Value::Object(split) => {
            placed_panels(&split["first"], out);
            placed_panels(&split["second"], out);
        }
        other => panic!("unexpected layout node {other}"),
    }
}

#[test]
fn world_layout_plots_fields_that_a_written_log_has() {
    let layout: Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../foxglove/world-layout.json"
        ))
        .unwrap(),
    )
    .unwrap();
    let config = layout["configById"].as_object().unwrap();
    let mut placed = Vec::new();
    placed_panels(&layout["layout"], &mut placed);
    let placed: BTreeSet<&str> = placed.iter().map(String::as_str).collect();
    let defined: BTreeSet<&str> = config.keys().map(String::as_str).collect();
    assert_eq!(placed, defined, "every panel placed once and defined");

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layout.mcap");
    let mut a = args(&path);
    a.duration_secs = 0.1;
    simulate(&a).unwrap();
    let log = McapLog::open(&path).unwrap();
    let mut plotted = 0;
    for (id, panel) in config {
        // The Log panel shows the foxglove.Log channel the log writes; the raw-message panel
        // a channel it writes.
        if id.starts_with("Log!") {
            let topic = panel["topicToRender"].as_str().unwrap();
            assert_eq!(log.channel(topic).unwrap().schema_name, "foxglove.Log");
        }
        if id.starts_with("RawMessages!") {
            let topic = panel["topicPath"].as_str().unwrap();
            assert!(
                log.channel(topic).is_some(),
                "{id}: {topic} is not in the log"
            );
        }
        if !id.starts_with("Plot!") {
            continue;
        }
        for series in panel["paths"].as_array().unwrap() {
            let value = series["value"].as_str().unwrap();
            let (topic, fields) = split_message_path(value);
            let channel = log
                .channel(topic)
                .unwrap_or_else(|| panic!("{id}: {topic} is not in the log"));
            assert!(channel.message_count > 0);
            let schema: Value = serde_json::from_str(channel.schema_text().unwrap()).unwrap();
            assert!(
                schema_has_numeric_field(&schema, fields),
                "{id}: {value} is not a numeric field of {topic}"
            );
            // The field has numbers in the log, under the reader's column name.
            let column = fields.trim_start_matches('.');
            let numbers = log.numeric_series(topic).unwrap();
            assert!(
                numbers
                    .column(column)
                    .is_some_and(|c| c.iter().any(|x| x.is_finite())),
                "{id}: no numbers at {value}"
            );
            assert_eq!(series["timestampMethod"], "receiveTime");
            plotted += 1;
        }
    }
    assert!(plotted >= 14, "{plotted} plotted paths");

    // The 3D panel follows a frame that the log publishes and shows the scene topic.
    let frames = log.decode::<FrameTransforms>(topics::TRANSFORMS).unwrap();
    let children: BTreeSet<&str> = frames[0]
        .1
        .transforms
        .iter()
        .map(|f| f.child_frame_id.as_str())
        .collect();
    let three_d = config
        .iter()
        .find(|(id, _)| id.starts_with("3D!"))
        .unwrap()
        .1;
    let follow = three_d["followTf"].as_str().unwrap();
    assert!(children.contains(follow), "{follow} is not published");
    assert!(
        three_d["topics"][topics::SCENE]["visible"]
            .as_bool()
            .unwrap()
    );
    for frame in ["world", "ball", "body", "ow1", "ow2", "ow3"] {
        assert!(
            three_d["transforms"][format!("frame:{frame}")].is_object(),
            "{frame}"
        );
    }
}

#[test]
fn world_message_schemas_are_well_formed() {
    for schema in [
        schema_for::<WorldTelemetryMsg>(),
        schema_for::<WorldControllerMsg>(),
        schema_for::<WorldEventMsg>(),
    ] {
        check_schema(&schema).unwrap();
    }
    let schema = schema_for::<WorldTelemetryMsg>();
    assert_eq!(
        schema["properties"]["wheels"]["items"]["properties"]["cone_utilisation"]["type"],
        "number"
    );
}

/// The telemetry message is the world's `StepTelemetry` itself (flattened) plus derived
/// fields: every telemetry field appears in the message schema with the telemetry type's own
/// schema, and a message serialises its record field by field.
#[test]
fn telemetry_schema_is_the_step_telemetry_schema() {
    let step_schema = schema_for::<StepTelemetry>();
    let msg_schema = schema_for::<WorldTelemetryMsg>();
    let step_props = step_schema["properties"].as_object().unwrap();
    assert!(step_props.len() >= 11, "{step_props:?}");
    for (name, schema) in step_props {
        assert_eq!(&msg_schema["properties"][name], schema, "{name}");
    }
    assert_eq!(
        schema_for::<WheelTelemetry>()["properties"],
        msg_schema["properties"]["wheels"]["items"]["properties"],
    );
    let mut world = BallbotWorld::new(WorldParams::miapure_60kg()).unwrap();
    world.tilt_body([0.01, -0.02]);
    for _ in 0..80 {
        world.step([0.5, -0.2, 0.1]);
    }
    let step = *world.telemetry();
    let msg = serde_json::to_value(WorldTelemetryMsg::new(&step, false)).unwrap();
    let record = serde_json::to_value(step).unwrap();
    for (name, value) in record.as_object().unwrap() {
        assert_eq!(&msg[name], value, "{name}");
    }
    check_message(&msg_schema, &msg).unwrap();
    let q = &step.body_orientation;
    assert_eq!(msg["body_orientation"]["w"], q.w);
    assert_eq!(msg["body_orientation"]["x"], q.i);
    assert_eq!(msg["ball_position_m"][2], step.ball_position_m.z);
    // And it reads back bit for bit.
    let back: WorldTelemetryMsg = serde_json::from_value(msg).unwrap();
    assert_eq!(back.step, step);
}

/// `--reference-filter-secs` reaches the core's command shaper: in the world a 1 m/s^2 ramp to
/// 1.5 m/s overshoots to 1.76 m/s without the filter and stays within 2 % of 1.5 m/s with
/// 0.3 s (release run: 1.762 against 1.472 m/s, docs/embedding.md).
#[test]
fn the_reference_filter_flag_removes_the_ramp_overshoot_in_the_world() {
    let dir = tempfile::tempdir().unwrap();
    let run = |filter_secs: f64, name: &str| {
        let a = WorldArgs {
            accel_m_per_s2: 1.0,
            top_speed_m_per_s: 1.5,
            duration_secs: 4.0,
            // The filter's own effect, without traction-aware control's envelope.
            controller: ControllerChoice::Paper,
            reference_filter_secs: Some(filter_secs),
            decimate: 80,
            out: dir.path().join(name),
            ..WorldArgs::default()
        };
        let outcome = simulate(&a).unwrap();
        assert!(outcome.failure.is_none(), "{outcome:?}");
        outcome.max_speed_m_per_s
    };
    let plain = run(0.0, "plain.mcap");
    let filtered = run(0.3, "filtered.mcap");
    assert!(
        plain > 1.7,
        "without the filter the ramp overshoots: {plain}"
    );
    assert!(filtered < 1.53, "with it the overshoot is gone: {filtered}");
}
