//! Cost of MCAP logging: the generic [`McapLogger`] writing a typical telemetry message and
//! [`McapLog`] reading the file back into numeric columns, and the 3D world's [`WorldLogger`]
//! recording every step of a [`WorldRobot`] (against the same step unlogged).
//!
//! - `mcap_write_10k_messages`: create a file, write 10,000 messages of a 3-wheel robot state
//!   (about 400 bytes of JSON; default options: zstd chunks), finish it. Per message: median /
//!   10,000.
//! - `mcap_read_10k_messages_to_columns`: open that file and decode its channel into columns
//!   (`McapLog::numeric_series`). Per message: median / 10,000.
//! - `world_step_8khz_unlogged` and `world_step_8khz_logged`: one 8 kHz step of the world with
//!   the core's controller driving the cycle of `common/world_drive.rs` (as bench
//!   `world_step`), without and with `WorldLogger::record_robot` at the default options
//!   (telemetry every step, transforms 100 Hz, scene 50 Hz, controller 400 Hz). The logged
//!   step's file is restarted every 10 simulated seconds so the disk use stays bounded; the
//!   finish and the restart are amortised into the step.
//! - `world_step_8khz_logged_1hz`: the same logged step with the log decimated to 1 Hz
//!   (`telemetry_every_steps` 8000, every channel capped at that rate:
//!   `WorldLogOptions::capped_at_telemetry_rate`, what `ballbot world --decimate 8000` writes);
//!   against `world_step_8khz_unlogged`, what such a log costs between the steps it writes.
//!
//! The bytes per message on disk are printed once. Every bench is measured twice: wall-clock
//! time and, with the `_cpu` suffix, the thread's CPU time (Unix only).
//!
//! Run: `cargo bench -p ballbot-benches --bench mcap_log -- --warm-up-time 1 --measurement-time 2`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
#[path = "common/world_drive.rs"]
mod world_drive;
use ballbot_sim::log::{LoggerOptions, McapLog, McapLogger, WorldLogOptions, WorldLogger};
use ballbot_sim::world::WorldParams;
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};
use schemars::JsonSchema;
use serde::Serialize;
use std::path::Path;
use world_drive::WorldDrive;

/// Messages written (and read back) per iteration of the MCAP benches.
const MESSAGES: u64 = 10_000;

/// Steps written into one world log before it is finished and restarted (10 s at 8 kHz).
const WORLD_STEPS_PER_FILE: u64 = 80_000;

/// One omniwheel's contact telemetry.
#[derive(Debug, Clone, Serialize, JsonSchema)]
struct WheelTelemetry {
    /// Normal force at the wheel contact (N).
    normal_force_n: f64,
    /// Traction along the rolling direction (N).
    traction_n: f64,
    /// Whether the wheel slips.
    slipping: bool,
}

/// A typical telemetry message: tilt, ball rate, three wheels, mode, step counter.
#[derive(Debug, Clone, Serialize, JsonSchema)]
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

/// The state at control step `step` of a 400 Hz run (full-precision, varying floats).
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

/// Writes `states` to a fresh file at `path` on `/robot/state`, one per 400 Hz step.
fn write_states(path: &Path, states: &[RobotState]) {
    let mut log = McapLogger::create(path, LoggerOptions::default()).unwrap();
    let channel = log.channel::<RobotState>("/robot/state").unwrap();
    for (step, state) in states.iter().enumerate() {
        log.write(&channel, step as f64 * 2.5e-3, state).unwrap();
    }
    log.finish().unwrap();
}

fn mcap(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let states: Vec<RobotState> = (0..MESSAGES).map(state_at).collect();

    let write_path = dir.path().join("write.mcap");
    bench_both(c, "mcap_write_10k_messages", || {
        write_states(&write_path, &states)
    });

    let read_path = dir.path().join("read.mcap");
    write_states(&read_path, &states);
    let bytes = std::fs::metadata(&read_path).unwrap().len();
    let json_bytes = serde_json::to_vec(&states[1]).unwrap().len();
    println!(
        "mcap_log: {:.1} bytes per message on disk ({json_bytes} bytes of JSON, zstd chunks)",
        bytes as f64 / MESSAGES as f64
    );
    bench_both(c, "mcap_read_10k_messages_to_columns", || {
        let series = McapLog::open(&read_path)
            .unwrap()
            .numeric_series("/robot/state")
            .unwrap();
        assert_eq!(series.len() as u64, MESSAGES);
        series
    });
}

fn world(c: &mut Criterion) {
    let mut drive = WorldDrive::new().unwrap();
    bench_both(c, "world_step_8khz_unlogged", || {
        drive.step().unwrap().time_secs
    });
    assert_eq!(drive.restarts, 0, "the robot failed during the bench");

    bench_logged(c, "world_step_8khz_logged", WorldLogOptions::default());
    let dt_secs = WorldParams::miapure_60kg().dt_secs;
    let one_hz = WorldLogOptions {
        telemetry_every_steps: 8000,
        ..WorldLogOptions::default()
    }
    .capped_at_telemetry_rate(dt_secs);
    bench_logged(c, "world_step_8khz_logged_1hz", one_hz);
}

/// Benches the world's step logged with `options` as `name` (and `name_cpu`), and prints the
/// bytes per step of the last file.
fn bench_logged(c: &mut Criterion, name: &str, options: WorldLogOptions) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("world.mcap");
    let params = WorldParams::miapure_60kg();
    let create = || WorldLogger::with_options(&path, &params, options.clone()).unwrap();
    let mut drive = WorldDrive::new().unwrap();
    let mut log = Some(create());
    let mut steps_in_file = 0_u64;
    bench_both(c, name, || {
        let time_secs = drive.step().unwrap().time_secs;
        if steps_in_file == WORLD_STEPS_PER_FILE {
            log.take().unwrap().finish().unwrap();
            log = Some(create());
            steps_in_file = 0;
        }
        log.as_mut().unwrap().record_robot(drive.sim()).unwrap();
        steps_in_file += 1;
        time_secs
    });
    assert_eq!(drive.restarts, 0, "the robot failed during the bench");
    let channels = log.take().unwrap().finish().unwrap();
    let messages: u64 = channels.iter().map(|channel| channel.message_count).sum();
    let bytes = std::fs::metadata(&path).unwrap().len();
    // A bench left out by a filter logged no step.
    if steps_in_file > 0 {
        println!(
            "{name}: {:.1} bytes per logged step on disk (last file: {steps_in_file} steps, {messages} messages)",
            bytes as f64 / steps_in_file as f64
        );
    }
}

criterion_group! {
    name = mcap_benches;
    // One iteration writes or reads 10,000 messages (milliseconds): ten samples suffice.
    config = Criterion::default().sample_size(10);
    targets = mcap
}
criterion_group!(world_benches, world);
criterion_main!(mcap_benches, world_benches);
