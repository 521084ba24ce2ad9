//! Fuzzing the core (the reliability campaign's first part; widened by the safe-by-default
//! hardening's invariants, [`invariants`]): seeded hostile input sequences for the 3D
//! controller (outer step, motor speed PIs, estimation, command shaper, supervisor) in closed
//! loop on the planar plant, in `f64` and instantiated in `f32`; the
//! shipped `RobotLoop` on devices that fail; the planar controllers; and the parsers of the
//! TOML files the tools read. Only the stable toolchain is available here, so the generator is
//! a seeded ChaCha8, not a coverage-guided fuzzer.
//!
//! The generator ([`hostile`]): magnitudes log-uniform over the whole `f64` and `f32` ranges
//! (random sign, subnormals, zero, the largest finite values) for every corrupted sensor field
//! and every accepted command; pushes on the plant from 1 to 200 N s; clocks that stall for up
//! to 60 ticks, jump and go back; wrong encoder samples in the 8 kHz loop, singly, in bursts
//! longer than the guard's hold and as the first sample after enabling; random stops, disarms
//! and re-arms. Traction-aware control and balance-point estimation are on in exactly half the
//! episodes of each kind.
//!
//! The invariants, each checked on every step, and how a break counts: [`invariants`]. The
//! parsers ([`parsers`]): mutated TOML files give a value or an error, never a panic, and an
//! error names the key whose value was made wrong.

mod corruption;
pub mod episode;
pub mod hostile;
pub mod invariants;
pub mod parsers;
pub mod planar;
pub mod plant;
pub mod rig;
pub mod runtime;
mod trajectories;

use super::monte_carlo::run_seed;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::safety::Fault;
use ballbot_world::runner::run_jobs;
use ballbot_world::world::WorldError;
use episode::{EpisodeCounts, EpisodeKind, Violation, run_episode, run_episode_on};
use invariants::{BAD, Invariant};
use planar::run_planar_episode;
use rig::FuzzRig;
use runtime::run_runtime_episode;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How much the fuzzer runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FuzzSettings {
    /// Base seed; episode `i` uses `run_seed(seed, i)`.
    pub seed: u64,
    /// Episodes of the `f64` controller with hostile inputs.
    pub hostile_episodes: usize,
    /// Episodes of the `f64` controller with accepted commands only (half of them with
    /// trajectories among the commands).
    pub accepted_episodes: usize,
    /// Episodes of the `f32` controller (half hostile, half accepted commands).
    pub f32_episodes: usize,
    /// Episodes of `RobotLoop` on failing devices.
    pub runtime_episodes: usize,
    /// Outer steps per episode (400 a simulated second).
    pub outer_steps_per_episode: u64,
    /// Steps of the planar controllers (each of the three, in `f64` and in `f32`).
    pub planar_steps: u64,
    /// Mutated TOML files parsed.
    pub parser_files: u64,
}

impl FuzzSettings {
    /// The documented size: 10^8 outer steps (2 x 10^9 motor-loop steps), 69 simulated hours.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FuzzSettings;
    /// assert!(FuzzSettings::full().planned_outer_steps() >= 100_000_000);
    /// ```
    pub fn full() -> Self {
        Self {
            seed: 1,
            hostile_episodes: 1_200,
            accepted_episodes: 400,
            f32_episodes: 200,
            runtime_episodes: 200,
            outer_steps_per_episode: 50_000,
            planar_steps: 1_000_000,
            parser_files: 100_000,
        }
    }

    /// The CI size: 10^5 outer steps (2 x 10^6 motor-loop steps), every kind of episode with
    /// and without traction-aware control.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FuzzSettings;
    /// assert_eq!(FuzzSettings::quick().planned_outer_steps(), 100_800);
    /// ```
    pub fn quick() -> Self {
        Self {
            seed: 1,
            hostile_episodes: 4,
            accepted_episodes: 4,
            f32_episodes: 2,
            runtime_episodes: 2,
            outer_steps_per_episode: 8_400,
            planar_steps: 20_000,
            parser_files: 2_000,
        }
    }

    /// Episodes of every kind.
    pub fn episodes(&self) -> usize {
        self.hostile_episodes + self.accepted_episodes + self.f32_episodes + self.runtime_episodes
    }

    /// Outer steps planned (the twins of the single-sample checks take some of them).
    pub fn planned_outer_steps(&self) -> u64 {
        self.episodes() as u64 * self.outer_steps_per_episode
    }

    /// Checks the settings.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FuzzSettings;
    /// let none = FuzzSettings {
    ///     hostile_episodes: 0,
    ///     accepted_episodes: 0,
    ///     f32_episodes: 0,
    ///     runtime_episodes: 0,
    ///     ..FuzzSettings::quick()
    /// };
    /// assert!(none.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        if self.episodes() == 0 || self.outer_steps_per_episode == 0 {
            return Err(WorldError::InvalidParameter {
                field: "fuzz episodes",
                requirement: "at least one episode of at least one step",
            });
        }
        Ok(())
    }
}

/// One invariant's count in a campaign.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InvariantCount {
    /// The invariant (key, hardening item, class, what it checks).
    #[serde(flatten)]
    pub invariant: Invariant,
    /// Breaks counted (events: once when a break starts).
    pub breaks: u64,
}

/// The fuzzer's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FuzzResult {
    /// The settings.
    pub settings: FuzzSettings,
    /// Controller steps executed: outer plus motor-loop steps.
    pub steps: u64,
    /// Outer (400 Hz) steps executed (3D controller and `RobotLoop`).
    pub outer_steps: u64,
    /// Motor-loop (8 kHz) steps executed.
    pub inner_steps: u64,
    /// Steps of the planar controllers (each of the three, `f64` and `f32`).
    pub planar_steps: u64,
    /// Simulated time (h).
    pub simulated_hours: f64,
    /// Episodes run.
    pub episodes: usize,
    /// Episodes with traction-aware control and balance-point estimation on (half of
    /// `episodes` but for rounding).
    pub traction_on_episodes: usize,
    /// Pushes on the plant.
    pub pushes: u64,
    /// Episodes and parsed files that panicked (must be 0).
    pub panics: usize,
    /// Breaks of invariants whose class is `bad_command` (must be 0).
    pub bad_commands: u64,
    /// Breaks of invariants whose class is `finding`.
    pub findings: u64,
    /// Findings by what happened.
    pub findings_by_what: BTreeMap<String, u64>,
    /// Every invariant with its count.
    pub invariants: Vec<InvariantCount>,
    /// The first ten bad commands and the first ten findings, each with its episode seed.
    pub violations: Vec<Violation>,
    /// Steps on which each fault class was raised.
    pub faults_raised: BTreeMap<&'static str, u64>,
    /// Single corrupted samples compared against a clean twin.
    pub single_sample_checks: u64,
    /// The parsers' tally.
    pub parsers: parsers::ParserFuzz,
}

/// What episode `i` of a campaign runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Job {
    /// The 3D controller on the fuzz plant.
    Controller {
        /// The episode's kind.
        kind: EpisodeKind,
        /// The `f32` instantiation.
        f32: bool,
        /// Traction-aware control and balance-point estimation on.
        traction: bool,
    },
    /// `RobotLoop` on failing devices.
    Runtime {
        /// Traction-aware control and balance-point estimation on.
        traction: bool,
    },
}

impl FuzzSettings {
    /// Episode `i`'s job: hostile, accepted and `f32` episodes, then `RobotLoop`; within each
    /// block every other episode has traction-aware control and balance-point estimation on,
    /// and the accepted (and `f32`) blocks alternate their kinds in pairs, so that each
    /// kind has both controllers.
    pub fn job(&self, i: usize) -> Job {
        let (h, a, f) = (
            self.hostile_episodes,
            self.accepted_episodes,
            self.f32_episodes,
        );
        let (j, block) = if i < h {
            (i, 0)
        } else if i < h + a {
            (i - h, 1)
        } else if i < h + a + f {
            (i - h - a, 2)
        } else {
            (i - h - a - f, 3)
        };
        let traction = j % 2 == 1;
        let pair = (j / 2) % 2 == 1;
        match block {
            0 => Job::Controller {
                kind: EpisodeKind::Hostile,
                f32: false,
                traction,
            },
            1 => Job::Controller {
                kind: if pair {
                    EpisodeKind::AcceptedTrajectories
                } else {
                    EpisodeKind::Accepted
                },
                f32: false,
                traction,
            },
            2 => Job::Controller {
                kind: if pair {
                    EpisodeKind::Accepted
                } else {
                    EpisodeKind::Hostile
                },
                f32: true,
                traction,
            },
            _ => Job::Runtime { traction },
        }
    }
}

/// Runs the campaign on `robot` on `threads` threads; `progress(done, total)` after each
/// episode.
pub fn run_fuzz(
    robot: &BallbotParams<f64>,
    settings: &FuzzSettings,
    threads: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<FuzzResult, WorldError> {
    settings.validate()?;
    let designed = BallbotControllerConfig::paper(robot)?;
    let all_on = BallbotControllerConfig::design(robot)?;
    let robot32 = BallbotParams::<f32>::miapure_60kg();
    let designed32 = BallbotControllerConfig::paper(&robot32)?;
    let all_on32 = BallbotControllerConfig::design(&robot32)?;
    let total = settings.episodes();
    let jobs: Vec<usize> = (0..total).collect();
    let done = AtomicUsize::new(0);
    let outcomes = run_jobs(
        &jobs,
        threads,
        |&i| -> Result<Option<EpisodeCounts>, WorldError> {
            let seed = run_seed(settings.seed, i);
            let steps = settings.outer_steps_per_episode;
            // A panic is a finding, not a crash of the campaign.
            let run = std::panic::catch_unwind(|| -> Result<EpisodeCounts, ballbot_core::Error> {
                match settings.job(i) {
                    Job::Controller {
                        kind,
                        f32: false,
                        traction,
                    } => run_episode(if traction { all_on } else { designed }, kind, seed, steps),
                    Job::Controller {
                        kind,
                        f32: true,
                        traction,
                    } => {
                        let (c, c32) = if traction {
                            (all_on, all_on32)
                        } else {
                            (designed, designed32)
                        };
                        Ok(run_episode_on(FuzzRig::new_f32(c, c32)?, kind, seed, steps))
                    }
                    Job::Runtime { traction } => {
                        run_runtime_episode(if traction { all_on } else { designed }, seed, steps)
                    }
                }
            });
            match run {
                Ok(counts) => Ok(Some(counts?)),
                Err(_) => Ok(None),
            }
        },
        &|_| progress(done.fetch_add(1, Ordering::Relaxed) + 1, total),
    )?;
    let planar = std::panic::catch_unwind(|| {
        run_planar_episode(run_seed(settings.seed, total), settings.planar_steps)
    });
    let traction_on_episodes = (0..total)
        .filter(|&i| {
            matches!(
                settings.job(i),
                Job::Controller { traction: true, .. } | Job::Runtime { traction: true }
            )
        })
        .count();
    let mut result = FuzzResult {
        settings: *settings,
        steps: 0,
        outer_steps: 0,
        inner_steps: 0,
        planar_steps: 0,
        simulated_hours: 0.0,
        episodes: total,
        traction_on_episodes,
        pushes: 0,
        panics: 0,
        bad_commands: 0,
        findings: 0,
        findings_by_what: BTreeMap::new(),
        invariants: Vec::new(),
        violations: Vec::new(),
        faults_raised: Fault::ALL.iter().map(|f| (f.as_str(), 0)).collect(),
        single_sample_checks: 0,
        parsers: parsers::fuzz_parsers(settings.seed, settings.parser_files),
    };
    let mut by_invariant: BTreeMap<&'static str, u64> = BTreeMap::new();
    let planar = match planar {
        Ok(p) => Some((total, Some(p?))),
        Err(_) => Some((total, None)),
    };
    let all = outcomes.into_iter().enumerate().chain(planar);
    for (i, outcome) in all {
        let Some(c) = outcome else {
            result.panics += 1;
            result.violations.push(Violation {
                kind: BAD,
                invariant: "panic",
                episode_seed: run_seed(settings.seed, i),
                outer_step: 0,
                what: "the episode panicked".to_owned(),
            });
            continue;
        };
        if i < total {
            result.outer_steps += c.outer_steps;
            result.inner_steps += c.inner_steps;
        } else {
            result.planar_steps += c.outer_steps;
        }
        result.pushes += c.pushes;
        result.single_sample_checks += c.single_sample_checks;
        result.bad_commands += c.bad_commands;
        result.findings += c.findings;
        for (what, n) in c.findings_by_what {
            *result.findings_by_what.entry(what).or_insert(0) += n;
        }
        for (key, n) in c.by_invariant {
            *by_invariant.entry(key).or_insert(0) += n;
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
    result.invariants = invariants::ALL
        .iter()
        .map(|inv| InvariantCount {
            invariant: *inv,
            breaks: by_invariant.get(inv.key).copied().unwrap_or(0),
        })
        .collect();
    result.panics += result.parsers.panics as usize;
    result.steps = result.outer_steps + result.inner_steps;
    result.simulated_hours = result.outer_steps as f64 * 0.0025 / 3600.0;
    Ok(result)
}
