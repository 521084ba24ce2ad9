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
    5.31613674806438521e-2,
    3.41041195148387571e-2,
    1.13006609294452193e-1,
    -1.41121089554950858e-2,
    2.43627941492803174e-2,
    3.62636040797802139e2,
    8.56544504817668440e0,
    1.44297365681796985e0,
    3.36151618993472425e2,
    -1.93501877427131816e1,
    -2.85277508573538841e0,
    3.32271039522201193e2,
    1.31823209160980745e1,
    1.43250684727890598e0,
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
