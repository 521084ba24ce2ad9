//! Shared by the bench targets: wall-clock and thread-CPU-time measurement of one closure.
//!
//! On a shared, oversubscribed machine wall time counts the time spent waiting for a core; the
//! thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`, Unix only) does not. Every bench reports both:
//! `name` (wall) and `name_cpu`.

use criterion::Criterion;
use std::hint::black_box;
use std::time::Duration;

/// CPU time consumed by the calling thread.
#[cfg(unix)]
#[allow(unsafe_code)]
pub fn thread_cpu_time() -> Duration {
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
pub fn bench_both<R>(c: &mut Criterion, name: &str, mut f: impl FnMut() -> R) {
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
