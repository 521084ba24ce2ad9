//! One step of the rapier3d ballbot world at 8 kHz with its controller: the core's 3D cascaded
//! LQR-PI in the loop (`WorldRobot`: outer loop every 20th step, i.e. 400 Hz, on the seeded
//! simulated IMU and encoders; the three motor speed PIs every step), the omniwheel contact
//! model, wheel spin states, floor friction, the rapier step, telemetry and failure checks.
//! The robot balances while it drives a fixed cycle of velocity commands
//! (`common/world_drive.rs`), so accelerating, cruising and turning steps are all measured; in
//! the default (realistic) world and, as the baseline of the same run, in the ideal one.
//!
//! Measured twice: wall-clock time and, with the `_cpu` suffix, the thread's CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`, Unix only), which on a shared machine does not count the time
//! spent waiting for a core. Steps per second on one core = 1 / (median of `_cpu`). Instruction
//! count of the same step: `bash scripts/icount.sh` (`world_step_with_controller`).
//!
//! Run: `cargo bench -p ballbot-benches --bench world_step -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
#[path = "common/world_drive.rs"]
mod world_drive;
use ballbot_core::BallbotParams;
use ballbot_sim::world::WorldParams;
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};
use world_drive::WorldDrive;

fn world_step(c: &mut Criterion) {
    let mut drive = WorldDrive::new().unwrap();
    bench_both(c, "world_step_8khz_with_controller", || {
        drive.step().unwrap().time_secs
    });
    assert_eq!(drive.restarts, 0, "the robot failed during the bench");
    assert!(drive.sim().world().failure().is_none());
    // The default world at a single rate (rapier at every step, the default before the
    // multi-rate world): the baseline of the multi-rate step, measured in the same run.
    let mut single = WorldParams::miapure_60kg();
    single.rigid_step_ratio = 1;
    let mut drive = WorldDrive::with_params(single).unwrap();
    bench_both(c, "world_step_8khz_single_rate", || {
        drive.step().unwrap().time_secs
    });
    assert_eq!(drive.restarts, 0, "the robot failed during the bench");
    // The same drive in the ideal world (the default before the realistic world): the baseline
    // measured in the same run.
    let ideal = WorldParams::ideal(BallbotParams::miapure_60kg());
    let mut drive = WorldDrive::with_params(ideal).unwrap();
    bench_both(c, "world_step_8khz_ideal_world", || {
        drive.step().unwrap().time_secs
    });
    assert_eq!(drive.restarts, 0, "the robot failed during the bench");
}

criterion_group!(benches, world_step);
criterion_main!(benches);
