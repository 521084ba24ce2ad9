//! The traction study as a type on the experiment driver ([`crate::studies::driver`]): per
//! heading a failing-acceleration search with traction-aware control off (the maximum-speed
//! study's search, [`MaxSpeedExperiment`]), and one trial per other run: ramps on, stops,
//! patch crossings, rider runs. The second phase is the same type over other jobs
//! ([`TractionExperiment::phase_two`]).

use super::probe::RunRecord;
use super::runs::{
    Control, PatchCrossing, cross_patch_observed, ramp_observed, rider_lean_observed,
    stop_from_cruise_observed,
};
use super::settings::{PatchVariant, TractionStudySettings};
use crate::studies::driver::{Bisection, JobRecord, Study};
use crate::studies::max_speed::{
    FailingAccel, MaxSpeedExperiment, MaxSpeedJob, RampTrial, Variant,
};
use ballbot_core::BallbotParams;
use ballbot_core::traction::{TractionEnvelope, TractionParams};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{WorldError, WorldParams};

/// Cruise speed of the stops (m/s).
const STOP_SPEED_M_PER_S: f64 = 1.4;

/// One job of the traction study.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TractionJob {
    /// Traction-aware control off: the failing-acceleration search at a heading (the
    /// protocol's grid bisection, [`crate::studies::max_speed::MaxSpeedProtocol::accel_search`],
    /// sensor seed [`TractionStudySettings::seed`]).
    Search {
        /// Heading (deg).
        heading_deg: f64,
    },
    /// Traction-aware control on: one ramp of the search's protocol at an acceleration.
    RampOn {
        /// Heading (deg).
        heading_deg: f64,
        /// The ramp's acceleration (m/s^2).
        accel_m_per_s2: f64,
        /// Seed of the sensor noise.
        seed: u64,
    },
    /// A stop from 1.4 m/s after 4 s of cruise (rest below 0.05 m/s, at most 6 s).
    Stop {
        /// Heading of travel (deg).
        heading_deg: f64,
        /// Controller.
        control: Control,
    },
    /// A friction patch crossed towards OW1 (0 deg).
    Patch {
        /// Which patch.
        variant: PatchVariant,
        /// Controller.
        control: Control,
    },
    /// A rider's lean.
    Rider {
        /// Direction of the lean (deg).
        heading_deg: f64,
        /// Controller.
        control: Control,
    },
}

/// One run of a job without a search: what it measured, and what the run adds.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionRun {
    /// What the run measured (with its samples).
    pub record: RunRecord,
    /// When the ball was on the patch (patch crossings only).
    pub on_patch: Option<PatchCrossing>,
    /// Time from the stop command to rest (s) (stops only, when reached).
    pub stop_secs: Option<f64>,
}

/// One world run of the study.
#[derive(Clone, Debug, PartialEq)]
pub enum TractionTrial {
    /// A ramp of a failing-acceleration search (traction-aware control off).
    Search(RampTrial),
    /// Any other run.
    Run(TractionRun),
}

/// The traction study's jobs on the default world of a robot.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionExperiment {
    /// The robot's default world, sensor seed [`TractionStudySettings::seed`].
    pub params: WorldParams,
    /// What the study runs.
    pub settings: TractionStudySettings,
    /// The jobs, the searches (the longest) first.
    pub jobs: Vec<TractionJob>,
}

impl TractionExperiment {
    /// The study's first phase on the default world of `robot`: per heading a search, the
    /// ramps on at the search's top request (each seed), the stops, the patch crossings and
    /// the rider runs, in that order.
    pub fn phase_one(robot: BallbotParams<f64>, settings: &TractionStudySettings) -> Self {
        let mut params = WorldParams::with_robot(robot);
        params.sensors.seed = settings.seed;
        Self {
            params,
            settings: settings.clone(),
            jobs: phase_one_jobs(settings),
        }
    }

    /// The second phase: traction-aware control on at exactly the acceleration that failed
    /// off, for each search in `failing` that found one, in their order.
    pub fn phase_two(&self, failing: &[FailingAccel]) -> Self {
        let jobs = failing
            .iter()
            .filter_map(|f| {
                Some(TractionJob::RampOn {
                    heading_deg: f.heading_deg,
                    accel_m_per_s2: f.smallest_failing_m_per_s2?,
                    seed: self.settings.seed,
                })
            })
            .collect();
        Self {
            jobs,
            ..self.clone()
        }
    }

    /// The maximum-speed study whose search job this study's searches run.
    fn search_study(&self) -> MaxSpeedExperiment {
        MaxSpeedExperiment {
            params: self.params,
            protocol: self.settings.protocol,
            jobs: Vec::new(),
        }
    }

    /// The search job of the maximum-speed study at `heading_deg`.
    fn search_job(&self, heading_deg: f64) -> MaxSpeedJob {
        MaxSpeedJob::Search {
            variant: Variant::Nominal,
            heading_deg,
            seed: self.settings.seed,
        }
    }

    /// The run of a job without a search, each step shown to `observe`.
    fn run(
        &self,
        job: &TractionJob,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<TractionRun, WorldError> {
        let params = self.params;
        let s = &self.settings;
        let caps = &s.protocol.shaper;
        let plain = |record| TractionRun {
            record,
            on_patch: None,
            stop_secs: None,
        };
        Ok(match *job {
            // A search's trials are the maximum-speed study's ramps (`Study::trial`).
            TractionJob::Search { .. } => return Err(wrong_kind()),
            TractionJob::RampOn {
                heading_deg,
                accel_m_per_s2,
                seed,
            } => {
                let config = Control::TractionOn.config(&params, caps)?;
                let mut p = params;
                p.sensors.seed = seed;
                let top = s.protocol.fast_top_m_per_s;
                plain(ramp_observed(
                    p,
                    config,
                    heading_deg,
                    accel_m_per_s2,
                    top,
                    observe,
                )?)
            }
            TractionJob::Stop {
                heading_deg,
                control,
            } => {
                let config = control.config(&params, caps)?;
                let (record, stop_secs) = stop_from_cruise_observed(
                    params,
                    config,
                    heading_deg,
                    STOP_SPEED_M_PER_S,
                    4.0,
                    0.05,
                    6.0,
                    observe,
                )?;
                TractionRun {
                    record,
                    on_patch: None,
                    stop_secs,
                }
            }
            TractionJob::Patch { variant, control } => self.patch(variant, control, observe)?,
            TractionJob::Rider {
                heading_deg,
                control,
            } => {
                let config = control.config(&params, caps)?;
                plain(rider_lean_observed(
                    params,
                    config,
                    s.rider,
                    heading_deg,
                    s.rider_lean_rad,
                    3.0,
                    3.0,
                    observe,
                )?)
            }
        })
    }

    /// A patch crossing towards OW1. Cruising: the shipped acceleration, then 1 s at 1.4 m/s
    /// before the patch. Accelerating: at the envelope's acceleration towards OW1 for both
    /// controllers (on, the envelope holds any request to it; off, the ramp asks for exactly
    /// it).
    fn patch(
        &self,
        variant: PatchVariant,
        control: Control,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<TractionRun, WorldError> {
        let params = self.params;
        let config = control.config(&params, &self.settings.protocol.shaper)?;
        let (accel, lead, top) = if variant.cruising() {
            (1.0, 1.0, 1.4)
        } else {
            let envelope =
                TractionEnvelope::new(&params.robot, &TractionParams::recommended(&params.robot))?;
            (envelope.friction_limit_m_per_s2(1.0, 0.0), 0.0, 2.0)
        };
        let (record, on_patch) = cross_patch_observed(
            params,
            config,
            0.0,
            accel,
            top,
            1.4,
            lead,
            &variant.patch(),
            1.0,
            observe,
        )?;
        Ok(TractionRun {
            record,
            on_patch,
            stop_secs: None,
        })
    }
}

/// The first phase's jobs (see [`TractionExperiment::phase_one`]).
pub(super) fn phase_one_jobs(s: &TractionStudySettings) -> Vec<TractionJob> {
    let top = s.protocol.accel_bracket_m_per_s2[1];
    let mut jobs: Vec<TractionJob> = s
        .headings_deg
        .iter()
        .map(|&heading_deg| TractionJob::Search { heading_deg })
        .collect();
    for &seed in std::iter::once(&s.seed).chain(&s.extra_on_seeds) {
        jobs.extend(
            s.headings_deg
                .iter()
                .map(|&heading_deg| TractionJob::RampOn {
                    heading_deg,
                    accel_m_per_s2: top,
                    seed,
                }),
        );
    }
    for &heading_deg in &s.stop_headings_deg {
        jobs.extend(s.stop_controls.iter().map(|&control| TractionJob::Stop {
            heading_deg,
            control,
        }));
    }
    for &variant in &s.patch_variants {
        jobs.extend(
            s.controls
                .iter()
                .map(|&control| TractionJob::Patch { variant, control }),
        );
    }
    for &heading_deg in &s.rider_headings_deg {
        jobs.extend(s.controls.iter().map(|&control| TractionJob::Rider {
            heading_deg,
            control,
        }));
    }
    jobs
}

impl Study for TractionExperiment {
    type Job = TractionJob;
    type Trial = TractionTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<TractionJob> {
        self.jobs.clone()
    }

    fn bisection(&self, job: &TractionJob) -> Option<Bisection> {
        matches!(job, TractionJob::Search { .. }).then(|| self.settings.protocol.accel_search())
    }

    /// A search's trial is the maximum-speed study's search ramp at `value` (the same run as
    /// [`crate::studies::max_speed::failing_acceleration`]'s); any other job's is its run.
    fn trial(
        &self,
        job: &TractionJob,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<TractionTrial, WorldError> {
        match *job {
            TractionJob::Search { heading_deg } => {
                let search = self.search_job(heading_deg);
                let trial = self.search_study().trial(&search, value, observe)?;
                Ok(TractionTrial::Search(trial))
            }
            _ => Ok(TractionTrial::Run(self.run(job, observe)?)),
        }
    }

    /// A search ramp passes when it survived; any other run when the world did not fail.
    fn passed(&self, trial: &TractionTrial) -> bool {
        match trial {
            TractionTrial::Search(t) => self.search_study().passed(t),
            TractionTrial::Run(r) => r.record.failure.is_none(),
        }
    }

    fn describe(&self, job: &TractionJob, value: Option<f64>, trial: &TractionTrial) -> String {
        let end = if self.passed(trial) {
            "survived"
        } else {
            "failed"
        };
        let what = match *job {
            TractionJob::Search { heading_deg } => {
                let accel = value.map_or(String::new(), |a| format!(" {a:.2} m/s^2"));
                format!("off: accel search {heading_deg} deg{accel}")
            }
            TractionJob::RampOn {
                heading_deg,
                accel_m_per_s2,
                seed,
            } => format!("on: ramp {heading_deg} deg {accel_m_per_s2:.2} m/s^2 seed {seed}"),
            TractionJob::Stop {
                heading_deg,
                control,
            } => format!("{}: stop {heading_deg} deg", control.as_str()),
            TractionJob::Patch { variant, control } => {
                format!("{}: patch {}", control.as_str(), variant.as_str())
            }
            TractionJob::Rider {
                heading_deg,
                control,
            } => format!("{}: rider {heading_deg} deg", control.as_str()),
        };
        format!("traction {what}: {end}")
    }
}

/// The error of a record whose trials are not of its job's kind (a search's ramps, or one
/// run); the driver never makes one.
fn wrong_kind() -> WorldError {
    WorldError::InvalidParameter {
        field: "traction",
        requirement: "internal: a job's trials are not of its kind",
    }
}

/// A search job's record as its result ([`FailingAccel::from_record`]: the bracket's ends and
/// the trials at them).
pub fn search_result(
    heading_deg: f64,
    record: JobRecord<TractionTrial>,
) -> Result<FailingAccel, WorldError> {
    let trials = record
        .trials
        .into_iter()
        .map(|(value, trial)| match trial {
            TractionTrial::Search(t) => Ok((value, t)),
            TractionTrial::Run(_) => Err(wrong_kind()),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let record = JobRecord {
        index: record.index,
        trials,
        scanned: record.scanned,
        bracket: record.bracket,
    };
    Ok(FailingAccel::from_record(heading_deg, record))
}

/// The one run of a job without a search.
pub fn single_run(mut record: JobRecord<TractionTrial>) -> Result<TractionRun, WorldError> {
    match record.trials.pop() {
        Some((None, TractionTrial::Run(run))) if record.trials.is_empty() => Ok(run),
        _ => Err(wrong_kind()),
    }
}

/// World runs the study of `robot` with `settings` takes at most (a progress bar's length;
/// [`super::run_study`] reports each): the first phase's ([`Study::runs_estimate`] of each
/// job: a search's ends and halvings, one per other job), and one ramp per heading in the
/// second.
pub fn runs_estimate(robot: BallbotParams<f64>, settings: &TractionStudySettings) -> u64 {
    let first = TractionExperiment::phase_one(robot, settings);
    let one: u64 = first.jobs.iter().map(|j| first.runs_estimate(j)).sum();
    one + settings.headings_deg.len() as u64
}
