//! Unit tests of the safety supervision.

use super::*;
use crate::Error;
use crate::estimation::{EncoderSample, ImuSample};
use nalgebra::Vector3;

const PERIOD_US: u64 = 2500;

/// A healthy robot at time `t`, with a little sensor noise so the IMU is not frozen.
fn healthy(t: u64) -> SafetyInput<f64> {
    let noise = (t as f64 * 1e-3).sin() * 1e-4;
    let mut imu = ImuSample::upright(t);
    imu.roll_rad = noise;
    SafetyInput {
        now_us: t,
        imu,
        encoders: EncoderSample::still(t),
        command_timestamp_us: Some(t),
        command_finite: true,
        request: ModeRequest::None,
    }
}

fn supervisor() -> SafetySupervisor<f64> {
    SafetySupervisor::new(SafetyParams::miapure()).unwrap()
}

/// Steps a healthy robot from `*t`, then arms it.
fn armed(t: &mut u64) -> SafetySupervisor<f64> {
    let mut sup = supervisor();
    sup.step(&healthy(*t));
    *t += PERIOD_US;
    let status = sup.step(&SafetyInput {
        request: ModeRequest::Arm,
        ..healthy(*t)
    });
    assert_eq!(status.mode, Mode::Balancing);
    assert!(status.transitioned());
    *t += PERIOD_US;
    sup
}

#[test]
fn fault_codes_are_stable_and_sets_behave() {
    for (i, f) in Fault::ALL.iter().enumerate() {
        assert_eq!(f.code() as usize, i);
    }
    let mut set = FaultSet::empty();
    assert!(set.is_empty());
    set.insert(Fault::TiltLimit);
    set.insert(Fault::LoopOverrun);
    assert!(set.contains(Fault::TiltLimit) && !set.contains(Fault::ImuStale));
    assert!(set.any(Severity::Unrecoverable) && set.any(Severity::Recoverable));
    let listed: [Option<Fault>; 3] = {
        let mut it = set.iter();
        [it.next(), it.next(), it.next()]
    };
    assert_eq!(
        listed,
        [Some(Fault::TiltLimit), Some(Fault::LoopOverrun), None]
    );
    assert_eq!(set.bits(), (1 << 7) | (1 << 9));
}

#[test]
fn arming_needs_healthy_upright_still_robot() {
    let mut sup = supervisor();
    // Never seen a sample: stale everything, so no arming.
    let mut first = healthy(0);
    first.request = ModeRequest::Arm;
    first.command_timestamp_us = None;
    let status = sup.step(&first);
    assert_eq!(status.mode, Mode::Idle);
    assert!(status.faults.contains(Fault::CommandLinkLost));
    // Tilted beyond the arming limit (but within the tilt limit): refused.
    let mut tilted = healthy(PERIOD_US);
    tilted.request = ModeRequest::Arm;
    tilted.imu.pitch_rad = 0.1;
    assert_eq!(sup.step(&tilted).mode, Mode::Idle);
    // Moving: refused.
    let mut moving = healthy(2 * PERIOD_US);
    moving.request = ModeRequest::Arm;
    moving.imu.angular_velocity_rad_per_s = Vector3::new(0.0, 0.5, 0.0);
    assert_eq!(sup.step(&moving).mode, Mode::Idle);
    // Upright and still: armed.
    let mut good = healthy(3 * PERIOD_US);
    good.request = ModeRequest::Arm;
    assert_eq!(sup.step(&good).mode, Mode::Balancing);
}

#[test]
fn idle_reports_faults_but_never_enters_fault_mode() {
    let mut sup = supervisor();
    let mut lying = healthy(0);
    lying.imu.pitch_rad = 1.2;
    let status = sup.step(&lying);
    assert!(status.faults.contains(Fault::TiltLimit));
    assert_eq!(status.mode, Mode::Idle);
}

#[test]
fn stop_resume_and_disarm() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    let mut input = healthy(t);
    input.request = ModeRequest::Stop;
    assert_eq!(sup.step(&input).mode, Mode::ControlledStop);
    t += PERIOD_US;
    assert_eq!(sup.step(&healthy(t)).mode, Mode::ControlledStop, "holds");
    t += PERIOD_US;
    let mut input = healthy(t);
    input.request = ModeRequest::Resume;
    assert_eq!(sup.step(&input).mode, Mode::Balancing);
    t += PERIOD_US;
    let mut input = healthy(t);
    input.request = ModeRequest::Disarm;
    let status = sup.step(&input);
    assert_eq!(status.mode, Mode::Idle);
    assert!(!status.mode.motors_enabled());
}

#[test]
fn lost_command_link_stops_under_control_and_resume_waits_for_it() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    let last_command = t;
    let mut status = sup.step(&healthy(t));
    while t < last_command + 300_000 {
        t += PERIOD_US;
        let mut input = healthy(t);
        input.command_timestamp_us = Some(last_command);
        input.request = ModeRequest::Resume; // refused while the link is down
        status = sup.step(&input);
    }
    assert_eq!(status.mode, Mode::ControlledStop);
    assert!(status.faults.contains(Fault::CommandLinkLost));
    assert!(status.mode.motors_enabled());
    // Link back: still holding until resumed.
    t += PERIOD_US;
    assert_eq!(sup.step(&healthy(t)).mode, Mode::ControlledStop);
    assert!(sup.latched_faults().contains(Fault::CommandLinkLost));
    t += PERIOD_US;
    let mut input = healthy(t);
    input.request = ModeRequest::Resume;
    assert_eq!(sup.step(&input).mode, Mode::Balancing);
    assert!(sup.latched_faults().is_empty());
}

#[test]
fn a_single_bad_imu_sample_stops_and_a_persistent_one_disables() {
    for bad in [f64::NAN, f64::INFINITY, 10.0] {
        let mut t = 0;
        let mut sup = armed(&mut t);
        let mut input = healthy(t);
        input.imu.angular_velocity_rad_per_s[1] = bad * 1e3;
        let status = sup.step(&input);
        assert!(!status.imu_valid);
        let expected = if bad.is_finite() {
            Fault::ImuOutOfRange
        } else {
            Fault::ImuNonFinite
        };
        assert!(status.faults.contains(expected));
        assert_eq!(status.mode, Mode::ControlledStop);
        // It persists: after the timeout the data is stale.
        let start = t;
        while t <= start + 20_000 + PERIOD_US {
            t += PERIOD_US;
            let mut input = healthy(t);
            input.imu.pitch_rad = bad;
            input.imu.pitch_rad *= 1e3;
            sup.step(&input);
        }
        assert_eq!(sup.mode(), Mode::Fault);
        assert!(sup.latched_faults().contains(Fault::ImuStale));
    }
}

#[test]
fn stale_encoders_disable_the_motors() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    let frozen_stamp = t;
    let mut status = sup.step(&healthy(t));
    for _ in 0..9 {
        t += PERIOD_US;
        let mut input = healthy(t);
        input.encoders.timestamp_us = frozen_stamp;
        status = sup.step(&input);
    }
    assert_eq!(status.mode, Mode::Fault);
    assert!(status.faults.contains(Fault::EncoderStale));
    // Reset acknowledges; the motors stay off.
    t += PERIOD_US;
    let mut input = healthy(t);
    input.request = ModeRequest::Reset;
    assert_eq!(sup.step(&input).mode, Mode::Idle);
}

#[test]
fn frozen_imu_is_detected_only_when_enabled() {
    for enabled in [true, false] {
        let mut params = SafetyParams::miapure();
        if !enabled {
            params.frozen_imu_timeout_us = None;
        }
        let mut sup = SafetySupervisor::new(params).unwrap();
        let mut t = 0;
        let mut input = healthy(t);
        input.request = ModeRequest::Arm;
        sup.step(&input);
        let frozen = healthy(t).imu;
        for _ in 0..60 {
            t += PERIOD_US;
            let mut input = healthy(t);
            input.imu = ImuSample {
                timestamp_us: t,
                ..frozen
            };
            sup.step(&input);
        }
        let expected = if enabled {
            Mode::Fault
        } else {
            Mode::Balancing
        };
        assert_eq!(sup.mode(), expected);
    }
}

#[test]
fn tilt_beyond_limit_disables_and_wheel_speed_stops() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    let mut input = healthy(t);
    input.encoders.wheel_speeds_rad_per_s[2] = 60.0;
    let status = sup.step(&input);
    assert!(status.faults.contains(Fault::WheelSpeedLimit));
    assert_eq!(status.mode, Mode::ControlledStop);
    t += PERIOD_US;
    let mut input = healthy(t);
    input.imu.roll_rad = -0.4;
    let status = sup.step(&input);
    assert!(status.faults.contains(Fault::TiltLimit));
    assert_eq!(status.mode, Mode::Fault);
}

#[test]
fn loop_overrun_and_clock_faults_are_recoverable() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    t += 10_000;
    let status = sup.step(&healthy(t));
    assert!(status.faults.contains(Fault::LoopOverrun));
    assert_eq!(status.mode, Mode::ControlledStop);
    let mut input = healthy(t - 1);
    input.request = ModeRequest::Resume;
    let status = sup.step(&input);
    assert!(status.faults.contains(Fault::ClockFault));
    assert_eq!(status.mode, Mode::ControlledStop, "resume refused");
}

#[test]
fn reported_faults_act_at_once() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    assert_eq!(sup.report(Fault::LoopOverrun), Mode::ControlledStop);
    assert!(sup.step(&healthy(t)).faults.contains(Fault::LoopOverrun));
    assert_eq!(sup.report(Fault::StateNonFinite), Mode::Fault);
    // In Idle a report changes nothing.
    let mut idle = supervisor();
    assert_eq!(idle.report(Fault::StateNonFinite), Mode::Idle);
}

#[test]
fn non_finite_command_stops() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    let mut input = healthy(t);
    input.command_finite = false;
    let status = sup.step(&input);
    assert!(status.faults.contains(Fault::CommandNonFinite));
    assert_eq!(status.mode, Mode::ControlledStop);
}

#[test]
fn params_validation_names_the_field() {
    let mut p = SafetyParams::<f64>::miapure();
    p.arm_tilt_limit_rad = 1.0;
    assert_eq!(
        p.validate(),
        Err(Error::invalid(
            "arm_tilt_limit_rad",
            "must not exceed tilt_limit_rad"
        ))
    );
    let mut p = SafetyParams::<f64>::miapure();
    p.imu_timeout_us = 0;
    assert!(SafetySupervisor::new(p).is_err());
}

/// A supervisor without the frozen-IMU check, armed (see `armed`).
fn armed_without_frozen_check(t: &mut u64) -> SafetySupervisor<f64> {
    let params = SafetyParams {
        frozen_imu_timeout_us: None,
        ..SafetyParams::miapure()
    };
    let mut sup = SafetySupervisor::new(params).unwrap();
    sup.step(&healthy(*t));
    *t += PERIOD_US;
    let status = sup.step(&SafetyInput {
        request: ModeRequest::Arm,
        ..healthy(*t)
    });
    assert_eq!(status.mode, Mode::Balancing);
    *t += PERIOD_US;
    sup
}

#[test]
fn a_fall_between_the_axes_trips_the_tilt_limit() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    // 15 deg in roll and in pitch: below the 20 deg limit in each, 21.1 deg from the vertical.
    let mut input = healthy(t);
    input.imu.roll_rad = 15f64.to_radians();
    input.imu.pitch_rad = 15f64.to_radians();
    let status = sup.step(&input);
    assert!(
        status.faults.contains(Fault::TiltLimit),
        "{:?}",
        status.faults
    );
    assert_eq!(status.mode, Mode::Fault);
}

#[test]
fn arming_needs_the_body_upright_from_the_vertical() {
    let mut sup = supervisor();
    sup.step(&healthy(0));
    // 2.5 deg in each: within the 3 deg arming limit per axis, 3.5 deg from the vertical.
    let mut input = healthy(PERIOD_US);
    input.imu.roll_rad = 2.5f64.to_radians();
    input.imu.pitch_rad = 2.5f64.to_radians();
    input.request = ModeRequest::Arm;
    assert_eq!(sup.step(&input).mode, Mode::Idle);
    input.now_us += PERIOD_US;
    input.imu.roll_rad = 0.0;
    assert_eq!(sup.step(&input).mode, Mode::Balancing);
}

proptest::proptest! {
    /// The tilt limit trips exactly when the tilt from the vertical passes it (away from the
    /// boundary by 1e-9 rad), whatever the split between roll and pitch.
    #[test]
    fn the_tilt_limit_is_the_tilt_from_the_vertical(
        roll in -1.5f64..1.5,
        pitch in -1.5f64..1.5,
    ) {
        let sup = supervisor();
        let tilt = tilt_from_vertical_rad(roll, pitch);
        let limit = sup.params().tilt_limit_rad;
        proptest::prop_assume!((tilt - limit).abs() > 1e-9);
        proptest::prop_assert_eq!(sup.within_tilt_limit(roll, pitch), tilt <= limit);
        // And the angle is the one between the body's z axis and the world's.
        let z = nalgebra::Rotation3::from_euler_angles(roll, pitch, 0.3) * Vector3::z();
        proptest::prop_assert!((tilt - z.z.clamp(-1.0, 1.0).acos()).abs() < 1e-7);
    }
}

#[test]
fn a_clock_stepped_back_with_a_held_imu_is_stale_within_the_tick_limit() {
    let mut t = 2_000_000;
    let mut sup = armed_without_frozen_check(&mut t);
    let held_imu = healthy(t).imu;
    sup.step(&healthy(t));
    // The clock steps back 1 s; the IMU keeps returning its last sample (stamp and values),
    // the encoders and the command link stay fresh. By the clock the held sample is never
    // old (it is stamped ahead of it), so only the ticks can see it.
    let mut steps = 0;
    for k in 1..=400u64 {
        let mut input = healthy(t - 1_000_000 + k * PERIOD_US);
        input.imu = held_imu;
        steps = k;
        if sup.step(&input).mode == Mode::Fault {
            break;
        }
    }
    assert_eq!(
        sup.mode(),
        Mode::Fault,
        "motors still on after {steps} steps"
    );
    assert!(sup.latched_faults().contains(Fault::ImuStale));
    assert!(sup.latched_faults().contains(Fault::ClockFault));
    // 8 ticks (20 ms at 400 Hz) unrefreshed are allowed, the 9th is stale.
    assert_eq!(steps, 9);
}

#[test]
fn encoders_and_command_link_held_across_a_clock_step_back_are_stale_in_ticks() {
    let mut t = 2_000_000;
    let mut sup = armed(&mut t);
    let held = healthy(t);
    sup.step(&held);
    let mut encoder_stale_at = None;
    let mut link_lost_at = None;
    for k in 1..=200u64 {
        let mut input = healthy(t - 1_000_000 + k * PERIOD_US);
        input.encoders = held.encoders;
        input.command_timestamp_us = held.command_timestamp_us;
        let faults = sup.step(&input).faults;
        if faults.contains(Fault::EncoderStale) {
            encoder_stale_at.get_or_insert(k);
        }
        if faults.contains(Fault::CommandLinkLost) {
            link_lost_at.get_or_insert(k);
        }
    }
    // 20 ms and 250 ms at 2.5 ms a tick: 8 and 100 ticks allowed.
    assert_eq!(encoder_stale_at, Some(9));
    assert_eq!(link_lost_at, Some(101));
}

#[test]
fn a_stalled_clock_is_a_fault_and_its_samples_go_stale() {
    let mut t = 0;
    let mut sup = armed_without_frozen_check(&mut t);
    sup.step(&healthy(t));
    // The clock stops; the sensors, stamped with it, repeat its last time.
    let status = sup.step(&healthy(t));
    assert!(
        status.faults.contains(Fault::ClockStalled),
        "{:?}",
        status.faults
    );
    assert_eq!(status.mode, Mode::ControlledStop);
    let mut steps = 1;
    while sup.mode() != Mode::Fault && steps < 400 {
        sup.step(&healthy(t));
        steps += 1;
    }
    assert_eq!(
        sup.mode(),
        Mode::Fault,
        "motors still on after {steps} stalled steps"
    );
    assert!(sup.latched_faults().contains(Fault::ImuStale));
    assert_eq!(steps, 9);
    assert_eq!(Fault::ClockStalled.severity(), Severity::Recoverable);
}

#[test]
fn a_running_clock_raises_no_clock_fault() {
    let mut t = 0;
    let mut sup = armed(&mut t);
    for _ in 0..1000 {
        let status = sup.step(&healthy(t));
        assert!(status.faults.is_empty(), "{:?} at {t}", status.faults);
        t += PERIOD_US;
    }
    assert_eq!(sup.mode(), Mode::Balancing);
}
