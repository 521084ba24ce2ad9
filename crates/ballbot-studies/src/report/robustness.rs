//! `ballbot robustness` as a library call: the reliability campaign (fuzzing, fault
//! injection, Monte Carlo).
//!
//! Writes `OUT/robustness.json` (keys `fuzz`, `fault_matrix`, `monte_carlo`), the figures
//! (`OUT/fault_matrix_<controller>.{svg,png}` and the Monte Carlo figures, with the `plot`
//! feature) and the MCAP log of every faulted run (`OUT/logs/fault_matrix/*.mcap`), and hands
//! the tables and progress to a [`ReproduceObserver`].

use super::ReportError;
use super::reproduce::{ReproduceObserver, write_json};
use crate::studies::robustness::{
    ControllerVariant, FaultMatrix, FaultMatrixSettings, FuzzResult, FuzzSettings, MonteCarlo,
    MonteCarloCount, MonteCarloSettings, run_fault_matrix, run_fuzz, run_monte_carlo,
};
use ballbot_world::world::WorldParams;
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
    fuzz_section(options, observer, &mut summary)?;
    fault_matrix_section(options, observer, &mut summary)?;
    monte_carlo_section(options, observer, &mut summary)?;
    let summary = Value::Object(summary);
    write_json(&out.join("robustness.json"), &summary, observer)?;
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

fn monte_carlo_section(
    options: &RobustnessOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let base = if options.quick {
        MonteCarloSettings::quick()
    } else {
        MonteCarloSettings::full()
    };
    let world = WorldParams::miapure_60kg();
    let mut results = Map::new();
    let mut by_falls = Map::new();
    for count in MonteCarloCount::ALL {
        for controller in ControllerVariant::ALL {
            let settings = MonteCarloSettings {
                controller,
                count,
                seed: options.seed,
                ..base
            };
            // The figures keep their names for the published protocol (the stop rules).
            let name = match count {
                MonteCarloCount::StopRules => controller.as_str().to_owned(),
                MonteCarloCount::Falls => format!("{}_falls", controller.as_str()),
            };
            observer.start(&format!("mc {name}"), settings.runs as u64);
            let mc = run_monte_carlo(&world, &settings, options.threads, &|_, _| {
                observer.step("run")
            })?;
            observer.finish();
            observer.text(&monte_carlo_table(&mc));
            #[cfg(feature = "plot")]
            if options.plots {
                super::robustness_figures::monte_carlo_figure(&mc)
                    .save_svg_and_png(&options.out.join(format!("monte_carlo_{name}")))?;
            }
            let target = match count {
                MonteCarloCount::StopRules => &mut results,
                MonteCarloCount::Falls => &mut by_falls,
            };
            target.insert(controller.as_str().to_owned(), serde_json::to_value(&mc)?);
        }
    }
    // The headline: the designed controller's rate, as the issue asks for it, by the stop
    // rules (the published protocol) and by falls.
    let design = results.get("design").cloned().unwrap_or(Value::Null);
    let mut value = Map::new();
    let design_falls = by_falls.get("design").cloned().unwrap_or(Value::Null);
    for (key, source) in [
        ("recovery_rate", "recovery_rate"),
        ("recovery_rate_ci95", "recovery_rate_ci95"),
    ] {
        value.insert(
            format!("{key}_by_falls"),
            design_falls.get(source).cloned().unwrap_or(Value::Null),
        );
    }
    value.insert("by_falls".to_owned(), Value::Object(by_falls));
    value.insert(
        "recovery_rate".to_owned(),
        design.get("recovery_rate").cloned().unwrap_or(Value::Null),
    );
    value.insert(
        "recovery_rate_ci95".to_owned(),
        design
            .get("recovery_rate_ci95")
            .cloned()
            .unwrap_or(Value::Null),
    );
    for key in ["at_rest_rate", "at_rest_rate_ci95"] {
        value.insert(
            key.to_owned(),
            design.get(key).cloned().unwrap_or(Value::Null),
        );
    }
    value.insert("by_controller".to_owned(), Value::Object(results));
    summary.insert("monte_carlo".to_owned(), Value::Object(value));
    Ok(())
}

/// The Monte Carlo study as text: the rate with its interval, outcomes, the largest
/// recovered push's quantiles, the worst runs with their seeds, and the throughput.
pub fn monte_carlo_table(mc: &MonteCarlo) -> String {
    let s = &mc.settings;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "Monte Carlo, controller `{}`, counting {}: {} runs, +-{:.0} % mismatch, {} N s push over 0.1 s at a random heading, base seed {}",
        s.controller.as_str(),
        s.count.as_str().replace('_', " "),
        mc.runs,
        s.fraction * 100.0,
        s.impulse_ns,
        s.seed
    );
    let [lo, hi] = mc.recovery_rate_ci95;
    let [rest_lo, rest_hi] = mc.at_rest_rate_ci95;
    let _ = writeln!(
        t,
        "  stayed up {} of {}: {:.1} % (95 % CI {:.1} to {:.1} %); also at rest within 3 s: {} ({:.1} %, CI {:.1} to {:.1} %); outcomes: {}",
        mc.stayed_up,
        mc.runs,
        100.0 * mc.recovery_rate,
        100.0 * lo,
        100.0 * hi,
        mc.at_rest,
        100.0 * mc.at_rest_rate,
        100.0 * rest_lo,
        100.0 * rest_hi,
        mc.outcomes
            .iter()
            .map(|(o, n)| format!("{o} {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if let Some(q) = &mc.limit_quantiles {
        let _ = writeln!(
            t,
            "  largest recovered push over {} bisected runs (N s): min {:.0}, 5 % {:.0}, median {:.0}, 95 % {:.0}, max {:.0}",
            s.limit_runs, q.min, q.p05, q.p50, q.p95, q.max
        );
    }
    for r in &mc.worst {
        let m = &r.mismatch;
        let _ = writeln!(
            t,
            "  run {:>4} seed {:>20}: {:<13} peak tilt {:>5.1} deg, heading {:>5.1} deg, payload x{:.2}, COM x{:.2}, tilt bias [{:+.3}, {:+.3}] rad{}",
            r.index,
            r.seed,
            r.verdict,
            r.peak_tilt_deg,
            m.heading_deg,
            m.payload_mass,
            m.com_height,
            m.tilt_bias_rad[0],
            m.tilt_bias_rad[1],
            r.failure
                .as_ref()
                .map_or(String::new(), |f| format!(": {f}"))
        );
    }
    let th = &mc.throughput;
    let _ = writeln!(
        t,
        "  throughput (this run's wall clock): {:.2} runs/s on one thread, {:.2} runs/s on {} threads",
        th.one_thread_runs_per_s, th.all_threads_runs_per_s, th.threads
    );
    t
}

fn fuzz_section(
    options: &RobustnessOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let settings = FuzzSettings {
        seed: options.seed,
        ..if options.quick {
            FuzzSettings::quick()
        } else {
            FuzzSettings::full()
        }
    };
    let episodes = settings.episodes();
    observer.start("fuzz", episodes as u64);
    let robot = ballbot_core::BallbotParams::miapure_60kg();
    let fuzz = run_fuzz(&robot, &settings, options.threads, &|_, _| {
        observer.step("episode")
    })?;
    observer.finish();
    observer.text(&fuzz_table(&fuzz));
    summary.insert("fuzz".to_owned(), serde_json::to_value(&fuzz)?);
    Ok(())
}

/// The fuzzer's counts as text.
pub fn fuzz_table(f: &FuzzResult) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "Fuzzing the core (seed {}): {} controller steps ({} outer at 400 Hz, {} motor-loop at 8 kHz), {:.2} simulated hours, {} episodes",
        f.settings.seed, f.steps, f.outer_steps, f.inner_steps, f.simulated_hours, f.episodes
    );
    let _ = writeln!(
        t,
        "  {} episodes with traction-aware control and balance-point estimation on, {} pushes, {} planar controller steps",
        f.traction_on_episodes, f.pushes, f.planar_steps
    );
    let _ = writeln!(
        t,
        "  panics {}, bad commands {}, findings {}, single corrupted samples compared with a clean twin {}",
        f.panics, f.bad_commands, f.findings, f.single_sample_checks
    );
    let _ = writeln!(t, "  breaks by invariant (hardening item, class):");
    for c in &f.invariants {
        let i = &c.invariant;
        let _ = writeln!(
            t,
            "    {:>8}  {:<22} item {} {:<11} {}",
            c.breaks, i.key, i.item, i.class, i.what
        );
    }
    for (what, n) in &f.findings_by_what {
        let _ = writeln!(t, "  finding x{n}: {what}");
    }
    let p = &f.parsers;
    let _ = writeln!(
        t,
        "  parsers: {} mutated TOML files, {} rejected, {} accepted, {} panics; {} made a value wrong, the error named the key in {} ({} accepted the token)",
        p.files, p.rejected, p.accepted, p.panics, p.targeted, p.named_the_key, p.targeted_accepted
    );
    for u in &p.unnamed {
        let first = u.lines().next().unwrap_or_default();
        let _ = writeln!(t, "    error without the key: {first} ...");
    }
    for a in &p.accepted_wrong {
        let _ = writeln!(t, "    accepted: {a}");
    }
    let raised: Vec<String> = f
        .faults_raised
        .iter()
        .filter(|(_, n)| **n > 0)
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    let _ = writeln!(t, "  steps with each fault raised: {}", raised.join(", "));
    for v in &f.violations {
        let _ = writeln!(
            t,
            "  {} {} (episode seed {}, step {}): {}",
            v.kind, v.invariant, v.episode_seed, v.outer_step, v.what
        );
    }
    t
}
