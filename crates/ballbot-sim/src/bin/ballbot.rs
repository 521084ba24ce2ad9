//! The `ballbot` command: `ballbot reproduce --out DIR`, `ballbot simulate <scenario.toml>`.

use clap::Parser;

fn main() -> anyhow::Result<()> {
    ballbot_sim::cli::run(ballbot_sim::cli::Cli::parse())
}
