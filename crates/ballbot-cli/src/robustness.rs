//! `ballbot robustness --out DIR [--quick] [--seed N] [--threads N]`: the reliability
//! campaign (`ballbot_sim::report::robustness`), with progress bars.
//!
//! Writes `DIR/robustness.json` (keys `fuzz`, `fault_matrix`, `monte_carlo`), figures
//! (`DIR/*.svg`, `DIR/*.png`) and the MCAP log of every faulted run
//! (`DIR/logs/fault_matrix/*.mcap`), and prints a table per part.

use crate::reproduce::Bars;
use anyhow::Context;
use ballbot_sim::report::{RobustnessOptions, robustness};
use std::path::PathBuf;

/// Arguments of `ballbot robustness`.
#[derive(Debug, clap::Args)]
pub struct RobustnessArgs {
    /// Output folder (created if missing).
    #[arg(long, default_value = "robustness")]
    pub out: PathBuf,
    /// The CI-sized campaign (10^5 fuzz steps, the fault matrix at one heading, a few Monte
    /// Carlo runs).
    #[arg(long)]
    pub quick: bool,
    /// Base seed of every random input; the output prints it, and every run's own seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (0: every core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Skip the figures.
    #[arg(long)]
    pub no_plots: bool,
}

/// Runs `ballbot robustness`.
pub fn run(args: &RobustnessArgs) -> anyhow::Result<()> {
    let options = RobustnessOptions {
        out: args.out.clone(),
        quick: args.quick,
        plots: !args.no_plots,
        threads: args.threads,
        seed: args.seed,
    };
    println!("ballbot robustness: seed {}", args.seed);
    robustness(&options, &Bars::default())
        .with_context(|| format!("robustness into {}", args.out.display()))?;
    Ok(())
}
