//! One slow-ramp trial of the maximum-speed study, its reduction to an outcome, the trials of a
//! heading, and the core's quasi-static prediction of the failing acceleration.

use super::protocol::MaxSpeedProtocol;
use crate::studies::ramp::{RampResult, max_speed_ramp_observed};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::{BallbotParams, OmniKinematics, Wip};
use ballbot_world::rig::Happened;
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{Failure, WorldError, WorldParams};
use nalgebra::Vector4;

/// One ramp run, reduced to what the study reports.
#[derive(Clone, Debug, PartialEq)]
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
    pub supervisor_stop_secs: Option<f64>,
    /// Largest friction-cone utilisation of any wheel in the samples.
    pub peak_cone_utilisation: f64,
    /// Smallest normal force of any wheel in the samples (N).
    pub min_normal_force_n: f64,
    /// Largest tilt from the vertical in the samples (rad).
    pub peak_tilt_rad: f64,
    /// How the run ended and its contact events ([`RampResult::happened`]).
    pub happened: Happened,
}

impl TrialOutcome {
    pub(super) fn from_run(run: &RampResult, seed: u64, accel_m_per_s2: f64) -> Self {
        let s = &run.samples;
        Self {
            heading_deg: run.heading_deg,
            seed,
            accel_m_per_s2,
            max_speed_m_per_s: run.max_speed_m_per_s,
            failure: run.failure,
            supervisor_stop_secs: run.supervisor_stop_secs,
            peak_cone_utilisation: s.iter().map(|x| x.max_cone_utilisation).fold(0.0, f64::max),
            min_normal_force_n: s
                .iter()
                .flat_map(|x| x.normal_force_n)
                .fold(f64::INFINITY, f64::min),
            peak_tilt_rad: s.iter().map(|x| x.tilt_rad).fold(0.0, f64::max),
            happened: run.happened.clone(),
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
    let mut config = BallbotControllerConfig::paper(&params.robot)?;
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
    let config = controller(&params, protocol)?;
    slow_ramp_trial_with_config(params, config, protocol, heading_deg, seed)
}

/// [`slow_ramp_trial`] with a given controller configuration (e.g. an ablation of the
/// controller); the protocol's shaper limits are not applied to it.
pub fn slow_ramp_trial_with_config(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
) -> Result<(RampResult, TrialOutcome), WorldError> {
    slow_ramp_trial_observed(params, config, protocol, heading_deg, seed, &mut |_| {})
}

/// [`slow_ramp_trial_with_config`] showing every physics step to `observe` after it is taken
/// (a logger); the run is the same with or without an observer.
pub fn slow_ramp_trial_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<(RampResult, TrialOutcome), WorldError> {
    let mut p = params;
    p.sensors.seed = seed;
    let run = max_speed_ramp_observed(
        p,
        config,
        heading_deg,
        &protocol.slow_ramp,
        &mut |sim, _| {
            observe(sim);
        },
    )?;
    let outcome = TrialOutcome::from_run(&run, seed, protocol.slow_ramp.accel_m_per_s2);
    Ok((run, outcome))
}
