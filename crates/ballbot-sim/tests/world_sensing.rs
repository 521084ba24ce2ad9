//! The IMU as the robot has it (the default world with `SensorParams::miapure`): under a sustained acceleration the
//! attitude filter's tilt is pulled towards the apparent vertical, as its first-order law
//! predicts; the link latency and the IMU's delay reach the controller.

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::{ImuParams, SensorParams, WorldParams};

const DT: f64 = 1.0 / 8000.0;

/// The default world with the VN-100 and the link latency.
fn with_sensing() -> WorldParams {
    WorldParams {
        sensors: SensorParams::miapure(),
        ..WorldParams::miapure_60kg()
    }
}

fn velocity(vx_m_per_s: f64) -> Command<'static, f64> {
    Command::Velocity(VelocityCommand {
        vx_m_per_s,
        vy_m_per_s: 0.0,
        yaw_rate_rad_per_s: 0.0,
    })
}

/// Per 400 Hz sample while the robot speeds up from rest to 0.8 m/s: time, ball speed, true
/// pitch and the pitch the IMU reports (rad).
fn speed_up(params: WorldParams) -> Vec<[f64; 4]> {
    let mut sim = WorldRobot::new(params).unwrap();
    let mut rows = Vec::new();
    for k in 0..(4.0 / DT) as u64 {
        let cmd = if k < 8000 {
            velocity(0.0)
        } else {
            velocity(0.8)
        };
        sim.step(cmd);
        if k % 20 == 0 {
            let t = sim.world().telemetry();
            let true_pitch = t.body_orientation.euler_angles().1;
            let (time, vx) = (t.time_secs, t.ball_velocity_m_per_s.x);
            let m = sim.world_mut().measure();
            rows.push([time, vx, true_pitch, m.tilt_rad[1]]);
        }
    }
    assert!(
        sim.world().failure().is_none(),
        "{:?}",
        sim.world().failure()
    );
    rows
}

#[test]
fn the_filters_tilt_error_under_acceleration_follows_its_first_order_law() {
    let params = with_sensing();
    let tau = params.sensors.imu.filter_time_constant_secs;
    let rows = speed_up(params);
    // The law, independent of the filter's code: the error (reported minus true pitch)
    // follows -atan(a / g) through a first-order lag tau, `a` the ball's acceleration.
    let mut predicted = 0.0;
    let (mut worst, mut peak) = (0.0_f64, 0.0_f64);
    for w in rows.windows(3) {
        let (dt, t) = (w[2][0] - w[0][0], w[1][0]);
        let accel = (w[2][1] - w[0][1]) / dt;
        predicted += (-(accel / 9.81).atan() - predicted) * (dt / 2.0) / tau;
        let error = w[1][3] - w[1][2];
        if t > 2.0 {
            peak = peak.max(predicted.abs());
            worst = worst.max((error - predicted).abs());
        }
    }
    println!("peak predicted error {peak:.4} rad, worst deviation {worst:.4} rad");
    assert!(peak > 5e-3, "the ramp must load the filter: {peak}");
    assert!(worst < 0.3 * peak, "{worst} of {peak}");
}

#[test]
fn the_truth_imu_reads_the_true_tilt() {
    let mut params = with_sensing();
    params.sensors.imu = ImuParams::truth();
    params.sensors.link_latency_secs = 0.0;
    let rows = speed_up(params);
    let worst = rows.iter().map(|r| (r[3] - r[2]).abs()).fold(0.0, f64::max);
    // White noise of 1e-3 rad: nothing like the filter's pull.
    assert!(worst < 5e-3, "{worst}");
}

#[test]
fn a_link_latency_of_a_control_period_or_more_is_refused() {
    let mut params = with_sensing();
    params.sensors.link_latency_secs = 2.5e-3;
    match WorldRobot::new(params) {
        Err(ballbot_sim::world::WorldError::InvalidParameter { field, .. }) => {
            assert_eq!(field, "sensors.link_latency_secs")
        }
        other => panic!("{:?}", other.err()),
    }
}

/// The ball's speed 2 s after a stop command that follows a 0.5 m/s^2 ramp to 1.4 m/s towards
/// `heading_deg` (m/s), the controller's tilt corrected for the filter's lean or not.
fn speed_after_stop(heading_deg: f64, correct: bool) -> f64 {
    let params = with_sensing();
    let mut config = BallbotControllerConfig::design(&params.robot).unwrap();
    if correct {
        let tau = params.sensors.imu.filter_time_constant_secs;
        config = config.with_imu_lean_correction(tau);
    }
    let mut sim = WorldRobot::with_config(params, config).unwrap();
    let (s, c) = heading_deg.to_radians().sin_cos();
    for k in 0..(7.0 / DT) as u64 {
        let t = k as f64 * DT;
        let v = if (0.5..5.0).contains(&t) {
            ((t - 0.5) * 0.5).min(1.4)
        } else {
            0.0
        };
        sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: v * c,
            vy_m_per_s: v * s,
            yaw_rate_rad_per_s: 0.0,
        }));
    }
    assert!(
        sim.world().failure().is_none(),
        "{:?}",
        sim.world().failure()
    );
    sim.world().telemetry().ball_velocity_m_per_s.norm()
}

#[test]
fn correcting_the_filters_lean_brings_the_robot_to_rest_after_a_stop() {
    for heading in [0.0, 90.0] {
        let (raw, corrected) = (
            speed_after_stop(heading, false),
            speed_after_stop(heading, true),
        );
        println!("{heading} deg: {raw:.3} m/s as measured, {corrected:.3} m/s corrected");
        assert!(
            raw > 0.1,
            "{heading} deg: the filter's lean keeps it rolling: {raw}"
        );
        assert!(corrected < 0.05, "{heading} deg: {corrected}");
    }
}
