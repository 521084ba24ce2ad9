//! The `ballbot` command: `ballbot reproduce --out DIR`, `ballbot simulate <scenario.toml>`,
//! `ballbot brake`, `ballbot world`, `ballbot params`.

use clap::Parser;
use std::process::ExitCode;

fn main() -> anyhow::Result<ExitCode> {
    ballbot_cli::run(ballbot_cli::Cli::parse())
}
