//! MCAP logging: round trip with the `mcap` crate's readers, recovery after SIGKILL, schemas.

mod layout;

use std::{
    collections::{BTreeMap, BTreeSet},
    io::{BufRead, BufReader},
    path::Path,
    process::{Command, Stdio},
};

use ballbot_sim::log::{
    LogCompression, LogError, LoggerOptions, McapLog, McapLogger, check_message, check_schema,
    foxglove::{BallbotScene, FrameTransform, FrameTransforms, SceneUpdate, WheelContact},
    ns_to_secs, schema_for, secs_to_ns,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
struct WheelTelemetry {
    /// Normal force at the wheel contact (N).
    normal_force_n: f64,
    /// Traction along the rolling direction (N).
    traction_n: f64,
    /// Whether the wheel slips.
    slipping: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
struct RobotState {
    /// Body tilt (rad).
    tilt_rad: f64,
    /// Ball rate (rad/s).
    ball_rate_rad_per_s: f64,
    /// Per-wheel contact telemetry.
    wheels: [WheelTelemetry; 3],
    /// Controller mode.
    mode: String,
    /// Control step counter.
    step: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
struct SpeedCommand {
    /// Commanded ball speed (m/s).
    speed_m_per_s: f64,
}

fn state_at(step: u64) -> RobotState {
    let time_secs = step as f64 * 2.5e-3;
    let wheel = |i: u32| WheelTelemetry {
        normal_force_n: 200.0 + f64::from(i) * 10.0 + (7.0 * time_secs).sin(),
        traction_n: (3.0 * time_secs + f64::from(i)).cos(),
        slipping: step % 17 == u64::from(i),
    };
    RobotState {
        tilt_rad: 0.02 * (2.0 * time_secs).sin(),
        ball_rate_rad_per_s: time_secs.min(1.0) / 0.12,
        wheels: [wheel(0), wheel(1), wheel(2)],
        mode: if step < 500 { "balance" } else { "brake" }.to_owned(),
        step,
    }
}

/// The wheel contacts of [`state_at`], for the scene's contact-force arrows.
fn contacts_at(step: u64) -> Vec<WheelContact> {
    state_at(step)
        .wheels
        .iter()
        .map(|w| WheelContact {
            normal_force_n: w.normal_force_n,
            traction_n: w.traction_n,
            slipping: w.slipping,
        })
        .collect()
}

/// Writes a 3 s run: state at 400 Hz, command at 50 Hz, 3D transforms at 100 Hz, the scene at
/// 10 Hz, and one channel that never gets a message. Returns the number written per topic.
fn write_run(path: &Path, options: LoggerOptions) -> BTreeMap<String, u64> {
    let mut log = McapLogger::create(path, options).unwrap();
    let state = log.channel::<RobotState>("/robot/state").unwrap();
    let command = log.channel::<SpeedCommand>("/robot/command").unwrap();
    let tf = log.foxglove_channel::<FrameTransforms>("/tf").unwrap();
    let single_tf = log.foxglove_channel::<FrameTransform>("/tf_body").unwrap();
    let scene = log.foxglove_channel::<SceneUpdate>("/scene").unwrap();
    let _faults = log.channel::<SpeedCommand>("/faults").unwrap();
    let robot = BallbotScene::miapure_like();
    for step in 0..1200_u64 {
        let time_secs = step as f64 * 2.5e-3;
        log.write(&state, time_secs, &state_at(step)).unwrap();
        if step % 8 == 0 {
            let speed_m_per_s = (time_secs / 2.0).min(1.0);
            log.write(&command, time_secs, &SpeedCommand { speed_m_per_s })
                .unwrap();
        }
        if step % 4 == 0 {
            let x_m = 0.3 * time_secs;
            let world_from_ball = Isometry3::from_parts(
                Translation3::new(x_m, 0.0, robot.ball_radius_m),
                UnitQuaternion::from_axis_angle(&Vector3::y_axis(), x_m / robot.ball_radius_m),
            );
            let world_from_body = Isometry3::from_parts(
                Translation3::new(x_m, 0.0, robot.ball_radius_m),
                UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.05),
            );
            let frames = robot.frames(time_secs, &world_from_ball, &world_from_body);
            log.write(&single_tf, time_secs, &frames.transforms[1])
                .unwrap();
            log.write(&tf, time_secs, &frames).unwrap();
        }
        if step % 40 == 0 {
            let mut update = robot.scene(time_secs);
            update
                .entities
                .push(robot.contact_forces(time_secs, &contacts_at(step), 0.002));
            log.write(&scene, time_secs, &update).unwrap();
        }
    }
    let channels = log.finish().unwrap();
    channels
        .into_iter()
        .map(|c| (c.topic, c.message_count))
        .collect()
}

fn expected_counts() -> BTreeMap<String, u64> {
    [
        ("/robot/state", 1200),
        ("/robot/command", 150),
        ("/tf", 300),
        ("/tf_body", 300),
        ("/scene", 30),
        ("/faults", 0),
    ]
    .into_iter()
    .map(|(t, n)| (t.to_owned(), n))
    .collect()
}

/// Whether `write_run` writes the topic with a Foxglove SDK message (protobuf).
fn is_foxglove(topic: &str) -> bool {
    ["/tf", "/tf_body", "/scene"].contains(&topic)
}

fn small_chunks() -> LoggerOptions {
    LoggerOptions {
        chunk_size_bytes: 16 * 1024,
        flush_interval_secs: 0.25,
        compression: LogCompression::Zstd,
    }
}

#[test]
fn round_trip_keeps_every_channel_and_message_count() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let written = write_run(&path, small_chunks());
    assert_eq!(written, expected_counts());

    // Our reader.
    let log = McapLog::open(&path).unwrap();
    assert!(log.is_complete(), "{:?}", log.stop_reason());
    let read: BTreeMap<String, u64> = log
        .channels()
        .iter()
        .map(|c| (c.topic.clone(), c.message_count))
        .collect();
    assert_eq!(read, expected_counts());
    for channel in log.channels() {
        let encodings = (
            channel.schema_encoding.as_str(),
            channel.message_encoding.as_str(),
        );
        if is_foxglove(&channel.topic) {
            assert_eq!(encodings, ("protobuf", "protobuf"), "{}", channel.topic);
        } else {
            assert_eq!(encodings, ("jsonschema", "json"), "{}", channel.topic);
        }
    }
    assert_eq!(
        log.channel("/robot/state").unwrap().schema_name,
        "ballbot.RobotState"
    );
    assert_eq!(
        log.channel("/tf").unwrap().schema_name,
        "foxglove.FrameTransforms"
    );
    assert_eq!(
        log.channel("/tf_body").unwrap().schema_name,
        "foxglove.FrameTransform"
    );
    assert_eq!(
        log.channel("/scene").unwrap().schema_name,
        "foxglove.SceneUpdate"
    );

    // Typed values and times come back exactly.
    let states = log.decode::<RobotState>("/robot/state").unwrap();
    for (step, (time_secs, state)) in states.iter().enumerate() {
        let expected_secs = step as f64 * 2.5e-3;
        assert_eq!(*time_secs, ns_to_secs(secs_to_ns(expected_secs).unwrap()));
        assert!((time_secs - expected_secs).abs() < 1e-12);
        assert_eq!(*state, state_at(step as u64));
    }

    // Numeric columns, as the Python package gets them.
    let series = log.numeric_series("/robot/state").unwrap();
    assert_eq!(series.len(), 1200);
    let names: Vec<&str> = series.columns.keys().map(String::as_str).collect();
    assert!(names.contains(&"wheels[2].normal_force_n"));
    assert!(!names.contains(&"mode"), "strings are not numeric columns");
    let normal = series.column("wheels[2].normal_force_n").unwrap();
    assert_eq!(normal[100], state_at(100).wheels[2].normal_force_n);
    assert_eq!(series.column("wheels[1].slipping").unwrap()[18], 1.0);
    assert_eq!(series.column("step").unwrap()[1199], 1199.0);
    let (times, normal_again) = log.field("/robot/state.wheels[2].normal_force_n").unwrap();
    assert_eq!(normal_again, normal);
    assert_eq!(times, series.time_secs);
    assert!(matches!(
        log.field("/robot/state.wheels[3].normal_force_n"),
        Err(LogError::NoSuchField { .. })
    ));
    assert!(matches!(
        log.field("/robot/stat.tilt_rad"),
        Err(LogError::NoSuchTopic { .. })
    ));
    let empty = log.numeric_series("/faults").unwrap();
    assert!(empty.is_empty() && empty.columns.is_empty());

    // The mcap crate's own strict readers agree: summary statistics and a full message stream.
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let stats = summary.stats.unwrap();
    assert_eq!(stats.message_count, 1200 + 150 + 300 + 300 + 30);
    assert_eq!(stats.channel_count, 6);
    assert!(stats.chunk_count > 5, "small chunks: {}", stats.chunk_count);
    let mut streamed: BTreeMap<String, u64> =
        expected_counts().keys().map(|t| (t.clone(), 0)).collect();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        *streamed.get_mut(&message.channel.topic).unwrap() += 1;
        let schema = message.channel.schema.as_ref().unwrap();
        let expected = if is_foxglove(&message.channel.topic) {
            "protobuf"
        } else {
            "jsonschema"
        };
        assert_eq!(schema.encoding, expected);
    }
    assert_eq!(streamed, expected_counts());
}

#[test]
fn same_messages_give_a_bit_identical_file() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.mcap");
    let b = dir.path().join("b.mcap");
    write_run(&a, LoggerOptions::default());
    write_run(&b, LoggerOptions::default());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let uncompressed = dir.path().join("plain.mcap");
    write_run(
        &uncompressed,
        LoggerOptions {
            compression: LogCompression::None,
            ..LoggerOptions::default()
        },
    );
    let compressed_len = std::fs::metadata(&a).unwrap().len();
    let plain_len = std::fs::metadata(&uncompressed).unwrap().len();
    assert!(
        compressed_len * 4 < plain_len,
        "zstd {compressed_len} B vs plain {plain_len} B"
    );
}

#[test]
fn every_schema_is_valid_and_describes_every_logged_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("schemas.mcap");
    write_run(&path, LoggerOptions::default());
    let log = McapLog::open(&path).unwrap();
    for channel in log.channels() {
        let Some(text) = channel.schema_text() else {
            assert!(is_foxglove(&channel.topic), "{}", channel.topic);
            continue;
        };
        let schema: Value = serde_json::from_str(text).unwrap();
        assert_eq!(
            schema["$schema"], "http://json-schema.org/draft-07/schema#",
            "{}",
            channel.topic
        );
        assert_eq!(schema["type"], "object", "{}", channel.topic);
        check_schema(&schema).unwrap_or_else(|e| panic!("{}: {e}", channel.topic));
        for (i, message) in log
            .json_series(&channel.topic)
            .unwrap()
            .values
            .iter()
            .enumerate()
        {
            check_message(&schema, message)
                .unwrap_or_else(|e| panic!("{} message {i}: {e}", channel.topic));
        }
    }
    // The checker does catch a schema that misses a field and a field of the wrong type.
    let schema = schema_for::<SpeedCommand>();
    assert!(check_message(&schema, &serde_json::json!({"speed_m_per_s": 1.0})).is_ok());
    assert!(check_message(&schema, &serde_json::json!({"speed_m_per_s": true})).is_err());
    assert!(
        check_message(
            &schema,
            &serde_json::json!({"speed_m_per_s": 1.0, "extra": 2})
        )
        .is_err()
    );
    assert!(check_message(&schema, &serde_json::json!({})).is_err());
}

/// The field names of a JSON object.
fn keys(value: &Value) -> BTreeSet<&str> {
    value
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect()
}

#[test]
fn foxglove_messages_read_back_with_the_published_field_names() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("foxglove.mcap");
    write_run(&path, LoggerOptions::default());
    let log = McapLog::open(&path).unwrap();
    // Exactly as written, through the SDK's own protobuf decoding.
    let robot = BallbotScene::miapure_like();
    let scenes = log.decode_protobuf::<SceneUpdate>("/scene").unwrap();
    assert_eq!(scenes.len(), 30);
    let (time_secs, first) = &scenes[1];
    assert_eq!(*time_secs, 0.1);
    let mut expected = robot.scene(0.1);
    expected
        .entities
        .push(robot.contact_forces(0.1, &contacts_at(40), 0.002));
    assert_eq!(*first, expected);
    // As JSON, the field names of the Foxglove schemas (what its panels and Python see).
    let tf = &log.json_series("/tf_body").unwrap().values[3];
    assert_eq!(
        keys(tf),
        BTreeSet::from([
            "timestamp",
            "parent_frame_id",
            "child_frame_id",
            "translation",
            "rotation"
        ])
    );
    assert_eq!(keys(&tf["timestamp"]), BTreeSet::from(["sec", "nsec"]));
    assert_eq!(keys(&tf["rotation"]), BTreeSet::from(["x", "y", "z", "w"]));
    let scene = &log.json_series("/scene").unwrap().values[0];
    let body = &scene["entities"][1];
    assert_eq!(body["id"], "body");
    assert_eq!(
        keys(&body["cylinders"][0]),
        BTreeSet::from(["pose", "size", "bottom_scale", "top_scale", "color"])
    );
    // Numeric columns of a protobuf channel, by the same message paths.
    let (_, ball_z) = log.field("/tf.transforms[0].translation.z").unwrap();
    assert_eq!(ball_z.len(), 300);
    assert!(
        ball_z
            .iter()
            .all(|z| (z - robot.ball_radius_m).abs() < 1e-12)
    );
}

#[test]
fn misuse_is_reported_with_the_file_name() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("misuse.mcap");
    let mut log = McapLogger::create(&path, LoggerOptions::default()).unwrap();
    let command = log.channel::<SpeedCommand>("/command").unwrap();
    let duplicate = log.channel::<SpeedCommand>("/command").unwrap_err();
    assert!(matches!(duplicate, LogError::DuplicateTopic { .. }));
    assert!(duplicate.to_string().contains("misuse.mcap"));
    let bad_time = log
        .write(&command, -0.5, &SpeedCommand { speed_m_per_s: 0.0 })
        .unwrap_err();
    assert!(
        matches!(bad_time, LogError::InvalidTime { .. }),
        "{bad_time}"
    );
    let bad_time = log
        .write(&command, f64::NAN, &SpeedCommand { speed_m_per_s: 0.0 })
        .unwrap_err();
    assert!(
        matches!(bad_time, LogError::InvalidTime { .. }),
        "{bad_time}"
    );

    let other_path = dir.path().join("other.mcap");
    let mut other = McapLogger::create(&other_path, LoggerOptions::default()).unwrap();
    let foreign = other
        .write(&command, 0.0, &SpeedCommand { speed_m_per_s: 0.0 })
        .unwrap_err();
    assert!(
        matches!(foreign, LogError::ForeignChannel { .. }),
        "{foreign}"
    );
    other.finish().unwrap();

    // NaN is logged as null and read back as NaN.
    log.write(
        &command,
        1.0,
        &SpeedCommand {
            speed_m_per_s: f64::NAN,
        },
    )
    .unwrap();
    log.finish().unwrap();
    let read = McapLog::open(&path).unwrap();
    assert!(
        read.numeric_series("/command")
            .unwrap()
            .column("speed_m_per_s")
            .unwrap()[0]
            .is_nan()
    );
    let missing = read.numeric_series("/nothing").unwrap_err();
    assert!(matches!(missing, LogError::NoSuchTopic { .. }));

    // Dropping a logger without `finish` still completes the file.
    let dropped = dir.path().join("dropped.mcap");
    {
        let mut log = McapLogger::create(&dropped, LoggerOptions::default()).unwrap();
        let command = log.channel::<SpeedCommand>("/command").unwrap();
        for i in 0..10 {
            log.write(&command, f64::from(i), &SpeedCommand { speed_m_per_s: 1.0 })
                .unwrap();
        }
    }
    let read = McapLog::open(&dropped).unwrap();
    assert!(read.is_complete());
    assert_eq!(read.message_count(), 10);

    let absent = McapLog::open(dir.path().join("absent.mcap")).unwrap_err();
    assert!(matches!(absent, LogError::Io { .. }));
    assert!(absent.to_string().contains("absent.mcap"));
    let not_mcap = dir.path().join("not.mcap");
    std::fs::write(&not_mcap, b"this is not an MCAP file at all").unwrap();
    assert!(matches!(
        McapLog::open(&not_mcap),
        Err(LogError::Mcap { .. })
    ));
}

/// Environment variable telling [`killed_writer_child`] where to write.
const CHILD_PATH_VAR: &str = "BALLBOT_LOGVIZ_KILLED_WRITER_PATH";
/// Environment variable telling [`killed_writer_child`] to write uncompressed chunks.
const CHILD_PLAIN_VAR: &str = "BALLBOT_LOGVIZ_KILLED_WRITER_PLAIN";
/// Messages per simulated second in the child.
const CHILD_RATE_HZ: u64 = 1000;
/// The child's flush interval (simulated seconds) and chunk bound.
const CHILD_FLUSH_SECS: f64 = 0.1;

/// The child process of [`run_killed_midway_is_still_readable`]: writes a log until killed,
/// printing how many messages it has written. Does nothing unless started by that test.
#[test]
#[ignore = "helper process for run_killed_midway_is_still_readable"]
fn killed_writer_child() {
    let Ok(path) = std::env::var(CHILD_PATH_VAR) else {
        return;
    };
    let mut log = McapLogger::create(
        path,
        LoggerOptions {
            // Far above what 0.1 s of messages fills (about 100 kB): only the periodic flush
            // closes chunks, so what survives the kill is what the flush interval promises.
            // (With 64 KiB chunks closing on size every ~65 steps, a writer flushing every
            // 0.2 s instead of 0.1 s passed.)
            chunk_size_bytes: 64 * 1024 * 1024,
            flush_interval_secs: CHILD_FLUSH_SECS,
            compression: if std::env::var_os(CHILD_PLAIN_VAR).is_some() {
                LogCompression::None
            } else {
                LogCompression::Zstd
            },
        },
    )
    .unwrap();
    let state = log.channel::<RobotState>("/robot/state").unwrap();
    let command = log.channel::<SpeedCommand>("/robot/command").unwrap();
    // Bounded: the parent kills it long before this ends (about 100 s of wall time).
    for step in 0..100 * CHILD_RATE_HZ * 10 {
        let time_secs = step as f64 / CHILD_RATE_HZ as f64;
        log.write(&state, time_secs, &state_at(step)).unwrap();
        log.write(
            &command,
            time_secs,
            &SpeedCommand {
                speed_m_per_s: step as f64,
            },
        )
        .unwrap();
        if step % 100 == 99 {
            println!("LOGVIZ_WRITTEN {}", step + 1);
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
}

#[test]
fn run_killed_midway_is_still_readable() {
    killed_midway(LogCompression::Zstd);
}

#[test]
fn uncompressed_run_killed_midway_is_still_readable() {
    killed_midway(LogCompression::None);
}

fn killed_midway(compression: LogCompression) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("killed.mcap");
    let mut command = Command::new(std::env::current_exe().unwrap());
    if compression == LogCompression::None {
        command.env(CHILD_PLAIN_VAR, "1");
    }
    let mut child = command
        .args([
            "--exact",
            "log::killed_writer_child",
            "--ignored",
            "--nocapture",
        ])
        .args(["--test-threads", "1"])
        .env(CHILD_PATH_VAR, &path)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let mut written_before_kill = 0_u64;
    for line in BufReader::new(stdout).lines() {
        let line = line.unwrap();
        if let Some(count) = line.split("LOGVIZ_WRITTEN ").nth(1) {
            written_before_kill = count.trim().parse().unwrap();
            // 2900 reported (t = 2.899 s) guarantees the flush at 2.8 s, an even multiple of
            // the 0.1 s interval, which a writer flushing at odd tenths only would miss.
            if written_before_kill >= 2900 {
                break;
            }
        }
    }
    // SIGKILL: no destructor, no summary, no footer; the open chunk is lost.
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success());
    assert!(
        written_before_kill >= 2900,
        "the child wrote {written_before_kill} messages"
    );

    let bytes = std::fs::read(&path).unwrap();
    assert!(
        mcap::MessageStream::new(&bytes)
            .unwrap()
            .any(|m| m.is_err()),
        "a strict reader must reject the truncated file, else the test kills nothing"
    );
    assert!(mcap::Summary::read(&bytes).is_err() || mcap::Summary::read(&bytes).unwrap().is_none());

    let log = McapLog::open(&path).unwrap();
    assert!(!log.is_complete());
    assert!(log.stop_reason().is_some());
    // Every message written before the last flush preceding the last report is there.
    let flushed_secs = ((written_before_kill - 1) as f64 / CHILD_RATE_HZ as f64 / CHILD_FLUSH_SECS)
        .floor()
        * CHILD_FLUSH_SECS;
    let guaranteed = (flushed_secs * CHILD_RATE_HZ as f64) as u64;
    let states = log.decode::<RobotState>("/robot/state").unwrap();
    println!(
        "{compression:?}: killed after {written_before_kill} reported steps; {} recovered ({guaranteed} guaranteed); stop: {:?}",
        states.len(),
        log.stop_reason()
    );
    let commands = log.decode::<SpeedCommand>("/robot/command").unwrap();
    assert!(
        states.len() as u64 >= guaranteed,
        "recovered {} states, {guaranteed} were flushed",
        states.len()
    );
    // The recovered messages are exactly a prefix of what was written, in order, intact.
    for (step, (time_secs, state)) in states.iter().enumerate() {
        assert_eq!(*state, state_at(step as u64));
        assert!((time_secs - step as f64 / CHILD_RATE_HZ as f64).abs() < 1e-9);
    }
    for (step, (_, command)) in commands.iter().enumerate() {
        assert_eq!(command.speed_m_per_s, step as f64);
    }
    assert!(commands.len().abs_diff(states.len()) <= 1);
    assert_eq!(
        log.channel("/robot/state").unwrap().message_count,
        states.len() as u64
    );
}
