//! One step of the rapier3d ballbot world at 8 kHz with its controller: the omniwheel contact
//! model, wheel spin states, floor friction, the rapier step, telemetry and failure checks,
//! plus the balancing loop's share (one outer update per 20 steps, i.e. 400 Hz).
#![allow(missing_docs, clippy::unwrap_used)]

use ballbot_sim::world::{BallbotWorld, PlanarBalancer, PlanarBalancerParams, WorldParams};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn world_step(c: &mut Criterion) {
    let params = WorldParams::miapure_60kg();
    let mut world = BallbotWorld::new(params).unwrap();
    let mut ctrl = PlanarBalancer::new(&params.robot, PlanarBalancerParams::default()).unwrap();
    let every = (ctrl.period_secs() / params.dt_secs).round() as u64;
    let mut torque = [0.0; 3];
    let mut k = 0_u64;
    c.bench_function("world_step_8khz_with_controller", |b| {
        b.iter(|| {
            if k.is_multiple_of(every) {
                let m = world.measure();
                torque = ctrl.update(&m, [0.3, 0.0]);
            }
            k += 1;
            black_box(world.step(black_box(torque)));
            if world.failure().is_some() {
                world = BallbotWorld::new(params).unwrap();
            }
        });
    });
}

criterion_group!(benches, world_step);
criterion_main!(benches);
