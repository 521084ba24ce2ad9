//! Contact realism of the 3D world (roller gaps, axle losses, rubber coating): the ideal
//! variant is unchanged, and each mechanism shows its physics.

use crate::balance::{PlanarBalancer, PlanarBalancerParams};
use ballbot_sim::world::{BallbotWorld, WorldParams};

/// Runs `world` for `duration_secs` under the planar balancer with a constant body-frame
/// velocity command (m/s).
fn cruise(world: &mut BallbotWorld, duration_secs: f64, command_m_per_s: [f64; 2]) {
    let mut ctrl =
        PlanarBalancer::new(&world.params().robot, PlanarBalancerParams::default()).unwrap();
    let dt = world.params().dt_secs;
    let every = (ctrl.period_secs() / dt).round() as usize;
    let steps = (duration_secs / dt).round() as usize;
    let mut torque = [0.0; 3];
    for k in 0..steps {
        if k.is_multiple_of(every) {
            let m = world.measure();
            torque = ctrl.update(&m, command_m_per_s);
        }
        world.step(torque);
    }
}

/// The numbers the golden test compares: ball position, tilt, then per wheel normal force,
/// traction and speed.
fn golden_numbers(world: &BallbotWorld) -> Vec<f64> {
    let t = world.telemetry();
    let mut v: Vec<f64> = t.ball_position_m.iter().copied().collect();
    v.extend(t.tilt_rad);
    for w in &t.wheels {
        v.extend([w.normal_force_n, w.traction_n, w.speed_rad_per_s]);
    }
    v
}

/// Recorded from the world before contact realism existed (commit 738e8ee): 1 s of a
/// 0.3 m/s cruise at 30 deg from a tilted start, under the planar balancer.
const GOLDEN: [f64; 14] = [
    0.05316136748064385,
    0.03410411951483876,
    0.11300660929445219,
    -0.014112108955495086,
    0.024362794149280317,
    362.63604079780214,
    8.565445048176684,
    1.4429736568179699,
    336.1516189934724,
    -19.35018774271318,
    -2.8527750857353884,
    332.2710395222012,
    13.182320916098075,
    1.432506847278906,
];

#[test]
fn ideal_contact_reproduces_the_world_before_contact_realism() {
    let mut world = BallbotWorld::new(WorldParams::miapure_60kg()).unwrap();
    world.tilt_body([0.01, -0.02]);
    let (s, c) = 30.0_f64.to_radians().sin_cos();
    cruise(&mut world, 1.0, [0.3 * c, 0.3 * s]);
    let got = golden_numbers(&world);
    for (i, (g, e)) in got.iter().zip(GOLDEN).enumerate() {
        assert!(
            (g - e).abs() <= 1e-12 * e.abs().max(1.0),
            "number {i}: {g:.17e} != {e:.17e}"
        );
    }
}
