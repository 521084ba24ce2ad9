//! Balance-point estimation in closed loop on the planar plants: an IMU mounted 0.05 rad
//! crooked (to the controller, the same as a centre of mass off the axis) makes the designed
//! controller drive off for good; with the estimator it comes back to rest.

#![allow(clippy::unwrap_used)] // test helpers

use crate::ballbot3d::{Rig, velocity};
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::safety::ModeRequest;

const CROOKED_RAD: f64 = 0.05;

/// Runs `seconds` standing on a zero command with the IMU's pitch reading `CROOKED_RAD` too
/// much; returns the body speed at the end (m/s).
fn stand_crooked(rig: &mut Rig, seconds: f64) -> f64 {
    let n = (seconds * 400.0).round() as usize;
    for _ in 0..n {
        let mut input = rig.input(velocity(0.0, 0.0, 0.0), ModeRequest::None);
        input.imu.pitch_rad += CROOKED_RAD;
        rig.step_with(&input);
    }
    let (vx, vy) = rig.body_speed();
    vx.hypot(vy)
}

fn rig(balance_point: bool) -> Rig {
    let designed = BallbotControllerConfig::paper(&BallbotParams::miapure_60kg()).unwrap();
    let config = if balance_point {
        designed.with_balance_point_estimation()
    } else {
        designed
    };
    let mut rig = Rig::with_config(config);
    rig.arm();
    rig
}

#[test]
fn a_crooked_imu_drives_the_designed_controller_off_for_good() {
    let mut rig = rig(false);
    let after_10 = stand_crooked(&mut rig, 10.0);
    let after_20 = stand_crooked(&mut rig, 10.0);
    // A steady drift, not a transient.
    assert!(after_10 > 0.1 && after_20 > 0.1, "{after_10} {after_20}");
}

#[test]
fn balance_point_estimation_learns_the_offset_and_comes_to_rest() {
    let mut rig = rig(true);
    let speed = stand_crooked(&mut rig, 20.0);
    assert!(speed < 0.02, "still moving at {speed} m/s");
    let offset = rig.outer.balance_point().unwrap().offset_rad();
    // The IMU reads the upright body as CROOKED_RAD: that is the balance point learnt.
    assert!((offset[1] - CROOKED_RAD).abs() < 0.005, "{offset}");
    assert!(offset[0].abs() < 0.005, "{offset}");
}

#[test]
fn on_a_straight_imu_the_estimate_stays_near_zero_through_a_drive() {
    let mut rig = rig(true);
    rig.run(velocity(1.0, 0.5, 0.0), 6.0);
    rig.run(velocity(0.0, 0.0, 0.0), 6.0);
    let offset = rig.outer.balance_point().unwrap().offset_rad();
    assert!(offset.amax() < 0.005, "{offset}");
    let (vx, vy) = rig.body_speed();
    assert!(vx.hypot(vy) < 0.02, "{vx} {vy}");
}
