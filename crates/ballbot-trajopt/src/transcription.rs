//! Direct collocation: decision variables, cost, constraints and their exact Jacobians, laid
//! out for clarabel (`A x + s = b`, `s` in a product of cones).
//!
//! Variables, interleaved per knot so the KKT matrix is banded: knot `k` holds
//! `[theta, phi, theta_dot, phi_dot, tau]_k` and, for Hermite-Simpson and `k < N`, the
//! midpoint torque `tau_{k+1/2}`. With `h = T / N` and `f_k = f(s_k, tau_k)`:
//!
//! ```text
//! Hermite-Simpson:  s_m = (s_k + s_{k+1}) / 2 + h (f_k - f_{k+1}) / 8,  f_m = f(s_m, tau_m)
//!                   s_{k+1} - s_k - h (f_k + 4 f_m + f_{k+1}) / 6 = 0
//!                   J = sum h (tau_k^2 + 4 tau_m^2 + tau_{k+1}^2) / 6      (Simpson)
//! Trapezoidal:      s_{k+1} - s_k - h (f_k + f_{k+1}) / 2 = 0
//!                   J = sum h (tau_k^2 + tau_{k+1}^2) / 2
//! ```
//!
//! The QP of each SQP iteration is written in the new point itself, not the step: the cost is
//! exactly quadratic (`1/2 x^T P x`, `P` diagonal), bounds are exact, and the nonlinear rows
//! (defects, traction) are linearised at the current point `z`:
//! `J_c(z) x = J_c(z) z - c(z)`.

use super::drive::DriveMap;
use super::method::Method;
use super::problem::BrakingProblem;
use ballbot_core::{Wip, WipState};
use nalgebra::{Matrix4, Vector4};

/// The cones of the constraint rows, in row order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ConeSizes {
    /// Equality rows.
    pub zero: usize,
    /// Inequality rows `a^T x <= b` (path and motor limits).
    pub nonnegative: usize,
    /// Traction rows `mu (N_i - N_min) -+ F_i >= 0` (nonnegative too), two per wheel and knot.
    pub traction: usize,
}

/// Receives the constraint matrix and right-hand side in a fixed order.
pub(crate) trait Sink {
    /// Entry `(row, col)` of `A` with `value`.
    fn entry(&mut self, row: usize, col: usize, value: f64);
    /// Right-hand side `b[row] = value`.
    fn rhs(&mut self, row: usize, value: f64);
}

/// A transcribed braking problem.
#[derive(Clone, Debug)]
pub(crate) struct Transcription {
    pub wip: Wip<f64>,
    pub method: Method,
    pub intervals: usize,
    pub step_secs: f64,
    pub initial_state: WipState<f64>,
    pub problem: BrakingProblem,
    drive: Option<DriveMap>,
    /// Cost weights `w` per variable: `J = sum w x^2`.
    pub weights: Vec<f64>,
    pub cones: ConeSizes,
}

/// Per-point evaluation: state derivative and its Jacobians.
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
struct Point {
    f: Vector4<f64>,
    A: Matrix4<f64>,
    B: Vector4<f64>,
}

/// Below this a motor's coupling to the plane is treated as absent (its rows would be
/// empty).
const COUPLING_EPS: f64 = 1e-12;

impl Transcription {
    pub fn new(problem: &BrakingProblem) -> Result<Self, super::error::TrajoptError> {
        problem.validate()?;
        let wip = Wip::new(problem.plane)?;
        let n = problem.intervals;
        let step_secs = problem.duration_secs / n as f64;
        let mut t = Self {
            wip,
            method: problem.method,
            intervals: n,
            step_secs,
            initial_state: Vector4::new(
                0.0,
                0.0,
                0.0,
                problem.initial_speed_m_per_s / problem.plane.ball_radius_m,
            ),
            problem: *problem,
            drive: problem.drive_map()?,
            weights: Vec::new(),
            cones: ConeSizes {
                zero: 0,
                nonnegative: 0,
                traction: 0,
            },
        };
        let mut w = vec![0.0; t.variable_count()];
        let h = step_secs;
        for k in 0..=n {
            let end = k == 0 || k == n;
            w[t.torque(k)] = match (t.method, end) {
                (Method::HermiteSimpson, true) => h / 6.0,
                (Method::HermiteSimpson, false) => h / 3.0,
                (Method::Trapezoidal, true) => h / 2.0,
                (Method::Trapezoidal, false) => h,
            };
            if t.method == Method::HermiteSimpson && k < n {
                w[t.torque(k) + 1] = 4.0 * h / 6.0;
            }
        }
        t.weights = w;
        t.cones = t.count_cones();
        Ok(t)
    }

    fn block(&self) -> usize {
        match self.method {
            Method::HermiteSimpson => 6,
            Method::Trapezoidal => 5,
        }
    }

    /// Index of `s_k[0]`.
    pub fn state(&self, k: usize) -> usize {
        self.block() * k
    }

    /// Index of `tau_k`.
    pub fn torque(&self, k: usize) -> usize {
        self.block() * k + 4
    }

    /// Index of the Hermite-Simpson midpoint torque of interval `k`.
    pub fn mid_torque(&self, k: usize) -> Option<usize> {
        (self.method == Method::HermiteSimpson).then(|| self.block() * k + 5)
    }

    pub fn variable_count(&self) -> usize {
        self.block() * self.intervals + 5
    }

    pub fn knot_state(&self, z: &[f64], k: usize) -> WipState<f64> {
        let i = self.state(k);
        Vector4::new(z[i], z[i + 1], z[i + 2], z[i + 3])
    }

    /// `J = sum w x^2` (N^2 m^2 s).
    pub fn cost(&self, z: &[f64]) -> f64 {
        self.weights.iter().zip(z).map(|(w, x)| w * x * x).sum()
    }

    fn point(&self, s: &WipState<f64>, tau: f64, jacobians: bool) -> Point {
        let f = self.wip.derivative(s, tau);
        if jacobians {
            let lin = self.wip.linearize(s, tau);
            Point {
                f,
                A: lin.A,
                B: lin.B,
            }
        } else {
            Point {
                f,
                A: Matrix4::zeros(),
                B: Vector4::zeros(),
            }
        }
    }

    /// The motors that give distinct limit rows: a motor's row set is symmetric under
    /// `(kappa, rho) -> (-kappa, -rho)`, so in the sagittal plane omniwheels 2 and 3 give the
    /// same rows and one is kept; a motor the plane does not load (omniwheel 1 there) gives
    /// none.
    fn motors(&self) -> Vec<super::drive::Motor> {
        let mut kept: Vec<super::drive::Motor> = Vec::new();
        let all = self.drive.iter().flat_map(|d| d.motors().iter());
        for m in all.filter(|m| m.torque_per_planar.abs() > COUPLING_EPS) {
            let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (a.abs() + b.abs());
            let duplicate = kept.iter().any(|k| {
                same(k.peak_torque_nm, m.peak_torque_nm)
                    && same(k.no_load_speed_rad_per_s, m.no_load_speed_rad_per_s)
                    && [1.0, -1.0].iter().any(|sg| {
                        same(k.torque_per_planar, sg * m.torque_per_planar)
                            && same(k.speed_per_relative_rate, sg * m.speed_per_relative_rate)
                    })
            });
            if !duplicate {
                kept.push(*m);
            }
        }
        kept
    }

    fn traction_wheels(&self) -> usize {
        if self.problem.limits.traction {
            self.drive.as_ref().map_or(0, |d| d.motors().len())
        } else {
            0
        }
    }

    fn count_cones(&self) -> ConeSizes {
        let n = self.intervals;
        let zero = 4 + 3 + if self.problem.zero_end_torques { 2 } else { 0 } + 4 * n;
        let lim = &self.problem.limits;
        let mut per_knot = 0;
        for b in [
            lim.tilt_rad,
            lim.tilt_rate_rad_per_s,
            lim.ball_speed_m_per_s,
            lim.torque_nm,
        ] {
            per_knot += 2 * usize::from(b.is_some());
        }
        let motors = self.motors().len();
        per_knot += 6 * motors;
        let mut per_mid = 2 * usize::from(lim.torque_nm.is_some()) + 2 * motors;
        if self.method == Method::Trapezoidal {
            per_mid = 0;
        }
        ConeSizes {
            zero,
            nonnegative: per_knot * (n + 1) + per_mid * n,
            traction: 2 * self.traction_wheels() * (n + 1),
        }
    }

    pub fn row_count(&self) -> usize {
        self.cones.zero + self.cones.nonnegative + self.cones.traction
    }

    /// Evaluates every point of the grid: knots first, then (Hermite-Simpson) midpoints.
    /// Returns knot points and midpoint data `(point, ds_m/ds_k, ds_m/ds_{k+1})`.
    fn evaluate(&self, z: &[f64], jacobians: bool) -> (Vec<Point>, Vec<Point>) {
        let n = self.intervals;
        let knots: Vec<Point> = (0..=n)
            .map(|k| self.point(&self.knot_state(z, k), z[self.torque(k)], jacobians))
            .collect();
        let mids = match self.method {
            Method::HermiteSimpson => (0..n)
                .map(|k| {
                    let sm = self.mid_state(z, &knots, k);
                    let um = z[self.torque(k) + 1];
                    self.point(&sm, um, jacobians)
                })
                .collect(),
            Method::Trapezoidal => Vec::new(),
        };
        (knots, mids)
    }

    fn mid_state(&self, z: &[f64], knots: &[Point], k: usize) -> WipState<f64> {
        let h = self.step_secs;
        (self.knot_state(z, k) + self.knot_state(z, k + 1)) * 0.5
            + (knots[k].f - knots[k + 1].f) * (h / 8.0)
    }

    fn defect(&self, z: &[f64], knots: &[Point], mids: &[Point], k: usize) -> Vector4<f64> {
        let h = self.step_secs;
        let ds = self.knot_state(z, k + 1) - self.knot_state(z, k);
        match self.method {
            Method::HermiteSimpson => {
                ds - (knots[k].f + mids[k].f * 4.0 + knots[k + 1].f) * (h / 6.0)
            }
            Method::Trapezoidal => ds - (knots[k].f + knots[k + 1].f) * (h / 2.0),
        }
    }

    /// The state derivatives at the knots (for interpolation).
    pub fn knot_rates(&self, z: &[f64]) -> Vec<WipState<f64>> {
        (0..=self.intervals)
            .map(|k| {
                self.wip
                    .derivative(&self.knot_state(z, k), z[self.torque(k)])
            })
            .collect()
    }

    /// Normal forces `N_i` and traction magnitudes `|F_i|` at knot `k` (N), when the drive
    /// has omniwheels.
    pub fn contact_forces(&self, z: &[f64], k: usize) -> Option<([f64; 3], [f64; 3])> {
        let c = self.drive.as_ref()?.contacts.as_ref()?;
        let f = c.forces(&self.wip, &self.knot_state(z, k), z[self.torque(k)]);
        Some((f.normal_n, f.traction_n.map(f64::abs)))
    }

    /// Emits `A` (linearised at `z`) and `b` in the fixed order that defines the pattern.
    /// Without `jacobians` the nonlinear rows' entries are emitted as zeros, which is enough to
    /// evaluate the constraints through [`Violation`].
    pub fn assemble(&self, z: &[f64], jacobians: bool, sink: &mut impl Sink) {
        let n = self.intervals;
        let h = self.step_secs;
        let (knots, mids) = self.evaluate(z, jacobians);
        let mut row = 0;
        // Equalities. Initial state.
        for j in 0..4 {
            sink.entry(row, self.state(0) + j, 1.0);
            sink.rhs(row, self.initial_state[j]);
            row += 1;
        }
        // Final state at rest upright, phi free.
        for j in [0, 2, 3] {
            sink.entry(row, self.state(n) + j, 1.0);
            sink.rhs(row, 0.0);
            row += 1;
        }
        if self.problem.zero_end_torques {
            for k in [0, n] {
                sink.entry(row, self.torque(k), 1.0);
                sink.rhs(row, 0.0);
                row += 1;
            }
        }
        // Defects, linearised: J_c x = J_c z - c.
        let eye = Matrix4::<f64>::identity();
        for k in 0..n {
            let c = self.defect(z, &knots, &mids, k);
            let (a, b) = (&knots[k], &knots[k + 1]);
            #[allow(non_snake_case)]
            let (d_sk, d_uk, d_sk1, d_uk1, d_um) = match self.method {
                Method::HermiteSimpson => {
                    let m = &mids[k];
                    let dsm_dsk = eye * 0.5 + a.A * (h / 8.0);
                    let dsm_dsk1 = eye * 0.5 - b.A * (h / 8.0);
                    let dsm_duk = a.B * (h / 8.0);
                    let dsm_duk1 = -b.B * (h / 8.0);
                    let g = h / 6.0;
                    (
                        -eye - (a.A + m.A * dsm_dsk * 4.0) * g,
                        -(a.B + m.A * dsm_duk * 4.0) * g,
                        eye - (b.A + m.A * dsm_dsk1 * 4.0) * g,
                        -(b.B + m.A * dsm_duk1 * 4.0) * g,
                        Some(-m.B * (4.0 * g)),
                    )
                }
                Method::Trapezoidal => {
                    let g = h / 2.0;
                    (-eye - a.A * g, -a.B * g, eye - b.A * g, -b.B * g, None)
                }
            };
            for i in 0..4 {
                let r = row + i;
                let mut lin = -c[i];
                let mut put = |col: usize, v: f64| {
                    lin += v * z[col];
                    sink.entry(r, col, v);
                };
                for j in 0..4 {
                    // The ball angle enters no right-hand side: its columns are exactly -1/+1
                    // on the diagonal, so only those entries are stored.
                    if j != 1 || i == 1 {
                        put(self.state(k) + j, d_sk[(i, j)]);
                    }
                }
                put(self.torque(k), d_uk[i]);
                if let (Some(col), Some(d)) = (self.mid_torque(k), d_um) {
                    put(col, d[i]);
                }
                for j in 0..4 {
                    if j != 1 || i == 1 {
                        put(self.state(k + 1) + j, d_sk1[(i, j)]);
                    }
                }
                put(self.torque(k + 1), d_uk1[i]);
                sink.rhs(r, lin);
            }
            row += 4;
        }
        debug_assert_eq!(row, self.cones.zero);
        // Inequalities a^T x <= b.
        let lim = self.problem.limits;
        let r_ball = self.problem.plane.ball_radius_m;
        let motors = self.motors();
        let bound = |row: &mut usize, cols: &[(usize, f64)], b: f64, sink: &mut dyn Sink| {
            for &(c, v) in cols {
                sink.entry(*row, c, v);
            }
            sink.rhs(*row, b);
            *row += 1;
        };
        for k in 0..=n {
            let s = self.state(k);
            let u = self.torque(k);
            for (limit, col, scale) in [
                (lim.tilt_rad, s, 1.0),
                (lim.tilt_rate_rad_per_s, s + 2, 1.0),
                (lim.ball_speed_m_per_s, s + 3, r_ball),
                (lim.torque_nm, u, 1.0),
            ] {
                if let Some(b) = limit {
                    bound(&mut row, &[(col, scale)], b, sink);
                    bound(&mut row, &[(col, -scale)], b, sink);
                }
            }
            for m in &motors {
                let kt = m.torque_per_planar;
                let ks = m.speed_per_relative_rate;
                let peak = m.peak_torque_nm;
                let slope = peak / m.no_load_speed_rad_per_s;
                // Torque-speed line: tau_i + slope psi_i <= peak and its mirror.
                let line = [(u, kt), (s + 3, slope * ks), (s + 2, -slope * ks)];
                let neg = line.map(|(c, v)| (c, -v));
                bound(&mut row, &line, peak, sink);
                bound(&mut row, &neg, peak, sink);
                bound(&mut row, &[(u, kt)], peak, sink);
                bound(&mut row, &[(u, -kt)], peak, sink);
                let speed = [(s + 3, ks), (s + 2, -ks)];
                bound(&mut row, &speed, m.no_load_speed_rad_per_s, sink);
                bound(
                    &mut row,
                    &speed.map(|(c, v)| (c, -v)),
                    m.no_load_speed_rad_per_s,
                    sink,
                );
            }
            if let Some(um) = self.mid_torque(k).filter(|_| k < n) {
                if let Some(b) = lim.torque_nm {
                    bound(&mut row, &[(um, 1.0)], b, sink);
                    bound(&mut row, &[(um, -1.0)], b, sink);
                }
                for m in &motors {
                    bound(
                        &mut row,
                        &[(um, m.torque_per_planar)],
                        m.peak_torque_nm,
                        sink,
                    );
                    bound(
                        &mut row,
                        &[(um, -m.torque_per_planar)],
                        m.peak_torque_nm,
                        sink,
                    );
                }
            }
        }
        debug_assert_eq!(row, self.cones.zero + self.cones.nonnegative);
        // Traction: |F_i| <= mu (N_i - N_min) as the two half-spaces mu (N_i - N_min) -+ F_i >= 0
        // (N_min = limits.normal_force_margin_n, 0 by default), N_i and F_i
        // linearised at z: s = b - A x = g(z) + grad g (x - z) >= 0 (exact values at z).
        // (clarabel's second-order cone of dimension 2 expresses the same set, but stalled
        // on long horizons and was 2-3x slower; the rollers carry no axle force, so there is
        // no third dimension that would make a true cone natural.)
        if self.traction_wheels() > 0
            && let Some((d, c)) = self
                .drive
                .as_ref()
                .and_then(|d| d.contacts.as_ref().map(|c| (d, c)))
        {
            let mu = c.wheel_ball_friction;
            // With a margin: mu (N_i - N_min) -+ F_i >= 0 (N_min = 0 leaves N_i unchanged).
            let margin = self.problem.limits.normal_force_margin_n;
            for k in 0..=n {
                let f = c.forces(&self.wip, &self.knot_state(z, k), z[self.torque(k)]);
                let cols = self.knot_columns(k);
                for i in 0..d.motors().len() {
                    for sign in [-1.0, 1.0] {
                        let mut lin = mu * (f.normal_n[i] - margin) + sign * f.traction_n[i];
                        for (j, col) in cols.iter().enumerate() {
                            let g = if jacobians {
                                mu * f.normal_grad[i][j] + sign * f.traction_grad[i][j]
                            } else {
                                0.0
                            };
                            sink.entry(row, *col, -g);
                            lin -= g * z[*col];
                        }
                        sink.rhs(row, lin);
                        row += 1;
                    }
                }
            }
        }
        debug_assert_eq!(row, self.row_count());
    }

    fn knot_columns(&self, k: usize) -> [usize; 5] {
        let s = self.state(k);
        [s, s + 1, s + 2, s + 3, self.torque(k)]
    }

    /// An initial guess from a state/torque function of time on this grid.
    pub fn guess_from(&self, state_torque_at: impl Fn(f64) -> (WipState<f64>, f64)) -> Vec<f64> {
        let mut z = vec![0.0; self.variable_count()];
        let h = self.step_secs;
        for k in 0..=self.intervals {
            let (s, u) = state_torque_at(k as f64 * h);
            let i = self.state(k);
            z[i..i + 4].copy_from_slice(s.as_slice());
            z[self.torque(k)] = u;
            if let Some(m) = self.mid_torque(k).filter(|_| k < self.intervals) {
                z[m] = state_torque_at((k as f64 + 0.5) * h).1;
            }
        }
        z
    }
}

/// Evaluates the slack `b - A z` of every row at the point `z` the rows were linearised at:
/// for the defect rows that is `-c(z)`, for the traction rows `(mu N(z), F(z))`, so the true
/// constraint values come out whether or not the Jacobians were computed.
struct Slacks<'a> {
    z: &'a [f64],
    slack: Vec<f64>,
}

impl Sink for Slacks<'_> {
    fn entry(&mut self, row: usize, col: usize, value: f64) {
        self.slack[row] -= value * self.z[col];
    }
    fn rhs(&mut self, row: usize, value: f64) {
        self.slack[row] += value;
    }
}

impl Transcription {
    /// Constraint violation at `z`: `(sum, max)` over every row (equalities by absolute
    /// value, inequalities and cones by their excess).
    pub fn violation(&self, z: &[f64]) -> (f64, f64) {
        let mut s = Slacks {
            z,
            slack: vec![0.0; self.row_count()],
        };
        self.assemble(z, false, &mut s);
        let c = self.cones;
        let (eq, ineq) = s.slack.split_at(c.zero);
        let parts = eq
            .iter()
            .map(|v| v.abs())
            .chain(ineq.iter().map(|v| (-v).max(0.0)));
        parts.fold((0.0, 0.0), |(sum, max), v| (sum + v, f64::max(max, v)))
    }
}

#[cfg(test)]
#[path = "transcription_tests.rs"]
mod tests;
