//! The PIPTB controller comparison (paper Sec. IV-C, MODEL.md section 7).
//!
//! Command `phi_dot_c = (v / T_a) t / r` for `T_a = 2 s` (0 to 1 m/s), hold `v / r` for 2 s,
//! then track the braking reference (state `s_c = s*(t)`) to rest in 1.4 s, then hold rest for
//! a settling second. Every controller runs the same seeded trials (trial `k` uses seed
//! `base_seed + k` for all three: the same noise samples, a paired comparison).
//!
//! Metrics, all from the true (simulated) state and the torque the actuator delivered:
//!
//! - `j_p`: braking effort `integral_{t2}^{t3} tau^2 dt` over the braking phase
//!   (N^2 m^2 s; times 1e6 for the paper's N^2 mm^2 s), integrated at the plant rate;
//! - `stopped`: `|r phi_dot(t3)| <= stop_speed` (default 0.05 m/s) at the end of the braking
//!   phase, and the run did not fall;
//! - `speed_rmse`: RMS of `r (phi_dot - phi_dot_c)` over the braking phase, sampled at the
//!   main controller's ticks (m/s);
//! - `torque_jitter_nm`: RMS of the change of the delivered torque between successive ticks of
//!   the main controller over the braking phase (N m): zero for a smooth torque, large for a
//!   torque that chatters (stick-slip limit cycles, noise amplification).

use super::braking::BrakingTrajectory;
use crate::log::{LogError, LoggerOptions, McapLogger};
use crate::planar::{
    CommandProfile, ControllerKind, ControllerSettings, Fault, FaultKind, McapRecorder, Observer,
    OuterTick, PlanarCommand, PlanarError, PlanarSim, PlantStep, SensorParams, SimConfig,
    TransmissionFriction,
};
use crate::plot::{PlotError, Series, Subplot, TimeSeriesFigure};
use crate::trajopt::BrakingProblem;
use ballbot_core::wip::{BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{PlanarRobotParams, WipState};
use std::path::{Path, PathBuf};

/// What the paper reports for one controller (Sec. IV-C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperResult {
    /// The controller.
    pub kind: ControllerKind,
    /// Braking effort, N^2 mm^2 s (mean, std), where the paper gives one.
    pub j_p_n2mm2s: Option<(f64, f64)>,
    /// Whether it stopped within 1.4 s.
    pub stopped: Option<bool>,
}

/// The paper's results. It gives no number for the LQR: it braked in time but jittered.
pub const PAPER: [PaperResult; 3] = [
    PaperResult {
        kind: ControllerKind::Lqr,
        j_p_n2mm2s: None,
        stopped: Some(true),
    },
    PaperResult {
        kind: ControllerKind::PiPd,
        j_p_n2mm2s: Some((1.2e6, 0.3e6)),
        stopped: Some(false),
    },
    PaperResult {
        kind: ControllerKind::LqrPi,
        j_p_n2mm2s: Some((8.2e5, 0.2e5)),
        stopped: Some(true),
    },
];

/// Errors of an experiment.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// The simulator's inputs are invalid.
    #[error(transparent)]
    Planar(#[from] PlanarError),
    /// Writing a log failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// Drawing a figure failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// No braking reference could be computed.
    #[error("braking reference: {0}")]
    Braking(String),
}

/// Settings of the PIPTB experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct PiptbSettings {
    /// The robot.
    pub robot: PlanarRobotParams<f64>,
    /// Its transmission friction.
    pub friction: TransmissionFriction,
    /// Its sensors.
    pub sensors: SensorParams,
    /// Rates and delay.
    pub sim: SimConfig,
    /// Cruise speed `v` (m/s). Paper: 1.
    pub cruise_speed_m_per_s: f64,
    /// Acceleration ramp `T_a` (s). Paper: 2.
    pub accel_secs: f64,
    /// Cruise hold (s). Paper: 2.
    pub hold_secs: f64,
    /// Braking time (s). Paper: 1.4.
    pub brake_secs: f64,
    /// Rest held after braking (s), to see whether the robot stays stopped.
    pub settle_secs: f64,
    /// Trials per controller. Paper: 3.
    pub trials: usize,
    /// Seed of trial 0; trial `k` uses `base_seed + k`.
    pub base_seed: u64,
    /// Speed below which the robot counts as stopped (m/s).
    pub stop_speed_m_per_s: f64,
}

impl PiptbSettings {
    /// The paper's protocol on the PIPTB preset with its transmission stiction and sensors
    /// ([`TransmissionFriction::piptb`], [`SensorParams::piptb`]), 3 trials.
    pub fn paper() -> Self {
        Self {
            robot: PlanarRobotParams::piptb(),
            friction: TransmissionFriction::piptb(),
            sensors: SensorParams::piptb(),
            sim: SimConfig::default(),
            cruise_speed_m_per_s: 1.0,
            accel_secs: 2.0,
            hold_secs: 2.0,
            brake_secs: 1.4,
            settle_secs: 1.0,
            trials: 3,
            base_seed: 1,
            stop_speed_m_per_s: 0.05,
        }
    }

    /// The CI variant: the same protocol, one trial per controller, a shorter hold (1 s) and
    /// settle (0.3 s).
    pub fn quick() -> Self {
        Self {
            hold_secs: 1.0,
            settle_secs: 0.3,
            trials: 1,
            ..Self::paper()
        }
    }

    /// Start of the braking phase `t2` (s).
    pub fn brake_start_secs(&self) -> f64 {
        self.accel_secs + self.hold_secs
    }

    /// End of the braking phase `t3` (s).
    pub fn brake_end_secs(&self) -> f64 {
        self.brake_start_secs() + self.brake_secs
    }

    /// Total simulated time per trial (s).
    pub fn duration_secs(&self) -> f64 {
        self.brake_end_secs() + self.settle_secs
    }
}

/// The command of the experiment as a function of time.
#[derive(Clone, Debug)]
pub struct PiptbProfile {
    radius_m: f64,
    speed_m_per_s: f64,
    accel_secs: f64,
    brake_start_secs: f64,
    brake: BrakingTrajectory,
}

impl PiptbProfile {
    /// The profile of `settings`, braking along `brake`.
    pub fn new(settings: &PiptbSettings, brake: BrakingTrajectory) -> Self {
        Self {
            radius_m: settings.robot.plane.ball_radius_m,
            speed_m_per_s: settings.cruise_speed_m_per_s,
            accel_secs: settings.accel_secs,
            brake_start_secs: settings.brake_start_secs(),
            brake,
        }
    }
}

impl CommandProfile for PiptbProfile {
    fn command(&self, t: f64) -> PlanarCommand {
        let cruise_rate = self.speed_m_per_s / self.radius_m;
        if t < self.accel_secs {
            PlanarCommand {
                ball_rate_rad_per_s: cruise_rate * t / self.accel_secs,
                ..PlanarCommand::default()
            }
        } else if t < self.brake_start_secs {
            PlanarCommand {
                ball_rate_rad_per_s: cruise_rate,
                ..PlanarCommand::default()
            }
        } else if t < self.brake_start_secs + self.brake.duration_secs() {
            let s = self.brake.state_at(t - self.brake_start_secs);
            PlanarCommand {
                tilt_rad: s[TILT],
                tilt_rate_rad_per_s: s[TILT_RATE],
                ball_rate_rad_per_s: s[BALL_RATE],
            }
        } else {
            PlanarCommand::default()
        }
    }
}

/// One trial's time series, sampled at the main controller's ticks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrialSeries {
    /// Time (s).
    pub time_secs: Vec<f64>,
    /// True tilt (rad).
    pub tilt_rad: Vec<f64>,
    /// True ball speed (m/s).
    pub speed_m_per_s: Vec<f64>,
    /// Commanded ball speed (m/s).
    pub command_speed_m_per_s: Vec<f64>,
    /// Delivered torque (N m).
    pub torque_nm: Vec<f64>,
    /// Transmission friction torque (N m).
    pub friction_torque_nm: Vec<f64>,
}

/// The result of one trial.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TrialResult {
    /// The noise seed.
    pub seed: u64,
    /// Braking effort (N^2 m^2 s).
    pub j_p: f64,
    /// Braking effort in the paper's unit (N^2 mm^2 s).
    pub j_p_n2mm2s: f64,
    /// Stopped within the braking time.
    pub stopped: bool,
    /// Speed tracking RMS error over the braking phase (m/s).
    pub speed_rmse: f64,
    /// RMS tick-to-tick change of the delivered torque over the braking phase (N m).
    pub torque_jitter_nm: f64,
    /// Ball speed at the end of the braking phase (m/s).
    pub end_speed_m_per_s: f64,
    /// Time from the start of braking until the speed stays within the stop band (s); `None`
    /// if it never settles before the run ends.
    pub settle_time_secs: Option<f64>,
    /// Largest tilt magnitude over the run (rad).
    pub peak_tilt_rad: f64,
    /// Share of the braking phase the transmission spent stuck (0..1).
    pub stuck_fraction: f64,
    /// Why the run stopped early, if it did.
    pub fault: Option<String>,
    /// The MCAP log of the run, if written.
    pub log_path: Option<PathBuf>,
    /// The time series (not serialised).
    #[serde(skip)]
    pub series: TrialSeries,
}

/// Collects the metrics of one trial while it runs.
struct Metrics {
    radius_m: f64,
    brake_start_secs: f64,
    brake_end_secs: f64,
    j_p: f64,
    brake_steps: u64,
    stuck_steps: u64,
    err_sq_sum: f64,
    err_n: u64,
    jitter_sq_sum: f64,
    jitter_n: u64,
    last_torque: Option<f64>,
    series: TrialSeries,
    fault: Option<Fault>,
}

impl Metrics {
    fn in_brake(&self, t: f64, dt: f64) -> bool {
        t >= self.brake_start_secs - 0.5 * dt && t < self.brake_end_secs - 0.5 * dt
    }
}

impl Observer for Metrics {
    fn plant_step(&mut self, t: f64, dt: f64, _s: &WipState<f64>, step: &PlantStep) {
        if self.in_brake(t, dt) {
            self.j_p += step.applied_torque_nm * step.applied_torque_nm * dt;
            self.brake_steps += 1;
            if step.friction_mode == crate::planar::FrictionMode::Stuck {
                self.stuck_steps += 1;
            }
        }
    }

    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        let t = tick.time_secs;
        let r = self.radius_m;
        let speed = r * tick.state[BALL_RATE];
        let command = r * tick.command.ball_rate_rad_per_s;
        let torque = tick.step.applied_torque_nm;
        let s = &mut self.series;
        s.time_secs.push(t);
        s.tilt_rad.push(tick.state[TILT]);
        s.speed_m_per_s.push(speed);
        s.command_speed_m_per_s.push(command);
        s.torque_nm.push(torque);
        s.friction_torque_nm.push(tick.step.friction_torque_nm);
        if self.in_brake(t, 1e-9) {
            self.err_sq_sum += (speed - command).powi(2);
            self.err_n += 1;
            if let Some(last) = self.last_torque {
                self.jitter_sq_sum += (torque - last).powi(2);
                self.jitter_n += 1;
            }
            self.last_torque = Some(torque);
        }
    }

    fn fault(&mut self, fault: &Fault) {
        self.fault = Some(*fault);
    }
}

fn rms(sum_sq: f64, n: u64) -> f64 {
    if n == 0 {
        0.0
    } else {
        (sum_sq / n as f64).sqrt()
    }
}

/// Runs one trial of `controller` with noise seed `seed`; writes an MCAP log to `log_path`
/// when given.
pub fn run_trial(
    settings: &PiptbSettings,
    profile: &PiptbProfile,
    controller: &ControllerSettings,
    seed: u64,
    log_path: Option<&Path>,
) -> Result<TrialResult, ExperimentError> {
    let mut sim = PlanarSim::new(
        settings.robot,
        settings.friction,
        settings.sensors,
        settings.sim,
        seed,
    )?;
    let joint_gain = sim.plant().joint_gain(0.0);
    let mut ctrl = controller.build(&settings.robot, joint_gain)?;
    sim.reset(WipState::zeros());
    let mut metrics = Metrics {
        radius_m: settings.robot.plane.ball_radius_m,
        brake_start_secs: settings.brake_start_secs(),
        brake_end_secs: settings.brake_end_secs(),
        j_p: 0.0,
        brake_steps: 0,
        stuck_steps: 0,
        err_sq_sum: 0.0,
        err_n: 0,
        jitter_sq_sum: 0.0,
        jitter_n: 0,
        last_torque: None,
        series: TrialSeries::default(),
        fault: None,
    };
    let duration = settings.duration_secs();
    match log_path {
        Some(path) => {
            let mut log = McapLogger::create(path, LoggerOptions::default())?;
            let mut recorder = McapRecorder::new(&mut log, metrics.radius_m)?;
            sim.run(
                &mut ctrl,
                profile,
                duration,
                &mut (&mut metrics, &mut recorder),
            );
            recorder.finish()?;
            log.finish()?;
        }
        None => {
            sim.run(&mut ctrl, profile, duration, &mut metrics);
        }
    }
    Ok(finish_trial(settings, seed, metrics, log_path))
}

fn finish_trial(
    settings: &PiptbSettings,
    seed: u64,
    m: Metrics,
    log_path: Option<&Path>,
) -> TrialResult {
    let s = &m.series;
    let t3 = settings.brake_end_secs();
    let t2 = settings.brake_start_secs();
    let band = settings.stop_speed_m_per_s;
    // The tick nearest the end of braking.
    let end_speed = s
        .time_secs
        .iter()
        .zip(&s.speed_m_per_s)
        .min_by(|a, b| (a.0 - t3).abs().total_cmp(&(b.0 - t3).abs()))
        .map_or(f64::NAN, |(_, v)| *v);
    // The last tick outside the stop band; settled after it (if any tick follows).
    let last_outside = s
        .time_secs
        .iter()
        .zip(&s.speed_m_per_s)
        .rposition(|(_, v)| v.abs() > band);
    let settle_time_secs = match last_outside {
        Some(k) if k + 1 < s.time_secs.len() => Some((s.time_secs[k + 1] - t2).max(0.0)),
        Some(_) => None,
        None => Some(0.0),
    };
    let fault = m.fault.map(|f| match f.kind {
        FaultKind::Fell { tilt_rad } => {
            format!("fell at {:.3} s (tilt {:.2} rad)", f.time_secs, tilt_rad)
        }
        FaultKind::NonFinite => format!("non-finite state at {:.3} s", f.time_secs),
    });
    let stopped = fault.is_none() && end_speed.abs() <= band;
    TrialResult {
        seed,
        j_p: m.j_p,
        j_p_n2mm2s: m.j_p * 1e6,
        stopped,
        speed_rmse: rms(m.err_sq_sum, m.err_n),
        torque_jitter_nm: rms(m.jitter_sq_sum, m.jitter_n),
        end_speed_m_per_s: end_speed,
        settle_time_secs,
        peak_tilt_rad: s.tilt_rad.iter().map(|x| x.abs()).fold(0.0, f64::max),
        stuck_fraction: if m.brake_steps == 0 {
            0.0
        } else {
            m.stuck_steps as f64 / m.brake_steps as f64
        },
        fault,
        log_path: log_path.map(Path::to_path_buf),
        series: m.series,
    }
}

/// One controller's trials and their statistics.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ControllerResult {
    /// Which controller.
    #[serde(skip)]
    pub kind: ControllerKind,
    /// Every trial.
    pub trials: Vec<TrialResult>,
    /// Mean braking effort over the trials (N^2 m^2 s).
    pub j_p: f64,
    /// Sample standard deviation of the braking effort (N^2 m^2 s); 0 for one trial.
    pub j_p_std: f64,
    /// Mean braking effort in the paper's unit (N^2 mm^2 s).
    pub j_p_n2mm2s: f64,
    /// Every trial stopped in time.
    pub stopped_all: bool,
    /// Mean speed RMS error over the braking phase (m/s).
    pub speed_rmse: f64,
    /// Mean torque jitter (N m).
    pub torque_jitter_nm: f64,
    /// The paper's braking effort (N^2 mm^2 s, mean and std), where it gives one.
    pub paper_j_p_n2mm2s: Option<(f64, f64)>,
    /// Whether the paper's robot stopped in time.
    pub paper_stopped: Option<bool>,
}

impl ControllerResult {
    fn new(kind: ControllerKind, trials: Vec<TrialResult>) -> Self {
        let n = trials.len().max(1) as f64;
        let j_p = trials.iter().map(|t| t.j_p).sum::<f64>() / n;
        let j_p_std = if trials.len() > 1 {
            (trials.iter().map(|t| (t.j_p - j_p).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            0.0
        };
        let paper = PAPER.iter().find(|p| p.kind == kind).copied();
        Self {
            kind,
            j_p,
            j_p_std,
            j_p_n2mm2s: j_p * 1e6,
            stopped_all: trials.iter().all(|t| t.stopped),
            speed_rmse: trials.iter().map(|t| t.speed_rmse).sum::<f64>() / n,
            torque_jitter_nm: trials.iter().map(|t| t.torque_jitter_nm).sum::<f64>() / n,
            paper_j_p_n2mm2s: paper.and_then(|p| p.j_p_n2mm2s),
            paper_stopped: paper.and_then(|p| p.stopped),
            trials,
        }
    }
}

/// The braking reference as the summary reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ReferenceSummary {
    /// How it was computed (`nonlinear_optimum` or `linear_quadratic`).
    pub source: super::braking::BrakingSource,
    /// Its own effort `integral tau^2` (N^2 m^2 s): the lower bound a perfect tracker of a
    /// frictionless plant would reach.
    pub effort_n2m2s: f64,
    /// Its largest tilt (rad).
    pub peak_tilt_rad: f64,
    /// Braking time (s).
    pub duration_secs: f64,
}

/// The whole experiment's result.
#[derive(Clone, Debug, PartialEq)]
pub struct PiptbReport {
    /// Per controller, in the order LQR, PI-PD, LQR-PI.
    pub controllers: Vec<ControllerResult>,
    /// The braking reference.
    pub reference: ReferenceSummary,
    /// The settings used.
    pub settings: PiptbSettings,
}

impl PiptbReport {
    /// The summary's `piptb` value: `{"lqr": {...}, "pi_pd": {...}, "lqr_pi": {...},
    /// "reference": {...}}`, each controller with `trials` (`j_p` N^2 m^2 s, `stopped`,
    /// `speed_rmse` m/s, ...) and the mean `j_p`.
    pub fn summary_json(&self) -> serde_json::Value {
        let mut map = serde_json::Map::new();
        for c in &self.controllers {
            map.insert(
                c.kind.key().to_owned(),
                serde_json::to_value(c).unwrap_or(serde_json::Value::Null),
            );
        }
        map.insert(
            "reference".to_owned(),
            serde_json::to_value(&self.reference).unwrap_or(serde_json::Value::Null),
        );
        let s = &self.settings;
        map.insert(
            "settings".to_owned(),
            serde_json::json!({
                "trials": s.trials,
                "base_seed": s.base_seed,
                "cruise_speed_m_per_s": s.cruise_speed_m_per_s,
                "accel_secs": s.accel_secs,
                "hold_secs": s.hold_secs,
                "brake_secs": s.brake_secs,
                "stop_speed_m_per_s": s.stop_speed_m_per_s,
                "friction": s.friction,
                "sensors": s.sensors,
                "sim": s.sim,
            }),
        );
        serde_json::Value::Object(map)
    }

    /// A plain-text comparison table, ours beside the paper's.
    pub fn table(&self) -> String {
        let mut out = String::new();
        out.push_str(&format!(
            "PIPTB braking, 1 m/s to rest in {:.1} s ({} trial(s) per controller; reference: {:?}, \
             its own effort {:.3} N^2 m^2 s)\n",
            self.settings.brake_secs,
            self.settings.trials,
            self.reference.source,
            self.reference.effort_n2m2s
        ));
        out.push_str(
            "controller |  J_P (N^2 m^2 s)  | J_P (N^2 mm^2 s) | paper J_P (N^2 mm^2 s) | stopped | paper | speed RMSE (m/s) | jitter (N m)\n",
        );
        out.push_str(
            "-----------|-------------------|------------------|------------------------|---------|-------|------------------|-------------\n",
        );
        for c in &self.controllers {
            let paper = c
                .paper_j_p_n2mm2s
                .map_or("(not given)".to_owned(), |(m, s)| {
                    format!("{m:.2e} +- {s:.1e}")
                });
            let stopped = format!(
                "{}/{}",
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len()
            );
            let paper_stopped = match c.paper_stopped {
                Some(true) => "yes",
                Some(false) => "no",
                None => "-",
            };
            out.push_str(&format!(
                "{:<10} | {:>7.3} +- {:<6.3} | {:>16.3e} | {:>22} | {:>7} | {:>5} | {:>16.4} | {:>11.4}\n",
                c.kind.label(),
                c.j_p,
                c.j_p_std,
                c.j_p_n2mm2s,
                paper,
                stopped,
                paper_stopped,
                c.speed_rmse,
                c.torque_jitter_nm,
            ));
        }
        out
    }

    /// Writes the paper-style figures into `dir`: `piptb_<controller>.{svg,png}` (tilt, speed
    /// with its command, torque; braking shaded) for trial 0 of each controller, and
    /// `piptb_comparison.{svg,png}` (speed and torque of all three).
    pub fn plot(&self, dir: &Path) -> Result<Vec<PathBuf>, ExperimentError> {
        let mut written = Vec::new();
        let (t2, t3) = (
            self.settings.brake_start_secs(),
            self.settings.brake_end_secs(),
        );
        let mut speed = Subplot::new("ball speed (m/s)");
        let mut torque = Subplot::new("torque τ (N·m)");
        for c in &self.controllers {
            let Some(trial) = c.trials.first() else {
                continue;
            };
            let s = &trial.series;
            let tilt_deg: Vec<f64> = s.tilt_rad.iter().map(|x| x.to_degrees()).collect();
            let mut fig = TimeSeriesFigure::new(&format!(
                "PIPTB braking, {} (seed {}): J_P = {:.3} N²m²s",
                c.kind.label(),
                trial.seed,
                trial.j_p
            ))
            .with(Subplot::new("tilt θ (deg)").with(Series::new("θ", &s.time_secs, &tilt_deg)))
            .with(
                Subplot::new("ball speed (m/s)")
                    .with(Series::new("r φ̇", &s.time_secs, &s.speed_m_per_s))
                    .with(Series::new(
                        "r φ̇_c (command)",
                        &s.time_secs,
                        &s.command_speed_m_per_s,
                    )),
            )
            .with(
                Subplot::new("torque τ (N·m)")
                    .with(Series::new("τ delivered", &s.time_secs, &s.torque_nm))
                    .with(Series::new(
                        "transmission friction",
                        &s.time_secs,
                        &s.friction_torque_nm,
                    )),
            )
            .shade(t2, t3, "braking");
            if let (Some(f), Some(t)) = (&trial.fault, s.time_secs.last()) {
                fig = fig.marker(*t, f);
            }
            let paths = fig.save_svg_and_png(&dir.join(format!("piptb_{}", c.kind.key())))?;
            written.extend(paths);
            speed = speed.with(Series::new(c.kind.label(), &s.time_secs, &s.speed_m_per_s));
            torque = torque.with(Series::new(c.kind.label(), &s.time_secs, &s.torque_nm));
        }
        if let Some(c) = self.controllers.first().and_then(|c| c.trials.first()) {
            speed = speed.with(Series::new(
                "command",
                &c.series.time_secs,
                &c.series.command_speed_m_per_s,
            ));
        }
        let fig = TimeSeriesFigure::new("PIPTB braking: the three controllers (trial 0)")
            .with(speed)
            .with(torque)
            .shade(t2, t3, "braking");
        written.extend(fig.save_svg_and_png(&dir.join("piptb_comparison"))?);
        Ok(written)
    }
}

/// Runs the experiment: every controller of `kinds` (with its default settings) on
/// `settings.trials` seeded trials tracking `brake`. With `log_dir`, each trial writes
/// `log_dir/piptb_<controller>_trial<k>.mcap`. `progress` is called after every trial.
pub fn run(
    settings: &PiptbSettings,
    brake: BrakingTrajectory,
    kinds: &[ControllerKind],
    log_dir: Option<&Path>,
    progress: &mut dyn FnMut(ControllerKind, &TrialResult),
) -> Result<PiptbReport, ExperimentError> {
    let reference = ReferenceSummary {
        source: brake.source(),
        effort_n2m2s: brake.effort_n2m2s(),
        peak_tilt_rad: brake.peak_tilt_rad(),
        duration_secs: brake.duration_secs(),
    };
    let profile = PiptbProfile::new(settings, brake);
    let mut controllers = Vec::new();
    for &kind in kinds {
        let controller = ControllerSettings::new(kind);
        let mut trials = Vec::new();
        for k in 0..settings.trials {
            let seed = settings.base_seed.wrapping_add(k as u64);
            let path = log_dir.map(|d| d.join(format!("piptb_{}_trial{}.mcap", kind.key(), k)));
            let trial = run_trial(settings, &profile, &controller, seed, path.as_deref())?;
            progress(kind, &trial);
            trials.push(trial);
        }
        controllers.push(ControllerResult::new(kind, trials));
    }
    Ok(PiptbReport {
        controllers,
        reference,
        settings: settings.clone(),
    })
}

/// The braking reference for `settings`: the nonlinear minimum-effort optimum of the
/// trajectory optimiser ([`crate::trajopt::BrakingProblem`], Hermite-Simpson, 100 intervals,
/// free end torques, no path limits: the PIPTB needs under 2 N m of its 43.2), sampled every
/// millisecond. Should the solve not converge, the linear-quadratic optimum of the upright
/// linearisation stands in, and the summary's `reference.source` says so.
pub fn braking_reference(settings: &PiptbSettings) -> Result<BrakingTrajectory, ExperimentError> {
    let problem = BrakingProblem {
        plane: settings.robot.plane,
        initial_speed_m_per_s: settings.cruise_speed_m_per_s,
        duration_secs: settings.brake_secs,
        ..BrakingProblem::piptb()
    };
    if let Ok(solution) = problem.solve()
        && solution.is_solved()
        && let Some(t) = BrakingTrajectory::from_optimum(&solution.trajectory, 1e-3)
    {
        return Ok(t);
    }
    let wip = ballbot_core::Wip::new(settings.robot.plane).map_err(PlanarError::from)?;
    BrakingTrajectory::linear_quadratic(
        &wip,
        settings.cruise_speed_m_per_s,
        settings.brake_secs,
        1e-3,
    )
    .ok_or_else(|| ExperimentError::Braking("the linear-quadratic problem is singular".into()))
}

/// One variant of the ablation: the paper's settings with some imperfections switched off.
#[derive(Clone, Debug, PartialEq)]
pub struct AblationVariant {
    /// Short name: `ideal`, `noise_only`, `friction_only`, `friction_and_noise`.
    pub name: &'static str,
    /// The result.
    pub report: PiptbReport,
}

/// Runs the experiment (no logs) four times, to separate the effects of transmission friction
/// and sensor noise: ideal sensors without friction, noise only, friction only, and both
/// (`settings` as given). Same seeds and reference throughout.
pub fn ablation(
    settings: &PiptbSettings,
    brake: &BrakingTrajectory,
) -> Result<Vec<AblationVariant>, ExperimentError> {
    let ideal = SensorParams::ideal();
    let none = TransmissionFriction::none();
    let variants = [
        ("ideal", none, ideal),
        ("noise_only", none, settings.sensors),
        ("friction_only", settings.friction, ideal),
        ("friction_and_noise", settings.friction, settings.sensors),
    ];
    variants
        .into_iter()
        .map(|(name, friction, sensors)| {
            let s = PiptbSettings {
                friction,
                sensors,
                ..settings.clone()
            };
            let report = run(
                &s,
                brake.clone(),
                &ControllerKind::ALL,
                None,
                &mut |_, _| {},
            )?;
            Ok(AblationVariant { name, report })
        })
        .collect()
}

/// The ablation as the summary's `piptb_ablation` value: per variant, per controller, the mean
/// `j_p`, the number of trials that stopped, and the mean torque jitter.
pub fn ablation_json(variants: &[AblationVariant]) -> serde_json::Value {
    let mut map = serde_json::Map::new();
    for v in variants {
        let mut per = serde_json::Map::new();
        for c in &v.report.controllers {
            per.insert(
                c.kind.key().to_owned(),
                serde_json::json!({
                    "j_p": c.j_p,
                    "stopped": c.trials.iter().filter(|t| t.stopped).count(),
                    "trials": c.trials.len(),
                    "torque_jitter_nm": c.torque_jitter_nm,
                    "speed_rmse": c.speed_rmse,
                }),
            );
        }
        map.insert(v.name.to_owned(), serde_json::Value::Object(per));
    }
    serde_json::Value::Object(map)
}

/// The ablation as a plain-text table: mean `J_P` (N^2 m^2 s) / stopped / jitter (N m).
pub fn ablation_table(variants: &[AblationVariant]) -> String {
    let mut out = String::from(
        "PIPTB ablation: mean J_P (N^2 m^2 s), trials stopped, torque jitter (N m)\n\
         variant            | LQR                   | PI-PD                 | LQR-PI\n\
         -------------------|-----------------------|-----------------------|----------------------\n",
    );
    for v in variants {
        out.push_str(&format!("{:<18}", v.name));
        for c in &v.report.controllers {
            let cell = format!(
                "{:.3} {}/{} {:.3}",
                c.j_p,
                c.trials.iter().filter(|t| t.stopped).count(),
                c.trials.len(),
                c.torque_jitter_nm
            );
            out.push_str(&format!(" | {cell:<21}"));
        }
        out.push('\n');
    }
    out
}
