//! Minimum-effort braking solves (the whole solve, building the problem included).
//!
//! `cargo bench -p ballbot-benches --bench brake`: MiaPURE with 60 kg, 1.4 m/s to rest in
//! 2 s, Hermite-Simpson with N = 50, 100, 200, from the LQ initial guess; and with the
//! MiaPURE actuator limits plus the friction-aware traction cones at N = 100.

use ballbot_sim::trajopt::{BrakingProblem, Limits, SolveStatus};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn brake(c: &mut Criterion) {
    let mut group = c.benchmark_group("brake_miapure_1.4mps_2s");
    for n in [50usize, 100, 200] {
        let problem = BrakingProblem {
            intervals: n,
            ..BrakingProblem::miapure()
        };
        // A bench of a failing solve would measure the wrong thing.
        if problem.solve().map(|s| s.status) != Ok(SolveStatus::Solved) {
            eprintln!("brake bench: N = {n} did not solve");
            continue;
        }
        group.bench_with_input(BenchmarkId::new("hermite_simpson", n), &problem, |b, p| {
            b.iter(|| black_box(p.solve()))
        });
    }
    let limited = BrakingProblem {
        limits: Limits {
            traction: true,
            ..Limits::miapure_actuators(0.0)
        },
        ..BrakingProblem::miapure()
    };
    if limited.solve().map(|s| s.status) == Ok(SolveStatus::Solved) {
        group.bench_function("hermite_simpson_actuators_traction/100", |b| {
            b.iter(|| black_box(limited.solve()))
        });
    }
    group.finish();
}

criterion_group!(benches, brake);
criterion_main!(benches);
