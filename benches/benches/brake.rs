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

use ballbot_sim::trajopt::{BrakingProblem, Limits, SolveStatus};
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
    if rc != 0 {
        return Duration::ZERO;
    }
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// Benches `problem.solve()` by wall-clock time as `name`, and by thread CPU time as
/// `name_cpu`.
fn bench_both(c: &mut Criterion, name: &str, problem: &BrakingProblem) {
    c.bench_function(name, |b| b.iter(|| black_box(problem.solve())));
    #[cfg(unix)]
    c.bench_function(&format!("{name}_cpu"), |b| {
        b.iter_custom(|iters| {
            let start = thread_cpu_time();
            for _ in 0..iters {
                black_box(problem.solve()).ok();
            }
            thread_cpu_time() - start
        })
    });
}

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
        bench_both(c, &format!("brake_miapure_hermite_simpson_n{n}"), &problem);
    }
    let limited = BrakingProblem {
        limits: Limits {
            traction: true,
            ..Limits::miapure_actuators(0.0)
        },
        ..BrakingProblem::miapure()
    };
    if limited.solve().map(|s| s.status) == Ok(SolveStatus::Solved) {
        bench_both(c, "brake_miapure_actuators_traction_n100", &limited);
    }
}

criterion_group!(benches, brake);
criterion_main!(benches);
