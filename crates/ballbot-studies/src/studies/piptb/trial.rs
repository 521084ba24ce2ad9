//! One PIPTB trial: the seeded run of one controller, its metrics and time series, and the
//! statistics of a controller's trials.

use super::{ExperimentError, PAPER, PiptbProfile, PiptbSettings};
use ballbot_core::WipState;
use ballbot_core::wip::{BALL_RATE, TILT};
use ballbot_log::planar::McapRecorder;
use ballbot_log::{LoggerOptions, McapLogger};
use ballbot_world::planar::{
    ControllerKind, ControllerSettings, Fault, FaultKind, Observer, OuterTick, PlanarSim, PlantStep,
};
use std::path::{Path, PathBuf};

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
    /// Braking effort so far, `integral_{t2}^{t} tau^2 dt` over the plant steps that start
    /// before the tick (N^2 m^2 s; 0 before braking), integrated at the plant rate.
    pub effort_n2m2s: Vec<f64>,
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
    /// Stopped: in the fixed window, within the stop band at its end `t3`; until stopped,
    /// the stop criterion was met before the cap.
    pub stopped: bool,
    /// End of the measured braking phase `t3` (s since the start of the run): the fixed end
    /// `t2 + brake_secs`, or, until stopped, when the testbed stopped (the cap if it never
    /// did).
    pub t3_secs: f64,
    /// Until stopped: the stop criterion was not met before the cap, so `t3` is the cap.
    /// Always false in the fixed window.
    pub t3_capped: bool,
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
    effort_n2m2s: f64,
    effort_before_step_n2m2s: f64,
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
        self.effort_before_step_n2m2s = self.effort_n2m2s;
        if t >= self.brake_start_secs - 0.5 * dt {
            self.effort_n2m2s += step.applied_torque_nm * step.applied_torque_nm * dt;
        }
        if self.in_brake(t, dt) {
            self.j_p += step.applied_torque_nm * step.applied_torque_nm * dt;
            self.brake_steps += 1;
            if step.friction_mode == ballbot_world::planar::FrictionMode::Stuck {
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
        // The tick comes after the plant step that starts at it: the effort before that step.
        s.effort_n2m2s.push(self.effort_before_step_n2m2s);
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

pub(super) fn rms(sum_sq: f64, n: u64) -> f64 {
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
        effort_n2m2s: 0.0,
        effort_before_step_n2m2s: 0.0,
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
        t3_secs: t3,
        t3_capped: false,
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
    pub(super) fn new(kind: ControllerKind, trials: Vec<TrialResult>) -> Self {
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
