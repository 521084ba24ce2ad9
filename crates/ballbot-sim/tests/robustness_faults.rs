//! The fault-injection matrix: cells whose outcome the supervisor's
//! documented timeouts predict, the balance-point estimator against the payload shift, logs,
//! determinism.

use ballbot_sim::rig::Outcome;
use ballbot_sim::studies::driver::{Study, replay};
use ballbot_sim::studies::robustness::{
    Cell, CellProtocol, CellResult, Condition, ControllerVariant, FaultClass, FaultMagnitudes,
    FaultMatrixSettings, FaultMatrixStudy, SafeState, run_cell,
};
use ballbot_sim::world::WorldParams;
use std::path::Path;

fn run(controller: ControllerVariant, class: FaultClass, condition: Condition) -> CellResult {
    run_logged(controller, class, condition, None)
}

fn run_logged(
    controller: ControllerVariant,
    class: FaultClass,
    condition: Condition,
    log: Option<&Path>,
) -> CellResult {
    let protocol = CellProtocol {
        moving_inject_secs: 3.0,
        observe_secs: 4.0,
        ..CellProtocol::fault_matrix()
    };
    let cell = Cell {
        controller,
        class,
        condition,
        heading_deg: 90.0,
        seed: 7,
    };
    run_cell(
        &WorldParams::miapure_60kg(),
        &protocol,
        &FaultMagnitudes::fault_matrix(),
        cell,
        log,
    )
    .unwrap()
}

#[test]
fn a_silent_imu_switches_the_motors_off_at_the_stale_timeout() {
    let c = run(
        ControllerVariant::Design,
        FaultClass::ImuStale,
        Condition::Standing,
    );
    assert_eq!(c.observed, SafeState::ProtectiveStop, "{c:?}");
    assert_eq!(c.detected.first(), Some(&"imu_stale"), "{c:?}");
    // The supervisor's 20 ms timeout, to within one outer period.
    let ms = c.time_to_detect_ms.unwrap();
    assert!((20.0..=22.5).contains(&ms), "{ms} ms");
    assert!(c.faults_before_injection.is_empty());
}

#[test]
fn a_lost_link_while_cruising_brakes_to_rest() {
    let c = run(
        ControllerVariant::Design,
        FaultClass::CommandLinkLost,
        Condition::Cruising,
    );
    assert_eq!(c.observed, SafeState::ControlledStop, "{c:?}");
    assert!(!c.fell && c.final_speed_m_per_s < 0.1, "{c:?}");
    let ms = c.time_to_detect_ms.unwrap();
    assert!((250.0..=252.5).contains(&ms), "{ms} ms");
    assert!((c.speed_at_injection_m_per_s - 1.4).abs() < 0.15, "{c:?}");
}

#[test]
fn a_shifted_payload_drives_the_paper_configuration_off_but_not_the_shipped_one() {
    let design = run(
        ControllerVariant::Paper,
        FaultClass::PayloadShift,
        Condition::Standing,
    );
    assert_eq!(design.observed, SafeState::Drifting, "{design:?}");
    assert!(design.final_speed_m_per_s > 0.4, "{design:?}");
    // The shipped controller learns the balance point.
    let learnt = run(
        ControllerVariant::Design,
        FaultClass::PayloadShift,
        Condition::Standing,
    );
    assert_eq!(learnt.observed, SafeState::KeepsBalancing, "{learnt:?}");
}

#[test]
fn an_overrun_is_a_controlled_stop_and_the_cell_is_deterministic() {
    let a = run(
        ControllerVariant::Design,
        FaultClass::LoopOverrun,
        Condition::Standing,
    );
    assert_eq!(a.observed, SafeState::ControlledStop, "{a:?}");
    assert_eq!(a.detected, ["loop_overrun"]);
    let b = run(
        ControllerVariant::Design,
        FaultClass::LoopOverrun,
        Condition::Standing,
    );
    assert_eq!(a, b);
}

/// The matrix as a driver study: a cell replayed with an observer is the cell as
/// `run_cell` runs it, and what happened in it is recorded (the supervisor's stop, no fall).
#[test]
fn a_fault_cell_replays_through_the_driver() {
    let settings = FaultMatrixSettings {
        protocol: CellProtocol {
            moving_inject_secs: 3.0,
            observe_secs: 4.0,
            ..CellProtocol::fault_matrix()
        },
        log_dir: None,
        ..FaultMatrixSettings::quick()
    };
    let world = WorldParams::miapure_60kg();
    let study = FaultMatrixStudy {
        world: &world,
        settings: &settings,
    };
    let cells = study.jobs();
    let i = cells
        .iter()
        .position(|c| c.class == FaultClass::LoopOverrun && c.condition == Condition::Standing)
        .unwrap();
    let mut steps = 0_u64;
    let replayed = replay(&study, i, None, &mut |_| steps += 1)
        .unwrap()
        .unwrap();
    let direct = run_cell(
        &world,
        &settings.protocol,
        &settings.magnitudes,
        cells[i],
        None,
    )
    .unwrap();
    assert_eq!(replayed, direct);
    assert!(steps > 8_000, "{steps}");
    assert_eq!(study.passed(&replayed), replayed.as_expected);
    assert!(
        matches!(replayed.happened.outcome, Outcome::Stopped { .. }),
        "{:?}",
        replayed.happened.outcome
    );
}

#[test]
fn every_faulted_run_writes_a_log_that_reads_back_whole() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("glitch.mcap");
    let c = run_logged(
        ControllerVariant::Design,
        FaultClass::EncoderGlitch,
        Condition::Standing,
        Some(&path),
    );
    let log = c.log.unwrap();
    assert!(log.read_back_whole && log.messages > 100, "{log:?}");
    let read = ballbot_sim::log::McapLog::open(&path).unwrap();
    // The injection is in the log as an event.
    let events: Vec<(f64, serde_json::Value)> =
        read.decode(ballbot_sim::log::topics::FAULTS).unwrap();
    assert!(
        events.iter().any(|(_, e)| e["kind"] == "fault"
            && e["description"]
                .as_str()
                .is_some_and(|d| d.contains("encoder_glitch"))),
        "{events:?}"
    );
}

/// The judge's tilt (the world body's z axis against the vertical) and the supervisor's (from
/// the IMU's roll and pitch) are the same angle: a fall between the axes, 15 deg in roll and
/// in pitch, is 21.1 deg from the vertical for both, and trips the 20 deg tilt limit.
#[test]
fn the_judge_and_the_supervisor_measure_the_same_tilt_from_the_vertical() {
    use ballbot_core::command::Command;
    use ballbot_core::safety::{Fault, Mode, tilt_from_vertical_rad as core_tilt};
    use ballbot_sim::rig::WorldRobot;
    use ballbot_sim::world::failure::tilt_from_vertical_rad as judge_tilt;
    let mut sim = WorldRobot::new(WorldParams::miapure_60kg()).unwrap();
    for _ in 0..800 {
        sim.step(Command::Stop);
    }
    let r = 15f64.to_radians();
    sim.world_mut().tilt_body([r, r]);
    sim.step(Command::Stop);
    let judge = judge_tilt(sim.world().telemetry());
    assert!(
        (judge - core_tilt(r, r)).abs() < 0.2f64.to_radians(),
        "{}",
        judge.to_degrees()
    );
    let m = sim.world_mut().measure();
    let from_imu = core_tilt(m.tilt_rad[0], m.tilt_rad[1]);
    assert!(
        (judge - from_imu).abs() < 0.2f64.to_radians(),
        "{}",
        from_imu.to_degrees()
    );
    assert!(m.tilt_rad.iter().all(|t| t.abs() < 20f64.to_radians()));
    for _ in 0..40 {
        sim.step(Command::Stop);
    }
    assert_eq!(sim.mode(), Mode::Fault);
    let latched = sim.robot().controller().supervisor().latched_faults();
    assert!(latched.contains(Fault::TiltLimit), "{latched}");
}
