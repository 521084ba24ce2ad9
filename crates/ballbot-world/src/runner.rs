//! The one job runner of the studies: independent jobs (seeded trials, bisection searches,
//! sensitivity points) on every core with [`std::thread::scope`], results in job order.
//!
//! Each job is seeded and independent, and its result is stored at its own index, so the
//! output does not depend on the number of threads or on which thread ran which job: a study
//! run on one core and on eight gives bit-identical results.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Worker threads for `jobs` jobs when `requested` are asked for (0: every available core):
/// at least 1, at most one per job.
///
/// ```
/// use ballbot_world::runner::thread_count;
/// assert_eq!(thread_count(4, 2), 2);
/// assert_eq!(thread_count(3, 0), 1);
/// assert!(thread_count(0, 100) >= 1);
/// ```
pub fn thread_count(requested: usize, jobs: usize) -> usize {
    let threads = if requested == 0 {
        std::thread::available_parallelism().map_or(1, usize::from)
    } else {
        requested
    };
    threads.clamp(1, jobs.max(1))
}

/// Runs `run` on every job of `jobs` on [`thread_count`]`(threads, jobs.len())` scoped
/// threads and returns the results in the jobs' order. `done(i)` is called (from the worker
/// thread) when job `i` has finished, e.g. to advance a progress bar.
///
/// Errors: after a job fails no new job starts, and the error of the failing job with the
/// smallest index is returned (every job before it has run, so this does not depend on the
/// scheduling). A panicking job is a bug: its panic is re-raised in the caller.
///
/// ```
/// use ballbot_world::runner::run_jobs;
/// let squares = run_jobs(&[1_u64, 2, 3, 4], 0, |&x| Ok::<_, String>(x * x), &|_| {});
/// assert_eq!(squares, Ok(vec![1, 4, 9, 16]));
/// let failed = run_jobs(&[1_u64, 2, 3], 2, |&x| if x == 2 { Err(x) } else { Ok(x) }, &|_| {});
/// assert_eq!(failed, Err(2));
/// ```
pub fn run_jobs<J, R, E, F>(
    jobs: &[J],
    threads: usize,
    run: F,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Vec<R>, E>
where
    J: Sync,
    R: Send,
    E: Send,
    F: Fn(&J) -> Result<R, E> + Sync,
{
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let worker = || {
        let mut finished = Vec::new();
        while !failed.load(Ordering::Relaxed) {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(job) = jobs.get(i) else { break };
            let result = run(job);
            if result.is_err() {
                failed.store(true, Ordering::Relaxed);
            }
            done(i);
            finished.push((i, result));
        }
        finished
    };
    let mut results: Vec<(usize, Result<R, E>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..thread_count(threads, jobs.len()))
            .map(|_| scope.spawn(worker))
            .collect();
        let mut all = Vec::with_capacity(jobs.len());
        for handle in handles {
            match handle.join() {
                Ok(finished) => all.extend(finished),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        all
    });
    // Without an error every job ran once: sorted by index, the results are in job order.
    // With one, the first `Err` in index order is the failing job with the smallest index.
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn results_are_in_job_order_for_any_thread_count() {
        let jobs: Vec<u64> = (0..50).collect();
        // Uneven job lengths, so threads finish out of order.
        let work = |&x: &u64| -> Result<u64, ()> {
            let mut h = x;
            for _ in 0..(50 - x) * 1000 {
                h = h.wrapping_mul(6364136223846793005).wrapping_add(1);
            }
            Ok(h)
        };
        let one = run_jobs(&jobs, 1, work, &|_| {}).unwrap();
        for threads in [2, 3, 8] {
            assert_eq!(run_jobs(&jobs, threads, work, &|_| {}).unwrap(), one);
        }
    }

    #[test]
    fn every_job_reports_done_once() {
        let seen = Mutex::new(Vec::new());
        run_jobs(&[10, 20, 30], 2, |&x| Ok::<_, ()>(x), &|i| {
            seen.lock().unwrap().push(i);
        })
        .unwrap();
        let mut seen = seen.into_inner().unwrap();
        seen.sort_unstable();
        assert_eq!(seen, vec![0, 1, 2]);
    }

    #[test]
    fn the_failing_job_with_the_smallest_index_is_reported() {
        let jobs: Vec<u32> = (0..40).collect();
        for threads in [1, 2, 4] {
            let r = run_jobs(
                &jobs,
                threads,
                |&x| if x % 7 == 3 { Err(x) } else { Ok(x) },
                &|_| {},
            );
            assert_eq!(r, Err(3));
        }
    }
}
