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

use ballbot_core::{PlanarRobotParams, WipState};
use ballbot_sim::planar::{
    ControllerKind, ControllerSettings, PlanarCommand, PlanarPlant, PlanarSim, SensorParams,
    SimConfig, TransmissionFriction,
};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

/// CPU time consumed by the calling thread.
#[cfg(unix)]
#[allow(unsafe_code)]
fn thread_cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes into it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// Benches `f` by wall-clock time as `name`, and by thread CPU time as `name_cpu`.
fn bench_both<R>(c: &mut Criterion, name: &str, mut f: impl FnMut() -> R) {
    c.bench_function(name, |bench| bench.iter(&mut f));
    #[cfg(unix)]
    c.bench_function(&format!("{name}_cpu"), |bench| {
        bench.iter_custom(|iters| {
            let start = thread_cpu_time();
            for _ in 0..iters {
                black_box(f());
            }
            thread_cpu_time() - start
        })
    });
}

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
