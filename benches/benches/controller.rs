//! The 3D ballbot controller's steps on MiaPURE with a 60 kg payload: the 400 Hz outer step
//! (safety, estimation, command shaping, two LQR-PI planes and the spin plane, the kinematic
//! mapping) in f64 and f32, in f64 with traction-aware control on, the command shaper alone, and the 8 kHz inner step of one motor
//! driver and of all three.
//!
//! Each is measured twice: wall-clock time (criterion's default) and, with the `_cpu` suffix,
//! the thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`, Unix only), which on a shared machine does
//! not count the time spent waiting for a core. Instruction counts of the same steps:
//! `bash scripts/icount.sh`.
//!
//! Run: `cargo bench -p ballbot-benches --bench controller -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
use ballbot_core::ballbot::{
    BallbotController, BallbotControllerConfig, MotorReferences, MotorSpeedLoop, MotorSpeedPi,
    OuterInput,
};
use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::safety::{Mode, ModeRequest};
use ballbot_core::{BallbotParams, OmniKinematics};
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{RealField, Vector3};
use std::hint::black_box;

/// An armed controller and an input stream: time advances 2.5 ms per step and the IMU
/// readings change every step (a frozen IMU would trip the supervisor).
fn bench_outer<T: RealField + Copy>(c: &mut Criterion, name: &str) {
    let v = |x: f64| -> T { nalgebra::convert(x) };
    let config = BallbotControllerConfig::paper(&BallbotParams::<T>::miapure_60kg()).unwrap();
    let mut outer = BallbotController::new(config).unwrap();
    let mut input = OuterInput {
        now_us: 0,
        imu: ImuSample::upright(0),
        encoders: EncoderSample::still(0),
        command: Command::Velocity(VelocityCommand {
            vx_m_per_s: v(0.8),
            vy_m_per_s: v(-0.3),
            yaw_rate_rad_per_s: v(0.2),
        }),
        command_timestamp_us: Some(0),
        request: ModeRequest::Arm,
    };
    outer.step(&input);
    input.request = ModeRequest::None;
    let mut k: u64 = 0;
    bench_both(c, name, || {
        k += 1;
        let t = k * 2500;
        let wobble = v((k % 7) as f64 * 1e-4);
        input.now_us = t;
        input.imu.timestamp_us = t;
        input.imu.roll_rad = wobble;
        input.imu.pitch_rad = v(0.01) - wobble;
        input.imu.angular_velocity_rad_per_s = Vector3::new(wobble, v(0.02), v(0.2));
        input.encoders.timestamp_us = t;
        input.encoders.wheel_speeds_rad_per_s = Vector3::new(v(1.0) + wobble, v(-3.0), v(2.5));
        input.command_timestamp_us = Some(t);
        outer.step(black_box(&input)).motors
    });
    assert_eq!(
        outer.mode(),
        Mode::Balancing,
        "the benchmark left balancing"
    );
}

/// [`bench_outer`] with traction-aware control on, on sensor readings that agree with each
/// other (a ball rolling at the encoders' rates under an upright body turning at the gyro's
/// yaw rate), so the slip monitor runs its quiet path as on a robot that does not slip.
fn bench_outer_traction(c: &mut Criterion) {
    let robot = BallbotParams::<f64>::miapure_60kg();
    let config = BallbotControllerConfig::paper(&robot)
        .unwrap()
        .with_traction_control();
    let kin = OmniKinematics::from_ballbot(&robot).unwrap();
    let mut outer = BallbotController::new(config).unwrap();
    let relative = |wobble: f64| Vector3::new(2.6 - wobble, 7.0, -0.2);
    let mut input = OuterInput {
        now_us: 0,
        imu: ImuSample::upright(0),
        encoders: EncoderSample::still(0),
        command: Command::Velocity(VelocityCommand {
            vx_m_per_s: 0.8,
            vy_m_per_s: -0.3,
            yaw_rate_rad_per_s: 0.2,
        }),
        command_timestamp_us: Some(0),
        request: ModeRequest::Arm,
    };
    input.imu.angular_velocity_rad_per_s = Vector3::new(0.0, 0.0, 0.2);
    input.encoders.wheel_speeds_rad_per_s = kin.wheel_speeds_rad_per_s(&relative(0.0));
    outer.step(&input);
    input.request = ModeRequest::None;
    let mut k: u64 = 0;
    bench_both(c, "ballbot_outer_step_traction_f64", || {
        k += 1;
        let t = k * 2500;
        let wobble = (k % 7) as f64 * 1e-4;
        input.now_us = t;
        input.imu.timestamp_us = t;
        input.imu.roll_rad = wobble;
        input.imu.pitch_rad = -wobble;
        input.imu.angular_velocity_rad_per_s = Vector3::new(wobble, 0.0, 0.2);
        input.encoders.timestamp_us = t;
        input.encoders.wheel_speeds_rad_per_s = kin.wheel_speeds_rad_per_s(&relative(wobble));
        input.command_timestamp_us = Some(t);
        outer.step(black_box(&input)).motors
    });
    assert_eq!(
        outer.mode(),
        Mode::Balancing,
        "the benchmark left balancing"
    );
}

fn bench_shaper(c: &mut Criterion) {
    let robot = BallbotParams::<f64>::miapure_60kg();
    let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot).unwrap();
    let mut k: u64 = 0;
    bench_both(c, "command_shaper_step_f64", || {
        k += 1;
        // A command that keeps changing, so the limiters are never settled.
        let vx = if (k / 400).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let command = Command::Velocity(VelocityCommand {
            vx_m_per_s: vx,
            vy_m_per_s: 0.5 * vx,
            yaw_rate_rad_per_s: 0.2 * vx,
        });
        shaper.step(black_box(&command), 0.0025).planar
    });
}

fn bench_inner(c: &mut Criterion) {
    let robot = BallbotParams::<f64>::miapure_60kg();
    let config = BallbotControllerConfig::paper(&robot).unwrap();
    let mut motor = MotorSpeedPi::new(config.motor, &robot.drivetrain.actuator).unwrap();
    let speeds: [f64; 8] = core::array::from_fn(|i| 1.9 + i as f64 * 0.01);
    let mut k: usize = 0;
    bench_both(c, "motor_speed_pi_step_f64", || {
        k += 1;
        motor.step(
            black_box(2.0),
            black_box(5.0),
            black_box(speeds[k & 7]),
            1.25e-4,
        )
    });

    let mut inner = MotorSpeedLoop::new(&config).unwrap();
    let references = MotorReferences {
        enabled: true,
        speed_rad_per_s: Vector3::new(1.0, -3.0, 2.5),
        accel_rad_per_s2: Vector3::new(10.0, -5.0, 2.0),
        feedforward_torque_nm: Vector3::new(3.0, -2.0, 1.0),
    };
    bench_both(c, "motor_speed_loop_step_3_motors_f64", || {
        k += 1;
        if k.is_multiple_of(20) {
            inner.set_references(&references);
        }
        let w = speeds[k & 7];
        inner.step(black_box(&Vector3::new(w, -w, 0.5 * w)), 1.25e-4)
    });
}

fn benches(c: &mut Criterion) {
    bench_outer::<f64>(c, "ballbot_outer_step_f64");
    bench_outer::<f32>(c, "ballbot_outer_step_f32");
    bench_outer_traction(c);
    bench_shaper(c);
    bench_inner(c);
}

criterion_group!(controller, benches);
criterion_main!(controller);
