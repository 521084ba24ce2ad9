//! `ballbot reproduce` as a library call: every paper experiment that exists so far.
//!
//! Writes `OUT/summary.json` (a stable interface: one key per experiment, e.g. `piptb`),
//! figures (`OUT/*.svg`, `OUT/*.png`, with the `plot` feature) and MCAP logs
//! (`OUT/logs/*.mcap`), and hands a comparison table per experiment and progress to a
//! [`ReproduceObserver`]. `piptb_until_stopped` is the PIPTB experiment read with `t3` = when
//! the testbed stopped (the shape of `piptb`, which keeps the fixed window) and
//! `piptb_stop_sensitivity` that reading over a grid of stop criteria. The full run (not
//! quick) also writes `piptb_ablation`: the PIPTB experiment without friction and noise, with
//! each alone, and with both; and `world_braking.normal_force_margin`, the braking studies
//! with the planner's normal-force margins.
//!
//! Summary keys of the 3D world: `max_speed_by_heading` (heading in deg as text -> mean
//! slow-ramp maximum speed in m/s) and `max_speed_study` ([`crate::report::max_speed`]);
//! `min_braking_time_3d_secs`, `push_recovery_ns`, `world_braking`, `world_push`
//! ([`crate::report::world_suite`]). Figures: `max_speed_polar`, `failing_accel_polar`,
//! `acc_h{0,90,180}` (slow ramp, first seed), `acc_fail_h{0,90,180}` (the ramp at the smallest
//! failing acceleration), `world_braking_success`, `world_braking_failure`, `world_push`.
//! Logs: `logs/max_speed_h{0,90,180}.mcap` (the first trial per heading),
//! `logs/world_braking_success_h180.mcap`, `world_braking_failure_h180.mcap` (the shortest
//! success and the first failure of the descent at 180 deg) and `world_push_h180.mcap` (the
//! largest push recovered at 180 deg); telemetry at 1 kHz, 100 Hz when quick. Open them with
//! `foxglove/world-layout.json`.
//!
//! Traction-aware control ([`crate::report::traction`]): summary key
//! `traction_aware`; figures `traction_envelope_polar`, `traction_limited_ramp`.
//!
//! Bump and step tolerance ([`crate::report::crossing`]): summary keys
//! `bump_tolerance` and `step_tolerance`, one [`crate::studies::crossing`] study each.

use super::ReportError;
use crate::studies::crossing::{CrossingSettings, CrossingStudy, Obstacle};
use crate::studies::driver::{JobRecord, Study, execute};
use crate::studies::max_speed::{self, MaxSpeedStudySettings};
use crate::studies::mechanisms::{self, MechanismStudySettings};
use crate::studies::piptb::{self, PiptbSettings};
use crate::studies::replay::{log_braking, log_push, log_slow_ramp};
use crate::studies::traction::{self, TractionStudySettings};
use crate::studies::world_suite::{WorldSuiteSettings, run_world_suite};
use ballbot_world::planar::ControllerKind;
use ballbot_world::runner;
use ballbot_world::world::WorldParams;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// What `ballbot reproduce` runs and where it writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReproduceOptions {
    /// Output folder (created if missing).
    pub out: PathBuf,
    /// The short variant for CI: fewer trials, shorter holds, coarser searches.
    pub quick: bool,
    /// Draw the figures (needs the `plot` feature; without it no figure is drawn).
    pub plots: bool,
}

/// Sees a reproduction progress: a progress bar and the printed tables in the command line.
/// Called from worker threads, hence `Sync`.
pub trait ReproduceObserver: Sync {
    /// A study starts, with about `steps` steps; `name` is short, e.g. `piptb`.
    fn start(&self, name: &str, steps: u64);
    /// One step of the running study finished; `what` describes it.
    fn step(&self, what: &str);
    /// The running study finished.
    fn finish(&self);
    /// A result to show: a table or a line (without the final newline).
    fn text(&self, text: &str);
}

/// An observer that ignores everything (for tests and batch use).
#[derive(Clone, Copy, Debug, Default)]
pub struct Quiet;

impl ReproduceObserver for Quiet {
    fn start(&self, _: &str, _: u64) {}
    fn step(&self, _: &str) {}
    fn finish(&self) {}
    fn text(&self, _: &str) {}
}

fn create_dir(path: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(path).map_err(|source| ReportError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Runs every experiment, writes figures, logs and `summary.json` into `options.out`, and
/// returns the summary.
pub fn reproduce(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
) -> Result<Value, ReportError> {
    let out = &options.out;
    let logs = out.join("logs");
    create_dir(&logs)?;
    let mut summary = Map::new();
    summary.insert("quick".to_owned(), Value::Bool(options.quick));

    // PIPTB controller comparison (paper Sec. IV-C).
    piptb_section(options, &logs, observer, &mut summary)?;

    // Braking trajectory optimisation (paper Sec. III-D, Fig. "DEC").
    summary.insert(
        "brake".to_owned(),
        brake(out, options.plots, options.quick, observer)?,
    );

    // MiaPURE maximum speed per heading in the 3D world (paper Sec. V).
    max_speed_section(options, observer, &mut summary)?;

    // What limits the slow ramp (the mechanism study): mechanisms, controller ablation, sweep,
    // ripple.
    mechanisms_section(options, observer, &mut summary)?;

    // 3D world: minimum braking time and push recovery (paper Sec. V).
    world_suite_section(options, observer, &mut summary)?;

    // Traction-aware control against the same controller without it.
    traction_section(options, observer, &mut summary)?;

    // The highest floor bump and step crossed, each a study on the experiment driver.
    for obstacle in [Obstacle::BUMP, Obstacle::STEP] {
        crossing_section(options, obstacle, observer, &mut summary)?;
    }

    // The paper's three controllers (LQR, PI-PD, LQR-PI) in the 3D world.
    controllers_3d_section(options, observer, &mut summary)?;

    let summary = Value::Object(summary);
    write_json(&out.join("summary.json"), &summary, observer)?;
    Ok(summary)
}

/// Writes `value` as pretty JSON to `path` and tells `observer`.
pub(crate) fn write_json(
    path: &Path,
    value: &Value,
    observer: &dyn ReproduceObserver,
) -> Result<(), ReportError> {
    let text = serde_json::to_string_pretty(value)?;
    std::fs::write(path, format!("{text}\n")).map_err(|source| ReportError::Io {
        path: path.to_owned(),
        source,
    })?;
    observer.text(&format!("wrote {}", path.display()));
    Ok(())
}

fn piptb_section(
    options: &ReproduceOptions,
    logs: &Path,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let settings = if options.quick {
        PiptbSettings::quick()
    } else {
        PiptbSettings::paper()
    };
    let brake = piptb::braking_reference(&settings)?;
    let ablation = if options.quick {
        None
    } else {
        Some(piptb::ablation(&settings, &brake)?)
    };
    let kinds = ControllerKind::ALL;
    observer.start("piptb", (kinds.len() * settings.trials) as u64);
    let report = piptb::run(&settings, brake, &kinds, Some(logs), &mut |kind, trial| {
        observer.step(&format!("{} seed {}", kind.label(), trial.seed));
    })?;
    observer.finish();
    observer.text(&report.table());
    #[cfg(feature = "plot")]
    if options.plots {
        report.plot(&options.out)?;
    }
    summary.insert("piptb".to_owned(), report.summary_json());
    // The until-stopped reading of the same trials, and its criterion's sensitivity.
    let until = report.until_stopped(&settings.stop_criterion())?;
    observer.text(&super::piptb::readings_table(&report, &until));
    summary.insert("piptb_until_stopped".to_owned(), until.summary_json());
    let sensitivity = report.stop_sensitivity(
        &super::piptb::SENSITIVITY_BANDS_M_PER_S,
        &super::piptb::SENSITIVITY_HOLDS_SECS,
    )?;
    observer.text(&super::piptb::stop_sensitivity_table(&sensitivity));
    summary.insert(
        "piptb_stop_sensitivity".to_owned(),
        super::piptb::stop_sensitivity_json(&sensitivity),
    );
    if let Some(variants) = &ablation {
        observer.text(&super::piptb::ablation_table(variants));
        summary.insert(
            "piptb_ablation".to_owned(),
            super::piptb::ablation_json(variants),
        );
    }
    Ok(())
}

/// The `brake` part of `ballbot reproduce` ([`super::brake::reproduce_brake`]): shows its
/// line, writes `out/brake_miapure.{svg,png}` if `plots`, and returns the summary record.
pub fn brake(
    out: &Path,
    plots: bool,
    quick: bool,
    observer: &dyn ReproduceObserver,
) -> Result<Value, ReportError> {
    let b = super::brake::reproduce_brake(quick)?;
    observer.text(&b.text);
    #[cfg(feature = "plot")]
    if plots {
        super::brake::figure(
            &b.solution,
            "MiaPURE braking 1.4 m/s → rest in 2 s (minimum ∫τ² dt)",
        )
        .save_svg_and_png(&out.join("brake_miapure"))?;
    }
    #[cfg(not(feature = "plot"))]
    let _ = (out, plots);
    Ok(b.record)
}

/// Telemetry decimation of the replay logs: 1 kHz, or 100 Hz when quick.
fn log_every_steps(quick: bool) -> u32 {
    if quick { 80 } else { 8 }
}

fn max_speed_section(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let (out, quick) = (&options.out, options.quick);
    let params = WorldParams::miapure_60kg();
    let settings = if quick {
        MaxSpeedStudySettings::quick()
    } else {
        MaxSpeedStudySettings::paper()
    };
    observer.start("maxspeed", max_speed::runs_estimate(&params, &settings));
    let study = max_speed::run_study(params, &settings, &|what| observer.step(what))?;
    observer.finish();
    observer.text(&study.table());
    for h in &study.trials {
        let Some(first) = h.trials.first() else {
            continue;
        };
        let path = out
            .join("logs")
            .join(format!("max_speed_h{:.0}.mcap", h.heading_deg));
        log_slow_ramp(
            params,
            &settings.protocol,
            h.heading_deg,
            first.seed,
            &h.first_run,
            &path,
            log_every_steps(quick),
        )?;
    }
    #[cfg(feature = "plot")]
    if options.plots {
        use super::max_speed_figures::acc_figure;
        let [speed, accel] = study.capability_figures();
        speed.save_svg_and_png(&out.join("max_speed_polar"))?;
        accel.save_svg_and_png(&out.join("failing_accel_polar"))?;
        for h in &study.trials {
            let deg = format!("{:.0}", h.heading_deg);
            acc_figure(
                &h.first_run,
                &format!(
                    "MiaPURE slow ramp {} m/s² at h_z = {deg}° (seed {})",
                    settings.protocol.slow_ramp.accel_m_per_s2,
                    h.trials.first().map_or(0, |t| t.seed)
                ),
            )
            .save_svg_and_png(&out.join(format!("acc_h{deg}")))?;
            if let Some(f) = study.failing_at(h.heading_deg)
                && let (Some(run), Some(a)) = (&f.failing_run, f.smallest_failing_m_per_s2)
            {
                acc_figure(
                    run,
                    &format!("MiaPURE ramp {a:.2} m/s² (smallest failing) at h_z = {deg}°"),
                )
                .save_svg_and_png(&out.join(format!("acc_fail_h{deg}")))?;
            }
        }
    }
    summary.insert(
        "max_speed_by_heading".to_owned(),
        study.max_speed_by_heading_json(),
    );
    summary.insert("max_speed_study".to_owned(), study.detail_json());
    Ok(())
}

fn mechanisms_section(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let settings = if options.quick {
        MechanismStudySettings::quick()
    } else {
        MechanismStudySettings::paper()
    };
    observer.start("mechanisms", mechanisms::job_count(&settings) as u64);
    let robot = ballbot_core::BallbotParams::miapure_60kg();
    let study = mechanisms::run_study(robot, &settings, &|what| observer.step(what))?;
    observer.finish();
    let table = study.table();
    observer.text(table.strip_suffix('\n').unwrap_or(&table));
    #[cfg(feature = "plot")]
    if options.plots {
        let out = &options.out;
        study
            .slow_ramp_figure()
            .save_svg_and_png(&out.join("slow_ramp_mechanisms"))?;
        study
            .sweep_figure()
            .save_svg_and_png(&out.join("failure_speed_vs_accel"))?;
        if let Some(f) = study.ripple_spectrum_figure() {
            f.save_svg_and_png(&out.join("contact_ripple_spectra"))?;
        }
        if let Some(f) = study.ripple_peak_figure() {
            f.save_svg_and_png(&out.join("contact_ripple_peaks"))?;
        }
    }
    summary.insert("slow_ramp_mechanisms".to_owned(), study.slow_ramp_json());
    summary.insert("ramp_accel_sweep".to_owned(), study.sweep_json());
    summary.insert("contact_ripple".to_owned(), study.ripple_json());
    Ok(())
}

fn traction_section(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let settings = if options.quick {
        TractionStudySettings::quick()
    } else {
        TractionStudySettings::paper()
    };
    let robot = ballbot_core::BallbotParams::miapure_60kg();
    observer.start("traction", traction::runs_estimate(robot, &settings));
    let study = traction::run_study(robot, &settings, &|what| observer.step(what))?;
    observer.finish();
    let table = study.table();
    observer.text(table.strip_suffix('\n').unwrap_or(&table));
    #[cfg(feature = "plot")]
    if options.plots {
        let out = &options.out;
        study
            .envelope_figure()
            .save_svg_and_png(&out.join("traction_envelope_polar"))?;
        if let Some(f) = study.limited_ramp_figure() {
            f.save_svg_and_png(&out.join("traction_limited_ramp"))?;
        }
    }
    summary.insert("traction_aware".to_owned(), study.summary_json());
    Ok(())
}

/// The crossing study of `obstacle`: summary key `bump_tolerance` or `step_tolerance`.
fn crossing_section(
    options: &ReproduceOptions,
    obstacle: Obstacle,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let settings = if options.quick {
        CrossingSettings::quick(obstacle)
    } else {
        CrossingSettings::full(obstacle)
    };
    settings.validate()?;
    let study = CrossingStudy {
        settings,
        world: WorldParams::miapure_60kg(),
    };
    let (table, json) = driver_section(
        &study,
        obstacle.name(),
        observer,
        super::crossing::table,
        super::crossing::summary_json,
    )?;
    observer.text(table.strip_suffix('\n').unwrap_or(&table));
    summary.insert(format!("{}_tolerance", obstacle.name()), json);
    Ok(())
}

fn controllers_3d_section(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    use crate::studies::controllers_3d::{Controllers3dSettings, Controllers3dStudy};
    let settings = if options.quick {
        Controllers3dSettings::quick()
    } else {
        Controllers3dSettings::full()
    };
    settings.validate()?;
    let study = Controllers3dStudy {
        settings,
        world: WorldParams::miapure_60kg(),
    };
    let (table, json) = driver_section(
        &study,
        "controllers_3d",
        observer,
        super::controllers_3d::table,
        super::controllers_3d::summary_json,
    )?;
    observer.text(table.strip_suffix('\n').unwrap_or(&table));
    summary.insert("controllers_3d".to_owned(), json);
    Ok(())
}

/// Runs `study` on the experiment driver under a progress bar named `name` and renders its
/// records: the table to print and the summary's JSON.
fn driver_section<S>(
    study: &S,
    name: &str,
    observer: &dyn ReproduceObserver,
    table: fn(&S, &[JobRecord<S::Trial>]) -> String,
    json: fn(&S, &[JobRecord<S::Trial>]) -> Value,
) -> Result<(String, Value), ReportError>
where
    S: Study,
    ReportError: From<S::Error>,
{
    let runs = study.jobs().iter().map(|j| study.runs_estimate(j)).sum();
    observer.start(name, runs);
    let records = execute(study, 0, &|what| observer.step(what))?;
    observer.finish();
    Ok((table(study, &records), json(study, &records)))
}

fn world_suite_section(
    options: &ReproduceOptions,
    observer: &dyn ReproduceObserver,
    summary: &mut Map<String, Value>,
) -> Result<(), ReportError> {
    let (out, quick) = (&options.out, options.quick);
    let settings = if quick {
        WorldSuiteSettings::quick()
    } else {
        WorldSuiteSettings::paper()
    };
    observer.start("world", settings.run_estimate());
    let suite = run_world_suite(&settings, &|what| observer.step(what))?;
    observer.finish();
    let table = suite.table();
    observer.text(table.strip_suffix('\n').unwrap_or(&table));

    let paper_heading = suite.paper_heading();
    #[cfg(feature = "plot")]
    if options.plots {
        use super::world_suite_figures::{braking_figure, push_figure};
        use crate::studies::world_braking::BrakingOutcome;
        if let Some(st) = paper_heading {
            if let Some(run) = st.shortest_success() {
                braking_figure(
                    run,
                    &format!(
                        "MiaPURE braking 1.4 m/s → rest at 180° in T = {:.1} s (shortest success, 3D world)",
                        run.duration_secs
                    ),
                )
                .save_svg_and_png(&out.join("world_braking_success"))?;
            }
            if let Some(run) = st.first_failure().filter(|r| !r.samples.is_empty()) {
                braking_figure(
                    run,
                    &format!(
                        "MiaPURE braking at 180° in T = {:.1} s (first failure: {})",
                        run.duration_secs,
                        match run.outcome {
                            BrakingOutcome::Failed(f) => f.kind.to_string(),
                            o => o.label().to_owned(),
                        }
                    ),
                )
                .save_svg_and_png(&out.join("world_braking_failure"))?;
            }
        }
        if !suite.pushes.is_empty() {
            let pushes: Vec<_> = suite.pushes.iter().collect();
            push_figure(&pushes).save_svg_and_png(&out.join("world_push"))?;
        }
    }

    // One MCAP log per experiment; the replays are independent jobs.
    let logs = out.join("logs");
    create_dir(&logs)?;
    let every = log_every_steps(quick);
    let world = suite.world;
    enum Replay<'a> {
        Braking(&'a crate::studies::world_braking::BrakingRun, &'static str),
        Push(&'a crate::studies::push::PushTrial),
    }
    let mut replays = Vec::new();
    if let Some(run) = paper_heading.and_then(|st| st.shortest_success()) {
        replays.push(Replay::Braking(run, "world_braking_success_h180.mcap"));
    }
    if let Some(run) = paper_heading.and_then(|st| st.first_failure()) {
        replays.push(Replay::Braking(run, "world_braking_failure_h180.mcap"));
    }
    if let Some(trial) = suite
        .pushes
        .iter()
        .find(|p| p.heading_deg == 180.0)
        .and_then(|p| p.largest_recovered())
    {
        replays.push(Replay::Push(trial));
    }
    runner::run_jobs(
        &replays,
        0,
        |replay| match replay {
            Replay::Braking(run, name) => {
                log_braking(world, &settings.braking, run, &logs.join(name), every)
            }
            Replay::Push(trial) => log_push(
                world,
                &settings.push,
                trial,
                &logs.join("world_push_h180.mcap"),
                every,
            ),
        },
        &|_| {},
    )?;

    suite.add_to_summary(summary);
    Ok(())
}
