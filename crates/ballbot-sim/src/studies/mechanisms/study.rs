//! The whole mechanism study on the shared job runner: slow ramps per controller, mechanism
//! and heading; the ramp-acceleration sweep of the default world; the ripple spectra.

use super::ripple::{RippleProtocol, RippleSpectrum, cruise_spectrum};
use super::variant::{ControllerVariant, Mechanism};
use crate::studies::max_speed::{MaxSpeedProtocol, TrialOutcome, slow_ramp_trial_with_config};
use crate::studies::ramp::RampParams;
use crate::studies::runner::run_jobs;
use crate::world::{WorldError, WorldParams};
use ballbot_core::BallbotParams;

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

enum Job {
    Ramp(ControllerVariant, Mechanism, f64),
    Sweep(f64, f64, f64),
    Ripple(f64, f64),
}

enum Done {
    Ramp(MechanismRun),
    Sweep(SweepPoint),
    Ripple(Box<RippleSpectrum>),
}

fn jobs(settings: &MechanismStudySettings) -> Vec<Job> {
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

/// Runs the study on `robot` in parallel; `progress` is called with a short description as
/// each run finishes. The default world is [`WorldParams::with_robot`].
pub fn run_study(
    robot: BallbotParams<f64>,
    settings: &MechanismStudySettings,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<MechanismStudy, WorldError> {
    settings.validate()?;
    let jobs = jobs(settings);
    let default_world = WorldParams::with_robot(robot);
    let run = |job: &Job| -> Result<Done, WorldError> {
        match *job {
            Job::Ramp(controller, mechanism, heading) => {
                let params = mechanism.params(robot);
                let config = controller.config(&params, &settings.protocol)?;
                let (_, outcome) = slow_ramp_trial_with_config(
                    params,
                    config,
                    &settings.protocol,
                    heading,
                    settings.seed,
                )?;
                progress(&format!(
                    "{} {} {heading:.0} deg",
                    controller.as_str(),
                    mechanism.as_str()
                ));
                Ok(Done::Ramp(MechanismRun {
                    controller,
                    mechanism,
                    outcome,
                }))
            }
            Job::Sweep(heading, mu, accel) => {
                let mut params = default_world;
                params.robot.drivetrain.wheel_ball_friction = mu;
                let mut protocol = settings.protocol;
                protocol.slow_ramp.accel_m_per_s2 = accel;
                let config = ControllerVariant::Corrected.config(&params, &protocol)?;
                let (_, outcome) =
                    slow_ramp_trial_with_config(params, config, &protocol, heading, settings.seed)?;
                progress(&format!("sweep {heading:.0} deg mu {mu} a {accel}"));
                Ok(Done::Sweep(SweepPoint {
                    wheel_ball_friction: mu,
                    outcome,
                }))
            }
            Job::Ripple(heading, speed) => {
                let mut params = default_world;
                params.sensors.seed = settings.seed;
                let config = ControllerVariant::Corrected.config(&params, &settings.protocol)?;
                let rollers = params.contact.rollers.count;
                let spectrum =
                    cruise_spectrum(params, config, rollers, heading, speed, &settings.ripple)?;
                progress(&format!("ripple {heading:.0} deg {speed} m/s"));
                Ok(Done::Ripple(Box::new(spectrum)))
            }
        }
    };
    let done = run_jobs(&jobs, settings.threads, run, &|_| {})?;
    let mut study = MechanismStudy {
        settings: settings.clone(),
        robot,
        runs: Vec::new(),
        sweep: Vec::new(),
        ripple: Vec::new(),
    };
    for d in done {
        match d {
            Done::Ramp(r) => study.runs.push(r),
            Done::Sweep(s) => study.sweep.push(s),
            Done::Ripple(r) => study.ripple.push(*r),
        }
    }
    Ok(study)
}
