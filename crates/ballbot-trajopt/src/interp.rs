//! The solved trajectory as a function of time: the command state `s_c(t)` for controllers.
//!
//! Hermite-Simpson: on each interval the state is the cubic with the knot values and knot
//! derivatives `f_k`, `f_{k+1}` (Hermite form). Where the collocation defect vanishes this is
//! exactly Hermite-Simpson's own cubic, whose derivative interpolates `f_k`, `f_m`, `f_{k+1}`;
//! the torque is the quadratic through `tau_k`, `tau_m`, `tau_{k+1}`. Trapezoidal: the state
//! is the quadratic with derivative linear from `f_k` to `f_{k+1}`, the torque linear. Before
//! the start the trajectory holds the initial state and torque, after the end the final ones.

use super::method::Method;
use ballbot_core::WipState;

/// A collocated state and torque trajectory on a uniform grid, `t` from 0 to `T`.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    method: Method,
    duration_secs: f64,
    states: Vec<WipState<f64>>,
    rates: Vec<WipState<f64>>,
    torques_nm: Vec<f64>,
    mid_torques_nm: Vec<f64>,
}

impl Trajectory {
    /// Assembles a trajectory from knot data; `None` on inconsistent lengths (at least two
    /// knots, `rates` and `torques_nm` one per knot, `mid_torques_nm` one per interval for
    /// Hermite-Simpson and empty for trapezoidal) or a non-positive duration.
    pub fn new(
        method: Method,
        duration_secs: f64,
        states: Vec<WipState<f64>>,
        rates: Vec<WipState<f64>>,
        torques_nm: Vec<f64>,
        mid_torques_nm: Vec<f64>,
    ) -> Option<Self> {
        let knots = states.len();
        let mids = match method {
            Method::HermiteSimpson => knots.saturating_sub(1),
            Method::Trapezoidal => 0,
        };
        let ok = knots >= 2
            && rates.len() == knots
            && torques_nm.len() == knots
            && mid_torques_nm.len() == mids
            && duration_secs.is_finite()
            && duration_secs > 0.0;
        ok.then_some(Self {
            method,
            duration_secs,
            states,
            rates,
            torques_nm,
            mid_torques_nm,
        })
    }

    /// The collocation scheme that produced it.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Duration `T` (s).
    pub fn duration_secs(&self) -> f64 {
        self.duration_secs
    }

    /// Number of intervals `N`.
    pub fn intervals(&self) -> usize {
        self.states.len() - 1
    }

    /// Knot times (s), `k T / N`.
    pub fn knot_times_secs(&self) -> Vec<f64> {
        let h = self.step_secs();
        (0..self.states.len()).map(|k| k as f64 * h).collect()
    }

    /// Knot states `[theta, phi, theta_dot, phi_dot]`.
    pub fn knot_states(&self) -> &[WipState<f64>] {
        &self.states
    }

    /// Knot state derivatives `f(s_k, tau_k)`.
    pub fn knot_rates(&self) -> &[WipState<f64>] {
        &self.rates
    }

    /// Knot torques (N m).
    pub fn knot_torques_nm(&self) -> &[f64] {
        &self.torques_nm
    }

    /// Hermite-Simpson midpoint torques (N m); empty for trapezoidal.
    pub fn mid_torques_nm(&self) -> &[f64] {
        &self.mid_torques_nm
    }

    fn step_secs(&self) -> f64 {
        self.duration_secs / self.intervals() as f64
    }

    /// Interval index and local time in `[0, h]`, `t` clamped to `[0, T]`.
    fn locate(&self, t_secs: f64) -> (usize, f64) {
        let h = self.step_secs();
        let t = if t_secs.is_nan() {
            0.0
        } else {
            t_secs.clamp(0.0, self.duration_secs)
        };
        let k = ((t / h) as usize).min(self.intervals() - 1);
        (k, t - k as f64 * h)
    }

    /// The command state `s_c(t)` (rad, rad, rad/s, rad/s).
    pub fn state_at(&self, t_secs: f64) -> WipState<f64> {
        let last = self.states.len() - 1;
        if t_secs >= self.duration_secs {
            return self.states[last];
        }
        if t_secs <= 0.0 || t_secs.is_nan() {
            return self.states[0];
        }
        let h = self.step_secs();
        let (k, tau) = self.locate(t_secs);
        let (s0, s1) = (&self.states[k], &self.states[k + 1]);
        let (f0, f1) = (&self.rates[k], &self.rates[k + 1]);
        match self.method {
            Method::HermiteSimpson => {
                let x = tau / h;
                let (x2, x3) = (x * x, x * x * x);
                s0 * (2.0 * x3 - 3.0 * x2 + 1.0)
                    + f0 * (h * (x3 - 2.0 * x2 + x))
                    + s1 * (-2.0 * x3 + 3.0 * x2)
                    + f1 * (h * (x3 - x2))
            }
            Method::Trapezoidal => s0 + f0 * tau + (f1 - f0) * (tau * tau / (2.0 * h)),
        }
    }

    /// The torque `tau(t)` (N m).
    pub fn torque_at(&self, t_secs: f64) -> f64 {
        let h = self.step_secs();
        let (k, tau) = self.locate(t_secs);
        let (u0, u1) = (self.torques_nm[k], self.torques_nm[k + 1]);
        let x = tau / h;
        match self.method {
            Method::HermiteSimpson => {
                let um = self.mid_torques_nm[k];
                // Lagrange basis on 0, 1/2, 1.
                u0 * (2.0 * x - 1.0) * (x - 1.0)
                    + um * 4.0 * x * (1.0 - x)
                    + u1 * x * (2.0 * x - 1.0)
            }
            Method::Trapezoidal => u0 + (u1 - u0) * x,
        }
    }

    /// Samples `(t, s_c(t), tau(t))` every `dt_secs` from 0 to `T` inclusive (empty for a
    /// non-positive or non-finite `dt_secs`).
    pub fn sample(&self, dt_secs: f64) -> Vec<(f64, WipState<f64>, f64)> {
        if !(dt_secs.is_finite() && dt_secs > 0.0) {
            return Vec::new();
        }
        let steps = (self.duration_secs / dt_secs).round() as usize;
        (0..=steps)
            .map(|i| {
                let t = (i as f64 * dt_secs).min(self.duration_secs);
                (t, self.state_at(t), self.torque_at(t))
            })
            .collect()
    }
}
