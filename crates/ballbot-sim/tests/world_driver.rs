//! The motor driver in the world: the ideal model reproduces the straight torque-speed line
//! bit for bit, the ODrive model's overspeed trip disarms the wheel and is reported.

use ballbot_sim::world::{BallbotWorld, WorldParams};

/// Bits of the world's state after a run whose torque commands push every wheel into the
/// actuator's limits (peak torque at rest, the falling line at speed, braking at speed).
fn saturating_run_bits(params: WorldParams) -> Vec<u64> {
    let mut world = BallbotWorld::new(params).unwrap();
    world.set_ball_fixed(true);
    world.set_body_fixed(true);
    for k in 0..2400 {
        // 0.15 s driving hard, then 0.15 s braking hard.
        let sign = if k < 1200 { 1.0 } else { -1.0 };
        world.step([60.0 * sign, -50.0 * sign, 20.0 * sign]);
    }
    let t = world.telemetry();
    let mut bits: Vec<u64> = t
        .wheels
        .iter()
        .flat_map(|w| {
            [
                w.speed_rad_per_s,
                w.motor_torque_nm,
                w.traction_n,
                w.angle_rad,
            ]
        })
        .map(f64::to_bits)
        .collect();
    bits.extend(t.ball_position_m.iter().map(|x| x.to_bits()));
    bits
}

/// [`saturating_run_bits`] of the default world, recorded before the driver model existed
/// (commit 738e8ee, when the world clamped with `ActuatorParams::clamp_torque_nm`): the wheels
/// end at -45.0, 45.0 and -45.0 rad/s with 11.85 N m, the straight line's motoring torque there.
const STRAIGHT_LINE_GOLDEN_BITS: [u64; 15] = [
    13854901550337860012,
    13846231259781490664,
    13863738604359613477,
    4602879949504732140,
    4631529513483084204,
    4622859222926714856,
    4640366567504837669,
    13826251986359507948,
    13854900857856700895,
    13846233207904576553,
    13863738604359612481,
    4606044097719317810,
    0,
    0,
    4592915015180507677,
];

#[test]
fn default_world_reproduces_the_straight_line_world_bit_for_bit() {
    let bits = saturating_run_bits(WorldParams::miapure_60kg());
    assert_eq!(bits, STRAIGHT_LINE_GOLDEN_BITS);
}
