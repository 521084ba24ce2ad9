//! One DARE solve for the reduced MiaPURE plane (`[theta, theta_dot, phi_dot]`, 60 kg
//! payload, Q = diag(100, 10, 1), R = 0.1) sampled at 400 Hz, in f64 and f32; the
//! zero-order-hold discretisation as a separate bench; the CARE; and the full discrete
//! design call (ZOH + DARE + checks) that a controller makes.
//!
//! Each is measured twice: wall-clock time (criterion's default) and, with the `_cpu`
//! suffix, the thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`, Unix only). On a shared,
//! oversubscribed machine the wall clock also counts the time the thread waits for a core;
//! the CPU time does not.
//!
//! Run: `cargo bench -p ballbot-benches --bench dare -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
use ballbot_core::linalg::zoh;
use ballbot_core::lqr::{
    RiccatiSettings, RiccatiStatus, WipLqrWeights, solve_care, solve_dare, wip_lqr_discrete,
};
use ballbot_core::{Wip, WipParams};
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix1, Matrix3, RealField, Vector3};
use std::hint::black_box;

const DT_SECS: f64 = 1.0 / 400.0;

#[allow(clippy::type_complexity)]
fn plant<T: RealField + Copy>() -> (Matrix3<T>, Vector3<T>, Matrix3<T>, Matrix1<T>) {
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).unwrap();
    let (a, b) = wip.linearize_upright().reduced();
    let w = WipLqrWeights::<T>::model_default();
    (a, b, w.q, Matrix1::new(w.r))
}

fn bench_precision<T: RealField + Copy>(c: &mut Criterion, name: &str) {
    let dt: T = nalgebra::convert(DT_SECS);
    let (a, b, q, r) = plant::<T>();
    let d = zoh(&a, &b, dt).unwrap();
    let settings = RiccatiSettings::<T>::default();
    let sol = solve_dare(&d.a, &d.b, &q, &r, &settings).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    eprintln!(
        "{name}: DARE converged in {} doubling steps, relative residual {:?}",
        sol.iterations, sol.residual
    );

    bench_both(c, &format!("zoh_reduced_miapure_400hz_{name}"), || {
        zoh(black_box(&a), black_box(&b), black_box(dt))
    });
    bench_both(c, &format!("dare_reduced_miapure_400hz_{name}"), || {
        solve_dare(
            black_box(&d.a),
            black_box(&d.b),
            black_box(&q),
            black_box(&r),
            &settings,
        )
    });
    bench_both(c, &format!("care_reduced_miapure_{name}"), || {
        solve_care(
            black_box(&a),
            black_box(&b),
            black_box(&q),
            black_box(&r),
            &settings,
        )
    });
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).unwrap();
    let weights = WipLqrWeights::<T>::model_default();
    bench_both(c, &format!("wip_lqr_discrete_400hz_{name}"), || {
        wip_lqr_discrete(black_box(&wip), black_box(&weights), black_box(dt))
    });
}

fn benches(c: &mut Criterion) {
    bench_precision::<f64>(c, "f64");
    bench_precision::<f32>(c, "f32");
}

criterion_group!(dare, benches);
criterion_main!(dare);
