//! Minimum braking time by bisection on the duration.
//!
//! A duration counts as feasible when the solve ends [`SolveStatus::Solved`]; anything else
//! (infeasible certificate, no convergence) counts as not shown feasible. Each trial starts
//! from the nearest feasible solution, time-scaled, which keeps the linearisations good near
//! the boundary.

use super::error::TrajoptError;
use super::error::invalid;
use super::problem::{BrakingProblem, InitialGuess, SolveOptions};
use super::sqp::{BrakingSolution, SolveStatus, solve};

/// Search range and resolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinTimeOptions {
    /// Shortest duration tried (s); it is tested first and returned if feasible.
    pub lower_secs: f64,
    /// Longest duration (s); it must be feasible for the search to start.
    pub upper_secs: f64,
    /// Stop when the bracket is at most this wide (s).
    pub resolution_secs: f64,
}

impl Default for MinTimeOptions {
    /// 0.1 s to 5 s (where the paper's hardware protocol starts), to 0.01 s.
    fn default() -> Self {
        Self {
            lower_secs: 0.1,
            upper_secs: 5.0,
            resolution_secs: 0.01,
        }
    }
}

/// The outcome of a minimum-time search.
#[derive(Clone, Debug, PartialEq)]
pub struct MinTimeResult {
    /// The shortest duration shown feasible (s); `None` if even `upper_secs` was not.
    pub min_duration_secs: Option<f64>,
    /// The longest duration shown not feasible (s); `None` if `lower_secs` was feasible.
    pub infeasible_below_secs: Option<f64>,
    /// The solution at `min_duration_secs` (or the failed one at `upper_secs`).
    pub solution: BrakingSolution,
    /// Number of solves.
    pub solves: usize,
}

/// Bisects the braking duration of `problem` (its own `duration_secs` is ignored) for the
/// shortest feasible one under its limits.
pub fn min_braking_time(
    problem: &BrakingProblem,
    options: &SolveOptions,
    search: &MinTimeOptions,
) -> Result<MinTimeResult, TrajoptError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !(ok(search.lower_secs) && ok(search.upper_secs) && ok(search.resolution_secs)) {
        return Err(invalid(
            "min_time",
            "bounds and resolution must be finite and > 0",
        ));
    }
    if search.lower_secs >= search.upper_secs {
        return Err(invalid("min_time.lower_secs", "must be < upper_secs"));
    }
    let mut solves = 0;
    let mut run = |duration_secs: f64, guess: &InitialGuess| {
        solves += 1;
        let p = BrakingProblem {
            duration_secs,
            ..*problem
        };
        let o = SolveOptions {
            initial_guess: guess.clone(),
            ..options.clone()
        };
        solve(&p, &o)
    };
    let hi_sol = run(search.upper_secs, &options.initial_guess)?;
    if hi_sol.status != SolveStatus::Solved {
        return Ok(MinTimeResult {
            min_duration_secs: None,
            infeasible_below_secs: None,
            solution: hi_sol,
            solves,
        });
    }
    let guess = InitialGuess::Trajectory(hi_sol.trajectory.clone());
    let lo_sol = run(search.lower_secs, &guess)?;
    if lo_sol.status == SolveStatus::Solved {
        return Ok(MinTimeResult {
            min_duration_secs: Some(search.lower_secs),
            infeasible_below_secs: None,
            solution: lo_sol,
            solves,
        });
    }
    let (mut lo, mut hi, mut best) = (search.lower_secs, search.upper_secs, hi_sol);
    while hi - lo > search.resolution_secs {
        let mid = 0.5 * (lo + hi);
        let guess = InitialGuess::Trajectory(best.trajectory.clone());
        let sol = run(mid, &guess)?;
        if sol.status == SolveStatus::Solved {
            hi = mid;
            best = sol;
        } else {
            lo = mid;
        }
    }
    Ok(MinTimeResult {
        min_duration_secs: Some(hi),
        infeasible_below_secs: Some(lo),
        solution: best,
        solves,
    })
}
