//! The braking trajectory optimisation (paper Sec. III-D, [`ballbot_trajopt`]) as JSON, CSV and
//! the `brake` part of `ballbot reproduce` (summary key `brake`, figure `brake_miapure`).

use super::ReportError;
use ballbot_trajopt::{
    BrakingProblem, BrakingSolution, Limits, Method, MinTimeOptions, SolveOptions, min_braking_time,
};
use serde_json::{Value, json};

/// The JSON record of a solve: `cost`, `status`, `iterations`, `solve_ms`, and context.
pub fn solution_json(sol: &BrakingSolution) -> Value {
    let p = &sol.problem;
    let r = p.plane.ball_radius_m;
    let states = sol.trajectory.knot_states();
    let peak_speed = states.iter().map(|s| r * s[3]).fold(f64::MIN, f64::max);
    json!({
        "cost": sol.cost_n2m2s,
        "status": sol.status.as_str(),
        "iterations": sol.iterations,
        "solve_ms": sol.solve_time_secs * 1e3,
        "intervals": p.intervals,
        "method": match p.method {
            Method::HermiteSimpson => "hermite-simpson",
            Method::Trapezoidal => "trapezoidal",
        },
        "v0_m_per_s": p.initial_speed_m_per_s,
        "duration_secs": p.duration_secs,
        "peak_tilt_deg": sol.peak_tilt_rad().to_degrees(),
        "peak_ball_speed_m_per_s": peak_speed,
        "primal_residual": sol.primal_residual,
        "dual_residual": sol.dual_residual,
    })
}

/// The trajectory sampled every 10 ms as CSV, with a header:
/// `t_secs,theta_rad,phi_rad,theta_dot_rad_per_s,phi_dot_rad_per_s,tau_nm`.
pub fn trajectory_csv(sol: &BrakingSolution) -> String {
    let mut text =
        String::from("t_secs,theta_rad,phi_rad,theta_dot_rad_per_s,phi_dot_rad_per_s,tau_nm\n");
    for (t, s, u) in sol.trajectory.sample(0.01) {
        text.push_str(&format!("{t},{},{},{},{},{u}\n", s[0], s[1], s[2], s[3]));
    }
    text
}

/// The `brake` part of `ballbot reproduce`, computed: the MiaPURE 1.4 m/s in 2 s optimum
/// (Hermite-Simpson, N = 100) and the minimum braking time under MiaPURE's actuator limits
/// (heading 180 deg; N = 100 to 0.01 s, or with `quick` N = 40 to 0.02 s).
#[derive(Clone, Debug)]
pub struct BrakeReproduction {
    /// The unconstrained optimum.
    pub solution: BrakingSolution,
    /// The summary record `{cost, status, intervals, solve_ms, min_braking_time_secs, ...}`.
    pub record: Value,
    /// The line `ballbot reproduce` prints.
    pub text: String,
}

/// Computes the `brake` part of `ballbot reproduce` (see [`BrakeReproduction`]).
pub fn reproduce_brake(quick: bool) -> Result<BrakeReproduction, ReportError> {
    let problem = BrakingProblem::miapure();
    let sol = problem.solve()?;
    let mut record = solution_json(&sol);
    let (intervals, resolution_secs) = if quick { (40, 0.02) } else { (100, 0.01) };
    let limited = BrakingProblem {
        limits: Limits::miapure_actuators(std::f64::consts::PI),
        intervals,
        ..problem
    };
    let search = MinTimeOptions {
        resolution_secs,
        ..MinTimeOptions::default()
    };
    let r = min_braking_time(&limited, &SolveOptions::default(), &search)?;
    record["min_braking_time_secs"] = json!(r.min_duration_secs);
    record["min_braking_time_intervals"] = json!(intervals);
    let text = format!(
        "brake (MiaPURE 1.4 m/s -> rest in 2 s, Hermite-Simpson N = 100): J = {:.2} N^2 m^2 s \
         (MODEL.md ~114), {} in {} iterations, {:.2} ms; lean {:.2} deg (paper ~7); \
         minimum braking time under the actuator limits {}",
        sol.cost_n2m2s,
        sol.status,
        sol.iterations,
        sol.solve_time_secs * 1e3,
        sol.peak_tilt_rad().to_degrees(),
        match r.min_duration_secs {
            Some(t) => format!("{t:.3} s"),
            None => "not found in the searched range".to_owned(),
        }
    );
    Ok(BrakeReproduction {
        solution: sol,
        record,
        text,
    })
}

/// The Fig. "DEC"-like figure: tilt, ball speed and torque against time.
#[cfg(feature = "plot")]
pub fn figure(sol: &BrakingSolution, title: &str) -> super::plot::TimeSeriesFigure {
    use super::plot::{LegendPosition, Series, Subplot, TimeSeriesFigure};
    let samples = sol.trajectory.sample(0.005);
    let t: Vec<f64> = samples.iter().map(|(t, _, _)| *t).collect();
    let tilt: Vec<f64> = samples.iter().map(|(_, s, _)| s[0].to_degrees()).collect();
    let rate: Vec<f64> = samples.iter().map(|(_, s, _)| s[3]).collect();
    let torque: Vec<f64> = samples.iter().map(|(_, _, u)| *u).collect();
    TimeSeriesFigure::new(title)
        .with(Subplot::new("tilt θ (deg)").with(Series::new("θ*", &t, &tilt)))
        .with(Subplot::new("ball rate φ̇ (rad/s)").with(Series::new("φ̇*", &t, &rate)))
        .with(
            Subplot::new("torque τ (N·m)")
                .with(Series::new("τ*", &t, &torque))
                .with_legend(LegendPosition::UpperRight),
        )
}
