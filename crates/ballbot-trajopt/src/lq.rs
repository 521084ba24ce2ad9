//! The linear-quadratic braking optimum in closed form (controllability Gramian).
//!
//! On the model linearised about upright, reduced state `x = [theta, theta_dot, phi_dot]`,
//! `x_dot = A x + B tau`, the minimum of `integral tau^2` that steers `x(0) = x0` to
//! `x(T) = 0` is `J = (e^{AT} x0)^T W(T)^{-1} (e^{AT} x0)`, with the Gramian
//! `W(T) = integral_0^T e^{As} B B^T e^{A^T s} ds`. For a ballbot `A` has an unstable pole
//! `+lambda` (8 rad/s for MiaPURE) and `W` grows like `e^{2 lambda T}`: formed directly it is
//! numerically singular. We evaluate the same closed form in modal coordinates
//! `x = V z` (`A V = V Lambda`, real distinct eigenvalues), scaling each mode's end condition
//! by its own growth: mode `i` must satisfy `c_i + beta_i integral g_i(s) tau(s) ds = 0`
//! with `g_i(s) = e^{-lambda_i s}`, `c_i = z_i(0)` for `lambda_i > 0`, and
//! `g_i(s) = e^{lambda_i (T - s)}`, `c_i = e^{lambda_i T} z_i(0)` otherwise. The minimum-norm
//! torque is `tau(s) = sum_j nu_j beta_j g_j(s)` with `G nu = -c`,
//! `G_ij = beta_i beta_j integral_0^T g_i g_j ds` (the scaled Gramian, every entry bounded),
//! and `J = c^T G^{-1} c`. States follow from the same exponential integrals, unstable modes
//! integrated backwards from their zero end value. Everything is a sum of
//! `integral e^{p + q s} ds` with non-positive exponents: no overflow, no cancellation.

use ballbot_core::{Wip, WipState};
use nalgebra::{Matrix3, Vector3};

/// The LQ braking optimum of the linearised model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqBraking {
    duration_secs: f64,
    eigenvalues: Vector3<f64>,
    modes: Matrix3<f64>,
    beta: Vector3<f64>,
    nu: Vector3<f64>,
    z0: Vector3<f64>,
    cost: f64,
}

/// `integral_a^b e^{p + q s} ds`, stable for small `q`.
fn exp_integral(p: f64, q: f64, a: f64, b: f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let len = b - a;
    // Factor out the larger end to keep the remaining exponential in (0, 1].
    let e_hi = if q >= 0.0 { p + q * b } else { p + q * a };
    let qa = q.abs();
    if qa * len < 1e-12 {
        return e_hi.exp() * len;
    }
    // integral = e^{e_hi} (1 - e^{-|q| len}) / |q|.
    e_hi.exp() * (-(-qa * len).exp_m1()) / qa
}

impl LqBraking {
    /// The LQ optimum braking from `initial_speed_m_per_s` to rest in `duration_secs`, on
    /// `wip` linearised about upright at rest. `None` when the reduced `A` has complex or
    /// repeated eigenvalues, a mode is uncontrollable, or the duration is not positive.
    pub fn new(wip: &Wip<f64>, initial_speed_m_per_s: f64, duration_secs: f64) -> Option<Self> {
        if !(duration_secs.is_finite() && duration_secs > 0.0) {
            return None;
        }
        #[allow(non_snake_case)]
        let (A, B) = wip.linearize_upright().reduced();
        let eig = A.eigenvalues()?;
        let scale = eig.amax().max(1.0);
        for i in 0..3 {
            for j in i + 1..3 {
                if (eig[i] - eig[j]).abs() < 1e-9 * scale {
                    return None;
                }
            }
        }
        let mut modes = Matrix3::zeros();
        for i in 0..3 {
            let m = A - Matrix3::identity() * eig[i];
            let rows = [
                m.row(0).transpose(),
                m.row(1).transpose(),
                m.row(2).transpose(),
            ];
            let v = [
                rows[0].cross(&rows[1]),
                rows[0].cross(&rows[2]),
                rows[1].cross(&rows[2]),
            ]
            .into_iter()
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))?;
            let norm = v.norm();
            if norm <= 0.0 || !norm.is_finite() {
                return None;
            }
            modes.set_column(i, &(v / norm));
        }
        let inv = modes.try_inverse()?;
        let x0 = Vector3::new(0.0, 0.0, initial_speed_m_per_s / wip.params().ball_radius_m);
        let z0 = inv * x0;
        let beta = inv * B;
        let mut lq = Self {
            duration_secs,
            eigenvalues: eig,
            modes,
            beta,
            nu: Vector3::zeros(),
            z0,
            cost: 0.0,
        };
        let c = Vector3::from_fn(|i, _| lq.end_scale(i) * z0[i]);
        let g = Matrix3::from_fn(|i, j| {
            let (pi, qi) = lq.kernel(i);
            let (pj, qj) = lq.kernel(j);
            beta[i] * beta[j] * exp_integral(pi + pj, qi + qj, 0.0, duration_secs)
        });
        let nu = g.lu().solve(&(-c))?;
        if !nu.iter().all(|v| v.is_finite()) {
            return None;
        }
        lq.nu = nu;
        lq.cost = -c.dot(&nu);
        Some(lq)
    }

    /// `g_i(s) = e^{p + q s}` as `(p, q)`.
    fn kernel(&self, i: usize) -> (f64, f64) {
        let l = self.eigenvalues[i];
        if l > 0.0 {
            (0.0, -l)
        } else {
            (l * self.duration_secs, -l)
        }
    }

    fn end_scale(&self, i: usize) -> f64 {
        let l = self.eigenvalues[i];
        if l > 0.0 {
            1.0
        } else {
            (l * self.duration_secs).exp()
        }
    }

    /// The optimal cost `integral tau^2` (N^2 m^2 s).
    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// The optimal torque at `t_secs` (N m), `t` clamped to `[0, T]`.
    pub fn torque_at(&self, t_secs: f64) -> f64 {
        let t = t_secs.clamp(0.0, self.duration_secs);
        (0..3)
            .map(|j| {
                let (p, q) = self.kernel(j);
                self.nu[j] * self.beta[j] * (p + q * t).exp()
            })
            .sum()
    }

    /// The optimal reduced state `[theta, theta_dot, phi_dot]` at `t_secs`, `t` clamped to
    /// `[0, T]`.
    pub fn reduced_state_at(&self, t_secs: f64) -> Vector3<f64> {
        let big_t = self.duration_secs;
        let t = t_secs.clamp(0.0, big_t);
        let z = Vector3::from_fn(|i, _| {
            let l = self.eigenvalues[i];
            // integral of e^{l (t - s)} tau(s) over the forward or backward range.
            let conv = |a: f64, b: f64| -> f64 {
                (0..3)
                    .map(|j| {
                        let (p, q) = self.kernel(j);
                        self.nu[j] * self.beta[j] * exp_integral(l * t + p, q - l, a, b)
                    })
                    .sum()
            };
            if l > 0.0 {
                -self.beta[i] * conv(t, big_t)
            } else {
                (l * t).exp() * self.z0[i] + self.beta[i] * conv(0.0, t)
            }
        });
        self.modes * z
    }

    /// The optimal full state at `t_secs` with `phi` integrated from `phi(0) = 0` by
    /// Simpson's rule on `steps` subintervals.
    pub fn state_at(&self, t_secs: f64, steps: usize) -> WipState<f64> {
        let t = t_secs.clamp(0.0, self.duration_secs);
        let x = self.reduced_state_at(t);
        let n = steps.max(1);
        let h = t / n as f64;
        let phi: f64 = (0..n)
            .map(|k| {
                let a = k as f64 * h;
                let rate = |s: f64| self.reduced_state_at(s)[2];
                h / 6.0 * (rate(a) + 4.0 * rate(a + h / 2.0) + rate(a + h))
            })
            .sum();
        WipState::new(x[0], phi, x[1], x[2])
    }
}
