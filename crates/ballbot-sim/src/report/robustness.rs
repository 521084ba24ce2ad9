//! `ballbot robustness` as a library call: the reliability campaign of issue 15.
//!
//! Writes `OUT/robustness.json` (keys `fuzz`, `fault_matrix`, `monte_carlo`), the figures
//! (`OUT/fault_matrix_<controller>.{svg,png}` and the Monte Carlo figures, with the `plot`
//! feature) and the MCAP log of every faulted run (`OUT/logs/fault_matrix/*.mcap`), and hands
//! the tables and progress to a [`ReproduceObserver`].

use super::ReportError;
use super::reproduce::ReproduceObserver;
use crate::studies::robustness::{
    ControllerVariant, FaultMatrix, FaultMatrixSettings, run_fault_matrix,
};
use crate::world::WorldParams;
use serde_json::{Map, Value, json};
use std::fmt::Write as _;
use std::path::PathBuf;

/// What `ballbot robustness` runs and where it writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobustnessOptions {
    /// Output folder (created if missing).
    pub out: PathBuf,
    /// The CI-sized campaign.
    pub quick: bool,
    /// Draw the figures (needs the `plot` feature).
    pub plots: bool,
    /// Worker threads (0: every core).
    pub threads: usize,
    /// Base seed of every random input (sensor noise, fuzz sequences, Monte Carlo samples).
    pub seed: u64,
}

/// Runs the campaign, writes `robustness.json`, figures and logs into `options.out`, and
/// returns the JSON.
pub fn robustness(
    options: &RobustnessOptions,
    observer: &dyn ReproduceObserver,
) -> Result<Value, ReportError> {
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(|source| ReportError::Io {
        path: out.clone(),
        source,
    })?;
    let mut summary = Map::new();
    summary.insert("quick".to_owned(), Value::Bool(options.quick));
    summary.insert("seed".to_owned(), json!(options.seed));
    fault_matrix_section(options, observer, &mut summary)?;
    let summary = Value::Object(summary);
    let path = out.join("robustness.json");
    let text = serde_json::to_string_pretty(&summary)?;
    std::fs::write(&path, format!("{text}\n")).map_err(|source| ReportError::Io {
        path: path.clone(),
        source,
    })?;
    observer.text(&format!("wrote {}", path.display()));
    Ok(summary)
}

fn fault_matrix_section(
    options: &RobustnessOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let mut settings = if options.quick {
        FaultMatrixSettings::quick()
    } else {
        FaultMatrixSettings::full()
    };
    settings.seed = options.seed;
    settings.log_dir = Some(options.out.join("logs").join("fault_matrix"));
    observer.start("faults", settings.cells().len() as u64);
    let world = WorldParams::miapure_60kg();
    let matrix = run_fault_matrix(&world, &settings, options.threads, &|_, _| {
        observer.step("fault cell")
    })?;
    observer.finish();
    for &controller in &settings.controllers {
        observer.text(&fault_matrix_table(&matrix, &settings, controller));
    }
    #[cfg(feature = "plot")]
    if options.plots {
        for &controller in &settings.controllers {
            super::robustness_figures::fault_matrix_figure(&matrix, &settings, controller)
                .save_svg_and_png(
                    &options
                        .out
                        .join(format!("fault_matrix_{}", controller.as_str())),
                )?;
        }
    }
    let mut value = serde_json::to_value(&matrix)?;
    if let Value::Object(map) = &mut value {
        map.insert("settings".to_owned(), serde_json::to_value(&settings)?);
    }
    summary.insert("fault_matrix".to_owned(), value);
    Ok(())
}

/// The matrix of one controller as text: one row per fault class, one column per condition
/// and heading, [`CellResult::mark`](crate::studies::robustness::CellResult::mark) in each cell, then the summary counts.
pub fn fault_matrix_table(
    matrix: &FaultMatrix,
    settings: &FaultMatrixSettings,
    controller: ControllerVariant,
) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "Fault-injection matrix, controller `{}` (expected state per class; ok = reached it)",
        controller.as_str()
    );
    let _ = write!(t, "{:<20} {:<16}", "fault", "expected");
    for condition in &settings.conditions {
        for heading in &settings.headings_deg {
            let _ = write!(t, " {:>13}", format!("{} {heading:.0}", condition.as_str()));
        }
    }
    let _ = writeln!(t);
    let mut as_expected = 0;
    let mut cells = 0;
    for &class in &settings.classes {
        let row = matrix.row(controller, class);
        let _ = write!(
            t,
            "{:<20} {:<16}",
            class.as_str(),
            class.expected().as_str()
        );
        for cell in &row {
            // The time to detect, where the fault was detected (not a fall's tilt limit).
            let detect = match cell.time_to_detect_ms {
                Some(ms) if cell.observed.is_safe() => format!(" {ms:.0}ms"),
                _ => String::new(),
            };
            let _ = write!(t, " {:>13}", format!("{}{detect}", cell.mark()));
            cells += 1;
            as_expected += usize::from(cell.as_expected);
        }
        let _ = writeln!(t);
    }
    let _ = writeln!(
        t,
        "{as_expected} of {cells} cells in their expected safe state; marks: kb keeps balancing, cs controlled stop, ps protective stop, dr drifting off the command, FELL fell undetected, n/a fault never acted; ms = time to detect"
    );
    t
}
