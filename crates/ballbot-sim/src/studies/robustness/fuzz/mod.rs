//! Fuzzing the core (issue 15, section 1): seeded hostile input sequences for the 3D
//! controller (outer step, motor speed PIs, estimation, command shaper, supervisor) in closed
//! loop on the planar plant, for the planar controllers, and for the parsers of the TOML files
//! the tools read. Only the stable toolchain is available here, so the generator is a seeded
//! ChaCha8, not a coverage-guided fuzzer.
//!
//! Invariants checked on every step (a broken one is a *bad command*, recorded with its
//! episode seed and step): no panic; every motor reference and torque finite, within the peak
//! torque, the no-load speed and the torque-speed line at the measured speed, zero with the
//! motors off; only the documented mode transitions; the motors off once no fresh IMU sample
//! has come for longer than the timeout, whatever the timestamps and the clock do; a single
//! corrupted sample, at either loop rate, never drives a motor to its torque limit where the
//! same run without it does not, and leaves no lasting torque difference (no wound-up
//! integrator); any command the API accepts never ends with the motors off on the healthy
//! plant. The parsers ([`parsers`]): mutated TOML files give a value or an error, never a
//! panic, and an error names the key whose value was made wrong.

pub mod episode;
pub mod hostile;
pub mod parsers;
pub mod plant;
pub mod rig;

use super::monte_carlo::run_seed;
use crate::studies::runner::run_jobs;
use crate::world::WorldError;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::safety::Fault;
use episode::{EpisodeKind, Violation, run_episode};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How much the fuzzer runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FuzzSettings {
    /// Base seed; episode `i` uses `run_seed(seed, i)`.
    pub seed: u64,
    /// Episodes with hostile inputs.
    pub hostile_episodes: usize,
    /// Episodes with accepted commands only (every other one with trajectories among them).
    pub accepted_episodes: usize,
    /// Outer steps per episode (400 a simulated second).
    pub outer_steps_per_episode: u64,
    /// Mutated TOML files parsed.
    pub parser_files: u64,
}

impl FuzzSettings {
    /// The documented size: 10^7 outer steps (2 x 10^8 motor-loop steps), 7 simulated hours.
    ///
    /// ```
    /// use ballbot_sim::studies::robustness::FuzzSettings;
    /// assert!(FuzzSettings::full().planned_outer_steps() >= 10_000_000);
    /// ```
    pub fn full() -> Self {
        Self {
            seed: 1,
            hostile_episodes: 160,
            accepted_episodes: 40,
            outer_steps_per_episode: 50_000,
            parser_files: 100_000,
        }
    }

    /// The CI size: 10^5 outer steps (2 x 10^6 motor-loop steps).
    ///
    /// ```
    /// use ballbot_sim::studies::robustness::FuzzSettings;
    /// assert_eq!(FuzzSettings::quick().planned_outer_steps(), 100_000);
    /// ```
    pub fn quick() -> Self {
        Self {
            seed: 1,
            hostile_episodes: 8,
            accepted_episodes: 2,
            outer_steps_per_episode: 10_000,
            parser_files: 2_000,
        }
    }

    /// Outer steps planned (the twins of the single-sample checks take some of them).
    pub fn planned_outer_steps(&self) -> u64 {
        (self.hostile_episodes + self.accepted_episodes) as u64 * self.outer_steps_per_episode
    }

    /// Checks the settings.
    ///
    /// ```
    /// use ballbot_sim::studies::robustness::FuzzSettings;
    /// let none = FuzzSettings { hostile_episodes: 0, accepted_episodes: 0, ..FuzzSettings::quick() };
    /// assert!(none.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        if self.hostile_episodes + self.accepted_episodes == 0 || self.outer_steps_per_episode == 0
        {
            return Err(WorldError::InvalidParameter {
                field: "fuzz episodes",
                requirement: "at least one episode of at least one step",
            });
        }
        Ok(())
    }
}

/// The fuzzer's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FuzzResult {
    /// The settings.
    pub settings: FuzzSettings,
    /// Controller steps executed: outer plus motor-loop steps.
    pub steps: u64,
    /// Outer (400 Hz) steps executed.
    pub outer_steps: u64,
    /// Motor-loop (8 kHz) steps executed.
    pub inner_steps: u64,
    /// Simulated time (h).
    pub simulated_hours: f64,
    /// Episodes run.
    pub episodes: usize,
    /// Episodes and parsed files that panicked (must be 0).
    pub panics: usize,
    /// Motor commands that broke a hard invariant (must be 0).
    pub bad_commands: u64,
    /// Findings: a single wrong in-range IMU sample reaching the torque limit, an accepted
    /// trajectory the robot cannot follow (see [`Violation::kind`]).
    pub findings: u64,
    /// Findings by what happened.
    pub findings_by_what: BTreeMap<String, u64>,
    /// The first ten bad commands and the first ten findings, each with its episode seed.
    pub violations: Vec<Violation>,
    /// Steps on which each fault class was raised.
    pub faults_raised: BTreeMap<&'static str, u64>,
    /// Single corrupted samples compared against a clean twin.
    pub single_sample_checks: u64,
    /// The parsers' tally.
    pub parsers: parsers::ParserFuzz,
}

/// Runs the campaign on `robot` (designed controller; every other episode with
/// traction-aware control and balance-point estimation on) on `threads` threads;
/// `progress(done, total)` after each episode.
pub fn run_fuzz(
    robot: &BallbotParams<f64>,
    settings: &FuzzSettings,
    threads: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<FuzzResult, WorldError> {
    settings.validate()?;
    let designed = BallbotControllerConfig::paper(robot)?;
    let all_on = BallbotControllerConfig::design(robot)?;
    let total = settings.hostile_episodes + settings.accepted_episodes;
    let jobs: Vec<usize> = (0..total).collect();
    let done = AtomicUsize::new(0);
    let outcomes = run_jobs(
        &jobs,
        threads,
        |&i| -> Result<Option<episode::EpisodeCounts>, WorldError> {
            let kind = if i < settings.hostile_episodes {
                EpisodeKind::Hostile
            } else if i % 2 == 0 {
                EpisodeKind::Accepted
            } else {
                EpisodeKind::AcceptedTrajectories
            };
            let config = if i % 2 == 0 { designed } else { all_on };
            let seed = run_seed(settings.seed, i);
            let steps = settings.outer_steps_per_episode;
            // A panic is a finding, not a crash of the campaign.
            let run = std::panic::catch_unwind(|| run_episode(config, kind, seed, steps));
            match run {
                Ok(counts) => Ok(Some(counts?)),
                Err(_) => Ok(None),
            }
        },
        &|_| progress(done.fetch_add(1, Ordering::Relaxed) + 1, total),
    )?;
    let mut result = FuzzResult {
        settings: *settings,
        steps: 0,
        outer_steps: 0,
        inner_steps: 0,
        simulated_hours: 0.0,
        episodes: total,
        panics: 0,
        bad_commands: 0,
        findings: 0,
        findings_by_what: BTreeMap::new(),
        violations: Vec::new(),
        faults_raised: Fault::ALL.iter().map(|f| (f.as_str(), 0)).collect(),
        single_sample_checks: 0,
        parsers: parsers::fuzz_parsers(settings.seed, settings.parser_files),
    };
    for (i, outcome) in outcomes.into_iter().enumerate() {
        let Some(c) = outcome else {
            result.panics += 1;
            result.violations.push(Violation {
                kind: episode::BAD,
                episode_seed: run_seed(settings.seed, i),
                outer_step: 0,
                what: "the episode panicked".to_owned(),
            });
            continue;
        };
        result.outer_steps += c.outer_steps;
        result.inner_steps += c.inner_steps;
        result.single_sample_checks += c.single_sample_checks;
        result.bad_commands += c.bad_commands;
        result.findings += c.findings;
        for (what, n) in c.findings_by_what {
            *result.findings_by_what.entry(what).or_insert(0) += n;
        }
        for v in c.violations {
            let recorded = result
                .violations
                .iter()
                .filter(|r| r.kind == v.kind)
                .count();
            if recorded < 10 {
                result.violations.push(v);
            }
        }
        for (f, n) in Fault::ALL.iter().zip(c.faults) {
            *result.faults_raised.entry(f.as_str()).or_insert(0) += n;
        }
    }
    result.panics += result.parsers.panics as usize;
    result.steps = result.outer_steps + result.inner_steps;
    result.simulated_hours = result.outer_steps as f64 * 0.0025 / 3600.0;
    Ok(result)
}
