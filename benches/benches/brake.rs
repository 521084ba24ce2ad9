//! Minimum-effort braking solves (the whole solve, building the problem included).
//!
//! `cargo bench -p ballbot-benches --bench brake`: MiaPURE with 60 kg, 1.4 m/s to rest in
//! 2 s, Hermite-Simpson with N = 50, 100, 200, from the LQ initial guess; and with the
//! MiaPURE actuator limits plus the friction-aware traction cones at N = 100.
//!
//! Each is measured twice: wall-clock time, and with the `_cpu` suffix the thread's CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`, Unix only), which on a shared, oversubscribed machine leaves out
//! the time the thread waits for a core.
//!
//! Run: `cargo bench -p ballbot-benches --bench brake -- --warm-up-time 1 --measurement-time 3`

mod common;
use ballbot_sim::trajopt::{BrakingProblem, Limits, SolveStatus};
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};

fn brake(c: &mut Criterion) {
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
        bench_both(c, &format!("brake_miapure_hermite_simpson_n{n}"), || {
            problem.solve()
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
        bench_both(c, "brake_miapure_actuators_traction_n100", || {
            limited.solve()
        });
    }
}

criterion_group!(benches, brake);
criterion_main!(benches);
