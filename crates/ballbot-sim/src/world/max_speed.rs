//! The paper's maximum-speed benchmark (Sec. V) as a study in the 3D world: seeded slow-ramp
//! trials per heading, the failing ramp acceleration per heading (bisection), a capability
//! map over headings, and the sensitivity to the roller-ball friction `mu` and the COM height
//! `l`.
//!
//! Two metrics, because the world separates what the paper's protocol mixes:
//!
//! * **Maximum speed** (the paper's protocol as we read it): a slow velocity ramp at
//!   [`MaxSpeedProtocol::slow_ramp`] (0.25 m/s^2 to 6 m/s, then 1 s hold) until failure;
//!   the highest ball speed along the heading before the failure. A run that reaches the end
//!   of the ramp without failing is *censored*: its maximum speed is only a lower bound
//!   (`>= X m/s`), never a failure speed.
//! * **Failing acceleration**: the largest constant ramp acceleration (on a grid of
//!   [`MaxSpeedProtocol::accel_resolution_m_per_s2`]) with which a ramp to
//!   [`MaxSpeedProtocol::fast_top_m_per_s`] and a 1 s hold survives. Traction demand in this
//!   world comes from acceleration, so this is where the paper's direction dependence shows.
//!
//! The command shaper of the core caps speed and acceleration by default (2 m/s, 1 m/s^2); the
//! study lifts those caps with [`ShaperLimits`] (documented defaults) and keeps the core's jerk
//! limit (2 m/s^3). Trials differ only by the seed of the sensor noise
//! ([`crate::world::SensorParams::seed`]); the simulation is otherwise deterministic, so a trial
//! is reproducible bit for bit from its seed. Jobs run in parallel on scoped threads; results
//! do not depend on the number of threads.

use super::WorldError;
use super::experiments::{RampParams, RampResult, max_speed_ramp_with_config};
use super::failure::{Failure, FailureKind};
use super::params::WorldParams;
use crate::plot::{LineStyle, PolarFigure, PolarSeries, Series, Subplot, TimeSeriesFigure};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::{BallbotParams, OmniKinematics, Wip};
use nalgebra::Vector4;
use serde_json::{Value, json};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The command-shaper limits used by the study instead of the core's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShaperLimits {
    /// Speed cap of each translation axis (m/s). Default 8 (above any ramp's top).
    pub max_speed_m_per_s: f64,
    /// Acceleration cap (m/s^2). Default 20 (above any ramp's acceleration).
    pub max_accel_m_per_s2: f64,
    /// Largest tilt command (rad). Default 0.5.
    pub max_tilt_command_rad: f64,
    /// Largest tilt-rate command (rad/s). Default 5.
    pub max_tilt_rate_command_rad_per_s: f64,
}

impl Default for ShaperLimits {
    fn default() -> Self {
        Self {
            max_speed_m_per_s: 8.0,
            max_accel_m_per_s2: 20.0,
            max_tilt_command_rad: 0.5,
            max_tilt_rate_command_rad_per_s: 5.0,
        }
    }
}

impl ShaperLimits {
    /// Writes these limits into a controller configuration (the jerk limit stays).
    pub fn apply(&self, config: &mut BallbotControllerConfig<f64>) {
        config.shaping.translation.max_value = self.max_speed_m_per_s;
        config.shaping.translation.max_rate_per_s = self.max_accel_m_per_s2;
        config.shaping.max_tilt_command_rad = self.max_tilt_command_rad;
        config.shaping.max_tilt_rate_command_rad_per_s = self.max_tilt_rate_command_rad_per_s;
    }
}

/// The protocol of one run of each metric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxSpeedProtocol {
    /// The slow ramp (maximum-speed metric). Default 0.25 m/s^2 to 6 m/s after 0.5 s at
    /// rest, samples every 10 ms (6 m/s: near the actuators' no-load speed, far above the
    /// paper's 2.3 m/s, so that the ramp's end rarely censors the result).
    pub slow_ramp: RampParams,
    /// Top speed of the ramps of the failing-acceleration search (m/s). Default 3.
    pub fast_top_m_per_s: f64,
    /// Searched accelerations (m/s^2), `[low, high]`. Default `[0.5, 3.0]`: with the core's
    /// jerk limit `j` (2 m/s^3) the shaped command of a ramp to the top speed `v` cannot
    /// accelerate faster than `sqrt(j v)` (2.45 m/s^2 to 3 m/s; the acceleration rises and
    /// falls at the jerk limit), so steeper ramps all give the same command.
    pub accel_bracket_m_per_s2: [f64; 2],
    /// Grid of the searched accelerations (m/s^2). Default 0.05.
    pub accel_resolution_m_per_s2: f64,
    /// Command-shaper limits.
    pub shaper: ShaperLimits,
}

impl MaxSpeedProtocol {
    /// Finest grid of the failing-acceleration search (m/s^2): finer grids only add runs
    /// (the bisection needs `log2((high - low) / resolution)` of them) and would overflow the
    /// integer grid for a zero resolution.
    pub const MIN_ACCEL_RESOLUTION_M_PER_S2: f64 = 1e-6;

    /// Checks the search bracket, its grid and the fast ramps' top speed (the slow ramp is
    /// checked by the run itself).
    ///
    /// ```
    /// use ballbot_sim::world::max_speed::MaxSpeedProtocol;
    /// assert!(MaxSpeedProtocol::default().validate().is_ok());
    /// let bad = MaxSpeedProtocol { accel_resolution_m_per_s2: 0.0, ..Default::default() };
    /// let err = bad.validate().err().map(|e| e.to_string()).unwrap_or_default();
    /// assert!(err.contains("accel_resolution_m_per_s2"), "{err}");
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let [low, high] = self.accel_bracket_m_per_s2;
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        if !(self.accel_resolution_m_per_s2 >= Self::MIN_ACCEL_RESOLUTION_M_PER_S2
            && self.accel_resolution_m_per_s2.is_finite())
        {
            return invalid(
                "protocol.accel_resolution_m_per_s2",
                "must be finite and >= 1e-6 m/s^2",
            );
        }
        if !(low > 0.0 && high > low && high.is_finite()) {
            return invalid(
                "protocol.accel_bracket_m_per_s2",
                "need 0 < low < high < inf",
            );
        }
        if !(self.fast_top_m_per_s.is_finite() && self.fast_top_m_per_s > 0.0) {
            return invalid("protocol.fast_top_m_per_s", "must be finite and > 0");
        }
        Ok(())
    }
}

impl Default for MaxSpeedProtocol {
    fn default() -> Self {
        Self {
            slow_ramp: RampParams {
                accel_m_per_s2: 0.25,
                max_command_m_per_s: 6.0,
                settle_s: 0.5,
                sample_every_s: 0.01,
            },
            fast_top_m_per_s: 3.0,
            accel_bracket_m_per_s2: [0.5, 3.0],
            accel_resolution_m_per_s2: 0.05,
            shaper: ShaperLimits::default(),
        }
    }
}

/// Which headings and variants the study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxSpeedStudySettings {
    /// Run protocol.
    pub protocol: MaxSpeedProtocol,
    /// Headings with seeded slow-ramp trials (deg, body frame, 0 towards OW1). Default
    /// 0, 90, 180 (the paper's).
    pub trial_headings_deg: Vec<f64>,
    /// Seeds of the trials (one trial per seed). Default 1, 2, 3.
    pub seeds: Vec<u64>,
    /// Headings of the capability map (deg): one slow ramp (first seed) and one
    /// failing-acceleration search each. Default every 15 deg from 0 to 345.
    pub map_headings_deg: Vec<f64>,
    /// Headings of the sensitivity study (deg). Default 0 and 180.
    pub sensitivity_headings_deg: Vec<f64>,
    /// Roller-ball friction coefficients of the sensitivity study. Default 0.4, 0.6, 0.8.
    pub sensitivity_mu: Vec<f64>,
    /// COM heights of the sensitivity study (m). Default 0.4, 0.5, 0.7.
    pub sensitivity_com_height_m: Vec<f64>,
    /// Worker threads; 0 uses every available core. Default 0.
    pub threads: usize,
}

impl MaxSpeedStudySettings {
    /// The full study (about 250 runs; a minute or two in a release build on two cores).
    pub fn paper() -> Self {
        Self {
            protocol: MaxSpeedProtocol::default(),
            trial_headings_deg: vec![0.0, 90.0, 180.0],
            seeds: vec![1, 2, 3],
            map_headings_deg: (0..24).map(|i| f64::from(i) * 15.0).collect(),
            sensitivity_headings_deg: vec![0.0, 180.0],
            sensitivity_mu: vec![0.4, 0.6, 0.8],
            sensitivity_com_height_m: vec![0.4, 0.5, 0.7],
            threads: 0,
        }
    }

    /// The CI smoke variant: one trial at 0 and 180 deg with a short fast ramp (1 m/s^2 to
    /// 3 m/s) in place of the slow one, the search on a 0.2 m/s^2 grid between 1.0 and
    /// 3.0 m/s^2, no further map headings, no sensitivity.
    pub fn quick() -> Self {
        let defaults = MaxSpeedProtocol::default();
        let protocol = MaxSpeedProtocol {
            slow_ramp: RampParams {
                accel_m_per_s2: 1.0,
                max_command_m_per_s: 3.0,
                ..defaults.slow_ramp
            },
            accel_bracket_m_per_s2: [1.0, 3.0],
            accel_resolution_m_per_s2: 0.2,
            ..defaults
        };
        Self {
            protocol,
            trial_headings_deg: vec![0.0, 180.0],
            seeds: vec![1],
            map_headings_deg: vec![0.0, 180.0],
            sensitivity_headings_deg: Vec::new(),
            sensitivity_mu: Vec::new(),
            sensitivity_com_height_m: Vec::new(),
            threads: 0,
        }
    }

    fn validate(&self) -> Result<(), WorldError> {
        self.protocol.validate()?;
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        if self.seeds.is_empty() {
            return invalid("seeds", "need at least one seed");
        }
        let positive = |x: &f64| x.is_finite() && *x > 0.0;
        if !self.sensitivity_mu.iter().all(positive)
            || !self.sensitivity_com_height_m.iter().all(positive)
        {
            return invalid("sensitivity", "mu and COM heights must be > 0");
        }
        Ok(())
    }
}

/// One ramp run, reduced to what the study reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrialOutcome {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// Ramp acceleration (m/s^2).
    pub accel_m_per_s2: f64,
    /// Highest ball speed along the heading before the failure (m/s).
    pub max_speed_m_per_s: f64,
    /// The failure; `None` if the ramp and its hold ended first (censored).
    pub failure: Option<Failure>,
    /// When the controller's supervisor stopped balancing (controlled stop, e.g. at a wheel's
    /// speed limit) (s), if it did; a failure after it is the stop's.
    pub supervisor_stop_s: Option<f64>,
    /// Largest friction-cone utilisation of any wheel in the samples.
    pub peak_cone_utilisation: f64,
    /// Smallest normal force of any wheel in the samples (N).
    pub min_normal_force_n: f64,
    /// Largest tilt from the vertical in the samples (rad).
    pub peak_tilt_rad: f64,
}

impl TrialOutcome {
    fn from_run(run: &RampResult, seed: u64, accel_m_per_s2: f64) -> Self {
        let s = &run.samples;
        Self {
            heading_deg: run.heading_deg,
            seed,
            accel_m_per_s2,
            max_speed_m_per_s: run.max_speed_m_per_s,
            failure: run.failure,
            supervisor_stop_s: run.supervisor_stop_s,
            peak_cone_utilisation: s.iter().map(|x| x.max_cone_utilisation).fold(0.0, f64::max),
            min_normal_force_n: s
                .iter()
                .flat_map(|x| x.normal_force_n)
                .fold(f64::INFINITY, f64::min),
            peak_tilt_rad: s.iter().map(|x| x.tilt_rad).fold(0.0, f64::max),
        }
    }

    /// Whether the run ended without failure: the maximum speed is then a lower bound.
    pub fn censored(&self) -> bool {
        self.failure.is_none()
    }

    /// The maximum speed as text: `2.31` for a failure, `>= 3.50` for a censored run.
    pub fn speed_text(&self) -> String {
        if self.censored() {
            format!(">= {:.2}", self.max_speed_m_per_s)
        } else {
            format!("{:.2}", self.max_speed_m_per_s)
        }
    }

    fn to_json(self) -> Value {
        json!({
            "heading_deg": self.heading_deg,
            "seed": self.seed,
            "accel_m_per_s2": self.accel_m_per_s2,
            "max_speed_m_per_s": self.max_speed_m_per_s,
            "censored": self.censored(),
            "failure": failure_json(self.failure),
            "supervisor_stop_s": self.supervisor_stop_s,
            "peak_cone_utilisation": self.peak_cone_utilisation,
            "min_normal_force_n": self.min_normal_force_n,
            "peak_tilt_deg": self.peak_tilt_rad.to_degrees(),
        })
    }
}

/// The paper's name of the wheel with index `wheel` (0 is OW1).
pub fn wheel_label(wheel: usize) -> String {
    format!("OW{}", wheel + 1)
}

/// A failure as short text, e.g. `slip OW3 at 13.09 s`; `-` for none.
pub fn failure_text(failure: Option<Failure>) -> String {
    match failure {
        None => "-".to_owned(),
        Some(f) => {
            let what = match f.kind {
                FailureKind::Tilt { tilt_rad } => format!("tilt {:.0} deg", tilt_rad.to_degrees()),
                FailureKind::BodyTouchedFloor => "body on floor".to_owned(),
                FailureKind::SustainedSlip { wheel } => format!("slip {}", wheel_label(wheel)),
                FailureKind::LiftOff { wheel } => format!("lift-off {}", wheel_label(wheel)),
            };
            format!("{what} at {:.2} s", f.time_s)
        }
    }
}

fn failure_json(failure: Option<Failure>) -> Value {
    match failure {
        None => Value::Null,
        Some(f) => {
            let (kind, wheel) = match f.kind {
                FailureKind::Tilt { .. } => ("tilt", None),
                FailureKind::BodyTouchedFloor => ("body_touched_floor", None),
                FailureKind::SustainedSlip { wheel } => ("sustained_slip", Some(wheel)),
                FailureKind::LiftOff { wheel } => ("lift_off", Some(wheel)),
            };
            json!({
                "kind": kind,
                "wheel": wheel.map(wheel_label),
                "time_s": f.time_s,
            })
        }
    }
}

/// The slow-ramp trials at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadingTrials {
    /// Heading (deg).
    pub heading_deg: f64,
    /// One outcome per seed, in seed order.
    pub trials: Vec<TrialOutcome>,
    /// The first trial's time series (for the Fig. "acc" plot).
    pub first_run: RampResult,
}

impl HeadingTrials {
    /// Mean of the trials' maximum speeds (m/s); a lower bound if any trial is censored.
    pub fn mean_max_speed_m_per_s(&self) -> f64 {
        let n = self.trials.len().max(1) as f64;
        self.trials.iter().map(|t| t.max_speed_m_per_s).sum::<f64>() / n
    }

    /// Sample standard deviation of the trials' maximum speeds (m/s); 0 for one trial.
    pub fn std_max_speed_m_per_s(&self) -> f64 {
        let n = self.trials.len();
        if n < 2 {
            return 0.0;
        }
        let mean = self.mean_max_speed_m_per_s();
        let ss: f64 = self
            .trials
            .iter()
            .map(|t| (t.max_speed_m_per_s - mean).powi(2))
            .sum();
        (ss / (n - 1) as f64).sqrt()
    }

    /// How many trials reached the end of the ramp without failure.
    pub fn censored_count(&self) -> usize {
        self.trials.iter().filter(|t| t.censored()).count()
    }
}

/// The result of a failing-acceleration search at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct FailingAccel {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Largest acceleration on the grid whose ramp survived (m/s^2); `None` if even the
    /// bracket's low end failed.
    pub largest_surviving_m_per_s2: Option<f64>,
    /// Smallest acceleration on the grid whose ramp failed (m/s^2); `None` if the bracket's
    /// high end survived (censored: the limit is above the bracket).
    pub smallest_failing_m_per_s2: Option<f64>,
    /// The run at `smallest_failing_m_per_s2` (reduced), if any.
    pub failing: Option<TrialOutcome>,
    /// The run at `largest_surviving_m_per_s2` (reduced), if any.
    pub surviving: Option<TrialOutcome>,
    /// The failing run's time series (for plots), if any.
    pub failing_run: Option<RampResult>,
    /// Ramps simulated by the search.
    pub runs: usize,
}

impl FailingAccel {
    /// Whether the failing run failed while its shaped command was still rising (below 98 % of
    /// the ramp's top `top_m_per_s`): a failure of acceleration; `Some(false)` is a failure at
    /// cruise (during the hold), `None` if no run failed.
    pub fn failed_during_ramp(&self, top_m_per_s: f64) -> Option<bool> {
        let run = self.failing_run.as_ref()?;
        let last = run.samples.last()?;
        Some(last.shaped_command_m_per_s < 0.98 * top_m_per_s)
    }

    /// The limit as text: `1.75` (largest surviving), `>= 4.00` if the bracket's top survived,
    /// `< 0.50` if its bottom failed.
    pub fn text(&self) -> String {
        match (
            self.largest_surviving_m_per_s2,
            self.smallest_failing_m_per_s2,
        ) {
            (Some(a), Some(_)) => format!("{a:.2}"),
            (Some(a), None) => format!(">= {a:.2}"),
            (None, Some(a)) => format!("< {a:.2}"),
            (None, None) => "-".to_owned(),
        }
    }

    fn to_json(&self, top_m_per_s: f64) -> Value {
        json!({
            "heading_deg": self.heading_deg,
            "failed_during_ramp": self.failed_during_ramp(top_m_per_s),
            "largest_surviving_m_per_s2": self.largest_surviving_m_per_s2,
            "smallest_failing_m_per_s2": self.smallest_failing_m_per_s2,
            "censored": self.smallest_failing_m_per_s2.is_none(),
            "failure": failure_json(self.failing.and_then(|f| f.failure)),
            "speed_at_failure_m_per_s": self.failing.map(|f| f.max_speed_m_per_s),
            "surviving_peak_cone_utilisation": self.surviving.map(|s| s.peak_cone_utilisation),
            "runs": self.runs,
        })
    }
}

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

/// Which parameter a sensitivity row varies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Variant {
    /// The robot as given.
    Nominal,
    /// Roller-ball friction coefficient `mu` (dimensionless).
    WheelBallFriction(f64),
    /// COM height `l` of the body above the ball centre (m), in both planes.
    ComHeight(f64),
}

impl Variant {
    /// The world parameters of this variant.
    pub fn apply(&self, params: WorldParams) -> WorldParams {
        let mut p = params;
        match *self {
            Self::Nominal => {}
            Self::WheelBallFriction(mu) => p.robot.drivetrain.wheel_ball_friction = mu,
            Self::ComHeight(l) => {
                p.robot.sagittal.com_height_m = l;
                p.robot.frontal.com_height_m = l;
            }
        }
        p
    }
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

/// A value the paper reports for MiaPURE's maximum speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperMaxSpeed {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Speed (m/s).
    pub speed_m_per_s: f64,
    /// Whether the paper gives only an upper bound ("less than").
    pub upper_bound: bool,
}

/// The paper's numbers (Sec. V, Fig. "acc"): below 0.6 m/s at 0 deg, 2.3 m/s at 180 deg; at
/// 90 deg it reports no number ("in between").
pub const PAPER_MAX_SPEED: [PaperMaxSpeed; 2] = [
    PaperMaxSpeed {
        heading_deg: 0.0,
        speed_m_per_s: 0.6,
        upper_bound: true,
    },
    PaperMaxSpeed {
        heading_deg: 180.0,
        speed_m_per_s: 2.3,
        upper_bound: false,
    },
];

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

#[derive(Clone, Copy, Debug)]
enum Job {
    Slow {
        variant: Variant,
        heading_deg: f64,
        seed: u64,
    },
    Search {
        variant: Variant,
        heading_deg: f64,
    },
}

enum JobResult {
    Slow(RampResult, TrialOutcome),
    Search(FailingAccel),
}

/// Number of jobs (one slow ramp or one failing-acceleration search each) the study runs, for
/// a progress bar.
pub fn job_count(params: &WorldParams, settings: &MaxSpeedStudySettings) -> usize {
    jobs(params, settings).len()
}

fn same(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// The distinct jobs of the study; variants equal to the nominal robot share its jobs.
fn jobs(params: &WorldParams, settings: &MaxSpeedStudySettings) -> Vec<Job> {
    let first_seed = settings.seeds.first().copied().unwrap_or(0);
    let mut out = Vec::new();
    // Searches first: they are the longest jobs, so the pool ends evenly.
    let search = |variant: Variant, heading_deg: f64, out: &mut Vec<Job>| {
        let job = Job::Search {
            variant: normalise(variant, params),
            heading_deg,
        };
        if !out.iter().any(|j| job_eq(j, &job)) {
            out.push(job);
        }
    };
    for &h in &settings.map_headings_deg {
        search(Variant::Nominal, h, &mut out);
    }
    for &h in &settings.sensitivity_headings_deg {
        search(Variant::Nominal, h, &mut out);
        for v in sensitivity_variants(settings) {
            search(v, h, &mut out);
        }
    }
    let slow = |variant: Variant, heading_deg: f64, seed: u64, out: &mut Vec<Job>| {
        let job = Job::Slow {
            variant: normalise(variant, params),
            heading_deg,
            seed,
        };
        if !out.iter().any(|j| job_eq(j, &job)) {
            out.push(job);
        }
    };
    for &h in &settings.trial_headings_deg {
        for &seed in &settings.seeds {
            slow(Variant::Nominal, h, seed, &mut out);
        }
    }
    for &h in &settings.map_headings_deg {
        slow(Variant::Nominal, h, first_seed, &mut out);
    }
    for &h in &settings.sensitivity_headings_deg {
        slow(Variant::Nominal, h, first_seed, &mut out);
        for v in sensitivity_variants(settings) {
            slow(v, h, first_seed, &mut out);
        }
    }
    out
}

/// The non-nominal sensitivity variants (values equal to the nominal robot's are the nominal
/// runs, not repeated).
fn sensitivity_variants(settings: &MaxSpeedStudySettings) -> Vec<Variant> {
    let mut v: Vec<Variant> = settings
        .sensitivity_mu
        .iter()
        .map(|&mu| Variant::WheelBallFriction(mu))
        .collect();
    v.extend(
        settings
            .sensitivity_com_height_m
            .iter()
            .map(|&l| Variant::ComHeight(l)),
    );
    v
}

fn variant_eq(a: Variant, b: Variant) -> bool {
    match (a, b) {
        (Variant::Nominal, Variant::Nominal) => true,
        (Variant::WheelBallFriction(x), Variant::WheelBallFriction(y))
        | (Variant::ComHeight(x), Variant::ComHeight(y)) => same(x, y),
        _ => false,
    }
}

fn job_eq(a: &Job, b: &Job) -> bool {
    match (a, b) {
        (
            Job::Slow {
                variant: va,
                heading_deg: ha,
                seed: sa,
            },
            Job::Slow {
                variant: vb,
                heading_deg: hb,
                seed: sb,
            },
        ) => variant_eq(*va, *vb) && same(*ha, *hb) && sa == sb,
        (
            Job::Search {
                variant: va,
                heading_deg: ha,
            },
            Job::Search {
                variant: vb,
                heading_deg: hb,
            },
        ) => variant_eq(*va, *vb) && same(*ha, *hb),
        _ => false,
    }
}

/// Collapses a variant equal to the nominal robot into [`Variant::Nominal`], so its runs are
/// shared with the nominal ones.
fn normalise(variant: Variant, params: &WorldParams) -> Variant {
    match variant {
        Variant::WheelBallFriction(mu) if same(mu, params.robot.drivetrain.wheel_ball_friction) => {
            Variant::Nominal
        }
        Variant::ComHeight(l)
            if same(l, params.robot.sagittal.com_height_m)
                && same(l, params.robot.frontal.com_height_m) =>
        {
            Variant::Nominal
        }
        v => v,
    }
}

/// The core's quasi-static prediction of the failing acceleration (m/s^2) at `heading_deg`:
/// the ball acceleration of the steady lean (tilt held by the WIP torque, upright speed zero)
/// at which the first omniwheel contact of the core's contact model
/// ([`ballbot_core::OmniKinematics::wip_contact_forces`]) fails (slip or lift-off), scanning the
/// lean in 0.05 deg steps up to 30 deg; `None` if no contact fails up to 30 deg or the robot
/// is invalid. MiaPURE 60 kg, mu 0.6: 2.25 (0 deg), 2.48 (90 deg), 4.07 (180 deg) m/s^2.
pub fn quasi_static_failing_accel_m_per_s2(
    robot: &BallbotParams<f64>,
    heading_deg: f64,
) -> Option<f64> {
    let kin = OmniKinematics::from_ballbot(robot).ok()?;
    let wip = Wip::new(robot.sagittal).ok()?;
    let r = robot.sagittal.ball_radius_m;
    (0..=600).find_map(|k| {
        let s = Vector4::new((f64::from(k) * 0.05).to_radians(), 0.0, 0.0, 0.0);
        // The torque that holds the lean: theta_ddot(tau) is affine in tau.
        let at_zero = wip.accelerations(&s, 0.0)[0];
        let slope = wip.accelerations(&s, 1.0)[0] - at_zero;
        let torque_nm = -at_zero / slope;
        let contacts = kin.wip_contact_forces(&wip, heading_deg.to_radians(), &s, torque_nm);
        (!contacts.all_hold()).then(|| wip.accelerations(&s, torque_nm)[1] * r)
    })
}

/// The controller the study runs: designed from the (varied) robot, shaper caps lifted
/// ([`MaxSpeedProtocol::shaper`]).
pub fn controller(
    params: &WorldParams,
    protocol: &MaxSpeedProtocol,
) -> Result<BallbotControllerConfig<f64>, WorldError> {
    let mut config = BallbotControllerConfig::design(&params.robot)?;
    protocol.shaper.apply(&mut config);
    Ok(config)
}

/// One slow-ramp trial: [`MaxSpeedProtocol::slow_ramp`] at `heading_deg` with the sensor
/// noise seeded by `seed`; returns the time series and its reduction.
pub fn slow_ramp_trial(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
) -> Result<(RampResult, TrialOutcome), WorldError> {
    let mut p = params;
    p.sensors.seed = seed;
    let config = controller(&p, protocol)?;
    let run = max_speed_ramp_with_config(p, config, heading_deg, &protocol.slow_ramp)?;
    let outcome = TrialOutcome::from_run(&run, seed, protocol.slow_ramp.accel_m_per_s2);
    Ok((run, outcome))
}

/// The failing-acceleration search at `heading_deg`: bisection on the grid of
/// [`MaxSpeedProtocol::accel_resolution_m_per_s2`] inside
/// [`MaxSpeedProtocol::accel_bracket_m_per_s2`] for the largest ramp acceleration whose ramp to
/// [`MaxSpeedProtocol::fast_top_m_per_s`] (and 1 s hold) survives. Assumes that failure is
/// monotonic in the acceleration (it checks both ends of the bracket first).
pub fn failing_acceleration(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
) -> Result<FailingAccel, WorldError> {
    protocol.validate()?;
    let mut p = params;
    p.sensors.seed = seed;
    let config = controller(&p, protocol)?;
    let res = protocol.accel_resolution_m_per_s2;
    let [low, high] = protocol.accel_bracket_m_per_s2;
    let mut runs = 0;
    let mut run = |k: i64| -> Result<(RampResult, TrialOutcome), WorldError> {
        runs += 1;
        // On the grid, without the product's rounding noise (1.95, not 1.9500000000000002).
        let accel_m_per_s2 = (k as f64 * res * 1e9).round() / 1e9;
        let ramp = RampParams {
            accel_m_per_s2,
            max_command_m_per_s: protocol.fast_top_m_per_s,
            ..protocol.slow_ramp
        };
        let r = max_speed_ramp_with_config(p, config, heading_deg, &ramp)?;
        let o = TrialOutcome::from_run(&r, seed, accel_m_per_s2);
        Ok((r, o))
    };
    let mut lo = ((low / res).round() as i64).max(1);
    let mut hi = ((high / res).round() as i64).max(lo + 1);
    let (lo_run, lo_out) = run(lo)?;
    if !lo_out.censored() {
        return Ok(FailingAccel {
            heading_deg,
            largest_surviving_m_per_s2: None,
            smallest_failing_m_per_s2: Some(lo_out.accel_m_per_s2),
            failing: Some(lo_out),
            surviving: None,
            failing_run: Some(lo_run),
            runs: 1,
        });
    }
    let (hi_run, hi_out) = run(hi)?;
    if hi_out.censored() {
        return Ok(FailingAccel {
            heading_deg,
            largest_surviving_m_per_s2: Some(hi_out.accel_m_per_s2),
            smallest_failing_m_per_s2: None,
            failing: None,
            surviving: Some(hi_out),
            failing_run: None,
            runs: 2,
        });
    }
    let (mut surviving, mut failing, mut failing_run) = (lo_out, hi_out, hi_run);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let (r, o) = run(mid)?;
        if o.censored() {
            lo = mid;
            surviving = o;
        } else {
            hi = mid;
            failing = o;
            failing_run = r;
        }
    }
    Ok(FailingAccel {
        heading_deg,
        largest_surviving_m_per_s2: Some(surviving.accel_m_per_s2),
        smallest_failing_m_per_s2: Some(failing.accel_m_per_s2),
        failing: Some(failing),
        surviving: Some(surviving),
        failing_run: Some(failing_run),
        runs,
    })
}

fn run_job(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    job: Job,
) -> Result<JobResult, WorldError> {
    let first = |v: Variant| v.apply(params);
    match job {
        Job::Slow {
            variant,
            heading_deg,
            seed,
        } => {
            let (run, outcome) = slow_ramp_trial(first(variant), protocol, heading_deg, seed)?;
            Ok(JobResult::Slow(run, outcome))
        }
        Job::Search {
            variant,
            heading_deg,
        } => Ok(JobResult::Search(failing_acceleration(
            first(variant),
            protocol,
            heading_deg,
            0,
        )?)),
    }
}

/// Runs the study on `params` (the nominal robot). `progress` is called after every job with
/// a short description (from worker threads).
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
    let unique = jobs(&params, settings);
    let threads = if settings.threads == 0 {
        std::thread::available_parallelism().map_or(1, usize::from)
    } else {
        settings.threads
    }
    .clamp(1, unique.len().max(1));
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<JobResult, WorldError>>>> =
        Mutex::new((0..unique.len()).map(|_| None).collect());
    let protocol = settings.protocol;
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&job) = unique.get(i) else { break };
                    let r = run_job(params, &protocol, job);
                    progress(&describe(job));
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(r);
                    }
                }
            });
        }
    });
    let results = results
        .into_inner()
        .map_err(|_| WorldError::InvalidParameter {
            field: "threads",
            requirement: "a worker thread panicked",
        })?;
    let mut done: Vec<(Job, JobResult)> = Vec::with_capacity(unique.len());
    for (job, r) in unique.into_iter().zip(results) {
        let r = r.ok_or(WorldError::InvalidParameter {
            field: "threads",
            requirement: "a worker thread stopped before its job finished",
        })??;
        done.push((job, r));
    }
    assemble(params, settings, &done)
}

fn describe(job: Job) -> String {
    let v = match job {
        Job::Slow { variant, .. } | Job::Search { variant, .. } => match variant {
            Variant::Nominal => String::new(),
            Variant::WheelBallFriction(mu) => format!(" mu {mu}"),
            Variant::ComHeight(l) => format!(" l {l} m"),
        },
    };
    match job {
        Job::Slow {
            heading_deg, seed, ..
        } => format!("slow ramp {heading_deg} deg seed {seed}{v}"),
        Job::Search { heading_deg, .. } => format!("accel search {heading_deg} deg{v}"),
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
            JobResult::Slow(run, o) if job_eq(j, &want) => Some((run, *o)),
            _ => None,
        })
    };
    let search = |variant: Variant, heading_deg: f64| {
        let want = Job::Search {
            variant: normalise(variant, &params),
            heading_deg,
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
    let mut mus = settings.sensitivity_mu.clone();
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
        .map(|&mu| ("mu", mu, Variant::WheelBallFriction(mu)))
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

/// `{:.2}` of a value, `-` for none.
fn optional(value: Option<f64>) -> String {
    value.map_or("-".to_owned(), |v| format!("{v:.2}"))
}

/// `{:.0}` of a heading, as the summary's object key.
fn heading_key(heading_deg: f64) -> String {
    format!("{heading_deg:.0}")
}

impl MaxSpeedStudy {
    /// The failing-acceleration search at `heading_deg` (from the map), if it ran.
    pub fn failing_at(&self, heading_deg: f64) -> Option<&FailingAccel> {
        self.map
            .iter()
            .find(|m| same(m.heading_deg, heading_deg))
            .map(|m| &m.failing)
    }

    /// `max_speed_by_heading`: heading (deg, as text) to the mean slow-ramp maximum speed
    /// (m/s) over the seeded trials.
    pub fn max_speed_by_heading_json(&self) -> Value {
        let mut m = serde_json::Map::new();
        for h in &self.trials {
            m.insert(
                heading_key(h.heading_deg),
                json!(h.mean_max_speed_m_per_s()),
            );
        }
        Value::Object(m)
    }

    /// The detailed record (summary key `max_speed_study`): protocol, mu and COM height, the
    /// trials with failures and censoring, the failing acceleration by heading, the map, the
    /// sensitivity and the paper's values.
    pub fn detail_json(&self) -> Value {
        let p = &self.settings.protocol;
        let s = &p.slow_ramp;
        let robot = &self.params.robot;
        let trials: Vec<Value> = self
            .trials
            .iter()
            .map(|h| {
                json!({
                    "heading_deg": h.heading_deg,
                    "mean_max_speed_m_per_s": h.mean_max_speed_m_per_s(),
                    "std_max_speed_m_per_s": h.std_max_speed_m_per_s(),
                    "censored_trials": h.censored_count(),
                    "mean_is_lower_bound": h.censored_count() > 0,
                    "trials": h.trials.iter().map(|t| t.to_json()).collect::<Vec<_>>(),
                })
            })
            .collect();
        let mut failing = serde_json::Map::new();
        for h in &self.trials {
            if let Some(f) = self.failing_at(h.heading_deg) {
                failing.insert(heading_key(h.heading_deg), f.to_json(p.fast_top_m_per_s));
            }
        }
        let map: Vec<Value> = self
            .map
            .iter()
            .map(|m| {
                json!({
                    "heading_deg": m.heading_deg,
                    "quasi_static_failing_accel_m_per_s2":
                        quasi_static_failing_accel_m_per_s2(robot, m.heading_deg),
                    "slow_ramp": m.slow.to_json(),
                    "failing_accel": m.failing.to_json(p.fast_top_m_per_s),
                })
            })
            .collect();
        let sensitivity: Vec<Value> = self
            .sensitivity
            .iter()
            .map(|r| {
                json!({
                    "parameter": r.parameter,
                    "value": r.value,
                    "heading_deg": r.heading_deg,
                    "quasi_static_failing_accel_m_per_s2": quasi_static_failing_accel_m_per_s2(
                        &r.variant.apply(self.params).robot,
                        r.heading_deg,
                    ),
                    "slow_ramp": r.slow.to_json(),
                    "failing_accel": r.failing.to_json(p.fast_top_m_per_s),
                })
            })
            .collect();
        json!({
            "protocol": {
                "slow_ramp": {
                    "accel_m_per_s2": s.accel_m_per_s2,
                    "top_m_per_s": s.max_command_m_per_s,
                    "settle_s": s.settle_s,
                    "hold_s": 1.0,
                },
                "failing_accel_search": {
                    "top_m_per_s": p.fast_top_m_per_s,
                    "hold_s": 1.0,
                    "bracket_m_per_s2": p.accel_bracket_m_per_s2,
                    "resolution_m_per_s2": p.accel_resolution_m_per_s2,
                    "sensor_seed": 0,
                    "command_accel_ceiling_m_per_s2": self.command_accel_ceiling_m_per_s2(),
                },
                "shaper": {
                    "max_speed_m_per_s": p.shaper.max_speed_m_per_s,
                    "max_accel_m_per_s2": p.shaper.max_accel_m_per_s2,
                    "max_jerk_m_per_s3": self.jerk_limit_m_per_s3,
                    "max_tilt_command_rad": p.shaper.max_tilt_command_rad,
                    "max_tilt_rate_command_rad_per_s": p.shaper.max_tilt_rate_command_rad_per_s,
                },
                "seeds": self.settings.seeds,
                "seed_drives": "sensor noise (IMU tilt and gyro)",
            },
            "mu": robot.drivetrain.wheel_ball_friction,
            "com_height_m": robot.sagittal.com_height_m,
            "trials": trials,
            "failing_accel_by_heading": Value::Object(failing),
            "map": map,
            "sensitivity": sensitivity,
            "paper": PAPER_MAX_SPEED.iter().map(|p| json!({
                "heading_deg": p.heading_deg,
                "max_speed_m_per_s": p.speed_m_per_s,
                "upper_bound": p.upper_bound,
            })).collect::<Vec<_>>(),
        })
    }

    /// The comparison table: per heading, our trials and mean beside the paper's value, and
    /// the failing acceleration.
    pub fn table(&self) -> String {
        let mut out = format!(
            "MiaPURE maximum speed per heading (3D world, slow ramp {} m/s^2 to {} m/s, mu {}, l {} m)\n",
            self.settings.protocol.slow_ramp.accel_m_per_s2,
            self.settings.protocol.slow_ramp.max_command_m_per_s,
            self.params.robot.drivetrain.wheel_ball_friction,
            self.params.robot.sagittal.com_height_m,
        );
        let p = &self.settings.protocol;
        out.push_str(&format!(
            "fail accel: largest surviving ramp acceleration to {} m/s on a {} m/s^2 grid in \
             [{}, {}]; the jerk limit {} m/s^3 caps the shaped command at {:.2} m/s^2\n",
            p.fast_top_m_per_s,
            p.accel_resolution_m_per_s2,
            p.accel_bracket_m_per_s2[0],
            p.accel_bracket_m_per_s2[1],
            self.jerk_limit_m_per_s3,
            self.command_accel_ceiling_m_per_s2(),
        ));
        out.push_str(&format!(
            "{:>8} | {:>30} | {:>12} | {:>10} | {:>16} | {:>12} | {}\n",
            "heading",
            "trials max speed (m/s)",
            "mean (m/s)",
            "paper",
            "fail accel m/s^2",
            "quasi-static",
            "failure at the next grid step"
        ));
        for h in &self.trials {
            let speeds: Vec<String> = h.trials.iter().map(TrialOutcome::speed_text).collect();
            let mean = if h.censored_count() > 0 {
                format!(">= {:.2}", h.mean_max_speed_m_per_s())
            } else {
                format!("{:.2}", h.mean_max_speed_m_per_s())
            };
            let paper = PAPER_MAX_SPEED
                .iter()
                .find(|p| same(p.heading_deg, h.heading_deg))
                .map_or("-".to_owned(), |p| {
                    format!(
                        "{}{}",
                        if p.upper_bound { "< " } else { "" },
                        p.speed_m_per_s
                    )
                });
            let f = self.failing_at(h.heading_deg);
            out.push_str(&format!(
                "{:>8} | {:>30} | {:>12} | {:>10} | {:>16} | {:>12} | {}\n",
                format!("{:.0} deg", h.heading_deg),
                speeds.join(", "),
                mean,
                paper,
                f.map_or("-".to_owned(), FailingAccel::text),
                optional(quasi_static_failing_accel_m_per_s2(
                    &self.params.robot,
                    h.heading_deg
                )),
                f.map_or("-".to_owned(), |f| f.failing.map_or(
                    "-".to_owned(),
                    |o| format!(
                        "{} ({:.2} m/s, {})",
                        failure_text(o.failure),
                        o.max_speed_m_per_s,
                        match f.failed_during_ramp(p.fast_top_m_per_s) {
                            Some(false) => "at cruise",
                            _ => "accelerating",
                        }
                    )
                )),
            ));
        }
        for h in &self.trials {
            for t in &h.trials {
                if let Some(f) = t.failure {
                    let stop = t.supervisor_stop_s.map_or(String::new(), |s| {
                        format!(", after the supervisor's controlled stop at {s:.2} s")
                    });
                    out.push_str(&format!(
                        "  {:.0} deg seed {}: {}{stop}\n",
                        h.heading_deg,
                        t.seed,
                        failure_text(Some(f))
                    ));
                }
            }
        }
        if !self.sensitivity.is_empty() {
            out.push_str("sensitivity (first seed):\n");
            out.push_str(&format!(
                "{:>14} | {:>6} | {:>8} | {:>14} | {:>16} | {:>12}\n",
                "parameter",
                "value",
                "heading",
                "max speed m/s",
                "fail accel m/s^2",
                "quasi-static"
            ));
            for r in &self.sensitivity {
                out.push_str(&format!(
                    "{:>14} | {:>6} | {:>8} | {:>14} | {:>16} | {:>12}\n",
                    r.parameter,
                    r.value,
                    format!("{:.0} deg", r.heading_deg),
                    r.slow.speed_text(),
                    r.failing.text(),
                    optional(quasi_static_failing_accel_m_per_s2(
                        &r.variant.apply(self.params).robot,
                        r.heading_deg
                    )),
                ));
            }
        }
        out
    }

    /// Polar plots of the capability map: maximum speed (slow ramp) and failing acceleration
    /// against heading, the paper's points marked. Censored values are drawn at their lower
    /// bound.
    pub fn capability_figures(&self) -> [PolarFigure; 2] {
        let h: Vec<f64> = self.map.iter().map(|m| m.heading_deg).collect();
        let speed: Vec<f64> = self.map.iter().map(|m| m.slow.max_speed_m_per_s).collect();
        let accel: Vec<f64> = self
            .map
            .iter()
            .map(|m| m.failing.largest_surviving_m_per_s2.unwrap_or(0.0))
            .collect();
        let closed = self.map.len() > 2;
        let line = |s: PolarSeries| if closed { s } else { s.open() };
        let paper_h: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.heading_deg).collect();
        let paper_v: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.speed_m_per_s).collect();
        let speed_fig = PolarFigure::new(
            "MiaPURE maximum speed (slow ramp) per heading",
            "max speed (m/s)",
        )
        .with(line(PolarSeries::new(
            "simulated (≥ where censored)",
            &h,
            &speed,
        )))
        .with(
            PolarSeries::new("paper (0 deg: upper bound)", &paper_h, &paper_v)
                .with_style(LineStyle::Points),
        );
        let accel_fig = PolarFigure::new(
            "MiaPURE largest surviving ramp acceleration per heading",
            "acceleration (m/s²)",
        )
        .with(line(PolarSeries::new("simulated", &h, &accel)))
        .with(line(
            PolarSeries::new(
                "quasi-static contact model (core)",
                &h,
                &h.iter()
                    .map(|&d| {
                        quasi_static_failing_accel_m_per_s2(&self.params.robot, d)
                            .unwrap_or(f64::NAN)
                    })
                    .collect::<Vec<_>>(),
            )
            .with_style(LineStyle::Dashed),
        ));
        let top = self.settings.protocol.fast_top_m_per_s;
        let (cruise_h, cruise_a): (Vec<f64>, Vec<f64>) = self
            .map
            .iter()
            .filter(|m| m.failing.failed_during_ramp(top) == Some(false))
            .map(|m| {
                (
                    m.heading_deg,
                    m.failing.largest_surviving_m_per_s2.unwrap_or(0.0),
                )
            })
            .unzip();
        let accel_fig = if cruise_h.is_empty() {
            accel_fig
        } else {
            accel_fig.with(
                PolarSeries::new(
                    "next step failed at cruise, not accelerating",
                    &cruise_h,
                    &cruise_a,
                )
                .with_style(LineStyle::Points),
            )
        };
        [speed_fig, accel_fig]
    }
}

/// The Fig. "acc"-like figure of one ramp: command and ball speed, tilt, the three normal
/// forces and cone utilisations against time, the failure instant as a vertical line.
pub fn acc_figure(run: &RampResult, title: &str) -> TimeSeriesFigure {
    let s = &run.samples;
    let t: Vec<f64> = s.iter().map(|x| x.time_s).collect();
    let col = |f: &dyn Fn(&super::experiments::RampSample) -> f64| -> Vec<f64> {
        s.iter().map(f).collect()
    };
    let mut normal = Subplot::new("normal force N (N)");
    let mut cone = Subplot::new("cone use |F|/(μN)");
    for i in 0..3 {
        let label = wheel_label(i);
        normal = normal.with(Series::new(&label, &t, &col(&|x| x.normal_force_n[i])));
        cone = cone.with(Series::new(&label, &t, &col(&|x| x.cone_utilisation[i])));
    }
    let mut fig = TimeSeriesFigure::new(title)
        .with(
            Subplot::new("speed (m/s)")
                .with(
                    Series::new("ramp command", &t, &col(&|x| x.command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(
                    Series::new("shaped command", &t, &col(&|x| x.shaped_command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("ball", &t, &col(&|x| x.speed_m_per_s))),
        )
        .with(Subplot::new("tilt (deg)").with(Series::new(
            "tilt",
            &t,
            &col(&|x| x.tilt_rad.to_degrees()),
        )))
        .with(normal)
        .with(cone);
    if let Some(f) = run.failure {
        fig = fig.marker(f.time_s, &format!("failure: {}", failure_text(Some(f))));
    }
    fig
}
