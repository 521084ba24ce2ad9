//! The robot loop on the simulated robot: the demonstration's outcome, a lost IMU, and
//! start-up refusing a tilted body.

#![allow(clippy::unwrap_used)]

use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::Command;
use ballbot_core::safety::{Fault, FaultSet, Mode, ModeRequest};
use ballbot_core::wip::TILT;
use ballbot_examples::demo::{self, Timeline};
use ballbot_examples::sim::{SimPlant, devices, run_until};
use ballbot_runtime::{LoopConfig, OperatorInput, Phase, RobotLoop};
use core::cell::RefCell;

#[derive(Clone, Copy, Debug)]
struct Sample {
    t_us: u64,
    phase: Phase,
    mode: Mode,
    link_lost: bool,
    vx: f64,
    vy: f64,
    tilt_deg: f64,
    peak_ff_nm: f64,
    motors_on: bool,
}

fn demo_samples() -> Vec<Sample> {
    let mut samples = Vec::new();
    demo::run(
        &BallbotParams::miapure_60kg(),
        &Timeline::DEFAULT,
        |r, plant| {
            let (vx, vy) = plant.body_velocity_m_per_s();
            samples.push(Sample {
                t_us: r.now_us,
                phase: r.phase,
                mode: r.output.safety.mode,
                link_lost: r.output.safety.faults.contains(Fault::CommandLinkLost),
                vx,
                vy,
                tilt_deg: plant.states.sagittal[TILT]
                    .abs()
                    .max(plant.states.frontal[TILT].abs())
                    .to_degrees(),
                peak_ff_nm: r.output.motors.feedforward_torque_nm.amax(),
                motors_on: plant.motors_enabled,
            });
        },
    )
    .unwrap();
    samples
}

fn at(samples: &[Sample], t_us: u64) -> Sample {
    *samples.iter().find(|s| s.t_us >= t_us).unwrap()
}

#[test]
fn demo_arms_drives_stops_on_a_lost_link_and_shuts_down() {
    let s = demo_samples();
    let t = Timeline::DEFAULT;
    // Armed after the 0.25 s settle, not before.
    let armed = s.iter().find(|x| x.mode == Mode::Balancing).unwrap();
    assert!(
        (250_000..=260_000).contains(&armed.t_us),
        "armed at {} us",
        armed.t_us
    );
    assert_eq!(armed.phase, Phase::Running);
    // Driving: 0.8 m/s commanded, cruising within 0.2 m/s of it just before the curve.
    let cruise = at(&s, t.curve_us - 10_000);
    assert!((cruise.vx - 0.8).abs() < 0.2, "vx {}", cruise.vx);
    assert!(cruise.vy.abs() < 1e-3);
    // The link is lost at 3.5 s; 250 ms later the fault is reported and a controlled stop
    // starts, motors on.
    let lost = s.iter().find(|x| x.link_lost).unwrap();
    assert!(
        (t.link_lost_us + 240_000..=t.link_lost_us + 260_000).contains(&lost.t_us),
        "fault at {} us",
        lost.t_us
    );
    assert_eq!(lost.mode, Mode::ControlledStop);
    assert!(lost.motors_on);
    // Before the link is back the robot is at rest, upright, still balancing.
    let rest = at(&s, t.link_back_us - 2_500);
    assert_eq!(rest.mode, Mode::ControlledStop);
    assert!(rest.vx.abs() < 0.05 && rest.vy.abs() < 0.05, "{rest:?}");
    assert!(rest.tilt_deg < 1.0, "{rest:?}");
    // Balancing never dropped the body beyond 10 deg, torques stayed in the limits.
    let balancing = s.iter().filter(|x| x.mode.motors_enabled());
    assert!(balancing.clone().all(|x| x.tilt_deg < 10.0));
    assert!(balancing.clone().all(|x| x.peak_ff_nm <= 43.2));
    // Resumed, then shut down: off, motors disabled.
    assert_eq!(at(&s, t.link_back_us).mode, Mode::Balancing);
    let last = s.last().unwrap();
    assert_eq!(last.phase, Phase::Off);
    assert_eq!(last.mode, Mode::Idle);
    assert!(!last.motors_on);
    // It disarmed from rest, upright.
    let off = s.iter().find(|x| x.phase == Phase::Off).unwrap();
    assert!(off.t_us >= t.shutdown_us);
    assert!(off.vx.abs() < 0.05 && off.tilt_deg < 1.0, "{off:?}");
}

/// Runs a loop on `plant` standing still with the link up, in segments: before segment `k`
/// (ending at `ends_us[k]`), `inject(k, plant)`. Returns the phase, mode, latched faults and
/// whether the motors are on at the end of each segment.
fn run_segments(
    plant: &RefCell<SimPlant>,
    ends_us: &[u64],
    mut inject: impl FnMut(usize, &mut SimPlant),
) -> Vec<(Phase, Mode, FaultSet, bool)> {
    let robot = BallbotParams::miapure_60kg();
    let (imu, enc, mot, clk) = devices(plant);
    let config = LoopConfig::miapure();
    let controller = BallbotControllerConfig::design(&robot).unwrap();
    let mut lp = RobotLoop::new(controller, config, imu, enc, mot, clk).unwrap();
    let mut out = Vec::new();
    for (k, &end_us) in ends_us.iter().enumerate() {
        inject(k, &mut plant.borrow_mut());
        run_until(
            plant,
            &mut lp,
            &config,
            end_us,
            |now_us, _, _| OperatorInput {
                command: Command::Stop,
                command_timestamp_us: Some(now_us),
                request: ModeRequest::None,
            },
            |_, _| {},
        )
        .unwrap();
        out.push((
            lp.phase(),
            lp.mode(),
            lp.controller().supervisor().latched_faults(),
            plant.borrow().motors_enabled,
        ));
    }
    out
}

#[test]
fn a_silent_imu_is_stale_after_its_timeout_and_disables_the_motors() {
    let plant = RefCell::new(SimPlant::new(&BallbotParams::miapure_60kg()).unwrap());
    let r = run_segments(&plant, &[500_000, 510_000, 600_000], |k, p| {
        p.faults.imu_silent = k >= 1;
    });
    assert_eq!(
        (r[0].0, r[0].1, r[0].3),
        (Phase::Running, Mode::Balancing, true)
    );
    // 10 ms of silence: still within the 20 ms timeout, still balancing on the held sample.
    assert_eq!(r[1].1, Mode::Balancing);
    assert!(r[1].3);
    // Then stale: unrecoverable, motors off.
    assert_eq!(r[2].1, Mode::Fault);
    assert!(r[2].2.contains(Fault::ImuStale));
    assert!(!r[2].3);
}

#[test]
fn a_nan_imu_sample_starts_a_controlled_stop_that_keeps_balancing() {
    let plant = RefCell::new(SimPlant::new(&BallbotParams::miapure_60kg()).unwrap());
    // One outer period of NaN samples, then good ones again.
    let r = run_segments(&plant, &[500_000, 502_500, 1_500_000], |k, p| {
        p.faults.imu_nan = k == 1;
    });
    assert_eq!(r[0].1, Mode::Balancing);
    assert_eq!(r[1].1, Mode::ControlledStop);
    assert!(r[1].2.contains(Fault::ImuNonFinite));
    assert_eq!(r[2].1, Mode::ControlledStop);
    assert!(r[2].3, "motors stay on");
    let s = plant.borrow().states;
    assert!(s.sagittal[TILT].abs() < 0.01 && s.frontal[TILT].abs() < 0.01);
}

#[test]
fn start_up_does_not_arm_a_tilted_body() {
    let plant = RefCell::new(SimPlant::new(&BallbotParams::miapure_60kg()).unwrap());
    // 5 deg: beyond the 3 deg arming limit (the unsupported body falls further).
    plant.borrow_mut().states.sagittal[TILT] = 5f64.to_radians();
    let r = run_segments(&plant, &[400_000], |_, _| {});
    assert_eq!(
        (r[0].0, r[0].1, r[0].3),
        (Phase::StartingUp, Mode::Idle, false)
    );
}

#[test]
fn start_up_waits_the_settle_time_before_arming() {
    let plant = RefCell::new(SimPlant::new(&BallbotParams::miapure_60kg()).unwrap());
    let r = run_segments(&plant, &[247_500, 252_500], |_, _| {});
    assert_eq!(r[0].1, Mode::Idle);
    assert_eq!(r[1].1, Mode::Balancing);
}
