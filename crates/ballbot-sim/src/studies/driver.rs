//! The one experiment driver: a study is a type ([`Study`]): its jobs, one world run (a
//! *trial*) per job or a bisection over a scalar per job, and what counts as passing. The
//! driver ([`execute`]) runs the jobs on the shared job runner ([`crate::studies::runner`]) with
//! progress, returns every trial in job order, and [`replay`] runs one trial again with an
//! observer (an MCAP logger, a plot) bit for bit. The report layer renders the result; it
//! does not choose settings or run anything.
//!
//! Adding a study is one type implementing [`Study`] plus one report function:
//! [`crate::studies::bump`] is the example (`ARCHITECTURE.md`, "Adding a study").
//!
//! Every trial carries what happened in its run ([`crate::rig::Happened`]: how it ended, and
//! its contact events), so a study reports falls and events whatever stop rules it runs with.

use crate::rig::WorldRobot;
use crate::studies::runner;

/// A scalar bisection: the value between `passing` and `failing`, nearest `failing`, at which
/// a trial still passes, to within `resolution` (the largest push recovered, the shortest
/// braking time). The study's own [`Study::passed`] says what passing is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Bisection {
    /// A value assumed to pass (not tried), e.g. 0 for a push or a bump.
    pub passing: f64,
    /// The value tried first; if it passes, the search ends there (the limit is beyond it).
    pub failing: f64,
    /// Stop when the bracket is at most this wide (same unit, > 0).
    pub resolution: f64,
}

impl Bisection {
    /// The most halvings a bracket may need (a finer resolution is refused).
    pub const MAX_HALVINGS: u32 = 40;

    /// Checks the bracket: finite ends that differ, a resolution > 0 that at most
    /// [`Self::MAX_HALVINGS`] halvings reach.
    pub fn validate(&self) -> Result<(), &'static str> {
        let width = (self.failing - self.passing).abs();
        if !(self.passing.is_finite() && self.failing.is_finite() && width > 0.0) {
            return Err("the bracket's ends must be finite and differ");
        }
        if !(self.resolution.is_finite() && self.resolution > 0.0) {
            return Err("the resolution must be finite and > 0");
        }
        if width / self.resolution > 2f64.powi(Self::MAX_HALVINGS as i32) {
            return Err("the resolution is finer than 2^-40 of the bracket");
        }
        Ok(())
    }
}

/// The bracket a [`bisect`] ended with.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Bracket {
    /// The value closest to `failing` that passed (`Bisection::passing` if none was tried and
    /// passed).
    pub passed: f64,
    /// The value closest to `passing` that failed; `None` when `Bisection::failing` passed
    /// (censored: the limit lies beyond the bracket).
    pub failed: Option<f64>,
}

/// Bisects `search`: tries `search.failing` first, then halves the bracket until it is at
/// most `search.resolution` wide, calling `trial` at each value and `passed` on its result;
/// every trial goes to `on_trial` in order. Assumes passing is monotone between the ends
/// (every trial is reported, so a non-monotone outcome is visible). Works in either
/// direction: `passing` may lie above `failing` (a braking time) or below (a push).
///
/// ```
/// use ballbot_sim::studies::driver::{Bisection, bisect};
/// // The largest x below 10 with x^2 < 30, to 0.01.
/// let mut tried = Vec::new();
/// let search = Bisection { passing: 0.0, failing: 10.0, resolution: 0.01 };
/// let b = bisect(&search, |x| Ok::<_, ()>(x * x), |y| *y < 30.0, |x, _| tried.push(x))?;
/// assert!(b.passed < 30f64.sqrt() && 30f64.sqrt() <= b.failed.unwrap());
/// assert!(b.failed.unwrap() - b.passed <= 0.01);
/// assert_eq!(tried[0], 10.0);
/// # Ok::<(), ()>(())
/// ```
pub fn bisect<R, E>(
    search: &Bisection,
    mut trial: impl FnMut(f64) -> Result<R, E>,
    passed: impl Fn(&R) -> bool,
    mut on_trial: impl FnMut(f64, R),
) -> Result<Bracket, E> {
    let first = trial(search.failing)?;
    let first_passed = passed(&first);
    on_trial(search.failing, first);
    if first_passed {
        return Ok(Bracket {
            passed: search.failing,
            failed: None,
        });
    }
    halve(
        search.passing,
        search.failing,
        search.resolution,
        trial,
        passed,
        on_trial,
    )
}

/// The halving part of [`bisect`], for a bracket whose ends are known already (`pass` passed
/// or is assumed to, `fail` failed; e.g. by the braking protocol's descent): halves it until it
/// is at most `resolution` wide, at most [`Bisection::MAX_HALVINGS`] times.
pub fn halve<R, E>(
    mut pass: f64,
    mut fail: f64,
    resolution: f64,
    mut trial: impl FnMut(f64) -> Result<R, E>,
    passed: impl Fn(&R) -> bool,
    mut on_trial: impl FnMut(f64, R),
) -> Result<Bracket, E> {
    // The cap bounds a bracket that `Bisection::validate` would refuse (an infinite end).
    for _ in 0..Bisection::MAX_HALVINGS {
        if (fail - pass).abs() <= resolution {
            break;
        }
        let mid = 0.5 * (pass + fail);
        let r = trial(mid)?;
        if passed(&r) {
            pass = mid;
        } else {
            fail = mid;
        }
        on_trial(mid, r);
    }
    Ok(Bracket {
        passed: pass,
        failed: Some(fail),
    })
}

/// An experiment on the world: its jobs, a trial per job (or a bisection over a scalar), and
/// what passing is. See the [module](self) docs.
pub trait Study: Sync {
    /// One independent job: a heading, a speed, a controller... and its seed.
    type Job: Sync;
    /// What one world run produced (with its [`crate::rig::Happened`]).
    type Trial: Send;
    /// What can go wrong setting a run up (the outcome of a run is not an error).
    type Error: Send;

    /// The jobs, longest first so that the cores finish together.
    fn jobs(&self) -> Vec<Self::Job>;

    /// The scalar a job bisects, if the study searches one; `None`: one trial per job, at
    /// no scalar.
    fn bisection(&self, job: &Self::Job) -> Option<Bisection>;

    /// One world run of `job`, at `value` when the job bisects one, each physics step shown
    /// to `observe` after it is taken (a logger; the run is the same with or without one).
    fn trial(
        &self,
        job: &Self::Job,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<Self::Trial, Self::Error>;

    /// Whether a trial passed (what the bisection keeps).
    fn passed(&self, trial: &Self::Trial) -> bool;

    /// A short line for a progress display, e.g. `bump 90 deg 1.0 m/s 4.0 mm: fell`.
    fn describe(&self, job: &Self::Job, value: Option<f64>, trial: &Self::Trial) -> String;

    /// World runs a job takes about (a progress bar's length): 1, or the bisection's
    /// halvings plus its first trial.
    fn runs_estimate(&self, job: &Self::Job) -> u64 {
        self.bisection(job).map_or(1, |b| {
            let halvings = ((b.failing - b.passing).abs() / b.resolution)
                .log2()
                .ceil()
                .max(0.0);
            1 + halvings as u64
        })
    }
}

/// What one job of a study gave: its trials in order (with the scalar of each, when the job
/// bisects one) and the bisection's final bracket.
#[derive(Clone, Debug, PartialEq)]
pub struct JobRecord<T> {
    /// The job's index in [`Study::jobs`].
    pub index: usize,
    /// Every trial, in the order run: `(value, trial)`.
    pub trials: Vec<(Option<f64>, T)>,
    /// The bisection's bracket; `None` for a job without one.
    pub bracket: Option<Bracket>,
}

impl<T> JobRecord<T> {
    /// The trial run at `value` (the first, if several were).
    pub fn trial_at(&self, value: f64) -> Option<&T> {
        self.trials
            .iter()
            .find(|(v, _)| *v == Some(value))
            .map(|(_, t)| t)
    }
}

/// Runs one job of `study`: one trial, or its bisection. `on_trial` sees each trial as it
/// finishes, with its value (a progress line: [`Study::describe`]).
pub fn run_job<S: Study>(
    study: &S,
    index: usize,
    job: &S::Job,
    on_trial: &mut dyn FnMut(Option<f64>, &S::Trial),
) -> Result<JobRecord<S::Trial>, S::Error> {
    let mut trials = Vec::new();
    let bracket = match study.bisection(job) {
        None => {
            let t = study.trial(job, None, &mut |_| {})?;
            on_trial(None, &t);
            trials.push((None, t));
            None
        }
        Some(search) => Some(bisect(
            &search,
            |v| study.trial(job, Some(v), &mut |_| {}),
            |t| study.passed(t),
            |v, t| {
                on_trial(Some(v), &t);
                trials.push((Some(v), t));
            },
        )?),
    };
    Ok(JobRecord {
        index,
        trials,
        bracket,
    })
}

/// Runs every job of `study` on `threads` threads (0: every core) and returns their records
/// in job order; the result does not depend on the number of threads. `progress` is called
/// (from worker threads) after every trial.
pub fn execute<S: Study>(
    study: &S,
    threads: usize,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Vec<JobRecord<S::Trial>>, S::Error> {
    let jobs: Vec<(usize, S::Job)> = study.jobs().into_iter().enumerate().collect();
    runner::run_jobs(
        &jobs,
        threads,
        |(i, job)| {
            run_job(study, *i, job, &mut |v, t| {
                progress(&study.describe(job, v, t));
            })
        },
        &|_| {},
    )
}

/// The trial of `study`'s job `index` at `value` again, each step shown to `observe` (e.g. a
/// [`crate::log::WorldLogger`]): the same run, bit for bit, as the one [`execute`] recorded.
/// `None` when there is no such job.
pub fn replay<S: Study>(
    study: &S,
    index: usize,
    value: Option<f64>,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Option<Result<S::Trial, S::Error>> {
    let job = study.jobs().into_iter().nth(index)?;
    Some(study.trial(&job, value, observe))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn bisection_brackets_the_limit_from_either_side() {
        // Passing below the limit (a push)...
        let up = Bisection {
            passing: 0.0,
            failing: 100.0,
            resolution: 0.5,
        };
        let b = bisect(&up, Ok::<_, ()>, |x| *x <= 37.3, |_, _| {}).unwrap();
        assert!(b.passed <= 37.3 && 37.3 < b.failed.unwrap());
        assert!(b.failed.unwrap() - b.passed <= 0.5);
        // ... and above it (a braking time).
        let down = Bisection {
            passing: 5.0,
            failing: 1.0,
            resolution: 0.05,
        };
        let b = bisect(&down, Ok::<_, ()>, |x| *x >= 1.53, |_, _| {}).unwrap();
        assert!(b.passed >= 1.53 && 1.53 > b.failed.unwrap());
        assert!(b.passed - b.failed.unwrap() <= 0.05);
        // A failing end that passes ends the search there, censored.
        let b = bisect(&up, Ok::<_, ()>, |_| true, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (100.0, None));
    }

    #[test]
    fn bisection_checks_its_bracket() {
        let ok = Bisection {
            passing: 0.0,
            failing: 1.0,
            resolution: 0.1,
        };
        assert!(ok.validate().is_ok());
        for bad in [
            Bisection { failing: 0.0, ..ok },
            Bisection {
                resolution: 0.0,
                ..ok
            },
            Bisection {
                passing: f64::NAN,
                ..ok
            },
            Bisection {
                resolution: 1e-15,
                ..ok
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
