//! Motor health in the world: a dead or stuck OW1 (the fault matrix's injector) is detected
//! from the drivers' feedback within the monitor's stated latency, and a healthy robot driven
//! hard (steps, reversals, a push; the ODrive driver model and the ideal one) never is.

use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::{Fault, Mode, MotorHealthParams};
use ballbot_core::{ActuatorParams, BallbotParams};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::studies::robustness::{FaultClass, FaultInjector, FaultMagnitudes};
use ballbot_sim::world::WorldParams;
use nalgebra::Vector3;

const DT_SECS: f64 = 1.0 / 8000.0;

fn motor_faults(sim: &WorldRobot) -> Vec<Fault> {
    sim.robot()
        .controller()
        .supervisor()
        .latched_faults()
        .iter()
        .filter(|f| {
            matches!(
                f,
                Fault::MotorDead | Fault::MotorStuck | Fault::MotorTripped
            )
        })
        .collect()
}

fn along_y(speed_m_per_s: f64) -> Command<'static, f64> {
    Command::Velocity(VelocityCommand {
        vx_m_per_s: 0.0,
        vy_m_per_s: speed_m_per_s,
        yaw_rate_rad_per_s: 0.0,
    })
}

/// What one faulted run saw: OW1's commanded torque per inner step from the injection on, and
/// the step (counted from the injection) at which the monitor's fault was latched.
struct Faulted {
    command_nm: Vec<f64>,
    detected_at: Option<(usize, Fault)>,
    mode_after: Mode,
}

/// Drives along +y (90 deg, where OW1 works hardest) at 0.8 m/s from 0.5 s, injects `class` on
/// OW1 at `inject_us` (while accelerating at 0.6 s, cruising at 2 s), runs 1.5 s more.
fn faulted_run(class: FaultClass, inject_us: u64) -> Faulted {
    let params = WorldParams::miapure_60kg();
    let steps = (inject_us + 1_500_000) / 125;
    let mut injector = FaultInjector::new(
        class,
        FaultMagnitudes::fault_matrix(),
        inject_us,
        params.robot.drivetrain.actuator,
    );
    let mut sim = WorldRobot::new(params).unwrap();
    let mut command_nm = Vec::new();
    let mut detected_at = None;
    for k in 0..steps {
        let speed = if k >= 4000 { 0.8 } else { 0.0 };
        sim.step_injected(along_y(speed), &mut injector);
        let t_us = (sim.world().time_secs() * 1e6).round() as u64;
        if t_us <= inject_us {
            assert!(
                motor_faults(&sim).is_empty(),
                "a motor fault before the injection"
            );
            continue;
        }
        command_nm.push(sim.robot().devices().2.torque_nm[0]);
        if detected_at.is_none()
            && let Some(&f) = motor_faults(&sim).first()
        {
            detected_at = Some((command_nm.len() - 1, f));
        }
    }
    Faulted {
        command_nm,
        detected_at,
        mode_after: sim.mode(),
    }
}

/// The first step `k` from which `asks(c)` holds up to the detection at `at` or for 6 ms
/// (the monitor's persistence, 5 ms, and the current loop's rise, 1 ms), whichever is first.
fn first_sustained(command_nm: &[f64], at: usize, asks: impl Fn(f64) -> bool) -> Option<usize> {
    let window = LATENCY_STEPS - 1;
    (0..at).find(|&k| {
        let end = (k + window).min(at).min(command_nm.len());
        command_nm[k..end].iter().all(|&c| asks(c))
    })
}

/// The monitor's tolerance at command `c` (N m).
fn tolerance_nm(c: f64) -> f64 {
    let p = MotorHealthParams::for_actuator(&ActuatorParams::<f64>::miapure());
    p.torque_tolerance_nm + p.torque_tolerance_ratio * c.abs()
}

/// The stated latency in steps (5 ms persistence, one step of feedback delay) plus the
/// current loop's rise past the tolerance to 1.5 times it (1 ms, from a setpoint near 0).
const LATENCY_STEPS: usize = 41 + 8;

#[test]
fn a_dead_motor_is_detected_in_the_world_within_the_stated_latency() {
    let mut asked = 0;
    for inject_us in [600_000, 2_000_000] {
        let run = faulted_run(FaultClass::MotorDead, inject_us);
        let (at, fault) = run.detected_at.expect("the dead motor was never detected");
        assert_eq!(fault, Fault::MotorDead);
        assert_eq!(run.mode_after, Mode::Fault, "the motors must be off");
        // The first moment OW1 was asked for 1.5 times the tolerance, for 6 ms on end.
        let asks = first_sustained(&run.command_nm, at, |c| c.abs() >= 1.5 * tolerance_nm(c));
        if let Some(k) = asks {
            asked += 1;
            assert!(
                at <= k + LATENCY_STEPS,
                "detected {at} steps after the injection, asked at {k}"
            );
        }
        println!(
            "dead OW1 at {inject_us} us: detected {:.2} ms after the injection (asked at {:?} ms)",
            at as f64 * DT_SECS * 1e3,
            asks.map(|k| k as f64 * DT_SECS * 1e3)
        );
    }
    // The latency bound was checked at least once, not only vacuously.
    assert!(asked > 0);
}

#[test]
fn a_stuck_motor_is_detected_in_the_world_within_the_stated_latency() {
    let run = faulted_run(FaultClass::MotorStuck, 600_000);
    let (at, fault) = run.detected_at.expect("the stuck motor was never detected");
    let stuck_nm = run.command_nm[0];
    // Stuck below the tolerance, it reports as dead (the monitor cannot tell them apart).
    let expected = if stuck_nm.abs() > tolerance_nm(0.0) {
        Fault::MotorStuck
    } else {
        Fault::MotorDead
    };
    assert_eq!(fault, expected, "stuck at {stuck_nm} N m");
    assert_eq!(run.mode_after, Mode::Fault, "the motors must be off");
    let asks = first_sustained(&run.command_nm, at, |c| {
        (c - stuck_nm).abs() >= 1.5 * tolerance_nm(c.abs().max(stuck_nm.abs()))
    });
    if let Some(k) = asks {
        assert!(
            at <= k + LATENCY_STEPS,
            "detected {at} steps after the injection, asked at {k}"
        );
    }
    println!(
        "stuck OW1 at {stuck_nm:.2} N m: detected {:.2} ms after the injection (command away at {:?} ms)",
        at as f64 * DT_SECS * 1e3,
        asks.map(|k| k as f64 * DT_SECS * 1e3)
    );
}

/// A hard drive without a fault: 1.4 m/s at 90 deg, a reversal to -1.4 m/s, a stop, a 25 N s
/// push, in the default world (ODrive drivers) and the ideal one.
#[test]
fn a_healthy_robot_driven_hard_raises_no_motor_fault() {
    for params in [
        WorldParams::miapure_60kg(),
        WorldParams::ideal(BallbotParams::miapure_60kg()),
    ] {
        let mut sim = WorldRobot::new(params).unwrap();
        let mut peak_nm = 0.0_f64;
        for k in 0..56_000_u64 {
            let speed = match k {
                0..4_000 => 0.0,
                4_000..20_000 => 1.4,
                20_000..36_000 => -1.4,
                _ => 0.0,
            };
            if k == 44_000 {
                sim.world_mut().push_body(Vector3::new(25.0, 0.0, 0.0));
            }
            sim.step(along_y(speed));
            peak_nm = peak_nm.max(sim.robot().devices().2.torque_nm.amax());
            assert!(
                motor_faults(&sim).is_empty(),
                "false motor fault at step {k}"
            );
        }
        assert!(sim.mode().motors_enabled(), "{:?}", sim.mode());
        // The drive was hard: a wheel near its limits.
        assert!(peak_nm > 8.0, "peak {peak_nm} N m");
        println!("healthy drive: peak wheel torque {peak_nm:.1} N m, no motor fault");
    }
}
