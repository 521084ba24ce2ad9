//! The whole maximum-speed study: its jobs run on the experiment driver
//! ([`MaxSpeedExperiment`]) and assembled into trials, the capability map and the sensitivity
//! rows.

use super::bisection::FailingAccel;
use super::experiment::{MaxSpeedExperiment, RampTrial};
use super::jobs::{MaxSpeedJob as Job, job_eq, jobs, normalise, same};
use super::protocol::MaxSpeedStudySettings;
use super::trial::{HeadingTrials, TrialOutcome, controller};
use super::variant::Variant;
use crate::studies::driver::{self, JobRecord};
use crate::studies::ramp::RampResult;
use ballbot_world::world::{WorldError, WorldParams};

/// One heading of the capability map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapPoint {
    /// Heading (deg).
    pub heading_deg: f64,
    /// The slow ramp with the first seed.
    pub slow: TrialOutcome,
    /// The failing-acceleration search.
    pub failing: FailingAccel,
}

/// One row of the sensitivity table: a parameter value at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct SensitivityRow {
    /// The parameter varied.
    pub parameter: &'static str,
    /// Its value (mu dimensionless, COM height in m).
    pub value: f64,
    /// The robot variant this row ran.
    pub variant: Variant,
    /// Heading (deg).
    pub heading_deg: f64,
    /// The slow ramp with the first seed.
    pub slow: TrialOutcome,
    /// The failing-acceleration search.
    pub failing: FailingAccel,
}

/// Everything the study measured.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxSpeedStudy {
    /// The settings it ran with.
    pub settings: MaxSpeedStudySettings,
    /// The nominal world parameters.
    pub params: WorldParams,
    /// Seeded slow-ramp trials per heading.
    pub trials: Vec<HeadingTrials>,
    /// The capability map.
    pub map: Vec<MapPoint>,
    /// The sensitivity rows (nominal values included).
    pub sensitivity: Vec<SensitivityRow>,
    /// The command shaper's jerk limit the study kept (m/s^3, the core's default).
    pub jerk_limit_m_per_s3: f64,
}

impl MaxSpeedStudy {
    /// The steepest acceleration (m/s^2) the jerk-limited shaper commands on a ramp to the
    /// search's top speed `v`: `sqrt(j v)`. Searched accelerations above it give the same
    /// command, so a search whose bracket top survives is censored at this value in effect.
    pub fn command_accel_ceiling_m_per_s2(&self) -> f64 {
        (self.jerk_limit_m_per_s3 * self.settings.protocol.fast_top_m_per_s).sqrt()
    }
}

/// Runs the study on `params` (the nominal robot) on the experiment driver
/// ([`MaxSpeedExperiment`]). `progress` is called after every ramp with a short description
/// (from worker threads); [`super::job_count`] bounds how many there are.
///
/// The failing-acceleration searches use sensor seed 0 (one search per heading: the grid's
/// resolution, not the noise, dominates their spread).
pub fn run_study(
    params: WorldParams,
    settings: &MaxSpeedStudySettings,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<MaxSpeedStudy, WorldError> {
    settings.validate()?;
    params.validate()?;
    let experiment = MaxSpeedExperiment {
        params,
        protocol: settings.protocol,
        jobs: jobs(&params, settings),
    };
    let records = driver::execute(&experiment, settings.threads, progress)?;
    let done = experiment
        .jobs
        .iter()
        .copied()
        .zip(records)
        .map(|(job, record)| Ok((job, JobResult::of(job, record)?)))
        .collect::<Result<Vec<_>, WorldError>>()?;
    assemble(params, settings, &done)
}

/// A job's record as the study assembles it.
enum JobResult {
    Slow(RampResult, TrialOutcome),
    Search(FailingAccel),
}

impl JobResult {
    fn of(job: Job, mut record: JobRecord<RampTrial>) -> Result<Self, WorldError> {
        Ok(match job {
            Job::Search { heading_deg, .. } => {
                Self::Search(FailingAccel::from_record(heading_deg, record))
            }
            // The driver runs exactly one trial for a job without a bisection.
            Job::Slow { .. } => {
                let (_, t) = record.trials.pop().ok_or_else(missing)?;
                Self::Slow(t.run, t.outcome)
            }
        })
    }
}

fn missing() -> WorldError {
    WorldError::InvalidParameter {
        field: "settings",
        requirement: "internal: a job's result is missing",
    }
}

fn assemble(
    params: WorldParams,
    settings: &MaxSpeedStudySettings,
    done: &[(Job, JobResult)],
) -> Result<MaxSpeedStudy, WorldError> {
    let first_seed = settings.seeds.first().copied().unwrap_or(0);
    let slow = |variant: Variant, heading_deg: f64, seed: u64| {
        let want = Job::Slow {
            variant: normalise(variant, &params),
            heading_deg,
            seed,
        };
        done.iter().find_map(|(j, r)| match r {
            JobResult::Slow(run, o) if job_eq(j, &want) => Some((run, o.clone())),
            _ => None,
        })
    };
    let search = |variant: Variant, heading_deg: f64| {
        let want = Job::Search {
            variant: normalise(variant, &params),
            heading_deg,
            seed: 0,
        };
        done.iter().find_map(|(j, r)| match r {
            JobResult::Search(f) if job_eq(j, &want) => Some(f.clone()),
            _ => None,
        })
    };
    let mut trials = Vec::new();
    for &h in &settings.trial_headings_deg {
        let mut outcomes = Vec::new();
        let mut first_run = None;
        for &seed in &settings.seeds {
            let (run, o) = slow(Variant::Nominal, h, seed).ok_or_else(missing)?;
            if first_run.is_none() {
                first_run = Some(run.clone());
            }
            outcomes.push(o);
        }
        trials.push(HeadingTrials {
            heading_deg: h,
            trials: outcomes,
            first_run: first_run.ok_or_else(missing)?,
        });
    }
    let mut map = Vec::new();
    for &h in &settings.map_headings_deg {
        map.push(MapPoint {
            heading_deg: h,
            slow: slow(Variant::Nominal, h, first_seed).ok_or_else(missing)?.1,
            failing: search(Variant::Nominal, h).ok_or_else(missing)?,
        });
    }
    let mut sensitivity = Vec::new();
    let mu0 = params.robot.drivetrain.wheel_ball_friction;
    let l0 = params.robot.sagittal.com_height_m;
    let mut mus = settings.sensitivity_wheel_ball_friction.clone();
    let mut ls = settings.sensitivity_com_height_m.clone();
    if !mus.iter().any(|&m| same(m, mu0)) && !mus.is_empty() {
        mus.push(mu0);
    }
    if !ls.iter().any(|&l| same(l, l0)) && !ls.is_empty() {
        ls.push(l0);
    }
    mus.sort_by(f64::total_cmp);
    ls.sort_by(f64::total_cmp);
    let rows = mus
        .iter()
        .map(|&mu| ("wheel_ball_friction", mu, Variant::WheelBallFriction(mu)))
        .chain(
            ls.iter()
                .map(|&l| ("com_height_m", l, Variant::ComHeight(l))),
        );
    for (parameter, value, variant) in rows {
        for &h in &settings.sensitivity_headings_deg {
            sensitivity.push(SensitivityRow {
                parameter,
                value,
                variant,
                heading_deg: h,
                slow: slow(variant, h, first_seed).ok_or_else(missing)?.1,
                failing: search(variant, h).ok_or_else(missing)?,
            });
        }
    }
    let jerk_limit_m_per_s3 = controller(&params, &settings.protocol)?
        .shaping
        .translation
        .max_jerk_per_s2;
    Ok(MaxSpeedStudy {
        settings: settings.clone(),
        params,
        trials,
        map,
        sensitivity,
        jerk_limit_m_per_s3,
    })
}

impl MaxSpeedStudy {
    /// The failing-acceleration search at `heading_deg` (from the map), if it ran.
    pub fn failing_at(&self, heading_deg: f64) -> Option<&FailingAccel> {
        self.map
            .iter()
            .find(|m| same(m.heading_deg, heading_deg))
            .map(|m| &m.failing)
    }
}
