//! A study's run replayed with an MCAP logger ([`WorldLogger`]) and checked against the
//! study's own run: the runs are deterministic in their seed, so logging afterwards costs one
//! more run of the few that are logged instead of a logger on every run of a search.
//!
//! [`replay_and_check`] holds the part every replay shares (create the log, record until the
//! first write error, finish, compare); [`log_slow_ramp`], [`log_braking`] and [`log_push`]
//! are the three replays of `ballbot reproduce`.

use crate::studies::max_speed::{MaxSpeedProtocol, controller};
use crate::studies::push::{PushParams, PushTrial, push_trial_observed};
use crate::studies::ramp::{RampResult, max_speed_ramp_observed};
use crate::studies::world_braking::{BrakingError, BrakingParams, BrakingRun, fly_braking};
use ballbot_core::command::VelocityCommand;
use ballbot_log::LogError;
use ballbot_log::{WorldLogOptions, WorldLogger};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::{WorldError, WorldParams};
use std::path::{Path, PathBuf};

/// Why a logged replay failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// The log could not be created, written or finished.
    #[error("{}: {source}", path.display())]
    Log {
        /// The log's path.
        path: PathBuf,
        /// What went wrong.
        source: LogError,
    },
    /// The run rejected its parameters.
    #[error(transparent)]
    World(#[from] WorldError),
    /// The braking run rejected its parameters.
    #[error(transparent)]
    Braking(#[from] BrakingError),
    /// The replay is not the study's run (the simulation is not deterministic in its seed).
    #[error("the logged {what} differs from the study's")]
    Differs {
        /// Which run, e.g. `braking run at T = 2 s`.
        what: String,
    },
}

/// The logger of a replay: [`record`](Self::record) writes until the first error, which the
/// replay then reports.
pub struct ReplayLog {
    log: WorldLogger,
    error: Option<LogError>,
}

impl ReplayLog {
    /// Runs `write` on the logger unless an earlier write failed; keeps the first error.
    pub fn record(&mut self, write: impl FnOnce(&mut WorldLogger) -> Result<(), LogError>) {
        if self.error.is_none()
            && let Err(e) = write(&mut self.log)
        {
            self.error = Some(e);
        }
    }
}

/// Creates the log `path` for `world` (telemetry every `telemetry_every_steps`-th physics
/// step), runs `run` with it, finishes it, and checks the replay with `is_the_run`; `what`
/// names the run in the error.
pub fn replay_and_check<R>(
    path: &Path,
    world: &WorldParams,
    telemetry_every_steps: u32,
    what: &str,
    run: impl FnOnce(&mut ReplayLog) -> Result<R, ReplayError>,
    is_the_run: impl FnOnce(&R) -> bool,
) -> Result<R, ReplayError> {
    let log_error = |source| ReplayError::Log {
        path: path.to_owned(),
        source,
    };
    let options = WorldLogOptions {
        telemetry_every_steps,
        ..WorldLogOptions::default()
    };
    let log = WorldLogger::with_options(path, world, options).map_err(log_error)?;
    let mut replay = ReplayLog { log, error: None };
    let result = run(&mut replay)?;
    if let Some(e) = replay.error {
        return Err(log_error(e));
    }
    replay.log.finish().map_err(log_error)?;
    if !is_the_run(&result) {
        return Err(ReplayError::Differs {
            what: what.to_owned(),
        });
    }
    Ok(result)
}

/// Runs the slow-ramp trial of the maximum-speed study at `heading_deg` with `seed` again and
/// writes it to `path` (telemetry, controller, command, scene, failure event); checks that it
/// is `study_run`.
pub fn log_slow_ramp(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
    study_run: &RampResult,
    path: &Path,
    telemetry_every_steps: u32,
) -> Result<RampResult, ReplayError> {
    let mut p = params;
    p.sensors.seed = seed;
    let config = controller(&p, protocol)?;
    let what = format!("slow ramp at {heading_deg} deg (seed {seed})");
    replay_and_check(
        path,
        &p,
        telemetry_every_steps,
        &what,
        |log| {
            let observe = &mut |sim: &WorldRobot, cmd: &VelocityCommand<f64>| {
                let time_secs = sim.world().time_secs();
                log.record(|l| {
                    l.record_robot(sim)?;
                    l.record_command(time_secs, cmd)
                });
            };
            Ok(max_speed_ramp_observed(
                p,
                config,
                heading_deg,
                &protocol.slow_ramp,
                observe,
            )?)
        },
        |replay| replay == study_run,
    )
}

/// Flies a braking run again with its own trajectory and writes it to `path` (telemetry,
/// controller, commands, scene, failure, and an event when braking starts); checks the
/// replay's telemetry hash against the run's. A run without a plan writes nothing.
pub fn log_braking(
    world: WorldParams,
    params: &BrakingParams,
    run: &BrakingRun,
    path: &Path,
    telemetry_every_steps: u32,
) -> Result<(), ReplayError> {
    let Some(plan) = &run.plan else {
        return Ok(());
    };
    let what = format!("braking run at T = {} s", run.duration_secs);
    let mut braking = false;
    replay_and_check(
        path,
        &world,
        telemetry_every_steps,
        &what,
        |log| {
            let observe = &mut |sim: &WorldRobot, cmd: Option<&VelocityCommand<f64>>| {
                let time_secs = sim.world().time_secs();
                log.record(|l| {
                    l.record_robot(sim)?;
                    if let Some(v) = cmd {
                        l.record_command(time_secs, v)?;
                    }
                    if !braking && cmd.is_none() {
                        braking = true;
                        let what = format!(
                            "optimal braking from {:.2} m/s to rest in {:.3} s at {:.0} deg",
                            params.cruise_speed_m_per_s, run.duration_secs, run.heading_deg
                        );
                        let tilt = tilt_from_vertical_rad(sim.world().telemetry());
                        l.record_event(time_secs, "brake", &what, tilt)?;
                    }
                    Ok(())
                });
            };
            Ok(fly_braking(world, params, run.heading_deg, plan, observe)?)
        },
        |replay| replay.telemetry_hash == run.telemetry_hash,
    )?;
    Ok(())
}

/// Runs a push trial again and writes it to `path` (telemetry, controller, scene, failure,
/// and an event when the push starts); checks the replay's telemetry hash against the
/// trial's.
pub fn log_push(
    world: WorldParams,
    params: &PushParams,
    trial: &PushTrial,
    path: &Path,
    telemetry_every_steps: u32,
) -> Result<(), ReplayError> {
    let what = format!("push of {} N s", trial.impulse_ns);
    let mut pushed = false;
    replay_and_check(
        path,
        &world,
        telemetry_every_steps,
        &what,
        |log| {
            let observe = &mut |sim: &WorldRobot| {
                let time_secs = sim.world().time_secs();
                log.record(|l| {
                    l.record_robot(sim)?;
                    if !pushed && time_secs >= params.settle_secs {
                        pushed = true;
                        let what = format!(
                            "push {:.2} N s at the body's COM towards {:.0} deg over {} s",
                            trial.impulse_ns, trial.heading_deg, params.push_duration_secs
                        );
                        let tilt = tilt_from_vertical_rad(sim.world().telemetry());
                        l.record_event(time_secs, "push", &what, tilt)?;
                    }
                    Ok(())
                });
            };
            Ok(push_trial_observed(
                world,
                params,
                trial.heading_deg,
                trial.impulse_ns,
                observe,
            )?)
        },
        |replay| replay.telemetry_hash == trial.telemetry_hash,
    )?;
    Ok(())
}
