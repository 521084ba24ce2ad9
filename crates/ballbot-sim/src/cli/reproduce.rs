//! `ballbot reproduce --out DIR [--quick]`: every paper experiment that exists so far.
//!
//! Writes `DIR/summary.json` (a stable interface: one key per experiment, e.g. `piptb`),
//! figures (`DIR/*.svg`, `DIR/*.png`) and MCAP logs (`DIR/logs/*.mcap`), prints a comparison
//! table per experiment, and shows a progress bar on a terminal. The full run (not `--quick`)
//! also writes `piptb_ablation`: the PIPTB experiment without friction and noise, with each
//! alone, and with both, to show what each does to the comparison.

use crate::experiments::piptb::{self, PiptbSettings};
use crate::planar::ControllerKind;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

/// Arguments of `ballbot reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Output folder (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// The short variant for CI: one trial per controller, shorter holds.
    #[arg(long)]
    pub quick: bool,
    /// Skip the figures (faster; the summary and logs are still written).
    #[arg(long)]
    pub no_plots: bool,
}

pub(crate) fn progress_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{prefix:>8} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(what.to_owned());
    bar
}

/// Runs `ballbot reproduce`.
pub fn run(args: &ReproduceArgs) -> anyhow::Result<()> {
    let logs = args.out.join("logs");
    std::fs::create_dir_all(&logs).with_context(|| format!("cannot create {}", logs.display()))?;
    let mut summary = serde_json::Map::new();
    summary.insert("quick".to_owned(), serde_json::Value::Bool(args.quick));

    // PIPTB controller comparison (paper Sec. IV-C).
    let settings = if args.quick {
        PiptbSettings::quick()
    } else {
        PiptbSettings::paper()
    };
    let brake = piptb::braking_reference(&settings)?;
    let ablation = if args.quick {
        None
    } else {
        Some(piptb::ablation(&settings, &brake)?)
    };
    let kinds = ControllerKind::ALL;
    let bar = progress_bar((kinds.len() * settings.trials) as u64, "piptb");
    let report = piptb::run(&settings, brake, &kinds, Some(&logs), &mut |kind, trial| {
        bar.set_message(format!("{} seed {}", kind.label(), trial.seed));
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    println!("{}", report.table());
    if !args.no_plots {
        report.plot(&args.out)?;
    }
    summary.insert("piptb".to_owned(), report.summary_json());
    if let Some(variants) = &ablation {
        println!("{}", piptb::ablation_table(variants));
        summary.insert("piptb_ablation".to_owned(), piptb::ablation_json(variants));
    }

    // Braking trajectory optimisation (paper Sec. III-D, Fig. "DEC").
    summary.insert(
        "brake".to_owned(),
        super::brake::reproduce(&args.out, args.no_plots, args.quick)?,
    );

    // MiaPURE maximum speed per heading in the 3D world (paper Sec. V).
    super::world_reproduce::max_speed(&args.out, args.no_plots, args.quick, &mut summary)?;

    // 3D world: minimum braking time and push recovery (paper Sec. V, issue 6).
    super::world_brake::reproduce(&args.out, args.no_plots, args.quick, &mut summary)?;

    let path = args.out.join("summary.json");
    let text = serde_json::to_string_pretty(&serde_json::Value::Object(summary))?;
    std::fs::write(&path, format!("{text}\n"))
        .with_context(|| format!("cannot write {}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}
