//! The multi-rate world (`WorldParams::rigid_step_ratio`, `ballbot_sim::world::rigid`): rapier
//! steps the rigid bodies once every `ratio` world steps while contacts, wheels and drivers step
//! every world step. It must agree with the single-rate world, conserve what that one conserves
//! and reject ratios beyond its stability bound.

use crate::world::free_flight;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::{BallbotWorld, WorldError, WorldParams};
use nalgebra::Vector3;

/// The world with the paper's controller configuration: these tests compare the world's
/// stepping, with the controller the earlier measurements were made with.
fn paper_robot(params: WorldParams) -> WorldRobot {
    let config = BallbotControllerConfig::paper(&params.robot).unwrap();
    WorldRobot::with_config(params, config).unwrap()
}

/// Drives the world with the core's controller through two velocity commands (2 s each, after
/// 1 s at rest) and samples every 40th step: ball x, y, tilts, normal forces, OW1's speed.
fn drive(params: WorldParams) -> Vec<[f64; 8]> {
    let mut sim = paper_robot(params);
    let mut samples = Vec::new();
    for k in 0..40_000_u32 {
        let (vx, vy, wz) = match k / 8000 {
            0 => (0.0, 0.0, 0.0),
            1 | 2 => (0.8, -0.3, 0.2),
            _ => (0.6, 0.5, -0.3),
        };
        let t = sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: vx,
            vy_m_per_s: vy,
            yaw_rate_rad_per_s: wz,
        }));
        if k % 40 == 39 {
            let w = &t.wheels;
            samples.push([
                t.ball_position_m.x,
                t.ball_position_m.y,
                t.tilt_rad[0],
                t.tilt_rad[1],
                w[0].normal_force_n,
                w[1].normal_force_n,
                w[2].normal_force_n,
                w[0].speed_rad_per_s,
            ]);
        }
    }
    assert!(
        sim.world().failure().is_none(),
        "{:?}",
        sim.world().failure()
    );
    samples
}

/// The largest difference per quantity between two drives, after the first 0.5 s: while the
/// ball settles into rapier's soft floor (1.5 mm, time constant 0.1 s) the two bounce with
/// different phases, since rapier's floor contact itself steps at the rigid step.
fn max_differences(a: &[[f64; 8]], b: &[[f64; 8]]) -> [f64; 8] {
    let mut out = [0.0_f64; 8];
    for (x, y) in a.iter().zip(b).skip(100) {
        for i in 0..8 {
            out[i] = out[i].max((x[i] - y[i]).abs());
        }
    }
    out
}

#[test]
fn multi_rate_drive_agrees_with_the_single_rate_world() {
    // The ideal world (stiff, continuous rims: no roller-gap ripple, whose phase is sensitive)
    // at its largest ratio, 10. Measured over 10 s of the bench's cycle (docs/world-speed.md): ball
    // position within 0.5 mm, tilts within 1e-4 rad, normal forces within 1.3 N, OW1's speed
    // within 0.02 rad/s; a changed sensor-noise seed moves them 1.5 mm, 8e-4 rad, 14 N.
    let ideal = WorldParams::ideal(BallbotParams::miapure_60kg());
    let mut fast = ideal;
    fast.rigid_step_ratio = ideal.max_rigid_step_ratio();
    assert_eq!(fast.rigid_step_ratio, 10);
    let one = drive(ideal);
    let d = max_differences(&one, &drive(fast));
    assert!(d[0] < 1e-3 && d[1] < 1e-3, "ball position differs by {d:?}");
    assert!(d[2] < 3e-4 && d[3] < 3e-4, "tilt differs by {d:?}");
    assert!(
        d[4..7].iter().all(|&n| n < 3.0),
        "normal forces differ by {d:?}"
    );
    assert!(d[7] < 0.05, "OW1's speed differs by {d:?}");
    // The default world at its default ratio against itself at ratio 1: looser (the roller
    // gaps' ripple), but far inside the sensor-noise spread.
    let default = WorldParams::miapure_60kg();
    assert_eq!(default.rigid_step_ratio, 10);
    let mut single = default;
    single.rigid_step_ratio = 1;
    let d = max_differences(&drive(single), &drive(default));
    assert!(d[0] < 3e-3 && d[1] < 3e-3, "ball position differs by {d:?}");
    assert!(d[2] < 1e-3 && d[3] < 1e-3, "tilt differs by {d:?}");
    assert!(
        d[4..7].iter().all(|&n| n < 25.0),
        "normal forces differ by {d:?}"
    );
}

#[test]
fn multi_rate_free_flight_conserves_momentum_and_energy() {
    // As `world::free_flight_conserves_momentum_and_energy`, with rapier at a tenth of the rate:
    // the contact pairs still act equal and opposite every world step, so the linear momentum
    // is kept to round-off; the angular momentum to the relative displacement of ball and body
    // within one rigid step; and the energy error stays first order in the world step.
    let (dp1, dl1, de1) = free_flight(1.0, 1);
    let (dp, dl, de) = free_flight(1.0, 10);
    assert!(
        dp < 1e-9,
        "linear momentum changed by {dp} (single rate {dp1})"
    );
    assert!(
        dl < 1e-3,
        "angular momentum changed by {dl} (single rate {dl1})"
    );
    assert!(de < 0.015, "energy changed by {de} (single rate {de1})");
    let (_, _, de_half) = free_flight(2.0, 20);
    assert!(
        de_half < 0.6 * de && de_half > 0.4 * de,
        "first order: {de} -> {de_half}"
    );
}

#[test]
fn a_push_between_rigid_steps_acts_at_once() {
    // A push 3 world steps into a rigid interval completes that interval first, then applies
    // the impulse: the momentum jumps by exactly the impulse, and the recovery follows the
    // single-rate world's.
    let run = |ratio: u32| {
        let mut p = WorldParams::ideal(BallbotParams::miapure_60kg());
        p.rigid_step_ratio = ratio;
        let mut sim = paper_robot(p);
        let hold = Command::Velocity(VelocityCommand::default());
        for _ in 0..8003 {
            sim.step(hold);
        }
        let before = sim.world().linear_momentum_ns();
        let impulse = Vector3::new(12.0, -6.0, 0.0);
        sim.world_mut().push_body(impulse);
        // Besides the impulse, the momentum changed by gravity and the floor over the 3 steps
        // that the push completed (the robot at rest: they nearly cancel).
        let jump = sim.world().linear_momentum_ns() - before;
        assert!((jump - impulse).norm() < 1e-2, "{jump} != {impulse}");
        let mut peak = 0.0_f64;
        for _ in 0..8000 {
            let t = sim.step(hold);
            peak = peak.max(t.tilt_rad[0].hypot(t.tilt_rad[1]));
        }
        assert!(sim.world().failure().is_none());
        peak
    };
    let (one, ten) = (run(1), run(10));
    assert!(one > 0.01, "the push must tilt the robot: {one}");
    assert!((one - ten).abs() < 0.02 * one, "peak tilt {one} vs {ten}");
}

#[test]
fn rigid_step_ratios_beyond_the_bound_are_rejected_naming_the_field() {
    let field = |p: WorldParams| match BallbotWorld::new(p) {
        Err(WorldError::InvalidParameter { field, .. }) => field,
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => panic!("accepted ratio {}", p.rigid_step_ratio),
    };
    let ideal = WorldParams::ideal(BallbotParams::miapure_60kg());
    for ratio in [0, 11, 41] {
        let mut p = ideal;
        p.rigid_step_ratio = ratio;
        assert_eq!(field(p), "rigid_step_ratio");
    }
    // The soft rubber-coated contact of the default world allows up to 26 (omega_B = 365 rad/s
    // on the coating law's tangent at the static load).
    let mut p = WorldParams::miapure_60kg();
    p.rigid_step_ratio = 26;
    assert!(BallbotWorld::new(p).is_ok());
    p.rigid_step_ratio = 27;
    assert_eq!(field(p), "rigid_step_ratio");
    // Files without the field get the single-rate world.
    let mut json = serde_json::to_value(ideal).unwrap();
    json.as_object_mut().unwrap().remove("rigid_step_ratio");
    let back: WorldParams = serde_json::from_value(json).unwrap();
    assert_eq!(back.rigid_step_ratio, 1);
}
