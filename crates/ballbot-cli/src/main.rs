//! The `ballbot` command: `ballbot reproduce --out DIR`, `ballbot simulate <scenario.toml>`,
//! `ballbot brake`, `ballbot world`.

use clap::Parser;

fn main() -> anyhow::Result<()> {
    ballbot_cli::run(ballbot_cli::Cli::parse())
}
