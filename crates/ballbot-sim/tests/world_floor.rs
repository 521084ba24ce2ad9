//! The floor in the world (`ballbot_sim::world::floor`): the robot dropped onto it and driven
//! over a bump agree between the single-rate world and the default multi-rate one (the impact
//! is on the 8 kHz path), and it climbs a step onto the plateau.

use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::{BallbotWorld, FloorBump, FloorStep, StopRules, WorldParams};
use nalgebra::Vector3;

/// The robot dropped from `height_m` with its motors off: the floor force's peak (N), the time
/// the ball first leaves the floor again (s, `None` if it does not) and the ball's lowest
/// centre (m), over 0.15 s.
fn drop(params: WorldParams, height_m: f64) -> (f64, Option<f64>, f64) {
    let mut world = BallbotWorld::new(params).unwrap();
    world.translate_robot(Vector3::new(0.0, 0.0, height_m));
    let (mut peak, mut left, mut lowest) = (0.0_f64, None, f64::INFINITY);
    let mut touched = false;
    for _ in 0..1200 {
        let t = world.step([0.0; 3]);
        peak = peak.max(t.floor_force_n);
        lowest = lowest.min(t.ball_position_m.z);
        if t.floor_force_n > 0.0 {
            touched = true;
        } else if touched && left.is_none() {
            left = Some(t.time_secs);
        }
    }
    (peak, left, lowest)
}

#[test]
fn a_drop_agrees_between_the_single_rate_and_the_default_world() {
    let default = WorldParams::miapure_60kg();
    assert!(default.rigid_step_ratio > 1);
    let single = WorldParams {
        rigid_step_ratio: 1,
        ..default
    };
    let (peak_10, left_10, low_10) = drop(default, 0.005);
    let (peak_1, left_1, low_1) = drop(single, 0.005);
    println!(
        "ratio {}: peak {peak_10:.1} N, leaves {left_10:?}, lowest {low_10:.6} m; \
         ratio 1: {peak_1:.1} N, {left_1:?}, {low_1:.6} m",
        default.rigid_step_ratio
    );
    // A 5 mm drop of 78 kg: the floor force rises far above the weight (764 N).
    assert!(peak_1 > 2000.0, "{peak_1}");
    assert!(
        (peak_10 - peak_1).abs() < 0.01 * peak_1,
        "{peak_10} {peak_1}"
    );
    // The ball's lowest point within 1 % of its deepest compression of the coating.
    let radius = default.robot.ball_radius_m();
    assert!(
        (low_10 - low_1).abs() < 0.01 * (radius - low_1),
        "{low_10} {low_1}"
    );
    assert_eq!(left_10.is_some(), left_1.is_some());
    if let (Some(a), Some(b)) = (left_10, left_1) {
        assert!((a - b).abs() < 0.5e-3, "{a} {b}");
    }
}

/// Drives at 0.5 m/s towards +x over a 2 mm bar 0.25 m ahead; the peak floor force (N) and the
/// ball's x after 3 s (m). Slips and lift-offs are events, as in the bump study.
fn over_the_bump(params: WorldParams) -> (f64, f64) {
    let mut sim = WorldRobot::new(params).unwrap();
    sim.world_mut()
        .set_stop_rules(StopRules::contact_rules_off());
    sim.world_mut()
        .add_floor_bump(FloorBump {
            centre_m: [0.25, 0.0],
            heading_deg: 0.0,
            height_m: 0.002,
            width_m: 0.04,
            length_m: 2.0,
        })
        .unwrap();
    let mut peak = 0.0_f64;
    for k in 0..24_000 {
        let v = if k < 4000 { 0.0 } else { 0.5 };
        let t = sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: v,
            vy_m_per_s: 0.0,
            yaw_rate_rad_per_s: 0.0,
        }));
        peak = peak.max(t.floor_force_n);
    }
    assert!(
        sim.world().failure().is_none(),
        "{:?}",
        sim.world().failure()
    );
    (peak, sim.world().telemetry().ball_position_m.x)
}

#[test]
fn a_bump_crossing_agrees_between_ratios_within_the_sensor_noise_spread() {
    let default = WorldParams::miapure_60kg();
    let single = WorldParams {
        rigid_step_ratio: 1,
        ..default
    };
    let mut reseeded = default;
    reseeded.sensors.seed += 1;
    let (peak_10, x_10) = over_the_bump(default);
    let (peak_1, x_1) = over_the_bump(single);
    let (peak_s, x_s) = over_the_bump(reseeded);
    println!(
        "ratio 10: peak {peak_10:.1} N, x {x_10:.4} m; ratio 1: {peak_1:.1} N, {x_1:.4} m; \
         seed + 1: {peak_s:.1} N, {x_s:.4} m"
    );
    // The bar is crossed (the ball is past it) and loads the floor beyond the weight.
    assert!(x_1 > 0.4 && peak_1 > 900.0, "{x_1} {peak_1}");
    let noise_peak = (peak_s - peak_10).abs();
    let noise_x = (x_s - x_10).abs();
    assert!(
        (peak_10 - peak_1).abs() <= 2.0 * noise_peak + 0.01 * peak_1,
        "peak {peak_10} vs {peak_1}, seed spread {noise_peak}"
    );
    assert!(
        (x_10 - x_1).abs() <= 2.0 * noise_x + 1e-3,
        "x {x_10} vs {x_1}, seed spread {noise_x}"
    );
}

#[test]
fn the_robot_climbs_a_rounded_step_onto_the_plateau() {
    // As in the bump study, slips and lift-offs are events, a fall is the failure.
    let mut sim = WorldRobot::new(WorldParams::miapure_60kg()).unwrap();
    sim.world_mut()
        .set_stop_rules(StopRules::contact_rules_off());
    sim.world_mut()
        .add_floor_step(FloorStep {
            edge_m: [0.5, 0.0],
            heading_deg: 0.0,
            height_m: 0.003,
            edge_radius_m: 0.002,
        })
        .unwrap();
    let z0 = sim.world().telemetry().ball_position_m.z;
    for k in 0..24_000 {
        let v = if (4000..=16_000).contains(&k) {
            0.4
        } else {
            0.0
        };
        sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: v,
            vy_m_per_s: 0.0,
            yaw_rate_rad_per_s: 0.0,
        }));
    }
    let t = sim.world().telemetry();
    println!(
        "ball at x {:.3} m, {:.4} m higher",
        t.ball_position_m.x,
        t.ball_position_m.z - z0
    );
    assert!(
        sim.world().failure().is_none(),
        "{:?}",
        sim.world().failure()
    );
    // On the plateau: the ball's centre beyond the edge and its radius.
    assert!(t.ball_position_m.x > 0.52, "{}", t.ball_position_m.x);
    assert!(
        (t.ball_position_m.z - z0 - 0.003).abs() < 5e-4,
        "{}",
        t.ball_position_m.z - z0
    );
}
