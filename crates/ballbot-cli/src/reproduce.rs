//! `ballbot reproduce --out DIR [--quick]`: every paper experiment that exists so far
//! (`ballbot_sim::report::reproduce`), with a progress bar on a terminal.
//!
//! Writes `DIR/summary.json` (a stable interface: one key per experiment, e.g. `piptb`),
//! figures (`DIR/*.svg`, `DIR/*.png`) and MCAP logs (`DIR/logs/*.mcap`), and prints a
//! comparison table per experiment. The full run (not `--quick`) also writes
//! `piptb_ablation`: the PIPTB experiment without friction and noise, with each alone, and
//! with both, to show what each does to the comparison.

use anyhow::Context;
use ballbot_sim::report::{ReproduceObserver, ReproduceOptions, reproduce};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::sync::Mutex;

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

/// A progress bar per study; tables go to stdout (also `ballbot robustness`'s).
#[derive(Default)]
pub(crate) struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Bars {
    fn with_bar(&self, f: impl FnOnce(&ProgressBar)) {
        if let Ok(bar) = self.bar.lock()
            && let Some(bar) = bar.as_ref()
        {
            f(bar);
        }
    }
}

impl ReproduceObserver for Bars {
    fn start(&self, name: &str, steps: u64) {
        let bar = ProgressBar::new(steps);
        if let Ok(style) =
            ProgressStyle::with_template("{prefix:>8} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(name.to_owned());
        if let Ok(mut slot) = self.bar.lock() {
            *slot = Some(bar);
        }
    }

    fn step(&self, what: &str) {
        self.with_bar(|bar| {
            bar.set_message(what.to_owned());
            bar.inc(1);
        });
    }

    fn finish(&self) {
        self.with_bar(ProgressBar::finish_and_clear);
        if let Ok(mut slot) = self.bar.lock() {
            *slot = None;
        }
    }

    fn text(&self, text: &str) {
        println!("{text}");
    }
}

/// Runs `ballbot reproduce`.
pub fn run(args: &ReproduceArgs) -> anyhow::Result<()> {
    let options = ReproduceOptions {
        out: args.out.clone(),
        quick: args.quick,
        plots: !args.no_plots,
    };
    reproduce(&options, &Bars::default())
        .with_context(|| format!("reproduce into {}", args.out.display()))?;
    Ok(())
}
