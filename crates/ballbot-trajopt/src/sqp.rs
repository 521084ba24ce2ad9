//! Sequential quadratic programming with clarabel QPs and an L1 merit line search.
//!
//! Each iteration linearises the collocation defects and traction cones at the current point
//! with the exact analytic Jacobians (`Wip::linearize`, chained through the Hermite-Simpson
//! midpoint) and solves the QP `min 1/2 x^T P x` under the linearised constraints and the
//! exact linear bounds. The Hessian is the cost's own (exact for `integral tau^2`, positive
//! semidefinite as clarabel needs); the constraint curvature is left out, a Gauss-Newton
//! choice that converges linearly at a rate set by the (small) curvature of the dynamics
//! along the trajectory. Globalisation: backtracking on the L1 merit
//! `J + rho * sum|violation|` with `rho` at least twice the largest QP multiplier.
//!
//! Convergence: at the point `z` with the QP's multipliers `y`, the KKT stationarity residual
//! `grad J(z) + J_c(z)^T y = P z + A(z)^T y` is evaluated explicitly (for an exact QP solution
//! it is `-P d`, the QP being stationary at `z + d`), so the test is
//! `max violation(z) <= primal_tolerance` and
//! `||P z + A(z)^T y||_inf <= dual_tolerance ||P z||_inf` (relative, so a small initial speed,
//! whose cost is small, is solved as accurately as a large one); the multipliers lie in the
//! dual cones by clarabel's construction. The same test is also made right after each step,
//! at the new point with the same multipliers, which can save the QP that would only confirm
//! convergence.

use super::error::TrajoptError;
use super::interp::Trajectory;
use super::lq::LqBraking;
use super::problem::{BrakingProblem, InitialGuess, SolveOptions};
use super::qp::{Qp, QpOutcome};
use super::transcription::Transcription;
use ballbot_core::WipState;
use std::time::Instant;

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, schemars::JsonSchema)]
#[schemars(rename_all = "snake_case")]
#[non_exhaustive]
pub enum SolveStatus {
    /// The KKT residuals are within the tolerances.
    Solved,
    /// The iteration limit was reached first; the last iterate is returned.
    MaxIterations,
    /// A linearised problem has no feasible point (clarabel's certificate): the limits cannot
    /// be met, e.g. a braking time far too short for the torque bound.
    Infeasible,
    /// The line search could not reduce the merit function.
    LineSearchFailed,
    /// clarabel stopped without a solution or a certificate.
    NumericalError,
}

impl SolveStatus {
    /// Lower-case name, as printed by the CLI and written to summaries.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Solved => "solved",
            Self::MaxIterations => "max_iterations",
            Self::Infeasible => "infeasible",
            Self::LineSearchFailed => "line_search_failed",
            Self::NumericalError => "numerical_error",
        }
    }
}

impl core::fmt::Display for SolveStatus {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Normal and traction force of each omniwheel at one knot (N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnotContact {
    /// Normal force `N_i` of each wheel (N); negative means lift-off.
    pub normal_n: [f64; 3],
    /// Traction magnitude `|F_i|` each wheel transmits (N).
    pub traction_n: [f64; 3],
}

/// The result of a braking solve.
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingSolution {
    /// How the solve ended. Only [`SolveStatus::Solved`] certifies the trajectory.
    pub status: SolveStatus,
    /// The problem that was solved.
    pub problem: BrakingProblem,
    /// Knot states, torques, and the interpolant `s_c(t)`.
    pub trajectory: Trajectory,
    /// `J = integral tau^2 dt` by the scheme's quadrature (N^2 m^2 s).
    pub cost_n2m2s: f64,
    /// SQP iterations (QPs solved).
    pub iterations: usize,
    /// Largest constraint violation at the returned point.
    pub primal_residual: f64,
    /// KKT stationarity residual `||grad J + J_c^T y||_inf` at the returned point (N^2 m^2 s
    /// per unit of the variable).
    pub dual_residual: f64,
    /// Wall time of the whole solve, building the problem included (s).
    pub solve_time_secs: f64,
    /// Contact forces at every knot when the limits name an omniwheel drive; else empty.
    pub contacts: Vec<KnotContact>,
}

impl BrakingSolution {
    /// Whether the solve converged.
    pub fn is_solved(&self) -> bool {
        self.status == SolveStatus::Solved
    }

    /// Peak tilt magnitude over the knots (rad).
    pub fn peak_tilt_rad(&self) -> f64 {
        self.trajectory
            .knot_states()
            .iter()
            .fold(0.0, |m, s| f64::max(m, s[0].abs()))
    }
}

impl BrakingProblem {
    /// Solves with default options (LQ initial guess).
    ///
    /// ```
    /// use ballbot_trajopt::BrakingProblem;
    /// let sol = BrakingProblem::miapure().solve()?;
    /// assert!(sol.is_solved());
    /// // MODEL.md section 7: about 114 N^2 m^2 s.
    /// assert!((sol.cost_n2m2s - 114.0).abs() < 2.0);
    /// # Ok::<(), ballbot_trajopt::TrajoptError>(())
    /// ```
    pub fn solve(&self) -> Result<BrakingSolution, TrajoptError> {
        solve(self, &SolveOptions::default())
    }
}

/// Solves `problem` by SQP. `Err` only for malformed input; the outcome is in the status.
pub fn solve(
    problem: &BrakingProblem,
    options: &SolveOptions,
) -> Result<BrakingSolution, TrajoptError> {
    let start = Instant::now();
    options.validate()?;
    let t = Transcription::new(problem)?;
    let mut z = initial_guess(&t, &options.initial_guess);
    let mut qp = Qp::new(&t, &z)?;
    let mut rho = 0.0_f64;
    let mut status = SolveStatus::MaxIterations;
    let mut iterations = 0;
    let mut primal_residual = f64::INFINITY;
    let mut dual_residual = f64::INFINITY;
    let mut d = vec![0.0; z.len()];
    let mut trial = vec![0.0; z.len()];
    for iter in 1..=options.max_iterations {
        if iter > 1 {
            qp.push()?;
        }
        iterations = iter;
        match qp.solve() {
            QpOutcome::Solved => {}
            QpOutcome::Infeasible => {
                status = SolveStatus::Infeasible;
                break;
            }
            QpOutcome::Failed => {
                status = SolveStatus::NumericalError;
                break;
            }
        }
        let pd = &qp.hessian_diagonal;
        let mut grad_dot_d = 0.0;
        for (i, (di, xi)) in d.iter_mut().zip(qp.primal()).enumerate() {
            *di = xi - z[i];
            grad_dot_d += pd[i] * z[i] * *di;
        }
        // Stationarity at z with the QP's multipliers, evaluated explicitly (it equals
        // ||P d|| when the QP is solved exactly).
        let (stationarity, grad_inf) = qp.stationarity(&z);
        dual_residual = stationarity;
        let (viol_sum, viol_max) = t.violation(&z);
        primal_residual = viol_max;
        if viol_max <= options.primal_tolerance
            && dual_residual <= options.dual_tolerance * grad_inf.max(f64::MIN_POSITIVE)
        {
            status = SolveStatus::Solved;
            break;
        }
        let y_max = qp.dual().iter().fold(0.0_f64, |m, y| m.max(y.abs()));
        rho = rho.max(2.0 * y_max);
        let merit0 = t.cost(&z) + rho * viol_sum;
        let slope = grad_dot_d - rho * viol_sum;
        let mut alpha = 1.0;
        let accepted = loop {
            for ((ti, zi), di) in trial.iter_mut().zip(&z).zip(&d) {
                *ti = zi + alpha * di;
            }
            let (viol_sum, viol_max) = t.violation(&trial);
            let merit = t.cost(&trial) + rho * viol_sum;
            // Armijo, or no increase beyond rounding (near convergence the predicted decrease
            // can fall below the merit's last digits).
            let rounding = 1e-12 * merit0.abs();
            if merit.is_finite()
                && (merit <= merit0 + 1e-4 * alpha * slope.min(0.0) || merit <= merit0 + rounding)
            {
                primal_residual = viol_max;
                break true;
            }
            alpha *= 0.5;
            if alpha < 1e-6 {
                break false;
            }
        };
        if !accepted {
            status = SolveStatus::LineSearchFailed;
            break;
        }
        std::mem::swap(&mut z, &mut trial);
        // KKT test at the new point with this QP's multipliers, which saves the QP that
        // would only confirm convergence.
        qp.relinearize(&t, &z);
        let (stationarity, grad_inf) = qp.stationarity(&z);
        if primal_residual <= options.primal_tolerance
            && stationarity <= options.dual_tolerance * grad_inf.max(f64::MIN_POSITIVE)
        {
            dual_residual = stationarity;
            status = SolveStatus::Solved;
            break;
        }
    }
    if status == SolveStatus::MaxIterations {
        primal_residual = t.violation(&z).1;
    }
    let n = t.intervals;
    let states: Vec<WipState<f64>> = (0..=n).map(|k| t.knot_state(&z, k)).collect();
    let torques: Vec<f64> = (0..=n).map(|k| z[t.torque(k)]).collect();
    let mids: Vec<f64> = (0..n)
        .filter_map(|k| t.mid_torque(k).map(|i| z[i]))
        .collect();
    let trajectory = Trajectory::new(
        t.method,
        problem.duration_secs,
        states,
        t.knot_rates(&z),
        torques,
        mids,
    )
    .ok_or(TrajoptError::QpSetup("inconsistent trajectory".into()))?;
    let contacts = (0..=n)
        .filter_map(|k| t.contact_forces(&z, k))
        .map(|(normal_n, traction_n)| KnotContact {
            normal_n,
            traction_n,
        })
        .collect();
    Ok(BrakingSolution {
        status,
        problem: *problem,
        trajectory,
        cost_n2m2s: t.cost(&z),
        iterations,
        primal_residual,
        dual_residual,
        solve_time_secs: start.elapsed().as_secs_f64(),
        contacts,
    })
}

fn initial_guess(t: &Transcription, guess: &InitialGuess) -> Vec<f64> {
    let big_t = t.problem.duration_secs;
    let v0 = t.initial_state[3];
    match guess {
        InitialGuess::Trajectory(tr) => {
            let scale = tr.duration_secs() / big_t;
            t.guess_from(|s| (tr.state_at(s * scale), tr.torque_at(s * scale)))
        }
        InitialGuess::LinearQuadratic => {
            let h = t.step_secs;
            let n = t.intervals;
            match LqBraking::new(&t.wip, t.problem.initial_speed_m_per_s, big_t) {
                Some(lq) => {
                    let mut z = t.guess_from(|s| {
                        let x = lq.reduced_state_at(s);
                        (WipState::new(x[0], 0.0, x[1], x[2]), lq.torque_at(s))
                    });
                    // phi by Simpson's rule on the closed-form ball rate.
                    let mut phi = 0.0;
                    for k in 0..n {
                        let a = k as f64 * h;
                        let rate = |s: f64| lq.reduced_state_at(s)[2];
                        phi += h / 6.0 * (rate(a) + 4.0 * rate(a + h / 2.0) + rate(a + h));
                        z[t.state(k + 1) + 1] = phi;
                    }
                    z
                }
                // Straight line: ball rate falling linearly to rest, upright, no torque.
                None => t.guess_from(|s| {
                    let x = s / big_t;
                    let phi = v0 * big_t * (x - x * x / 2.0);
                    (WipState::new(0.0, phi, 0.0, v0 * (1.0 - x)), 0.0)
                }),
            }
        }
    }
}
