//! The braking reference the PIPTB experiment tracks: a state and torque trajectory from
//! cruise to rest, sampled on a fine uniform grid and interpolated linearly.

use ballbot_core::linalg::zoh;
use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{Wip, WipState};
use nalgebra::{Matrix3, Vector3};

/// Where a braking reference came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BrakingSource {
    /// The nonlinear minimum-effort optimum (direct collocation, the trajectory optimiser).
    NonlinearOptimum,
    /// The minimum-effort optimum of the model linearised about upright (ZOH torque on a fine
    /// grid, exact discrete minimum-norm solution).
    LinearQuadratic,
}

/// A braking trajectory: states `[theta, phi, theta_dot, phi_dot]` and torques on a uniform
/// grid from `t = 0` (cruise) to `t = duration` (rest).
#[derive(Clone, Debug, PartialEq)]
pub struct BrakingTrajectory {
    dt_secs: f64,
    states: Vec<WipState<f64>>,
    torques_nm: Vec<f64>,
    source: BrakingSource,
}

impl BrakingTrajectory {
    /// A trajectory from samples: `states[k]` and `torques_nm[k]` at `k dt_secs`. `None` when
    /// the lengths differ, fewer than two samples are given, or `dt_secs` is not positive.
    pub fn from_samples(
        dt_secs: f64,
        states: Vec<WipState<f64>>,
        torques_nm: Vec<f64>,
        source: BrakingSource,
    ) -> Option<Self> {
        (states.len() == torques_nm.len()
            && states.len() >= 2
            && dt_secs.is_finite()
            && dt_secs > 0.0)
            .then_some(Self {
                dt_secs,
                states,
                torques_nm,
                source,
            })
    }

    /// The linear-quadratic optimum: braking `wip` from `speed_m_per_s` to rest upright in
    /// `duration_secs`, minimising `integral tau^2` on the upright linearisation with the torque
    /// held over `intervals` equal steps. With `x = [theta, theta_dot, phi_dot]`,
    /// `x[k+1] = Ad x[k] + Bd u[k]`, the end condition `x[N] = 0` reads `G u = -Ad^N x0` with
    /// columns `g_k = Ad^(N-1-k) Bd`; the minimum-norm `u = -G^T (G G^T)^-1 Ad^N x0`. States
    /// are the linear model's (small tilts: the PIPTB leans a few degrees).
    pub fn linear_quadratic(
        wip: &Wip<f64>,
        speed_m_per_s: f64,
        duration_secs: f64,
        intervals: usize,
    ) -> Option<Self> {
        if intervals < 2 || !(duration_secs.is_finite() && duration_secs > 0.0) {
            return None;
        }
        let dt = duration_secs / intervals as f64;
        #[allow(non_snake_case)]
        let (A, B) = wip.linearize_upright().reduced();
        let d = zoh(&A, &B, dt).ok()?;
        let r = wip.params().ball_radius_m;
        let x0 = Vector3::new(0.0, 0.0, speed_m_per_s / r);
        // Columns g_k from the end backwards, and Ad^N x0.
        let mut g = vec![Vector3::zeros(); intervals];
        let mut col = d.b;
        for k in (0..intervals).rev() {
            g[k] = col;
            col = d.a * col;
        }
        let mut free = x0;
        for _ in 0..intervals {
            free = d.a * free;
        }
        // Minimum-norm solution of G u = b, b = -Ad^N x0. The unstable mode makes G G^T
        // numerically singular (entries spread by exp(2 p0 T), 1e13 for the PIPTB), so factor
        // G = L Q with orthonormal rows Q (modified Gram-Schmidt, twice) and solve
        // u = Q^T L^-1 b: accurate to about eps cond(G), the square root of cond(G G^T).
        let mut rows: [Vec<f64>; 3] =
            std::array::from_fn(|i| g.iter().map(|c| c[i]).collect::<Vec<f64>>());
        let mut l = Matrix3::<f64>::zeros();
        for i in 0..3 {
            for _pass in 0..2 {
                for j in 0..i {
                    let proj: f64 = rows[i].iter().zip(&rows[j]).map(|(a, b)| a * b).sum();
                    l[(i, j)] += proj;
                    let (head, tail) = rows.split_at_mut(i);
                    for (a, b) in tail[0].iter_mut().zip(&head[j]) {
                        *a -= proj * b;
                    }
                }
            }
            let norm = rows[i].iter().map(|a| a * a).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            l[(i, i)] = norm;
            rows[i].iter_mut().for_each(|a| *a /= norm);
        }
        let b: Vector3<f64> = -free;
        // Forward substitution L y = b.
        let mut y = Vector3::zeros();
        for i in 0..3 {
            let mut acc = b[i];
            for j in 0..i {
                acc -= l[(i, j)] * y[j];
            }
            y[i] = acc / l[(i, i)];
        }
        let torques: Vec<f64> = (0..intervals)
            .map(|k| (0..3).map(|i| rows[i][k] * y[i]).sum())
            .collect();
        let mut states = Vec::with_capacity(intervals + 1);
        let mut x = x0;
        let mut phi = 0.0;
        for &u in &torques {
            states.push(WipState::new(x[0], phi, x[1], x[2]));
            let next = d.a * x + d.b * u;
            phi += 0.5 * (x[2] + next[2]) * dt;
            x = next;
        }
        states.push(WipState::new(x[0], phi, x[1], x[2]));
        // The torque grid holds one value per interval; repeat the last for the end sample.
        let mut torques_nm = torques;
        torques_nm.push(*torques_nm.last()?);
        Self::from_samples(dt, states, torques_nm, BrakingSource::LinearQuadratic)
    }

    /// How it was computed.
    pub fn source(&self) -> BrakingSource {
        self.source
    }

    /// Its duration (s).
    pub fn duration_secs(&self) -> f64 {
        self.dt_secs * (self.states.len() - 1) as f64
    }

    /// The state at `t_secs` after the start (clamped to the ends), linearly interpolated.
    pub fn state_at(&self, t_secs: f64) -> WipState<f64> {
        let (k, w) = self.locate(t_secs);
        self.states[k] * (1.0 - w) + self.states[(k + 1).min(self.states.len() - 1)] * w
    }

    /// The torque at `t_secs` (clamped), linearly interpolated (N m).
    pub fn torque_at_nm(&self, t_secs: f64) -> f64 {
        let (k, w) = self.locate(t_secs);
        self.torques_nm[k] * (1.0 - w) + self.torques_nm[(k + 1).min(self.torques_nm.len() - 1)] * w
    }

    /// `integral tau^2 dt` of the reference itself (N^2 m^2 s), trapezoidal.
    pub fn effort_n2m2s(&self) -> f64 {
        self.torques_nm
            .windows(2)
            .map(|w| 0.5 * (w[0] * w[0] + w[1] * w[1]) * self.dt_secs)
            .sum()
    }

    /// Largest tilt magnitude along the reference (rad).
    pub fn peak_tilt_rad(&self) -> f64 {
        self.states
            .iter()
            .map(|s| s[TILT].abs())
            .fold(0.0, f64::max)
    }

    /// The end state (should be at rest upright; `phi` is free).
    pub fn end_state(&self) -> WipState<f64> {
        let mut s = self.states[self.states.len() - 1];
        s[BALL_ANGLE] = 0.0;
        s
    }

    fn locate(&self, t_secs: f64) -> (usize, f64) {
        let last = self.states.len() - 1;
        let x = (t_secs / self.dt_secs).clamp(0.0, last as f64);
        // `x` is finite and in [0, last]; NaN clamps to NaN, caught here.
        if !x.is_finite() {
            return (0, 0.0);
        }
        let k = (x.floor() as usize).min(last.saturating_sub(1));
        (k, x - k as f64)
    }
}

/// Checks that a trajectory starts at cruise and ends at rest (used by tests and the
/// experiment's sanity check): largest deviation in rad and rad/s.
pub fn boundary_error(traj: &BrakingTrajectory, ball_rate_rad_per_s: f64) -> f64 {
    let s0 = traj.state_at(0.0);
    let s1 = traj.end_state();
    [
        s0[TILT],
        s0[TILT_RATE],
        s0[BALL_RATE] - ball_rate_rad_per_s,
        s1[TILT],
        s1[TILT_RATE],
        s1[BALL_RATE],
    ]
    .iter()
    .map(|x| x.abs())
    .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ballbot_core::WipParams;

    #[test]
    fn lq_braking_reaches_rest_and_costs_about_model_md() {
        let wip = Wip::new(WipParams::piptb()).unwrap();
        let t = BrakingTrajectory::linear_quadratic(&wip, 1.0, 1.4, 1400).unwrap();
        let rate = 1.0 / wip.params().ball_radius_m;
        assert!(
            boundary_error(&t, rate) < 1e-6,
            "{}",
            boundary_error(&t, rate)
        );
        // MODEL.md: the nonlinear optimum costs about 0.86 N^2 m^2 s; the linearisation is
        // close for the few degrees the PIPTB leans.
        let j = t.effort_n2m2s();
        assert!((j - 0.86).abs() < 0.1, "J = {j}");
        assert!(t.peak_tilt_rad() < 0.2);
        // Finer grids converge.
        let fine = BrakingTrajectory::linear_quadratic(&wip, 1.0, 1.4, 5600).unwrap();
        assert!((fine.effort_n2m2s() - j).abs() < 1e-3 * j);
    }
}
