//! One planar run described by a scenario file ([`crate::studies::scenario`]), written to an MCAP log
//! (every channel of [`McapRecorder`]) and reduced to a [`RunSummary`]. What `ballbot
//! simulate` runs.

use crate::studies::scenario::{Scenario, ScenarioError};
use ballbot_core::WipState;
use ballbot_core::wip::{BALL_RATE, TILT};
use ballbot_log::planar::McapRecorder;
use ballbot_log::{LogError, LoggerOptions, McapLogger};
use ballbot_world::planar::{Observer, OuterTick, PlanarError, PlantStep};
use std::path::{Path, PathBuf};

/// What can go wrong in a scenario run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioRunError {
    /// The scenario is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The controller could not be built for the robot.
    #[error(transparent)]
    Planar(#[from] PlanarError),
    /// The log could not be written.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The log's folder could not be created.
    #[error("cannot create {}: {source}", path.display())]
    Io {
        /// The folder.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
}

/// Whole-run statistics.
#[derive(Debug, Default, serde::Serialize)]
pub struct RunSummary {
    /// The scenario file.
    pub scenario: String,
    /// The controller.
    pub controller: String,
    /// Noise seed.
    pub seed: u64,
    /// Simulated time reached (s).
    pub end_time_secs: f64,
    /// Why the run stopped early, if it did.
    pub fault: Option<String>,
    /// `integral tau^2 dt` over the whole run, delivered torque (N^2 m^2 s).
    pub effort_n2m2s: f64,
    /// Largest tilt magnitude (rad).
    pub peak_tilt_rad: f64,
    /// Largest delivered torque magnitude (N m).
    pub peak_torque_nm: f64,
    /// Share of plant steps with the actuator saturated.
    pub saturated_fraction: f64,
    /// RMS of the ball-speed error against the command, at the controller's ticks (m/s).
    pub speed_rmse: f64,
    /// Final ball speed (m/s).
    pub final_speed_m_per_s: f64,
    /// Final tilt (rad).
    pub final_tilt_rad: f64,
    /// The MCAP log.
    pub log: String,
}

struct Stats {
    radius_m: f64,
    effort: f64,
    peak_tilt: f64,
    peak_torque: f64,
    steps: u64,
    saturated: u64,
    err_sq: f64,
    ticks: u64,
}

impl Observer for Stats {
    fn plant_step(&mut self, _t: f64, dt: f64, s: &WipState<f64>, step: &PlantStep) {
        self.effort += step.applied_torque_nm * step.applied_torque_nm * dt;
        self.peak_tilt = self.peak_tilt.max(s[TILT].abs());
        self.peak_torque = self.peak_torque.max(step.applied_torque_nm.abs());
        self.steps += 1;
        self.saturated += u64::from(step.saturated);
    }
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        let e = self.radius_m * (tick.state[BALL_RATE] - tick.command.ball_rate_rad_per_s);
        self.err_sq += e * e;
        self.ticks += 1;
    }
}

/// Runs `scenario` (named `label` in the summary, e.g. its file), writes every channel to the
/// MCAP log `log_path` (its folder is created once the scenario has been checked), and
/// returns the run's summary.
pub fn run_scenario(
    scenario: &Scenario,
    label: &str,
    log_path: &Path,
) -> Result<RunSummary, ScenarioRunError> {
    let robot = scenario.robot.params()?;
    let mut sim = scenario.simulator()?;
    let mut controller = scenario
        .controller
        .build(&robot, sim.plant().joint_gain(0.0))?;
    let profile = scenario.command_profile()?;
    if let Some(dir) = log_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| ScenarioRunError::Io {
            path: dir.to_owned(),
            source,
        })?;
    }
    let mut log = McapLogger::create(log_path, LoggerOptions::default())?;
    let mut recorder = McapRecorder::new(&mut log, robot.plane.ball_radius_m)?;
    let mut stats = Stats {
        radius_m: robot.plane.ball_radius_m,
        effort: 0.0,
        peak_tilt: 0.0,
        peak_torque: 0.0,
        steps: 0,
        saturated: 0,
        err_sq: 0.0,
        ticks: 0,
    };
    let outcome = sim.run(
        &mut controller,
        &profile,
        scenario.duration_secs,
        &mut (&mut stats, &mut recorder),
    );
    recorder.finish()?;
    log.finish()?;
    let s = sim.plant().state();
    Ok(RunSummary {
        scenario: label.to_owned(),
        controller: scenario.controller.kind.key().to_owned(),
        seed: scenario.seed,
        end_time_secs: outcome.end_time_secs,
        fault: outcome
            .fault
            .map(|f| format!("{:?} at {:.4} s", f.kind, f.time_secs)),
        effort_n2m2s: stats.effort,
        peak_tilt_rad: stats.peak_tilt,
        peak_torque_nm: stats.peak_torque,
        saturated_fraction: stats.saturated as f64 / stats.steps.max(1) as f64,
        speed_rmse: (stats.err_sq / stats.ticks.max(1) as f64).sqrt(),
        final_speed_m_per_s: robot.plane.ball_radius_m * s[BALL_RATE],
        final_tilt_rad: s[TILT],
        log: log_path.display().to_string(),
    })
}
