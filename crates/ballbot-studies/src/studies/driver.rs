//! The one experiment driver: a study is a type ([`Study`]): its jobs, one world run (a
//! *trial*) per job or a bisection over a scalar per job, and what counts as passing. The
//! driver ([`execute`]) runs the jobs on the shared job runner ([`ballbot_world::runner`]) with
//! progress, returns every trial in job order, and [`replay`] runs one trial again with an
//! observer (an MCAP logger, a plot) bit for bit. The report layer renders the result; it
//! does not choose settings or run anything.
//!
//! Adding a study is one type implementing [`Study`] plus one report function:
//! [`crate::studies::crossing`] is the example (`ARCHITECTURE.md`, "Adding a study").
//!
//! Every trial carries what happened in its run ([`ballbot_world::rig::Happened`]: how it ended, and
//! its contact events), so a study reports falls and events whatever stop rules it runs with.

use ballbot_world::rig::WorldRobot;
use ballbot_world::runner;

/// A scalar bisection: the value between `passing` and `failing`, nearest `failing`, at which
/// a trial still passes, to within `resolution` (the largest push recovered, the shortest
/// braking time). The study's own [`Study::passed`] says what passing is.
///
/// Two variants: the plain search ([`Self::new`]) assumes `passing` passes and halves the
/// bracket to `resolution`; the grid search ([`Self::grid`]) tries both ends, the passing one
/// first, and only ever tries multiples of `resolution` (a protocol's grid of accelerations).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Bisection {
    /// A value assumed to pass, e.g. 0 for a push or a bump (tried first when `try_passing`).
    pub passing: f64,
    /// The value tried first (after `passing`, when that is tried); if it passes, the search
    /// ends there (the limit is beyond it).
    pub failing: f64,
    /// Stop when the bracket is at most this wide (same unit, > 0); with `on_grid`, the grid's
    /// step.
    pub resolution: f64,
    /// Try `passing` before `failing`; if it fails, the search ends there
    /// ([`Bracket::passed`] is `None`: the limit lies below the bracket).
    pub try_passing: bool,
    /// Every value tried is a whole multiple of `resolution` (rounded to 1e-9 of the unit, so
    /// 1.95 and not 1.9500000000000002): the ends are rounded to the grid and each halving
    /// falls on the grid point at or next to the midpoint towards `passing`; the search ends
    /// when the ends are neighbouring grid points.
    pub on_grid: bool,
}

impl Bisection {
    /// The most halvings a bracket may need (a finer resolution is refused).
    pub const MAX_HALVINGS: u32 = 40;

    /// The plain search: `passing` assumed (not tried), `failing` tried first, halved until
    /// the bracket is at most `resolution` wide.
    pub const fn new(passing: f64, failing: f64, resolution: f64) -> Self {
        Self {
            passing,
            failing,
            resolution,
            try_passing: false,
            on_grid: false,
        }
    }

    /// The grid search: `passing` tried first, then `failing`, then halvings on the grid of
    /// `step` until the ends are neighbours (see [`Self::on_grid`]).
    pub const fn grid(passing: f64, failing: f64, step: f64) -> Self {
        Self {
            passing,
            failing,
            resolution: step,
            try_passing: true,
            on_grid: true,
        }
    }

    /// Grid point `k`: `k * resolution`, rounded to 1e-9 of the unit.
    fn grid_value(&self, k: i64) -> f64 {
        (k as f64 * self.resolution * 1e9).round() / 1e9
    }

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
    /// passed); `None` when a tried `passing` end (or a scan's first value) failed: the limit
    /// lies below the bracket.
    pub passed: Option<f64>,
    /// The value closest to `passing` that failed; `None` when `Bisection::failing` passed
    /// (censored: the limit lies beyond the bracket).
    pub failed: Option<f64>,
}

/// Bisects `search`: tries `search.failing` first (after `search.passing` when
/// [`Bisection::try_passing`]), then halves the bracket until it is at most
/// `search.resolution` wide (on the grid, until its ends are neighbours: [`Bisection::grid`]),
/// calling `trial` at each value and `passed` on its result; every trial goes to `on_trial` in
/// order. Assumes passing is monotone between the ends (every trial is reported, so a
/// non-monotone outcome is visible). Works in either direction: `passing` may lie above
/// `failing` (a braking time) or below (a push).
///
/// ```
/// use ballbot_studies::studies::driver::{Bisection, bisect};
/// // The largest x below 10 with x^2 < 30, to 0.01.
/// let mut tried = Vec::new();
/// let search = Bisection::new(0.0, 10.0, 0.01);
/// let b = bisect(&search, |x| Ok::<_, ()>(x * x), |y| *y < 30.0, |x, _| tried.push(x))?;
/// let (passed, failed) = (b.passed.unwrap(), b.failed.unwrap());
/// assert!(passed < 30f64.sqrt() && 30f64.sqrt() <= failed && failed - passed <= 0.01);
/// assert_eq!(tried[0], 10.0);
/// // The same on a grid of 0.25: both ends tried, every value a multiple of 0.25.
/// let b = bisect(&Bisection::grid(0.0, 10.0, 0.25), |x| Ok::<_, ()>(x * x), |y| *y < 30.0, |_, _| {})?;
/// assert_eq!((b.passed, b.failed), (Some(5.25), Some(5.5)));
/// # Ok::<(), ()>(())
/// ```
pub fn bisect<R, E>(
    search: &Bisection,
    mut trial: impl FnMut(f64) -> Result<R, E>,
    passed: impl Fn(&R) -> bool,
    mut on_trial: impl FnMut(f64, R),
) -> Result<Bracket, E> {
    if search.on_grid {
        return bisect_on_grid(search, trial, passed, on_trial);
    }
    let mut try_end = |v: f64| -> Result<bool, E> {
        let r = trial(v)?;
        let ok = passed(&r);
        on_trial(v, r);
        Ok(ok)
    };
    if search.try_passing && !try_end(search.passing)? {
        return Ok(below(search.passing));
    }
    if try_end(search.failing)? {
        return Ok(beyond(search.failing));
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

/// The bracket of a search whose passing end failed: the limit lies below it.
fn below(passing: f64) -> Bracket {
    Bracket {
        passed: None,
        failed: Some(passing),
    }
}

/// The bracket of a search whose failing end passed: censored, the limit lies beyond it.
fn beyond(failing: f64) -> Bracket {
    Bracket {
        passed: Some(failing),
        failed: None,
    }
}

/// [`bisect`] on the grid of `search.resolution`: grid indices `p` (passing) and `f`
/// (failing), the midpoint truncated towards `p`, until `|f - p| <= 1`.
fn bisect_on_grid<R, E>(
    search: &Bisection,
    mut trial: impl FnMut(f64) -> Result<R, E>,
    passed: impl Fn(&R) -> bool,
    mut on_trial: impl FnMut(f64, R),
) -> Result<Bracket, E> {
    let index = |v: f64| (v / search.resolution).round() as i64;
    let mut p = index(search.passing);
    let mut f = index(search.failing);
    if f == p {
        // Ends closer than one step: the failing end one step beyond the passing one.
        f = if search.failing >= search.passing {
            p + 1
        } else {
            p - 1
        };
    }
    let mut try_at = |k: i64| -> Result<bool, E> {
        let v = search.grid_value(k);
        let r = trial(v)?;
        let ok = passed(&r);
        on_trial(v, r);
        Ok(ok)
    };
    if search.try_passing && !try_at(p)? {
        return Ok(below(search.grid_value(p)));
    }
    if try_at(f)? {
        return Ok(beyond(search.grid_value(f)));
    }
    for _ in 0..Bisection::MAX_HALVINGS {
        if (f - p).abs() <= 1 {
            break;
        }
        // Integer division truncates towards zero, so towards `p`.
        let mid = p + (f - p) / 2;
        if try_at(mid)? {
            p = mid;
        } else {
            f = mid;
        }
    }
    Ok(Bracket {
        passed: Some(search.grid_value(p)),
        failed: Some(search.grid_value(f)),
    })
}

/// The halving part of [`bisect`], for a bracket whose ends are known already (`pass` passed
/// or is assumed to, `fail` failed): halves it until it is at most `resolution` wide, at most
/// [`Bisection::MAX_HALVINGS`] times.
fn halve<R, E>(
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
        passed: Some(pass),
        failed: Some(fail),
    })
}

/// A protocol's scan, then a bisection: tries `values` in order until one fails (the paper's
/// braking descent: 5 s, 4.5 s, ... until a stop fails), then, when `resolution` is given and
/// a value passed before the failure, halves between the last value that passed and the first
/// that failed until the bracket is at most `resolution` wide. Every trial goes to `on_trial`
/// in order. `passed` is `None` when the first value failed, `failed` `None` when none did.
///
/// ```
/// use ballbot_studies::studies::driver::scan_then_halve;
/// // The shortest t with t >= 1.53, scanning 5, 4.5, ..., then to 0.05.
/// let scan: Vec<f64> = (0..10).map(|k| 5.0 - 0.5 * f64::from(k)).collect();
/// let mut tried = Vec::new();
/// let b = scan_then_halve(&scan, Some(0.05), |t| Ok::<_, ()>(t), |t| *t >= 1.53, |t, _| tried.push(t))?;
/// assert_eq!(tried[..8], [5.0, 4.5, 4.0, 3.5, 3.0, 2.5, 2.0, 1.5]);
/// assert_eq!((b.passed, b.failed), (Some(1.53125), Some(1.5)));
/// # Ok::<(), ()>(())
/// ```
pub fn scan_then_halve<R, E>(
    values: &[f64],
    resolution: Option<f64>,
    mut trial: impl FnMut(f64) -> Result<R, E>,
    passed: impl Fn(&R) -> bool,
    mut on_trial: impl FnMut(f64, R),
) -> Result<Bracket, E> {
    let mut last_pass = None;
    let mut first_fail = None;
    for &v in values {
        let r = trial(v)?;
        let ok = passed(&r);
        on_trial(v, r);
        if ok {
            last_pass = Some(v);
        } else {
            first_fail = Some(v);
            break;
        }
    }
    match (resolution, last_pass, first_fail) {
        (Some(resolution), Some(pass), Some(fail)) => {
            halve(pass, fail, resolution, trial, passed, on_trial)
        }
        _ => Ok(Bracket {
            passed: last_pass,
            failed: first_fail,
        }),
    }
}

/// An experiment on the world: its jobs, a trial per job (or a bisection over a scalar), and
/// what passing is. See the [module](self) docs.
pub trait Study: Sync {
    /// One independent job: a heading, a speed, a controller... and its seed.
    type Job: Sync;
    /// What one world run produced (with its [`ballbot_world::rig::Happened`]).
    type Trial: Send;
    /// What can go wrong setting a run up (the outcome of a run is not an error).
    type Error: Send;

    /// The jobs, longest first so that the cores finish together.
    fn jobs(&self) -> Vec<Self::Job>;

    /// The scalar a job bisects, if the study searches one; `None`: one trial per job, at
    /// no scalar. After a [`Self::scan`], only its `resolution` is used.
    fn bisection(&self, job: &Self::Job) -> Option<Bisection>;

    /// Values a job tries in order before it bisects (a protocol's descent, e.g. the paper's
    /// braking times 5, 4.5, ... s): the scan stops at its first failure, then the
    /// [`Self::bisection`], if any, halves between the last value that passed and that failure
    /// to its resolution ([`scan_then_halve`]). Empty (the default): no scan.
    fn scan(&self, _job: &Self::Job) -> Vec<f64> {
        Vec::new()
    }

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

    /// World runs a job takes at most (a progress bar's length): 1; or the bisection's
    /// halvings plus the ends it tries; or a scan's values plus the halvings of its widest
    /// step.
    fn runs_estimate(&self, job: &Self::Job) -> u64 {
        let halvings = |width: f64, resolution: f64| {
            (width.abs() / resolution).log2().ceil().clamp(0.0, 64.0) as u64
        };
        let scan = self.scan(job);
        match self.bisection(job) {
            _ if !scan.is_empty() => {
                let widest = scan
                    .windows(2)
                    .map(|w| (w[1] - w[0]).abs())
                    .fold(0.0, f64::max);
                let refine = self
                    .bisection(job)
                    .map_or(0, |b| halvings(widest, b.resolution));
                scan.len() as u64 + refine
            }
            None => 1,
            Some(b) => 1 + u64::from(b.try_passing) + halvings(b.failing - b.passing, b.resolution),
        }
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
    /// How many of the first `trials` are the job's [`Study::scan`] (0 without one).
    pub scanned: usize,
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
    let scan = study.scan(job);
    if !scan.is_empty() {
        let resolution = study.bisection(job).map(|b| b.resolution);
        let bracket = scan_then_halve(
            &scan,
            resolution,
            |v| study.trial(job, Some(v), &mut |_| {}),
            |t| study.passed(t),
            |v, t| {
                on_trial(Some(v), &t);
                trials.push((Some(v), t));
            },
        )?;
        // The scan ran up to and with its first failure, or through all its values.
        let scanned = trials
            .iter()
            .position(|(_, t)| !study.passed(t))
            .map_or(trials.len(), |i| i + 1);
        return Ok(JobRecord {
            index,
            trials,
            scanned,
            bracket: Some(bracket),
        });
    }
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
        scanned: 0,
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
/// [`ballbot_log::WorldLogger`]): the same run, bit for bit, as the one [`execute`] recorded.
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
        let up = Bisection::new(0.0, 100.0, 0.5);
        let b = bisect(&up, Ok::<_, ()>, |x| *x <= 37.3, |_, _| {}).unwrap();
        let (passed, failed) = (b.passed.unwrap(), b.failed.unwrap());
        assert!(passed <= 37.3 && 37.3 < failed && failed - passed <= 0.5);
        // ... and above it (a braking time).
        let down = Bisection::new(5.0, 1.0, 0.05);
        let b = bisect(&down, Ok::<_, ()>, |x| *x >= 1.53, |_, _| {}).unwrap();
        let (passed, failed) = (b.passed.unwrap(), b.failed.unwrap());
        assert!(passed >= 1.53 && 1.53 > failed && passed - failed <= 0.05);
        // A failing end that passes ends the search there, censored.
        let b = bisect(&up, Ok::<_, ()>, |_| true, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (Some(100.0), None));
    }

    #[test]
    fn a_grid_search_tries_both_ends_and_stays_on_the_grid() {
        // The maximum-speed search: 0.5 to 4 m/s^2 on a grid of 0.05, limit 1.37.
        let search = Bisection::grid(0.5, 4.0, 0.05);
        let mut tried = Vec::new();
        let b = bisect(&search, Ok::<_, ()>, |a| *a <= 1.37, |a, _| tried.push(a)).unwrap();
        assert_eq!((b.passed, b.failed), (Some(1.35), Some(1.4)));
        // The passing end first, then the failing one; every value a printed grid point.
        assert_eq!(tried[..2], [0.5, 4.0]);
        for a in &tried {
            let k = a / 0.05;
            assert!((k - k.round()).abs() < 1e-9, "{a} is off the grid");
            assert!(format!("{a}").len() <= 4, "{a} carries rounding noise");
        }
        // Truncated midpoints: index 10 and 80, then 45 (2.25), 27 (1.35), 36, 31, 29, 28.
        assert_eq!(tried[2..], [2.25, 1.35, 1.8, 1.55, 1.45, 1.4]);
        // A passing end that fails ends the search below the bracket ...
        let b = bisect(&search, Ok::<_, ()>, |_| false, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (None, Some(0.5)));
        // ... and a failing end that passes, beyond it, after two trials.
        let mut n = 0;
        let b = bisect(&search, Ok::<_, ()>, |_| true, |_, _| n += 1).unwrap();
        assert_eq!((b.passed, b.failed, n), (Some(4.0), None, 2));
        // Downwards too: the shortest passing value on the grid.
        let down = Bisection::grid(5.0, 1.0, 0.25);
        let b = bisect(&down, Ok::<_, ()>, |t| *t >= 1.6, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (Some(1.75), Some(1.5)));
    }

    #[test]
    fn a_scan_stops_at_its_first_failure_then_halves() {
        let scan = [5.0, 4.5, 4.0, 3.5];
        let mut tried = Vec::new();
        let b = scan_then_halve(
            &scan,
            Some(0.1),
            Ok::<_, ()>,
            |t| *t >= 4.2,
            |t, _| tried.push(t),
        )
        .unwrap();
        assert_eq!(tried, [5.0, 4.5, 4.0, 4.25, 4.125, 4.1875]);
        assert_eq!((b.passed, b.failed), (Some(4.25), Some(4.1875)));
        // No refinement without a resolution; a first value that fails; none that fails.
        let b = scan_then_halve(&scan, None, Ok::<_, ()>, |t| *t >= 4.2, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (Some(4.5), Some(4.0)));
        let b = scan_then_halve(&scan, Some(0.1), Ok::<_, ()>, |_| false, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (None, Some(5.0)));
        let b = scan_then_halve(&scan, Some(0.1), Ok::<_, ()>, |_| true, |_, _| {}).unwrap();
        assert_eq!((b.passed, b.failed), (Some(3.5), None));
    }

    /// A study on a closed-form trial (no world): the driver's record of a scan.
    struct Descent;

    impl Study for Descent {
        type Job = f64;
        type Trial = f64;
        type Error = ();

        fn jobs(&self) -> Vec<f64> {
            vec![1.53, 3.2]
        }
        fn bisection(&self, _: &f64) -> Option<Bisection> {
            Some(Bisection::new(5.0, 0.5, 0.05))
        }
        fn scan(&self, _: &f64) -> Vec<f64> {
            (0..10).map(|k| 5.0 - 0.5 * f64::from(k)).collect()
        }
        fn trial(
            &self,
            limit: &f64,
            t: Option<f64>,
            _: &mut dyn FnMut(&WorldRobot),
        ) -> Result<f64, ()> {
            Ok(t.unwrap_or(0.0) - limit)
        }
        fn passed(&self, margin: &f64) -> bool {
            *margin >= 0.0
        }
        fn describe(&self, _: &f64, _: Option<f64>, _: &f64) -> String {
            String::new()
        }
    }

    #[test]
    fn the_driver_records_a_scan_and_its_refinement() {
        let records = execute(&Descent, 2, &|_| {}).unwrap();
        // Limit 1.53: 5 ... 1.5 (8 scanned, the last failing), then 1.75 ... 1.53125.
        let r = &records[0];
        assert_eq!(r.scanned, 8);
        assert_eq!(r.trials.len(), 12);
        let b = r.bracket.unwrap();
        assert_eq!((b.passed, b.failed), (Some(1.53125), Some(1.5)));
        // Limit 3.2: 5 ... 3.0 (5 scanned), then 3.25, 3.125, 3.1875, 3.21875.
        assert_eq!(records[1].scanned, 5);
        assert_eq!(records[1].trials.len(), 9);
        let b = records[1].bracket.unwrap();
        assert_eq!((b.passed, b.failed), (Some(3.21875), Some(3.1875)));
        // The estimate is an upper bound: 10 scanned and 4 halvings of 0.5 s to 0.05 s.
        assert_eq!(Descent.runs_estimate(&1.53), 14);
    }

    #[test]
    fn bisection_checks_its_bracket() {
        let ok = Bisection::new(0.0, 1.0, 0.1);
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
