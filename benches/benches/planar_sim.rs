//! The closed-loop planar simulation: the PIPTB with the cascaded LQR-PI (outer loop 400 Hz,
//! drive speed PI 8 kHz) over the 8 kHz RK4 plant with Karnopp transmission friction and the
//! seeded PIPTB sensors, one simulated second per iteration; the same without friction and
//! noise; and a single plant step.
//!
//! Also the planar rollout behind Python's `closed_loop_rollout` (LQR, 400 Hz, 4 RK4 substeps,
//! one simulated second on the ideal WIP) against the same loop written out on the core's WIP
//! (`rollout_lqr_direct_1s`), the baseline measured in the same run: their ratio is what
//! running the rollouts on the simulator's scheduler costs.
//!
//! Simulated seconds per wall-clock second = 1 / (median time of `closed_loop_*_1s`).
//! Each bench is also measured by the thread's CPU time (`_cpu` suffix, Unix): on a shared,
//! oversubscribed machine the wall clock also counts time spent waiting for a core.
//!
//! Run: `cargo bench -p ballbot-benches --bench planar_sim -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
use ballbot_core::control::{LqrController, LqrGains};
use ballbot_core::{PlanarRobotParams, Wip, WipParams, WipState, rk4_step};
use ballbot_sim::planar::{
    ControllerKind, ControllerSettings, PlanarCommand, PlanarPlant, PlanarSim, RolloutController,
    RolloutSettings, SensorParams, SimConfig, TransmissionFriction, rollout,
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

fn rollouts(c: &mut Criterion) {
    let plane = WipParams::miapure_60kg();
    let wip = Wip::new(plane).unwrap();
    let lqr = LqrController::new(LqrGains::for_wip(&wip, 83.9).unwrap()).unwrap();
    let start = WipState::new(0.1, 0.0, 0.0, 0.0);
    let command = WipState::zeros();
    let settings = RolloutSettings {
        dt_secs: 0.0025,
        n_steps: 400,
        substeps: 4,
    };
    let controller = RolloutController::Lqr(lqr);
    bench_both(c, "rollout_lqr_scheduler_1s", || {
        rollout(plane, &controller, start, &[command], &settings)
            .unwrap()
            .states[400]
    });
    bench_both(c, "rollout_lqr_direct_1s", || {
        let mut c = lqr;
        let mut s = start;
        let mut states = Vec::with_capacity(401);
        states.push(s);
        for _ in 0..400 {
            let torque = c.step(&s, &command, 0.0025).torque_nm;
            for _ in 0..4 {
                s = rk4_step(|x| wip.derivative(x, torque), &s, 0.0025 / 4.0);
            }
            states.push(s);
        }
        states[400]
    });
}

criterion_group!(benches, planar_sim, rollouts);
criterion_main!(benches);
