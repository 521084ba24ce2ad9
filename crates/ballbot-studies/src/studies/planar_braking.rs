//! The braking reference the PIPTB experiment tracks: a state and torque trajectory from
//! cruise to rest, sampled on a fine uniform grid and interpolated linearly.

use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{Wip, WipState};
use ballbot_trajopt::{LqBraking, Trajectory};

/// Where a braking reference came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BrakingSource {
    /// The nonlinear minimum-effort optimum (direct collocation, the trajectory optimiser).
    NonlinearOptimum,
    /// The minimum-effort optimum of the model linearised about upright (closed form).
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

    /// The linear-quadratic optimum of the trajectory optimiser
    /// ([`ballbot_trajopt::LqBraking`], closed form on the upright linearisation), sampled
    /// every `dt_secs`; `phi` is integrated by the trapezoidal rule.
    pub fn linear_quadratic(
        wip: &Wip<f64>,
        speed_m_per_s: f64,
        duration_secs: f64,
        dt_secs: f64,
    ) -> Option<Self> {
        if !(dt_secs.is_finite() && dt_secs > 0.0) {
            return None;
        }
        let lq = LqBraking::new(wip, speed_m_per_s, duration_secs)?;
        let steps = (duration_secs / dt_secs).round().max(1.0) as usize;
        let dt = duration_secs / steps as f64;
        let mut states = Vec::with_capacity(steps + 1);
        let mut torques_nm = Vec::with_capacity(steps + 1);
        let mut phi = 0.0;
        let mut last_rate = None;
        for k in 0..=steps {
            let t = k as f64 * dt;
            let x = lq.reduced_state_at(t);
            if let Some(prev) = last_rate {
                phi += 0.5 * (prev + x[2]) * dt;
            }
            last_rate = Some(x[2]);
            states.push(WipState::new(x[0], phi, x[1], x[2]));
            torques_nm.push(lq.torque_at(t));
        }
        Self::from_samples(dt, states, torques_nm, BrakingSource::LinearQuadratic)
    }

    /// The trajectory optimiser's solution, sampled every `dt_secs`.
    pub fn from_optimum(trajectory: &Trajectory, dt_secs: f64) -> Option<Self> {
        let samples = trajectory.sample(dt_secs);
        let dt = samples.get(1).map(|s| s.0 - samples[0].0)?;
        let (states, torques_nm) = samples.into_iter().map(|(_, s, u)| (s, u)).unzip();
        Self::from_samples(dt, states, torques_nm, BrakingSource::NonlinearOptimum)
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
        let t = BrakingTrajectory::linear_quadratic(&wip, 1.0, 1.4, 1e-3).unwrap();
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
        let fine = BrakingTrajectory::linear_quadratic(&wip, 1.0, 1.4, 0.25e-3).unwrap();
        assert!((fine.effort_n2m2s() - j).abs() < 1e-3 * j);
    }
}
