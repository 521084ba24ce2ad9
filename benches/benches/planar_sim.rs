//! The closed-loop planar simulation: the PIPTB with the cascaded LQR-PI (outer loop 400 Hz,
//! drive speed PI 8 kHz) over the 8 kHz RK4 plant with Karnopp transmission friction and the
//! seeded PIPTB sensors, one simulated second per iteration; the same without friction and
//! noise; and a single plant step.
//!
//! Simulated seconds per wall-clock second = 1 / (median time of `closed_loop_*_1s`).
//! Each bench is also measured by the thread's CPU time (`_cpu` suffix, Unix): on a shared,
//! oversubscribed machine the wall clock also counts time spent waiting for a core.
//!
//! Run: `cargo bench -p ballbot-benches --bench planar_sim -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
use ballbot_core::{PlanarRobotParams, WipState};
use ballbot_sim::planar::{
    ControllerKind, ControllerSettings, PlanarCommand, PlanarPlant, PlanarSim, SensorParams,
    SimConfig, TransmissionFriction,
};
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

/// Cruise command at 1 m/s on the PIPTB's 57.3 mm wheel.
fn cruise(_t: f64) -> PlanarCommand {
    PlanarCommand {
        ball_rate_rad_per_s: 1.0 / 0.0573,
        ..PlanarCommand::default()
    }
}

fn closed_loop(
    c: &mut Criterion,
    name: &str,
    friction: TransmissionFriction,
    sensors: SensorParams,
) {
    let robot = PlanarRobotParams::piptb();
    let mut sim = PlanarSim::new(robot, friction, sensors, SimConfig::default(), 1).unwrap();
    let mut controller = ControllerSettings::new(ControllerKind::LqrPi)
        .build(&robot, sim.plant().joint_gain(0.0))
        .unwrap();
    bench_both(c, name, || {
        sim.reset(WipState::new(0.0, 0.0, 0.0, 1.0 / 0.0573));
        controller.reset();
        let out = sim.run(&mut controller, &cruise, 1.0, &mut ());
        assert!(out.fault.is_none());
        out.plant_steps
    });
}

fn planar_sim(c: &mut Criterion) {
    closed_loop(
        c,
        "closed_loop_lqr_pi_piptb_friction_noise_1s",
        TransmissionFriction::piptb(),
        SensorParams::piptb(),
    );
    closed_loop(
        c,
        "closed_loop_lqr_pi_piptb_ideal_1s",
        TransmissionFriction::none(),
        SensorParams::ideal(),
    );
    let mut plant = PlanarPlant::new(
        PlanarRobotParams::piptb(),
        TransmissionFriction::piptb(),
        8000.0,
    )
    .unwrap();
    plant.set_state(WipState::new(0.01, 0.0, 0.0, 17.0));
    bench_both(c, "plant_step_piptb_friction", || {
        plant.set_state(WipState::new(0.01, 0.0, 0.0, 17.0));
        plant.step(black_box(0.3))
    });
}

criterion_group!(benches, planar_sim);
criterion_main!(benches);
