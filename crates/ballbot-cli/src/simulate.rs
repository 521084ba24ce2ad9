//! `ballbot simulate <scenario.toml> [--out DIR]`: one planar run
//! (`ballbot_sim::studies::scenario_run`).
//!
//! Writes `DIR/<scenario>.mcap` (every channel of `ballbot_sim::log::planar::McapRecorder`) and
//! `DIR/<scenario>.json` (the run's summary), and prints the summary.

use anyhow::Context;
use ballbot_sim::studies::scenario::Scenario;
pub use ballbot_sim::studies::scenario_run::RunSummary;
use ballbot_sim::studies::scenario_run::run_scenario;
use std::path::PathBuf;

/// Arguments of `ballbot simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// The scenario file (TOML; see `scenarios/` for examples).
    pub scenario: PathBuf,
    /// Output folder for the MCAP log and the JSON summary.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Runs `ballbot simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let scenario = Scenario::from_path(&args.scenario)?;
    let stem = args.scenario.file_stem().map_or_else(
        || "scenario".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    let log_path = args.out.join(format!("{stem}.mcap"));
    let summary = run_scenario(&scenario, &args.scenario.display().to_string(), &log_path)?;
    let json = serde_json::to_string_pretty(&summary)?;
    let json_path = args.out.join(format!("{stem}.json"));
    std::fs::write(&json_path, format!("{json}\n"))
        .with_context(|| format!("cannot write {}", json_path.display()))?;
    println!("{json}");
    Ok(())
}
