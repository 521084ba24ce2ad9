//! The whole mechanism study on the experiment driver ([`MechanismExperiment`]): slow ramps
//! per controller, mechanism and heading; the ramp-acceleration sweep of the default world;
//! the ripple spectra.

use super::ripple::{Cruise, RippleProtocol, RippleSpectrum, cruise_spectrum_observed};
use super::variant::{ControllerVariant, Mechanism};
use crate::studies::driver::{self, Bisection, Study};
use crate::studies::max_speed::{MaxSpeedProtocol, TrialOutcome, slow_ramp_trial_observed};
use crate::studies::ramp::RampParams;
use ballbot_core::BallbotParams;
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{WorldError, WorldParams};

/// What the study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismStudySettings {
    /// The slow ramp and the shaper caps ([`MaxSpeedProtocol::default`]: 0.25 m/s^2 to
    /// 6 m/s, held 1 s).
    pub protocol: MaxSpeedProtocol,
    /// Headings of the slow ramps (deg). Default 0, 90, 180 (the paper's).
    pub headings_deg: Vec<f64>,
    /// World variants. Default [`Mechanism::ALL`].
    pub mechanisms: Vec<Mechanism>,
    /// Controllers. Default [`ControllerVariant::ALL`].
    pub controllers: Vec<ControllerVariant>,
    /// Seed of the sensor noise of every run. Default 1.
    pub seed: u64,
    /// Ramp accelerations of the sweep (m/s^2), in the default world with the corrected
    /// controller. Default 0.25, 0.5, 1, 1.5, 2, 2.5, 3.
    pub sweep_accels_m_per_s2: Vec<f64>,
    /// Roller-ball friction coefficients of the sweep. Default 0.4, 0.6, 0.8.
    pub sweep_wheel_ball_friction: Vec<f64>,
    /// Headings of the sweep (deg). Default 0, 90, 180.
    pub sweep_headings_deg: Vec<f64>,
    /// Cruise speeds of the ripple spectra (m/s). Default 0.5 to 3 in steps of 0.5.
    pub ripple_speeds_m_per_s: Vec<f64>,
    /// Headings of the ripple spectra (deg). Default 0.
    pub ripple_headings_deg: Vec<f64>,
    /// How a ripple cruise runs.
    pub ripple: RippleProtocol,
    /// Worker threads; 0 uses every available core. Default 0.
    pub threads: usize,
}

impl MechanismStudySettings {
    /// The full study.
    pub fn paper() -> Self {
        Self {
            protocol: MaxSpeedProtocol::default(),
            headings_deg: vec![0.0, 90.0, 180.0],
            mechanisms: Mechanism::ALL.to_vec(),
            controllers: ControllerVariant::ALL.to_vec(),
            seed: 1,
            sweep_accels_m_per_s2: vec![0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
            sweep_wheel_ball_friction: vec![0.4, 0.6, 0.8],
            sweep_headings_deg: vec![0.0, 90.0, 180.0],
            ripple_speeds_m_per_s: vec![0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
            ripple_headings_deg: vec![0.0],
            ripple: RippleProtocol::default(),
            threads: 0,
        }
    }

    /// The CI smoke variant: the ideal and the default world at 0 and 180 deg on a 1 m/s^2
    /// ramp to 3 m/s, two sweep points, two ripple speeds.
    pub fn quick() -> Self {
        let defaults = MaxSpeedProtocol::default();
        let protocol = MaxSpeedProtocol {
            slow_ramp: RampParams {
                accel_m_per_s2: 1.0,
                max_command_m_per_s: 3.0,
                ..defaults.slow_ramp
            },
            ..defaults
        };
        let mut mechanisms = vec![Mechanism::ALL[0]];
        mechanisms.extend(Mechanism::ALL.last().filter(|m| **m != Mechanism::ALL[0]));
        Self {
            protocol,
            headings_deg: vec![0.0, 180.0],
            mechanisms,
            sweep_accels_m_per_s2: vec![1.0, 2.0],
            sweep_wheel_ball_friction: vec![0.6],
            sweep_headings_deg: vec![0.0],
            ripple_speeds_m_per_s: vec![1.0, 2.0],
            ..Self::paper()
        }
    }

    fn validate(&self) -> Result<(), WorldError> {
        self.protocol.validate()?;
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        let positive = |x: &f64| x.is_finite() && *x > 0.0;
        if !self.sweep_accels_m_per_s2.iter().all(positive)
            || !self.sweep_wheel_ball_friction.iter().all(positive)
        {
            return invalid(
                "mechanisms.sweep",
                "accelerations and friction coefficients must be > 0",
            );
        }
        if !self.ripple_speeds_m_per_s.iter().all(positive) {
            return invalid("mechanisms.ripple_speeds_m_per_s", "must be > 0");
        }
        Ok(())
    }
}

/// One slow ramp of the study.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismRun {
    /// The controller.
    pub controller: ControllerVariant,
    /// The world variant.
    pub mechanism: Mechanism,
    /// The run's outcome (heading, maximum speed, failure, ...).
    pub outcome: TrialOutcome,
}

/// One point of the ramp-acceleration sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// Roller-ball friction coefficient `mu`.
    pub wheel_ball_friction: f64,
    /// The run's outcome; its `accel_m_per_s2` is the ramp's.
    pub outcome: TrialOutcome,
}

impl SweepPoint {
    /// Ramp acceleration over `mu g` (dimensionless): the traction demand's scale.
    pub fn accel_over_mu_g(&self) -> f64 {
        self.outcome.accel_m_per_s2 / (self.wheel_ball_friction * 9.81)
    }
}

/// Everything the study measured.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismStudy {
    /// The settings it ran with.
    pub settings: MechanismStudySettings,
    /// The robot.
    pub robot: BallbotParams<f64>,
    /// Slow ramps, in the order controller, mechanism, heading.
    pub runs: Vec<MechanismRun>,
    /// The sweep, in the order heading, mu, acceleration.
    pub sweep: Vec<SweepPoint>,
    /// Ripple spectra of the default world, in the order heading, speed.
    pub ripple: Vec<RippleSpectrum>,
}

impl MechanismStudy {
    /// The run of `controller` in `mechanism` at `heading_deg`, if the study has it.
    pub fn run(
        &self,
        controller: ControllerVariant,
        mechanism: Mechanism,
        heading_deg: f64,
    ) -> Option<&MechanismRun> {
        self.runs.iter().find(|r| {
            r.controller == controller
                && r.mechanism == mechanism
                && (r.outcome.heading_deg - heading_deg).abs() < 1e-9
        })
    }
}

/// One job of the mechanism study: one world run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MechanismJob {
    /// A slow ramp of a controller in a world variant at a heading (deg).
    Ramp(ControllerVariant, Mechanism, f64),
    /// A sweep point of the default world: heading (deg), roller-ball friction `mu`, ramp
    /// acceleration (m/s^2).
    Sweep(f64, f64, f64),
    /// A ripple cruise of the default world: heading (deg), speed (m/s).
    Ripple(f64, f64),
}

/// What one job of the mechanism study gave.
#[derive(Clone, Debug, PartialEq)]
pub enum MechanismTrial {
    /// A slow ramp.
    Ramp(MechanismRun),
    /// A sweep point.
    Sweep(SweepPoint),
    /// A ripple cruise's spectra.
    Ripple(Box<RippleSpectrum>),
}

/// The mechanism study as a type on the experiment driver ([`crate::studies::driver`]): one
/// trial per job, no bisection.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismExperiment {
    /// The robot (its default world is [`WorldParams::with_robot`]).
    pub robot: BallbotParams<f64>,
    /// What the study runs.
    pub settings: MechanismStudySettings,
}

impl MechanismExperiment {
    fn ramp(
        &self,
        controller: ControllerVariant,
        mechanism: Mechanism,
        heading_deg: f64,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<MechanismTrial, WorldError> {
        let s = &self.settings;
        let params = mechanism.params(self.robot);
        let config = controller.config(&params, &s.protocol)?;
        let (_, outcome) =
            slow_ramp_trial_observed(params, config, &s.protocol, heading_deg, s.seed, observe)?;
        Ok(MechanismTrial::Ramp(MechanismRun {
            controller,
            mechanism,
            outcome,
        }))
    }

    fn sweep(
        &self,
        heading_deg: f64,
        mu: f64,
        accel_m_per_s2: f64,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<MechanismTrial, WorldError> {
        let s = &self.settings;
        let mut params = WorldParams::with_robot(self.robot);
        params.robot.drivetrain.wheel_ball_friction = mu;
        let mut protocol = s.protocol;
        protocol.slow_ramp.accel_m_per_s2 = accel_m_per_s2;
        let config = ControllerVariant::Corrected.config(&params, &protocol)?;
        let (_, outcome) =
            slow_ramp_trial_observed(params, config, &protocol, heading_deg, s.seed, observe)?;
        Ok(MechanismTrial::Sweep(SweepPoint {
            wheel_ball_friction: mu,
            outcome,
        }))
    }

    fn ripple(
        &self,
        heading_deg: f64,
        speed_m_per_s: f64,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<MechanismTrial, WorldError> {
        let s = &self.settings;
        let mut params = WorldParams::with_robot(self.robot);
        params.sensors.seed = s.seed;
        let config = ControllerVariant::Corrected.config(&params, &s.protocol)?;
        let cruise = Cruise {
            roller_count: params.contact.rollers.count,
            heading_deg,
            speed_m_per_s,
        };
        let spectrum = cruise_spectrum_observed(params, config, cruise, &s.ripple, observe)?;
        Ok(MechanismTrial::Ripple(Box::new(spectrum)))
    }
}

impl Study for MechanismExperiment {
    type Job = MechanismJob;
    type Trial = MechanismTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<MechanismJob> {
        jobs(&self.settings)
    }

    fn bisection(&self, _job: &MechanismJob) -> Option<Bisection> {
        None
    }

    fn trial(
        &self,
        job: &MechanismJob,
        _value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<MechanismTrial, WorldError> {
        match *job {
            MechanismJob::Ramp(c, m, h) => self.ramp(c, m, h, observe),
            MechanismJob::Sweep(h, mu, a) => self.sweep(h, mu, a, observe),
            MechanismJob::Ripple(h, v) => self.ripple(h, v, observe),
        }
    }

    /// A ramp or sweep point that reached its end without failing, a cruise that did not fail.
    fn passed(&self, trial: &MechanismTrial) -> bool {
        match trial {
            MechanismTrial::Ramp(r) => r.outcome.censored(),
            MechanismTrial::Sweep(p) => p.outcome.censored(),
            MechanismTrial::Ripple(r) => r.failure.is_none(),
        }
    }

    fn describe(&self, job: &MechanismJob, _value: Option<f64>, _t: &MechanismTrial) -> String {
        match *job {
            MechanismJob::Ramp(c, m, h) => format!("{} {} {h:.0} deg", c.as_str(), m.as_str()),
            MechanismJob::Sweep(h, mu, a) => format!("sweep {h:.0} deg mu {mu} a {a}"),
            MechanismJob::Ripple(h, v) => format!("ripple {h:.0} deg {v} m/s"),
        }
    }
}

fn jobs(settings: &MechanismStudySettings) -> Vec<MechanismJob> {
    use MechanismJob as Job;
    let mut jobs = Vec::new();
    for &c in &settings.controllers {
        for &m in &settings.mechanisms {
            jobs.extend(settings.headings_deg.iter().map(|&h| Job::Ramp(c, m, h)));
        }
    }
    for &h in &settings.sweep_headings_deg {
        for &mu in &settings.sweep_wheel_ball_friction {
            let accels = &settings.sweep_accels_m_per_s2;
            jobs.extend(accels.iter().map(|&a| Job::Sweep(h, mu, a)));
        }
    }
    for &h in &settings.ripple_headings_deg {
        let speeds = &settings.ripple_speeds_m_per_s;
        jobs.extend(speeds.iter().map(|&v| Job::Ripple(h, v)));
    }
    jobs
}

/// How many runs [`run_study`] makes (for a progress bar).
pub fn job_count(settings: &MechanismStudySettings) -> usize {
    jobs(settings).len()
}

/// Runs the study on `robot` on the experiment driver ([`MechanismExperiment`]); `progress`
/// is called with a short description as each run finishes. The default world is
/// [`WorldParams::with_robot`].
pub fn run_study(
    robot: BallbotParams<f64>,
    settings: &MechanismStudySettings,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<MechanismStudy, WorldError> {
    settings.validate()?;
    let experiment = MechanismExperiment {
        robot,
        settings: settings.clone(),
    };
    let records = driver::execute(&experiment, settings.threads, progress)?;
    let mut study = MechanismStudy {
        settings: settings.clone(),
        robot,
        runs: Vec::new(),
        sweep: Vec::new(),
        ripple: Vec::new(),
    };
    for (_, trial) in records.into_iter().flat_map(|r| r.trials) {
        match trial {
            MechanismTrial::Ramp(r) => study.runs.push(r),
            MechanismTrial::Sweep(s) => study.sweep.push(s),
            MechanismTrial::Ripple(r) => study.ripple.push(*r),
        }
    }
    Ok(study)
}
