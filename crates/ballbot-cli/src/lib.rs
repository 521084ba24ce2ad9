//! The `ballbot` command line: argument parsing and calls into ballbot-sim, one module per
//! subcommand (the studies, their reports and figures live in `ballbot_sim::studies` and
//! `ballbot_sim::report`).
//!
//! - `ballbot simulate <scenario.toml>`: one planar run described by a scenario file
//!   (`ballbot_sim::studies::scenario`); writes its MCAP log and a JSON summary.
//! - `ballbot reproduce --out DIR [--quick]`: every paper experiment that exists so far;
//!   prints a comparison table and writes plots, MCAP logs and `DIR/summary.json`.
//! - `ballbot robustness --out DIR [--quick]`: the reliability campaign (fuzzing, fault
//!   injection in the 3D world, Monte Carlo); writes `DIR/robustness.json`, figures and logs.
//! - `ballbot sweep GRID.toml [--out DIR]`: a study over a grid of world parameters and
//!   headings on every core; writes `DIR/sweep.csv` and `DIR/sweep.json`.
//! - `ballbot params schema|check|show|diff`: the parameter files' JSON Schemas, checking a
//!   file (errors name the dotted key and the bound), the presets as commented files, and the
//!   keys two files differ in.
//! - `ballbot brake [--preset miapure|piptb] [--json]`: a minimum-effort braking trajectory.
//! - `ballbot world [--heading-deg D --accel-m-per-s2 A ...] --out FILE.mcap`: one 3D world run
//!   with the core's controller; prints the outcome and writes an MCAP log for Foxglove.
//! - `ballbot export --format mjcf|urdf [--world FILE] --out PATH`: the world's robot in
//!   MuJoCo's or the URDF format, from the same parameters.

pub mod brake;
pub mod export;
pub mod params;
pub mod reproduce;
pub mod robustness;
pub mod simulate;
pub mod sweep;
pub mod video;
pub mod world;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Ballbot drivetrain simulation: reproduce the paper's experiments, run scenarios.
#[derive(Debug, Parser)]
#[command(name = "ballbot", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one planar scenario (TOML) and write its MCAP log and summary.
    Simulate(simulate::SimulateArgs),
    /// Run the paper's experiments; print the comparison and write plots, logs and
    /// DIR/summary.json.
    Reproduce(reproduce::ReproduceArgs),
    /// Run the reliability campaign: fuzz the core, inject faults in the 3D world, Monte Carlo
    /// pushes on mismatched robots; print the tables and write DIR/robustness.json, figures
    /// and logs.
    Robustness(robustness::RobustnessArgs),
    /// Run a study (failing acceleration, push recovery) over a grid of world parameters and
    /// headings from a TOML file, on every core; write DIR/sweep.csv and DIR/sweep.json.
    #[command(after_help = sweep::AFTER_HELP)]
    Sweep(sweep::SweepArgs),
    /// Compute a minimum-effort braking trajectory (direct collocation, SQP with clarabel).
    Brake(brake::BrakeArgs),
    /// Run the 3D world (rapier3d) with the core's controller: a velocity ramp and an optional
    /// push; print the outcome and write an MCAP log (telemetry, Foxglove 3D scene).
    #[command(after_help = world::AFTER_HELP)]
    World(world::WorldArgs),
    /// Parameter files (robot, scenario, world): write their JSON Schemas, check a file,
    /// print a preset with comments, list the keys two files differ in.
    Params(params::ParamsArgs),
    /// Write the world's robot (ball, body, omniwheels with rollers, actuators, inertias) as
    /// MJCF (MuJoCo) or URDF, from the same parameters the 3D world runs on.
    Export(export::ExportArgs),
}

/// The value parser of every floating-point flag: a finite `f64`, or an error that clap
/// reports with the flag's name (exit code 2). `nan`, `inf`, `-inf` and numbers that
/// overflow to infinity (`1e999`) are rejected wherever they appear, even for a flag the
/// chosen options do not read.
///
/// ```
/// use ballbot_cli::finite_f64;
/// assert_eq!(finite_f64("-1.5e3"), Ok(-1500.0));
/// for bad in ["nan", "inf", "-inf", "1e999", "x"] {
///     assert!(finite_f64(bad).is_err(), "{bad}");
/// }
/// ```
pub fn finite_f64(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|e| format!("`{text}` is not a number ({e})"))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("`{text}` is not a finite number"))
    }
}

/// Runs a parsed command line; the exit code is 0 unless the command says otherwise
/// (`params diff`: 1 when the files differ, 2 on an error).
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let done = match cli.command {
        Command::Simulate(args) => simulate::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
        Command::Robustness(args) => robustness::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Brake(args) => brake::run(&args),
        Command::World(args) => world::run(&args),
        Command::Params(args) => return params::run(&args),
        Command::Export(args) => export::run(&args),
    };
    done.map(|()| ExitCode::SUCCESS)
}
