//! The whole traction study on the experiment driver ([`TractionExperiment`]), assembled
//! from its records (see the [module](super) docs).

use super::experiment::{
    TractionExperiment, TractionJob, TractionTrial, phase_one_jobs, search_result, single_run,
};
use super::probe::RunRecord;
use super::runs::{Control, PatchCrossing};
use super::settings::{PatchVariant, TractionStudySettings};
use crate::studies::driver::{self, JobRecord};
use crate::studies::max_speed::FailingAccel;
use ballbot_core::BallbotParams;
use ballbot_core::traction::{TractionEnvelope, TractionParams};
use ballbot_world::world::{WorldError, WorldParams};

/// One heading of the failing-acceleration comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadingResult {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Traction control off: the failing-acceleration search.
    pub off: FailingAccel,
    /// On: the ramp at the search's top request.
    pub on_top: RunRecord,
    /// On: the same ramp with [`TractionStudySettings::extra_on_seeds`] (without samples), in
    /// their order.
    pub on_top_other_seeds: Vec<RunRecord>,
    /// On: the ramp at the acceleration that failed off (if one did).
    pub on_at_off_failing: Option<RunRecord>,
    /// The controller's envelope at this heading (m/s^2; friction and lift-off, recommended
    /// margins).
    pub envelope_m_per_s2: f64,
    /// The plain quasi-static limit (safety factor 1) (m/s^2).
    pub quasi_static_m_per_s2: f64,
}

/// A stop from 1.4 m/s.
#[derive(Clone, Debug, PartialEq)]
pub struct StopResult {
    /// Heading of travel (deg).
    pub heading_deg: f64,
    /// Controller.
    pub control: Control,
    /// The run (without its samples).
    pub record: RunRecord,
    /// Time from the stop command to below 0.05 m/s (s), if reached.
    pub stop_secs: Option<f64>,
}

/// A patch crossing.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchResult {
    /// Which patch.
    pub variant: PatchVariant,
    /// Controller.
    pub control: Control,
    /// The run.
    pub record: RunRecord,
    /// When the ball was on the patch.
    pub on_patch: Option<PatchCrossing>,
}

impl PatchResult {
    /// Whether the body stayed within the world's fall limit `fall_tilt_rad` through the
    /// crossing (a slip failure of the world does not end the run).
    pub fn stayed_up(&self, fall_tilt_rad: f64) -> bool {
        self.record.max_tilt_rad <= fall_tilt_rad
    }

    /// Time from the world's first wheel slip to the monitor's first flag (ms), when both
    /// happened.
    pub fn detection_latency_ms(&self) -> Option<f64> {
        let r = &self.record;
        Some((r.first_detection_secs? - r.first_world_slip_secs?) * 1e3)
    }
}

/// A rider's lean.
#[derive(Clone, Debug, PartialEq)]
pub struct RiderResult {
    /// Direction of the lean (deg).
    pub heading_deg: f64,
    /// Controller.
    pub control: Control,
    /// The run (without its samples).
    pub record: RunRecord,
}

/// The study's results.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionStudy {
    /// The settings it ran with.
    pub settings: TractionStudySettings,
    /// The robot.
    pub robot: BallbotParams<f64>,
    /// Per heading.
    pub headings: Vec<HeadingResult>,
    /// Stops.
    pub stops: Vec<StopResult>,
    /// Patch crossings.
    pub patches: Vec<PatchResult>,
    /// Rider runs.
    pub riders: Vec<RiderResult>,
}

/// Jobs of the study's first phase plus one per heading (the second phase's at most); the
/// world runs they take are bounded by [`super::runs_estimate`].
pub fn job_count(settings: &TractionStudySettings) -> usize {
    phase_one_jobs(settings).len() + settings.headings_deg.len()
}

/// Runs the study on the default world of `robot` on the experiment driver
/// ([`TractionExperiment`]: the first phase, then the second over the accelerations that failed
/// off); `progress(what)` after each world run (a search's ramps included, from worker
/// threads), at most [`super::runs_estimate`] times.
pub fn run_study(
    robot: BallbotParams<f64>,
    settings: &TractionStudySettings,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<TractionStudy, WorldError> {
    settings.protocol.validate()?;
    let first = TractionExperiment::phase_one(robot, settings);
    let records = driver::execute(&first, settings.threads, progress)?;
    let one = PhaseOne::of(settings, &first.jobs, records)?;
    // Phase two: traction control on at exactly the ramp that failed off.
    let second = first.phase_two(&one.failing);
    let second_runs = driver::execute(&second, settings.threads, progress)?
        .into_iter()
        .map(single_run)
        .collect::<Result<Vec<_>, _>>()?;
    let at_off_failing: Vec<(f64, RunRecord)> = second
        .jobs
        .iter()
        .zip(second_runs)
        .filter_map(|(job, run)| match *job {
            TractionJob::RampOn { heading_deg, .. } => Some((heading_deg, run.record)),
            _ => None,
        })
        .collect();
    let PhaseOne {
        failing,
        ramps_on,
        ramps_other,
        stops,
        patches,
        riders,
    } = one;
    let headings = heading_results(
        &robot,
        settings,
        failing,
        ramps_on,
        &ramps_other,
        &at_off_failing,
    )?;
    Ok(TractionStudy {
        settings: settings.clone(),
        robot,
        headings,
        stops,
        patches,
        riders,
    })
}

/// The first phase's records, sorted by kind (each in job order).
struct PhaseOne {
    failing: Vec<FailingAccel>,
    /// The ramps on at the top request with the settings' seed (with samples).
    ramps_on: Vec<RunRecord>,
    /// The same with the extra seeds (seed-major, without samples).
    ramps_other: Vec<RunRecord>,
    stops: Vec<StopResult>,
    patches: Vec<PatchResult>,
    riders: Vec<RiderResult>,
}

impl PhaseOne {
    fn of(
        settings: &TractionStudySettings,
        jobs: &[TractionJob],
        records: Vec<JobRecord<TractionTrial>>,
    ) -> Result<Self, WorldError> {
        let mut one = Self {
            failing: Vec::new(),
            ramps_on: Vec::new(),
            ramps_other: Vec::new(),
            stops: Vec::new(),
            patches: Vec::new(),
            riders: Vec::new(),
        };
        for (job, record) in jobs.iter().zip(records) {
            match *job {
                TractionJob::Search { heading_deg } => {
                    one.failing.push(search_result(heading_deg, record)?);
                }
                TractionJob::RampOn { seed, .. } => {
                    let r = single_run(record)?.record;
                    if seed == settings.seed {
                        one.ramps_on.push(r);
                    } else {
                        one.ramps_other.push(without_samples(r));
                    }
                }
                TractionJob::Stop {
                    heading_deg,
                    control,
                } => {
                    let run = single_run(record)?;
                    one.stops.push(StopResult {
                        heading_deg,
                        control,
                        record: without_samples(run.record),
                        stop_secs: run.stop_secs,
                    });
                }
                TractionJob::Patch { variant, control } => {
                    let run = single_run(record)?;
                    one.patches.push(PatchResult {
                        variant,
                        control,
                        record: run.record,
                        on_patch: run.on_patch,
                    });
                }
                TractionJob::Rider {
                    heading_deg,
                    control,
                } => one.riders.push(RiderResult {
                    heading_deg,
                    control,
                    record: without_samples(single_run(record)?.record),
                }),
            }
        }
        Ok(one)
    }
}

/// Per heading: the search, the ramps on at its top (the extra seeds' in seed-major order),
/// the ramp on at the acceleration that failed off (`at_off_failing`: heading, run) and the
/// envelope.
fn heading_results(
    robot: &BallbotParams<f64>,
    settings: &TractionStudySettings,
    failing: Vec<FailingAccel>,
    ramps_on: Vec<RunRecord>,
    ramps_other: &[RunRecord],
    at_off_failing: &[(f64, RunRecord)],
) -> Result<Vec<HeadingResult>, WorldError> {
    let recommended = TractionParams::recommended(robot);
    let planned = TractionEnvelope::new(robot, &recommended)?;
    let exact = TractionEnvelope::new(
        robot,
        &TractionParams {
            friction_safety_factor: 1.0,
            ..recommended
        },
    )?;
    let n = settings.headings_deg.len();
    let headings = failing
        .into_iter()
        .zip(ramps_on)
        .enumerate()
        .map(|(i, (off, on_top))| {
            let on_top_other_seeds = (0..settings.extra_on_seeds.len())
                .filter_map(|k| ramps_other.get(k * n + i).cloned())
                .collect();
            let h = off.heading_deg.to_radians();
            let (dx, dy) = (h.cos(), h.sin());
            let on_at_off_failing = at_off_failing
                .iter()
                .find(|(hd, _)| *hd == off.heading_deg)
                .map(|(_, r)| without_samples(r.clone()));
            HeadingResult {
                heading_deg: off.heading_deg,
                on_at_off_failing,
                envelope_m_per_s2: planned.friction_limit_m_per_s2(dx, dy),
                quasi_static_m_per_s2: exact.friction_limit_m_per_s2(dx, dy),
                off,
                on_top,
                on_top_other_seeds,
            }
        })
        .collect();
    Ok(headings)
}

impl TractionStudy {
    /// The world's fall limit: tilt from the vertical (rad).
    pub fn fall_tilt_rad(&self) -> f64 {
        WorldParams::with_robot(self.robot).failure.max_tilt_rad
    }
}

fn without_samples(mut r: RunRecord) -> RunRecord {
    r.samples = Vec::new();
    r
}
