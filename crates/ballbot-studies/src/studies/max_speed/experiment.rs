//! The maximum-speed study as a type on the experiment driver ([`crate::studies::driver`]):
//! its jobs are slow ramps (one trial each) and failing-acceleration searches (the ramp
//! acceleration bisected on the protocol's grid, both ends tried first).

use super::bisection::FailingAccel;
use super::jobs::MaxSpeedJob;
use super::protocol::MaxSpeedProtocol;
use super::trial::{TrialOutcome, controller};
use super::variant::Variant;
use crate::studies::driver::{self, Bisection, JobRecord, Study};
use crate::studies::ramp::{RampParams, RampResult, max_speed_ramp_observed};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{WorldError, WorldParams};

/// One ramp of the study: its time series and its reduction.
#[derive(Clone, Debug, PartialEq)]
pub struct RampTrial {
    /// The run's time series.
    pub run: RampResult,
    /// The run reduced to what the study reports (with its [`ballbot_world::rig::Happened`]).
    pub outcome: TrialOutcome,
}

/// The maximum-speed study's jobs on the nominal robot `params` (variants applied per job).
#[derive(Clone, Debug, PartialEq)]
pub struct MaxSpeedExperiment {
    /// The nominal robot and world.
    pub params: WorldParams,
    /// The ramps and the search's grid.
    pub protocol: MaxSpeedProtocol,
    /// The jobs, longest (the searches) first.
    pub jobs: Vec<MaxSpeedJob>,
}

impl MaxSpeedExperiment {
    /// The ramp of `job` at `accel_m_per_s2` (a search's trial), or its slow ramp.
    fn ramp(
        &self,
        job: &MaxSpeedJob,
        accel_m_per_s2: Option<f64>,
    ) -> (Variant, f64, u64, RampParams) {
        let slow = self.protocol.slow_ramp;
        match *job {
            MaxSpeedJob::Slow {
                variant,
                heading_deg,
                seed,
            } => (variant, heading_deg, seed, slow),
            MaxSpeedJob::Search {
                variant,
                heading_deg,
                seed,
            } => {
                let ramp = RampParams {
                    accel_m_per_s2: accel_m_per_s2.unwrap_or(slow.accel_m_per_s2),
                    max_command_m_per_s: self.protocol.fast_top_m_per_s,
                    ..slow
                };
                (variant, heading_deg, seed, ramp)
            }
        }
    }
}

impl Study for MaxSpeedExperiment {
    type Job = MaxSpeedJob;
    type Trial = RampTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<MaxSpeedJob> {
        self.jobs.clone()
    }

    fn bisection(&self, job: &MaxSpeedJob) -> Option<Bisection> {
        match job {
            MaxSpeedJob::Slow { .. } => None,
            MaxSpeedJob::Search { .. } => Some(self.protocol.accel_search()),
        }
    }

    fn trial(
        &self,
        job: &MaxSpeedJob,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<RampTrial, WorldError> {
        let (variant, heading_deg, seed, ramp) = self.ramp(job, value);
        let mut p = variant.apply(self.params);
        let config = controller(&p, &self.protocol)?;
        p.sensors.seed = seed;
        let run = max_speed_ramp_observed(p, config, heading_deg, &ramp, &mut |sim, _| {
            observe(sim);
        })?;
        let outcome = TrialOutcome::from_run(&run, seed, ramp.accel_m_per_s2);
        Ok(RampTrial { run, outcome })
    }

    fn passed(&self, trial: &RampTrial) -> bool {
        trial.outcome.censored()
    }

    fn describe(&self, job: &MaxSpeedJob, _value: Option<f64>, t: &RampTrial) -> String {
        let v = match job {
            MaxSpeedJob::Slow { variant, .. } | MaxSpeedJob::Search { variant, .. } => {
                match variant {
                    Variant::Nominal => String::new(),
                    Variant::WheelBallFriction(mu) => format!(" mu {mu}"),
                    Variant::ComHeight(l) => format!(" l {l} m"),
                }
            }
        };
        let o = &t.outcome;
        let end = if o.censored() { "survived" } else { "failed" };
        match job {
            MaxSpeedJob::Slow {
                heading_deg, seed, ..
            } => format!(
                "slow ramp {heading_deg} deg seed {seed}{v}: {}",
                o.speed_text()
            ),
            MaxSpeedJob::Search { heading_deg, .. } => format!(
                "accel search {heading_deg} deg{v} {:.2} m/s^2: {end}",
                o.accel_m_per_s2
            ),
        }
    }
}

impl FailingAccel {
    /// A search job's record as its result: the bracket's ends and the trials at them.
    pub fn from_record(heading_deg: f64, record: JobRecord<RampTrial>) -> Self {
        let bracket = record.bracket;
        let passed = bracket.and_then(|b| b.passed);
        let failed = bracket.and_then(|b| b.failed);
        let runs = record.trials.len();
        let mut surviving = None;
        let mut failing = None;
        for (value, trial) in record.trials {
            if value.is_some() && value == passed {
                surviving = Some(trial.outcome);
            } else if value.is_some() && value == failed {
                failing = Some(trial);
            }
        }
        let (failing, failing_run) =
            failing.map_or((None, None), |t| (Some(t.outcome), Some(t.run)));
        Self {
            heading_deg,
            largest_surviving_m_per_s2: passed,
            smallest_failing_m_per_s2: failed,
            failing,
            surviving,
            failing_run,
            runs,
        }
    }
}

/// The failing-acceleration search at `heading_deg`: bisection on the grid of
/// [`MaxSpeedProtocol::accel_resolution_m_per_s2`] inside
/// [`MaxSpeedProtocol::accel_bracket_m_per_s2`] for the largest ramp acceleration whose ramp to
/// [`MaxSpeedProtocol::fast_top_m_per_s`] (and 1 s hold) survives, with sensor seed `seed`.
/// Assumes that failure is monotonic in the acceleration (it checks both ends of the bracket
/// first). One job of [`MaxSpeedExperiment`], run by [`driver::run_job`].
pub fn failing_acceleration(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
) -> Result<FailingAccel, WorldError> {
    protocol.validate()?;
    let job = MaxSpeedJob::Search {
        variant: Variant::Nominal,
        heading_deg,
        seed,
    };
    let study = MaxSpeedExperiment {
        params,
        protocol: *protocol,
        jobs: vec![job],
    };
    let record = driver::run_job(&study, 0, &job, &mut |_, _| {})?;
    Ok(FailingAccel::from_record(heading_deg, record))
}

/// World runs the study takes at most (a progress bar's length; [`super::run_study`] reports
/// each): one per slow ramp, and both ends plus the halvings per search.
pub fn runs_estimate(params: &WorldParams, settings: &super::MaxSpeedStudySettings) -> u64 {
    let study = MaxSpeedExperiment {
        params: *params,
        protocol: settings.protocol,
        jobs: super::jobs::jobs(params, settings),
    };
    study.jobs.iter().map(|j| study.runs_estimate(j)).sum()
}
