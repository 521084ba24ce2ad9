//! `ballbot sweep GRID.toml [--out DIR] [--threads N]`: a study over a grid of world
//! parameters and study arguments (`ballbot_sim::studies::sweep`), on every core, with a
//! progress bar. Writes `DIR/sweep.csv` and `DIR/sweep.json` (one row per point) and prints
//! the table.

use anyhow::Context;
use ballbot_sim::studies::sweep::{Sweep, SweepRow};
use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `ballbot sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// The grid file (TOML): `study`, `preset` or `params`, `seed`, `quick`, and `[grid]`.
    pub file: PathBuf,
    /// Output folder (created if missing).
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    /// Worker threads (0: every core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// An example grid file, printed by `ballbot sweep --help`.
pub const AFTER_HELP: &str = "Grid file example:
  study = \"failing_acceleration\"   # or \"push_recovery\"
  preset = \"miapure_60kg\"          # or params = \"world.toml\"
  seed = 0
  [grid]
  heading_deg = [0.0, 60.0]
  \"robot.drivetrain.wheel_ball_friction\" = [0.5, 0.8]
  \"robot.{sagittal,frontal}.com_height_m\" = [0.45, 0.6]";

/// Runs `ballbot sweep`.
pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    let sweep = Sweep::load(&args.file)?;
    let n = sweep.points.len();
    println!(
        "ballbot sweep: {} at {n} points, seed {}",
        sweep.study.as_str(),
        sweep.seed
    );
    let bar = ProgressBar::new(n as u64);
    if let Ok(style) = ProgressStyle::with_template("sweep [{bar:30}] {pos}/{len} ({elapsed})") {
        bar.set_style(style.progress_chars("=> "));
    }
    let start = Instant::now();
    let rows = sweep.run(args.threads, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    let wall_secs = start.elapsed().as_secs_f64();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let csv = csv(&rows);
    std::fs::write(args.out.join("sweep.csv"), &csv).context("writing sweep.csv")?;
    let json = serde_json::json!({
        "study": sweep.study,
        "seed": sweep.seed,
        "quick": sweep.quick,
        "wall_secs": wall_secs,
        "rows": rows,
    });
    std::fs::write(
        args.out.join("sweep.json"),
        serde_json::to_string_pretty(&json)?,
    )
    .context("writing sweep.json")?;
    print!("{}", table(&rows));
    println!(
        "{n} points in {wall_secs:.1} s; wrote {}/sweep.csv and sweep.json",
        args.out.display()
    );
    Ok(())
}

/// One row per point: the point's keys, the study's numbers (empty where censored), then how
/// the run at the limit's failing end ended (`failing_outcome`, e.g.
/// `ended_by_stop_rule:lift_off`; empty where no run failed).
fn csv(rows: &[SweepRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = String::new();
    // Quoted as RFC 4180 asks: a brace key (`robot.{sagittal,frontal}.com_height_m`) holds a
    // comma.
    let header: Vec<String> = first
        .point
        .keys()
        .map(String::as_str)
        .chain(first.values.keys().copied())
        .chain(["failing_outcome"])
        .map(csv_cell)
        .collect();
    let _ = writeln!(out, "{}", header.join(","));
    for r in rows {
        let cells: Vec<String> = r
            .point
            .values()
            .map(|v| format!("{v}"))
            .chain(
                r.values
                    .values()
                    .map(|v| v.map_or(String::new(), |x| format!("{x}"))),
            )
            .chain([r
                .failing_run
                .as_ref()
                .map_or(String::new(), |f| f.happened.outcome.label())])
            .collect();
        let _ = writeln!(out, "{}", cells.join(","));
    }
    out
}

/// A CSV cell: quoted (quotes doubled) when it holds a comma, a quote or a line break.
fn csv_cell(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// The points and each one's result text, aligned.
fn table(rows: &[SweepRow]) -> String {
    let mut out = String::new();
    for r in rows {
        let point: Vec<String> = r.point.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let _ = writeln!(out, "  {:<70} {}", point.join("  "), r.text);
    }
    out
}
