//! `ballbot brake`: the minimum-effort braking trajectory (the paper's Sec. III-D) by direct
//! collocation, solved by SQP with clarabel (`ballbot_sim::trajopt`).
//!
//! ```text
//! ballbot brake --preset miapure --v0 1.4 --duration 2 --intervals 100 --json
//! ballbot brake --preset piptb --method trapezoidal --max-torque 2
//! ballbot brake --preset miapure --actuators --traction --min-time 0.01
//! ```

use anyhow::Context;
use ballbot_core::{ActuatorParams, DrivetrainParams, WipParams};
use ballbot_sim::report::brake::{solution_json, trajectory_csv};
use ballbot_sim::trajopt::{
    BrakingProblem, BrakingSolution, Drive, Limits, Method, MinTimeOptions, SolveOptions,
    SolveStatus, min_braking_time, solve,
};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Robot presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// MiaPURE with a 60 kg payload: 1.4 m/s to rest in 2 s by default.
    Miapure,
    /// The planar testbed: 1 m/s to rest in 1.4 s by default.
    Piptb,
}

/// Collocation schemes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Hermite-Simpson (fourth order).
    HermiteSimpson,
    /// Trapezoidal (second order).
    Trapezoidal,
}

/// Arguments of `ballbot brake`.
#[derive(Debug, clap::Args)]
pub struct BrakeArgs {
    /// Robot preset.
    #[arg(long, value_enum, default_value = "miapure")]
    pub preset: Preset,
    /// A TOML file with the plane's parameters (every `WipParams` field, e.g.
    /// `ball_radius_m = 0.1145`), replacing the preset's plane; limits stay the preset's.
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Cruise speed at the start (m/s); default 1.4 (MiaPURE) or 1.0 (PIPTB).
    #[arg(long, value_parser = crate::finite_f64)]
    pub v0: Option<f64>,
    /// Braking time (s); default 2.0 (MiaPURE) or 1.4 (PIPTB).
    #[arg(long, value_parser = crate::finite_f64)]
    pub duration: Option<f64>,
    /// Collocation intervals N.
    #[arg(long, default_value_t = 100)]
    pub intervals: usize,
    /// Collocation scheme.
    #[arg(long, value_enum, default_value = "hermite-simpson")]
    pub method: MethodArg,
    /// Pin the torque to 0 at both ends.
    #[arg(long)]
    pub zero_end_torques: bool,
    /// Planar torque bound |tau| (N m).
    #[arg(long, value_parser = crate::finite_f64)]
    pub max_torque: Option<f64>,
    /// Tilt bound |theta| (deg).
    #[arg(long, value_parser = crate::finite_f64)]
    pub max_tilt_deg: Option<f64>,
    /// Tilt-rate bound |theta_dot| (rad/s).
    #[arg(long, value_parser = crate::finite_f64)]
    pub max_tilt_rate: Option<f64>,
    /// Ball-speed bound |r phi_dot| (m/s).
    #[arg(long, value_parser = crate::finite_f64)]
    pub max_ball_speed: Option<f64>,
    /// The preset's actuator limits: peak torque, torque-speed line and no-load speed of each
    /// actuator (MiaPURE: three omniwheels at --heading-deg; PIPTB: one direct drive).
    #[arg(long)]
    pub actuators: bool,
    /// Friction-aware limit: every omniwheel's traction <= mu N (MiaPURE; implies
    /// --actuators).
    #[arg(long)]
    pub traction: bool,
    /// Normal-force margin of the traction limit (N): every omniwheel's traction
    /// <= mu (N - margin), so every N >= margin (needs --traction; 0 = the plain cone).
    #[arg(long, default_value_t = 0.0, value_parser = crate::finite_f64)]
    pub normal_force_margin: f64,
    /// Direction of travel in the body frame for the omniwheel limits (deg; 0 = towards
    /// omniwheel 1; the paper braked at 180).
    #[arg(long, default_value_t = 180.0, value_parser = crate::finite_f64)]
    pub heading_deg: f64,
    /// Also find the minimum braking time under the limits, by bisection to this resolution
    /// (s) between 0.1 s and 5 s.
    #[arg(long, value_parser = crate::finite_f64)]
    pub min_time: Option<f64>,
    /// Print the result as JSON (cost, status, iterations, solve_ms, ...).
    #[arg(long)]
    pub json: bool,
    /// Write the trajectory, sampled every 10 ms, as CSV
    /// (t_secs, theta_rad, phi_rad, theta_dot_rad_per_s, phi_dot_rad_per_s, tau_nm).
    #[arg(long)]
    pub csv: Option<PathBuf>,
}

impl BrakeArgs {
    /// The braking problem these arguments describe.
    pub fn problem(&self) -> anyhow::Result<BrakingProblem> {
        let mut p = match self.preset {
            Preset::Miapure => BrakingProblem::miapure(),
            Preset::Piptb => BrakingProblem::piptb(),
        };
        if let Some(path) = &self.params {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            p.plane = toml::from_str::<WipParams<f64>>(&text)
                .with_context(|| format!("{}: not a WIP parameter table", path.display()))?;
        }
        p.initial_speed_m_per_s = self.v0.unwrap_or(p.initial_speed_m_per_s);
        p.duration_secs = self.duration.unwrap_or(p.duration_secs);
        p.intervals = self.intervals;
        p.method = match self.method {
            MethodArg::HermiteSimpson => Method::HermiteSimpson,
            MethodArg::Trapezoidal => Method::Trapezoidal,
        };
        p.zero_end_torques = self.zero_end_torques;
        let drive = (self.actuators || self.traction).then(|| match self.preset {
            Preset::Miapure => Drive::Omniwheels {
                params: DrivetrainParams::miapure(),
                heading_rad: self.heading_deg.to_radians(),
            },
            Preset::Piptb => Drive::Direct(ActuatorParams::miapure()),
        });
        p.limits = Limits {
            tilt_rad: self.max_tilt_deg.map(f64::to_radians),
            tilt_rate_rad_per_s: self.max_tilt_rate,
            ball_speed_m_per_s: self.max_ball_speed,
            torque_nm: self.max_torque,
            drive,
            traction: self.traction,
            normal_force_margin_n: self.normal_force_margin,
        };
        p.validate()?;
        Ok(p)
    }
}

/// Runs `ballbot brake`.
pub fn run(args: &BrakeArgs) -> anyhow::Result<()> {
    let problem = args.problem()?;
    let sol = solve(&problem, &SolveOptions::default())?;
    let mut record = solution_json(&sol);
    if let Some(resolution_secs) = args.min_time {
        let search = MinTimeOptions {
            resolution_secs,
            ..MinTimeOptions::default()
        };
        let r = min_braking_time(&problem, &SolveOptions::default(), &search)?;
        record["min_braking_time_secs"] = json!(r.min_duration_secs);
    }
    if let Some(path) = &args.csv {
        write_csv(&sol, path)?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&record)?);
    } else {
        println!(
            "braking {} m/s -> rest in {} s, {} N = {}: {} after {} iterations in {:.2} ms",
            problem.initial_speed_m_per_s,
            problem.duration_secs,
            record["method"].as_str().unwrap_or_default(),
            problem.intervals,
            sol.status,
            sol.iterations,
            sol.solve_time_secs * 1e3
        );
        println!(
            "  J = {:.4} N^2 m^2 s, peak lean {:.2} deg, peak ball speed {:.3} m/s",
            sol.cost_n2m2s,
            sol.peak_tilt_rad().to_degrees(),
            record["peak_ball_speed_m_per_s"]
                .as_f64()
                .unwrap_or(f64::NAN)
        );
        if let Some(t) = record.get("min_braking_time_secs") {
            println!("  minimum braking time under the limits: {t} s");
        }
    }
    // The record is printed either way (it says what went wrong); a failed solve still fails
    // the command, so that scripts see it.
    if sol.status != SolveStatus::Solved {
        anyhow::bail!("the braking problem was not solved: {}", sol.status);
    }
    Ok(())
}

fn write_csv(sol: &BrakingSolution, path: &Path) -> anyhow::Result<()> {
    std::fs::write(path, trajectory_csv(sol))
        .with_context(|| format!("cannot write {}", path.display()))
}
