//! The 3D world's braking-time and push-recovery experiments in `ballbot reproduce` (issue 6):
//! summary keys `min_braking_time_3d_s`, `push_recovery_ns`, `world_braking`, `world_push`;
//! figures `world_braking_success`, `world_braking_failure`, `world_push`.
//!
//! Full run: the paper's braking protocol (T = 5 s, 0.5 s shorter per success) plus a
//! bisection to 0.05 s at 180 deg (the paper's heading), 0 and 90 deg; the same descent at
//! 180 deg with the equilibrium-lean feedforward only (ablation, see
//! [`crate::world::braking`]); the planar model's minimum braking time under the same limits;
//! push recovery at 0, 90 and 180 deg bisected to 0.5 N s, as a 0.1 s force pulse (summary
//! key) and applied in one physics step (detail, see [`crate::world::push`]). `--quick`:
//! T = 5, 3, 2 s at 180 deg with a shorter approach, and a coarse push bisection (12 N s) at
//! 180 deg.
//! Independent studies run on all cores (`std::thread::scope`).

use crate::log::{WorldLogOptions, WorldLogger};
use crate::plot::{LegendPosition, LineStyle, Series, Subplot, TimeSeriesFigure};
use crate::trajopt::{MinTimeOptions, SolveOptions, min_braking_time};
use crate::world::braking::fly_braking;
use crate::world::braking::{
    BrakingOutcome, BrakingParams, BrakingRun, BrakingStudy, BrakingStudyParams,
    TrajectoryFeedforward, braking_problem, braking_study,
};
use crate::world::push::{
    PushParams, PushRecovery, PushSearch, PushTrial, push_recovery_limit, push_trial_observed,
};
use crate::world::{Failure, FailureKind, WorldParams};
use anyhow::Context;
use indicatif::ProgressBar;
use serde_json::{Map, Value, json};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The paper's minimum braking time from 1.4 m/s at 180 deg (s).
pub const PAPER_MIN_BRAKING_TIME_S: f64 = 2.0;

/// Sensor-noise seed of every world run here.
const SEED: u64 = 6;

/// One independent study.
#[derive(Clone, Debug)]
enum Job {
    Braking {
        heading_deg: f64,
        feedforward: TrajectoryFeedforward,
        study: BrakingStudyParams,
    },
    Push {
        heading_deg: f64,
        search: PushSearch,
        /// The push's duration (s); 0: one physics step.
        duration_s: f64,
    },
}

enum JobResult {
    Braking(BrakingStudy, TrajectoryFeedforward),
    Push(PushRecovery, f64),
}

/// The protocol settings of a run.
struct Settings {
    braking: BrakingParams,
    push: PushParams,
    jobs: Vec<Job>,
    planar_headings_deg: Vec<f64>,
    planar_resolution_s: f64,
}

fn settings(quick: bool) -> Settings {
    if quick {
        let braking = BrakingParams {
            approach_accel_m_per_s2: 1.0,
            cruise_s: 1.5,
            ..BrakingParams::default()
        };
        Settings {
            braking,
            push: PushParams::default(),
            jobs: vec![
                Job::Braking {
                    heading_deg: 180.0,
                    feedforward: TrajectoryFeedforward::Full,
                    study: BrakingStudyParams {
                        durations_s: vec![5.0, 3.0, 2.0],
                        bisection_resolution_s: None,
                    },
                },
                Job::Push {
                    heading_deg: 180.0,
                    search: PushSearch {
                        upper_ns: 96.0,
                        resolution_ns: 12.0,
                    },
                    duration_s: PushParams::default().push_duration_s,
                },
            ],
            planar_headings_deg: vec![180.0],
            planar_resolution_s: 0.05,
        }
    } else {
        let braking = |heading_deg, feedforward, bisect: bool| Job::Braking {
            heading_deg,
            feedforward,
            study: BrakingStudyParams {
                bisection_resolution_s: bisect.then_some(0.05),
                ..BrakingStudyParams::paper()
            },
        };
        let push = |heading_deg, duration_s| Job::Push {
            heading_deg,
            search: PushSearch {
                upper_ns: 200.0,
                resolution_ns: 0.5,
            },
            duration_s,
        };
        let shove = PushParams::default().push_duration_s;
        Settings {
            braking: BrakingParams::default(),
            push: PushParams::default(),
            // Longest first, so the two cores finish together.
            jobs: vec![
                braking(180.0, TrajectoryFeedforward::Full, true),
                braking(0.0, TrajectoryFeedforward::Full, true),
                braking(90.0, TrajectoryFeedforward::Full, true),
                push(0.0, shove),
                push(90.0, shove),
                push(180.0, shove),
                braking(180.0, TrajectoryFeedforward::Core, false),
                push(0.0, 0.0),
                push(90.0, 0.0),
                push(180.0, 0.0),
            ],
            planar_headings_deg: vec![180.0, 0.0, 90.0],
            planar_resolution_s: 0.01,
        }
    }
}

/// Runs `jobs` on all cores; results in the jobs' order.
fn run_jobs(world: WorldParams, s: &Settings, bar: &ProgressBar) -> anyhow::Result<Vec<JobResult>> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<anyhow::Result<JobResult>>>> =
        Mutex::new((0..s.jobs.len()).map(|_| None).collect());
    let threads = std::thread::available_parallelism()
        .map_or(2, |n| n.get())
        .min(s.jobs.len())
        .max(1);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(job) = s.jobs.get(i) else { break };
                    let result = run_job(world, s, job, bar);
                    if let Ok(mut r) = results.lock() {
                        r[i] = Some(result);
                    }
                }
            });
        }
    });
    let results = results
        .into_inner()
        .map_err(|_| anyhow::anyhow!("a world experiment thread panicked"))?;
    results
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err(anyhow::anyhow!("a world experiment did not run"))))
        .collect()
}

fn run_job(
    world: WorldParams,
    s: &Settings,
    job: &Job,
    bar: &ProgressBar,
) -> anyhow::Result<JobResult> {
    match job {
        Job::Braking {
            heading_deg,
            feedforward,
            study,
        } => {
            let params = BrakingParams {
                feedforward: *feedforward,
                ..s.braking
            };
            let result = braking_study(world, &params, study, *heading_deg, &mut |run| {
                bar.set_message(format!(
                    "brake {:.0} deg T {:.2} s: {}",
                    run.heading_deg,
                    run.duration_s,
                    run.outcome.label()
                ));
                bar.inc(1);
            })?;
            Ok(JobResult::Braking(result, *feedforward))
        }
        Job::Push {
            heading_deg,
            search,
            duration_s,
        } => {
            let params = PushParams {
                push_duration_s: *duration_s,
                ..s.push
            };
            let result = push_recovery_limit(world, &params, search, *heading_deg, &mut |t| {
                bar.set_message(format!(
                    "push {:.0} deg {:.1} N s: {}",
                    t.heading_deg,
                    t.impulse_ns,
                    t.outcome.label()
                ));
                bar.inc(1);
            })?;
            Ok(JobResult::Push(result, *duration_s))
        }
    }
}

fn wheel_name(i: usize) -> String {
    format!("OW{}", i + 1)
}

/// A short description of a failure, e.g. `lift-off OW1 at 6.086 s`.
pub fn failure_label(f: &Failure) -> String {
    format!("{} at {:.3} s", failure_kind_label(f), f.time_s)
}

/// What failed, e.g. `lift-off OW1`.
fn failure_kind_label(f: &Failure) -> String {
    match f.kind {
        FailureKind::Tilt { tilt_rad } => format!("tilt {:.1} deg", tilt_rad.to_degrees()),
        FailureKind::BodyTouchedFloor => "chassis on the floor".to_owned(),
        FailureKind::SustainedSlip { wheel } => format!("slip {}", wheel_name(wheel)),
        FailureKind::LiftOff { wheel } => format!("lift-off {}", wheel_name(wheel)),
    }
}

fn failure_json(f: &Failure) -> Value {
    let (kind, wheel) = match f.kind {
        FailureKind::Tilt { .. } => ("tilt", None),
        FailureKind::BodyTouchedFloor => ("body_touched_floor", None),
        FailureKind::SustainedSlip { wheel } => ("sustained_slip", Some(wheel_name(wheel))),
        FailureKind::LiftOff { wheel } => ("lift_off", Some(wheel_name(wheel))),
    };
    json!({ "kind": kind, "wheel": wheel, "time_s": f.time_s, "label": failure_label(f) })
}

/// What bounded a braking run: the failure, or the most used resource.
fn limiting(run: &BrakingRun) -> String {
    let p = &run.peaks;
    let argmax = |v: &[f64; 3]| {
        (0..3)
            .max_by(|&a, &b| v[a].total_cmp(&v[b]))
            .unwrap_or_default()
    };
    let cone = argmax(&p.cone_utilisation);
    let act = argmax(&p.actuator_utilisation);
    let used = format!(
        "cone {} {:.2}, actuator {} {:.2}, tilt {:.1} deg",
        wheel_name(cone),
        p.cone_utilisation[cone],
        wheel_name(act),
        p.actuator_utilisation[act],
        p.tilt_rad.to_degrees()
    );
    match run.outcome {
        BrakingOutcome::Failed(f) => format!(
            "{} ({:.3} s after braking started); {used}",
            failure_label(&f),
            f.time_s - run.brake_start_s
        ),
        BrakingOutcome::NoTrajectory { status } => format!("no trajectory ({status})"),
        BrakingOutcome::NotAtRest {
            rest_speed_m_per_s, ..
        } => format!("not at rest ({rest_speed_m_per_s:.3} m/s); {used}"),
        BrakingOutcome::Stopped { .. } => used,
    }
}

fn run_json(run: &BrakingRun) -> Value {
    let p = &run.peaks;
    let outcome = match run.outcome {
        BrakingOutcome::Stopped { rest_speed_m_per_s } => {
            json!({ "rest_speed_m_per_s": rest_speed_m_per_s })
        }
        BrakingOutcome::NoTrajectory { status } => json!({ "solve_status": status.as_str() }),
        BrakingOutcome::Failed(f) => failure_json(&f),
        BrakingOutcome::NotAtRest {
            rest_speed_m_per_s,
            rest_tilt_rad,
        } => json!({
            "rest_speed_m_per_s": rest_speed_m_per_s,
            "rest_tilt_deg": rest_tilt_rad.to_degrees(),
        }),
    };
    json!({
        "duration_s": run.duration_s,
        "outcome": run.outcome.label(),
        "success": run.outcome.is_success(),
        "detail": outcome,
        "limiting": limiting(run),
        "plan_peak_tilt_deg": run.plan_peak_tilt_rad.map(f64::to_degrees),
        "plan_cost_n2m2s": run.plan_cost_n2m2s,
        "peak_cone_utilisation": p.cone_utilisation,
        "min_normal_force_n": p.min_normal_force_n,
        "peak_actuator_utilisation": p.actuator_utilisation,
        "peak_tilt_deg": p.tilt_rad.to_degrees(),
        "peak_speed_error_m_per_s": p.speed_error_m_per_s,
        "slip_s": p.slip_s,
        "brake_start_s": run.brake_start_s,
    })
}

fn study_json(study: &BrakingStudy, planar_s: Option<f64>) -> Value {
    json!({
        "heading_deg": study.heading_deg,
        "descent": study.descent.iter().map(run_json).collect::<Vec<_>>(),
        "bisection": study.bisection.iter().map(run_json).collect::<Vec<_>>(),
        "shortest_success_s": study.shortest_success_s,
        "first_failure_s": study.first_failure_s,
        "limit_s": study.limit_s,
        "limit_failure_s": study.limit_failure_s,
        "planar_min_braking_time_s": planar_s,
    })
}

fn push_json(r: &PushRecovery) -> Value {
    let trial = |t: &PushTrial| {
        json!({
            "impulse_ns": t.impulse_ns,
            "outcome": t.outcome.label(),
            "failure": match t.outcome {
                crate::world::push::PushOutcome::Failed(f) => failure_json(&f),
                _ => Value::Null,
            },
            "peak_tilt_deg": t.peak_tilt_rad.to_degrees(),
            "peak_speed_m_per_s": t.peak_speed_m_per_s,
            "rest_speed_m_per_s": t.rest_speed_m_per_s,
        })
    };
    json!({
        "heading_deg": r.heading_deg,
        "largest_recovered_ns": r.largest_recovered_ns,
        "smallest_failing_ns": r.smallest_failing_ns,
        "trials": r.trials.iter().map(trial).collect::<Vec<_>>(),
    })
}

fn key(heading_deg: f64) -> String {
    format!("{heading_deg:.0}")
}

fn braking_figure(run: &BrakingRun, title: &str) -> TimeSeriesFigure {
    let failure = match run.outcome {
        BrakingOutcome::Failed(f) => Some(f),
        _ => None,
    };
    // A failure comes within tens of ms of the onset: zoom in on it.
    let from = run.brake_start_s - if failure.is_some() { 0.25 } else { 1.0 };
    let samples: Vec<_> = run.samples.iter().filter(|s| s.time_s >= from).collect();
    let t: Vec<f64> = samples
        .iter()
        .map(|s| s.time_s - run.brake_start_s)
        .collect();
    let col = |f: &dyn Fn(&crate::world::braking::BrakingSample) -> f64| -> Vec<f64> {
        samples.iter().map(|s| f(s)).collect()
    };
    let mut cone =
        Subplot::new("cone utilisation |F|/(μN)").with_legend(LegendPosition::UpperRight);
    for i in 0..3 {
        cone = cone.with(Series::new(
            &wheel_name(i),
            &t,
            &col(&|s| s.cone_utilisation[i]),
        ));
    }
    let fig = TimeSeriesFigure::new(title)
        .with(
            Subplot::new("speed along heading (m/s)")
                .with(
                    Series::new("command", &t, &col(&|s| s.command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("ball", &t, &col(&|s| s.speed_m_per_s)))
                .with_legend(LegendPosition::UpperRight),
        )
        .with(
            Subplot::new("tilt in plane of travel (deg)")
                .with(
                    Series::new("command", &t, &col(&|s| s.command_tilt_rad.to_degrees()))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("body", &t, &col(&|s| s.tilt_rad.to_degrees())))
                .with_legend(LegendPosition::UpperRight),
        )
        .with(cone);
    let end = t
        .last()
        .copied()
        .unwrap_or(run.duration_s)
        .min(run.duration_s);
    let fig = fig.shade(0.0, end, "braking");
    match failure {
        Some(f) => fig.marker(f.time_s - run.brake_start_s, &failure_kind_label(&f)),
        None => fig,
    }
}

fn push_figure(push: &[&PushRecovery]) -> TimeSeriesFigure {
    let mut fig = TimeSeriesFigure::new(
        "MiaPURE push recovery (3D world): tilt after a push at the body's COM",
    );
    for r in push {
        let mut sub = Subplot::new(&format!("tilt (deg), push {:.0}°", r.heading_deg))
            .with_legend(LegendPosition::UpperRight);
        let trials = [
            (r.largest_recovered(), "recovered"),
            (r.smallest_failing(), "not recovered"),
        ];
        for (trial, what) in trials {
            if let Some(tr) = trial {
                let t: Vec<f64> = tr.samples.iter().map(|s| s.time_s).collect();
                let v: Vec<f64> = tr.samples.iter().map(|s| s.tilt_rad.to_degrees()).collect();
                sub = sub.with(Series::new(
                    &format!("{:.1} N·s {what}", tr.impulse_ns),
                    &t,
                    &v,
                ));
            }
        }
        let limit = 15.0;
        sub = sub.with(
            Series::new("15° bound", &[-1.0, 4.0], &[limit, limit]).with_style(LineStyle::Dashed),
        );
        fig = fig.with(sub);
    }
    fig.marker(0.0, "push")
}

/// Flies a braking run again with its own trajectory (deterministic in the seed) and writes
/// it to `path` with [`WorldLogger`] (telemetry every `every` physics steps, controller,
/// commands, scene, failure, and an event when braking starts); checks that the replay is the
/// run.
fn log_braking(
    world: WorldParams,
    params: &BrakingParams,
    run: &BrakingRun,
    path: &Path,
    every: u32,
) -> anyhow::Result<()> {
    let Some(plan) = &run.plan else {
        return Ok(());
    };
    let options = WorldLogOptions {
        telemetry_every_steps: every,
        ..WorldLogOptions::default()
    };
    let mut log = WorldLogger::with_options(path, &world, options)
        .with_context(|| format!("cannot create {}", path.display()))?;
    let mut error = None;
    let mut braking = false;
    let replay = fly_braking(world, params, run.heading_deg, plan, &mut |sim, cmd| {
        if error.is_some() {
            return;
        }
        let time_s = sim.world().time_s();
        let mut result = log.record_core(sim);
        if let (Ok(()), Some(v)) = (&result, cmd) {
            result = log.record_command(time_s, v);
        }
        if result.is_ok() && !braking && cmd.is_none() {
            braking = true;
            let what = format!(
                "optimal braking from {:.2} m/s to rest in {:.3} s at {:.0} deg",
                params.cruise_speed_m_per_s, run.duration_s, run.heading_deg
            );
            let tilt = crate::world::failure::tilt_from_vertical_rad(sim.world().telemetry());
            result = log.record_event(time_s, "brake", &what, tilt);
        }
        if let Err(e) = result {
            error = Some(e);
        }
    })?;
    if let Some(e) = error {
        return Err(e).with_context(|| format!("cannot write {}", path.display()));
    }
    log.finish()
        .with_context(|| format!("cannot finish {}", path.display()))?;
    anyhow::ensure!(
        replay.telemetry_hash == run.telemetry_hash,
        "the logged braking run at T = {} s differs from the study's",
        run.duration_s
    );
    Ok(())
}

/// Runs a push trial again and writes it to `path` (see [`log_braking`]).
fn log_push(
    world: WorldParams,
    params: &PushParams,
    trial: &PushTrial,
    path: &Path,
    every: u32,
) -> anyhow::Result<()> {
    let options = WorldLogOptions {
        telemetry_every_steps: every,
        ..WorldLogOptions::default()
    };
    let mut log = WorldLogger::with_options(path, &world, options)
        .with_context(|| format!("cannot create {}", path.display()))?;
    let mut error = None;
    let mut pushed = false;
    let replay = push_trial_observed(
        world,
        params,
        trial.heading_deg,
        trial.impulse_ns,
        &mut |sim| {
            if error.is_some() {
                return;
            }
            let time_s = sim.world().time_s();
            let mut result = log.record_core(sim);
            if result.is_ok() && !pushed && time_s >= params.settle_s {
                pushed = true;
                let what = format!(
                    "push {:.2} N s at the body's COM towards {:.0} deg over {} s",
                    trial.impulse_ns, trial.heading_deg, params.push_duration_s
                );
                let tilt = crate::world::failure::tilt_from_vertical_rad(sim.world().telemetry());
                result = log.record_event(time_s, "push", &what, tilt);
            }
            if let Err(e) = result {
                error = Some(e);
            }
        },
    )?;
    if let Some(e) = error {
        return Err(e).with_context(|| format!("cannot write {}", path.display()));
    }
    log.finish()
        .with_context(|| format!("cannot finish {}", path.display()))?;
    anyhow::ensure!(
        replay.telemetry_hash == trial.telemetry_hash,
        "the logged push of {} N s differs from the study's",
        trial.impulse_ns
    );
    Ok(())
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_owned(), |x| format!("{x:.digits$}"))
}

/// The world braking and push experiments of `ballbot reproduce`: runs them, prints the
/// comparison tables, writes the figures to `out` (unless `no_plots`) and the MCAP logs
/// `out/logs/world_braking_success_h180.mcap`, `world_braking_failure_h180.mcap` (the
/// shortest success and the first failure of the descent at 180 deg) and
/// `world_push_h180.mcap` (the largest push recovered at 180 deg), and adds
/// `min_braking_time_3d_s`, `push_recovery_ns`, `world_braking` and `world_push` to
/// `summary`.
pub fn reproduce(
    out: &Path,
    no_plots: bool,
    quick: bool,
    summary: &mut Map<String, Value>,
) -> anyhow::Result<()> {
    let mut world = WorldParams::miapure_60kg();
    world.sensors.seed = SEED;
    let s = settings(quick);
    let estimate: u64 = s
        .jobs
        .iter()
        .map(|j| match j {
            Job::Braking { study, .. } => {
                study.durations_s.len().min(8) as u64
                    + if study.bisection_resolution_s.is_some() {
                        4
                    } else {
                        0
                    }
            }
            Job::Push { search, .. } => {
                1 + (search.upper_ns / search.resolution_ns)
                    .log2()
                    .ceil()
                    .max(0.0) as u64
            }
        })
        .sum();
    let bar = super::reproduce::progress_bar(estimate, "world");
    let results = run_jobs(world, &s, &bar)?;
    bar.finish_and_clear();

    // The planar model's minimum braking time under the same limits (trajopt bisection).
    let mut planar = Map::new();
    for &h in &s.planar_headings_deg {
        let problem = braking_problem(&world.robot, &s.braking, h, 2.0);
        let search = MinTimeOptions {
            resolution_secs: s.planar_resolution_s,
            ..MinTimeOptions::default()
        };
        let r = min_braking_time(&problem, &SolveOptions::default(), &search)?;
        planar.insert(key(h), json!(r.min_duration_secs));
    }
    let planar_at = |h: f64| planar.get(&key(h)).and_then(Value::as_f64);

    let mut headings = Map::new();
    let mut ablation = Value::Null;
    let shove_s = s.push.push_duration_s;
    let mut pushes: Vec<&PushRecovery> = Vec::new();
    let mut impulsive: Vec<&PushRecovery> = Vec::new();
    let mut studies: Vec<&BrakingStudy> = Vec::new();
    for r in &results {
        match r {
            JobResult::Braking(study, TrajectoryFeedforward::Full) => {
                headings.insert(
                    key(study.heading_deg),
                    study_json(study, planar_at(study.heading_deg)),
                );
                studies.push(study);
            }
            JobResult::Braking(study, TrajectoryFeedforward::Core) => {
                ablation = study_json(study, planar_at(study.heading_deg));
            }
            JobResult::Push(p, d) if *d == shove_s => pushes.push(p),
            JobResult::Push(p, _) => impulsive.push(p),
        }
    }
    let paper_heading = studies.iter().find(|st| st.heading_deg == 180.0);

    println!(
        "world braking (MiaPURE 60 kg, 1.4 m/s at heading h -> rest in T, optimal trajectories \
         under actuator, traction and 15 deg tilt limits, seed {SEED}):"
    );
    println!(
        "  {:>7} | {:>24} | {:>15} | {:>15} | {:>13} | what failed first",
        "heading", "shortest success (desc.)", "bisection limit", "first failure", "planar min T",
    );
    for st in &studies {
        let fail = st.first_failure().map_or_else(|| "-".to_owned(), limiting);
        println!(
            "  {:>6.0}° | {:>22} s | {:>13} s | {:>13} s | {:>11} s | {}",
            st.heading_deg,
            opt(st.shortest_success_s, 2),
            opt(st.limit_s, 3),
            opt(st.first_failure_s, 2),
            opt(planar_at(st.heading_deg), 3),
            fail
        );
    }
    println!(
        "  paper (hardware, 180°): shortest success {PAPER_MIN_BRAKING_TIME_S:.1} s \
         (descent from 5 s by 0.5 s)"
    );
    if let Some(a) = ablation.as_object() {
        println!(
            "  ablation, 180° with the equilibrium feedforward only (no c θ̈* term): shortest success \
             {} s, first failure {} s",
            opt(a.get("shortest_success_s").and_then(Value::as_f64), 2),
            opt(a.get("first_failure_s").and_then(Value::as_f64), 2)
        );
    }
    println!(
        "push recovery (standing; impulse at the body's COM as a {shove_s} s force pulse, and in \
         one step; recovered: tilt < 15°, at rest < 0.1 m/s within 3 s):"
    );
    println!(
        "  {:>9} | {:>8} | {:>19} | {:>17} | failing trial",
        "direction", "push", "largest recovered", "smallest failing"
    );
    let rows = pushes
        .iter()
        .map(|p| (p, format!("{shove_s} s")))
        .chain(impulsive.iter().map(|p| (p, "1 step".to_owned())));
    for (p, kind) in rows {
        let how = p.smallest_failing().map_or_else(
            || "-".to_owned(),
            |t| match t.outcome {
                crate::world::push::PushOutcome::Failed(f) => failure_label(&f),
                o => format!(
                    "{} (peak tilt {:.1}°)",
                    o.label(),
                    t.peak_tilt_rad.to_degrees()
                ),
            },
        );
        println!(
            "  {:>8.0}° | {:>8} | {:>15.1} N·s | {:>13} N·s | {}",
            p.heading_deg,
            kind,
            p.largest_recovered_ns,
            opt(p.smallest_failing_ns, 1),
            how
        );
    }
    println!("  paper: not measured (MiaPURE was only pushed gently to steer it, pHRI demo)");

    if !no_plots {
        if let Some(st) = paper_heading {
            if let Some(run) = st.shortest_success() {
                braking_figure(
                    run,
                    &format!(
                        "MiaPURE braking 1.4 m/s → rest at 180° in T = {:.1} s (shortest success, 3D world)",
                        run.duration_s
                    ),
                )
                .save_svg_and_png(&out.join("world_braking_success"))?;
            }
            if let Some(run) = st.first_failure().filter(|r| !r.samples.is_empty()) {
                braking_figure(
                    run,
                    &format!(
                        "MiaPURE braking at 180° in T = {:.1} s (first failure: {})",
                        run.duration_s,
                        match run.outcome {
                            BrakingOutcome::Failed(f) => failure_kind_label(&f),
                            o => o.label().to_owned(),
                        }
                    ),
                )
                .save_svg_and_png(&out.join("world_braking_failure"))?;
            }
        }
        if !pushes.is_empty() {
            push_figure(&pushes).save_svg_and_png(&out.join("world_push"))?;
        }
    }

    // One MCAP log per experiment (telemetry at 1 kHz; 100 Hz with --quick).
    let logs = out.join("logs");
    std::fs::create_dir_all(&logs).with_context(|| format!("cannot create {}", logs.display()))?;
    let every = if quick { 80 } else { 8 };
    let success = paper_heading.and_then(|st| st.shortest_success());
    let failure = paper_heading.and_then(|st| st.first_failure());
    let push_180 = pushes
        .iter()
        .find(|p| p.heading_deg == 180.0)
        .and_then(|p| p.largest_recovered());
    // The replays are independent: one thread each.
    std::thread::scope(|scope| -> anyhow::Result<()> {
        let mut handles = Vec::new();
        for (run, name) in [
            (success, "world_braking_success_h180.mcap"),
            (failure, "world_braking_failure_h180.mcap"),
        ] {
            if let Some(run) = run {
                let (path, braking) = (logs.join(name), &s.braking);
                handles.push(scope.spawn(move || log_braking(world, braking, run, &path, every)));
            }
        }
        if let Some(trial) = push_180 {
            let (path, push) = (logs.join("world_push_h180.mcap"), &s.push);
            handles.push(scope.spawn(move || log_push(world, push, trial, &path, every)));
        }
        for h in handles {
            h.join()
                .map_err(|_| anyhow::anyhow!("a log replay thread panicked"))??;
        }
        Ok(())
    })?;

    let b = &s.braking;
    summary.insert(
        "min_braking_time_3d_s".to_owned(),
        json!(paper_heading.and_then(|st| st.shortest_success_s)),
    );
    let mut push_map = Map::new();
    for p in &pushes {
        push_map.insert(key(p.heading_deg), json!(p.largest_recovered_ns));
    }
    summary.insert("push_recovery_ns".to_owned(), Value::Object(push_map));
    summary.insert(
        "world_braking".to_owned(),
        json!({
            "paper_min_braking_time_s": PAPER_MIN_BRAKING_TIME_S,
            "seed": SEED,
            "protocol": {
                "cruise_speed_m_per_s": b.cruise_speed_m_per_s,
                "approach_accel_m_per_s2": b.approach_accel_m_per_s2,
                "approach_jerk_m_per_s3": b.approach_jerk_m_per_s3,
                "cruise_s": b.cruise_s,
                "rest_within_s": b.rest_within_s,
                "rest_hold_s": b.rest_hold_s,
                "rest_speed_m_per_s": b.rest_speed_m_per_s,
                "rest_tilt_deg": b.rest_tilt_rad.to_degrees(),
                "trajectory_tilt_limit_deg": b.trajectory_tilt_limit_rad.to_degrees(),
                "trajectory_limits": "actuators (peak torque, torque-speed line) and traction mu N at all three omniwheels, tilt bound; tau = 0 at both ends",
                "feedforward": b.feedforward.label(),
            },
            "headings": headings,
            "ablation_core_feedforward_180": ablation,
            "planar_min_braking_time_s": planar,
        }),
    );
    let pp = &s.push;
    summary.insert(
        "world_push".to_owned(),
        json!({
            "seed": SEED,
            "protocol": {
                "settle_s": pp.settle_s,
                "observe_s": pp.observe_s,
                "max_tilt_deg": pp.max_tilt_rad.to_degrees(),
                "rest_within_s": pp.rest_within_s,
                "rest_speed_m_per_s": pp.rest_speed_m_per_s,
                "rest_tilt_deg": pp.rest_tilt_rad.to_degrees(),
                "push_duration_s": pp.push_duration_s,
            },
            "headings": pushes.iter().map(|p| (key(p.heading_deg), push_json(p))).collect::<Map<_, _>>(),
            "impulsive": impulsive.iter().map(|p| (key(p.heading_deg), push_json(p))).collect::<Map<_, _>>(),
        }),
    );
    Ok(())
}
