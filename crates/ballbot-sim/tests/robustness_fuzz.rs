//! Fuzzing the core (issue 15, section 1): a small campaign finds no bad command, is
//! deterministic in its seed, and the checks can fail: a motor loop without its encoder guard
//! is caught.

use ballbot_core::BallbotParams;
use ballbot_core::ballbot::{BallbotControllerConfig, MotorSpeedLoop};
use ballbot_sim::studies::robustness::fuzz::episode::{EpisodeKind, run_episode_on};
use ballbot_sim::studies::robustness::fuzz::parsers::fuzz_parsers;
use ballbot_sim::studies::robustness::fuzz::rig::FuzzRig;
use ballbot_sim::studies::robustness::{FuzzSettings, run_fuzz};

fn small(seed: u64) -> FuzzSettings {
    FuzzSettings {
        seed,
        hostile_episodes: 2,
        accepted_episodes: 2,
        outer_steps_per_episode: 3_000,
        parser_files: 300,
    }
}

#[test]
fn a_small_campaign_finds_no_panic_and_no_bad_command_and_repeats_from_its_seed() {
    let robot = BallbotParams::miapure_60kg();
    let a = run_fuzz(&robot, &small(5), 2, &|_, _| {}).unwrap();
    assert_eq!((a.panics, a.bad_commands), (0, 0), "{:?}", a.violations);
    assert!(a.outer_steps >= 12_000 && a.inner_steps == 20 * a.outer_steps);
    assert!(
        a.faults_raised.values().sum::<u64>() > 0,
        "the inputs were hostile"
    );
    assert_eq!(a.parsers.files, 300);
    assert_eq!(a, run_fuzz(&robot, &small(5), 1, &|_, _| {}).unwrap());
    let b = run_fuzz(&robot, &small(6), 2, &|_, _| {}).unwrap();
    assert_ne!(a.faults_raised, b.faults_raised);
}

#[test]
fn a_motor_loop_without_its_encoder_guard_is_caught() {
    let config = BallbotControllerConfig::design(&BallbotParams::miapure_60kg()).unwrap();
    let mut rig = FuzzRig::new(config).unwrap();
    // Any acceleration believed: one wrong encoder sample in the 8 kHz loop reaches the PI.
    rig.inner = MotorSpeedLoop::new(&config)
        .unwrap()
        .with_max_wheel_accel_rad_per_s2(1e15)
        .unwrap();
    let caught: u64 = (0..6)
        .map(|seed| run_episode_on(rig, EpisodeKind::Hostile, seed, 12_000).bad_commands)
        .sum();
    assert!(caught > 0, "the fuzzer missed an unguarded motor loop");
    let guarded = FuzzRig::new(config).unwrap();
    let clean: u64 = (0..4)
        .map(|seed| run_episode_on(guarded, EpisodeKind::Hostile, seed, 4_000).bad_commands)
        .sum();
    assert_eq!(clean, 0);
}

#[test]
fn mutated_parameter_files_never_panic_and_errors_name_the_key() {
    let p = fuzz_parsers(3, 400);
    assert_eq!(p.panics, 0);
    assert!(p.rejected > 300, "{p:?}");
    // Most wrong values are named by key; the rest are listed in the report.
    assert!(p.named_the_key * 10 >= p.targeted * 9, "{p:?}");
}
