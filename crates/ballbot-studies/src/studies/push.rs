//! Push recovery in the 3D world: the robot stands still under the core's controller (a zero
//! velocity command), a horizontal impulse hits the body's centre of mass
//! ([`BallbotWorld::push_body`](ballbot_world::world::BallbotWorld::push_body)), and the robot must recover.
//!
//! The impulse is spread evenly over `push_duration_secs` (a constant force for that long, the
//! default 0.1 s being a shove with the hands), or applied in one physics step when that is
//! 0. An instantaneous impulse jumps the body's velocity while the ball has not moved yet: the
//! compliant omniwheel contacts on the side the body moves away from open at once, and from
//! about 44 N s on (0.6 m/s of body velocity) a wheel stays off the ball for longer than the
//! failure monitor's 20 ms, whatever the direction; that measures the contact model, not the
//! balance, which is why the default spreads the push.
//!
//! **Recovered**: the tilt from the vertical stays below `max_tilt_rad` (15 deg) for the whole
//! run, the world reports no failure, and from `rest_within_secs` after the push to the end of
//! the run (`observe_secs`) the horizontal ball speed stays below `rest_speed_m_per_s` and the
//! tilt below `rest_tilt_rad` ([`PushParams`]). [`push_recovery_limit`] bisects the impulse
//! for the largest one recovered.

use crate::studies::driver::{self, Bisection, JobRecord, Study, bisect};
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_world::rig::{Happened, Injector, NoFaults, OutcomeTracker, WorldRobot};
use ballbot_world::world::failure::{Failure, tilt_from_vertical_rad};
use ballbot_world::world::params::WorldParams;
use ballbot_world::world::{StopRules, WorldError};
use nalgebra::{Rotation3, Vector3};

/// One push trial's protocol and success criterion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PushParams {
    /// Standing still before the push (s). Default 1.0.
    pub settle_secs: f64,
    /// Run time after the push starts (s). Default 4.0.
    pub observe_secs: f64,
    /// Duration of the push: the impulse is applied as a constant force for this long (s);
    /// 0 applies it in one physics step. Default 0.1.
    pub push_duration_secs: f64,
    /// The tilt from the vertical must stay below this (rad). Default 15 deg.
    pub max_tilt_rad: f64,
    /// At rest from this long after the push on (s). Default 3.0.
    pub rest_within_secs: f64,
    /// At rest: horizontal ball speed at most this (m/s). Default 0.1.
    pub rest_speed_m_per_s: f64,
    /// At rest: tilt from the vertical at most this (rad). Default 3 deg.
    pub rest_tilt_rad: f64,
    /// Sample period of the returned series (s). Default 0.01.
    pub sample_every_secs: f64,
    /// The world's stop rules during the trial ([`StopRules`]; default all, the paper
    /// protocol's). With the slip and lift-off rules off, a push that slips or lifts a wheel
    /// briefly and is recovered counts as recovered (`world_push.rules_relaxed`).
    pub stop_rules: StopRules,
}

impl Default for PushParams {
    fn default() -> Self {
        Self {
            settle_secs: 1.0,
            observe_secs: 4.0,
            push_duration_secs: 0.1,
            max_tilt_rad: 15.0_f64.to_radians(),
            rest_within_secs: 3.0,
            rest_speed_m_per_s: 0.1,
            rest_tilt_rad: 3.0_f64.to_radians(),
            sample_every_secs: 0.01,
            stop_rules: StopRules::all(),
        }
    }
}

impl PushParams {
    /// Checks every field.
    ///
    /// ```
    /// use ballbot_studies::studies::push::PushParams;
    /// assert!(PushParams::default().validate().is_ok());
    /// // The rest window must start before the run ends.
    /// let late = PushParams { rest_within_secs: 5.0, ..PushParams::default() };
    /// assert!(late.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let check = |ok: bool, field, requirement| {
            if ok {
                Ok(())
            } else {
                Err(WorldError::InvalidParameter { field, requirement })
            }
        };
        let pos = |v: f64| v.is_finite() && v > 0.0;
        check(
            self.settle_secs.is_finite() && self.settle_secs >= 0.0,
            "settle_secs",
            "must be finite and >= 0",
        )?;
        check(
            pos(self.observe_secs),
            "observe_secs",
            "must be finite and > 0",
        )?;
        check(
            self.push_duration_secs.is_finite()
                && self.push_duration_secs >= 0.0
                && self.push_duration_secs < self.observe_secs,
            "push_duration_secs",
            "must be finite, >= 0 and < observe_secs",
        )?;
        check(
            pos(self.max_tilt_rad),
            "max_tilt_rad",
            "must be finite and > 0",
        )?;
        check(
            self.rest_within_secs.is_finite()
                && self.rest_within_secs >= 0.0
                && self.rest_within_secs < self.observe_secs,
            "rest_within_secs",
            "must be finite, >= 0 and < observe_secs",
        )?;
        check(
            pos(self.rest_speed_m_per_s),
            "rest_speed_m_per_s",
            "must be finite and > 0",
        )?;
        check(
            pos(self.rest_tilt_rad),
            "rest_tilt_rad",
            "must be finite and > 0",
        )?;
        check(
            pos(self.sample_every_secs),
            "sample_every_secs",
            "must be finite and > 0",
        )
    }
}

/// How a push trial ended.
#[derive(Clone, Copy, Debug, PartialEq, schemars::JsonSchema)]
#[schemars(rename_all = "snake_case")]
pub enum PushOutcome {
    /// Recovered (see the module doc).
    Recovered,
    /// The tilt reached `max_tilt_rad` (the run went on; it may or may not have fallen).
    TiltExceeded,
    /// The world detected a failure (tilt beyond 25 deg, floor contact, slip, lift-off).
    Failed(Failure),
    /// Within the tilt bound, but not at rest in the rest window.
    NotAtRest,
}

impl PushOutcome {
    /// A short label: `recovered`, `tilt_exceeded`, `failed`, `not_at_rest`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Recovered => "recovered",
            Self::TiltExceeded => "tilt_exceeded",
            Self::Failed(_) => "failed",
            Self::NotAtRest => "not_at_rest",
        }
    }
}

/// One sample of a push trial.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, schemars::JsonSchema)]
pub struct PushSample {
    /// Time since the push (s; negative before it).
    pub time_secs: f64,
    /// Tilt from the vertical (rad).
    pub tilt_rad: f64,
    /// Horizontal ball speed (m/s).
    pub speed_m_per_s: f64,
    /// Horizontal ball velocity `[x, y]` in the world frame (m/s).
    pub ball_velocity_m_per_s: [f64; 2],
    /// Largest friction-cone utilisation of the three omniwheels.
    pub max_cone_utilisation: f64,
}

/// One push trial.
#[derive(Clone, Debug, PartialEq)]
pub struct PushTrial {
    /// Direction the push moves the body, in the body frame (deg; 0 towards OW1).
    pub heading_deg: f64,
    /// Impulse magnitude (N s).
    pub impulse_ns: f64,
    /// How it ended.
    pub outcome: PushOutcome,
    /// Largest tilt from the vertical after the push (rad).
    pub peak_tilt_rad: f64,
    /// Largest horizontal ball speed after the push (m/s).
    pub peak_speed_m_per_s: f64,
    /// Largest horizontal ball speed in the rest window (m/s).
    pub rest_speed_m_per_s: f64,
    /// Samples every `sample_every_secs`.
    pub samples: Vec<PushSample>,
    /// FNV-1a hash of every step's telemetry (bit-identical runs have equal hashes).
    pub telemetry_hash: u64,
    /// How the run ended (fell, ended by a stop rule, at rest...) and its contact events,
    /// whatever the stop rules.
    pub happened: Happened,
}

impl PushTrial {
    /// Whether the robot recovered.
    pub fn recovered(&self) -> bool {
        self.outcome == PushOutcome::Recovered
    }

    /// Whether the robot stayed up: no failure, tilt below the bound (recovered, or not at
    /// rest in the rest window).
    pub fn stayed_up(&self) -> bool {
        matches!(
            self.outcome,
            PushOutcome::Recovered | PushOutcome::NotAtRest
        )
    }
}

/// Stands the robot still for `settle_secs`, pushes its body's centre of mass with a horizontal
/// impulse of `impulse_ns` towards `heading_deg` (body frame at the start of the push) spread
/// over `push_duration_secs`, and watches for `observe_secs` (or until
/// [`AFTER_FAILURE_SECS`](super::world_braking::AFTER_FAILURE_SECS) after the world fails: the samples
/// show what followed, the peaks and outcome are those at the failure).
pub fn push_trial(
    world_params: WorldParams,
    params: &PushParams,
    heading_deg: f64,
    impulse_ns: f64,
) -> Result<PushTrial, WorldError> {
    push_trial_observed(world_params, params, heading_deg, impulse_ns, &mut |_| {})
}

/// [`push_trial`] calling `observe` after every physics step with the loop (e.g. to write an
/// MCAP log with [`ballbot_log::WorldLogger`]); the trial is the same with or without it.
pub fn push_trial_observed(
    world_params: WorldParams,
    params: &PushParams,
    heading_deg: f64,
    impulse_ns: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<PushTrial, WorldError> {
    let sim = WorldRobot::new(world_params)?;
    push_trial_with(sim, &mut NoFaults, params, heading_deg, impulse_ns, observe)
}

/// [`push_trial_observed`] on a given robot (e.g. with a controller designed for another
/// model than the world's, [`WorldRobot::with_config`]) whose steps pass through `faults`
/// (e.g. a sensor bias, [`ballbot_world::rig::Injector`]).
pub fn push_trial_with(
    mut sim: WorldRobot,
    faults: &mut dyn Injector,
    params: &PushParams,
    heading_deg: f64,
    impulse_ns: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<PushTrial, WorldError> {
    params.validate()?;
    if !(heading_deg.is_finite() && impulse_ns.is_finite() && impulse_ns >= 0.0) {
        return Err(WorldError::InvalidParameter {
            field: "push",
            requirement: "heading must be finite and the impulse finite and >= 0",
        });
    }
    sim.world_mut().set_stop_rules(params.stop_rules);
    let dt = sim.world().params().dt_secs;
    let push_step = (params.settle_secs / dt).round() as u64;
    let push_steps = (params.push_duration_secs / dt).round().max(1.0) as u64;
    let mut direction = Vector3::x();
    let rest_step = push_step + (params.rest_within_secs / dt).round() as u64;
    let end_step = push_step + (params.observe_secs / dt).round() as u64;
    let every = (params.sample_every_secs / dt).round().max(1.0) as u64;
    let still = Command::Velocity(VelocityCommand::zero());
    let mut trial = PushTrial {
        heading_deg,
        impulse_ns,
        outcome: PushOutcome::Recovered,
        peak_tilt_rad: 0.0,
        peak_speed_m_per_s: 0.0,
        rest_speed_m_per_s: 0.0,
        samples: Vec::with_capacity((end_step / every + 1) as usize),
        telemetry_hash: ballbot_world::world::telemetry::FNV_OFFSET_BASIS,
        happened: Happened::of(&sim, &OutcomeTracker::default()),
    };
    let mut judge = OutcomeTracker::default();
    let mut rest_tilt: f64 = 0.0;
    let after_failure_steps = (super::world_braking::AFTER_FAILURE_SECS / dt).round() as u64;
    let mut failed_at: Option<u64> = None;
    for k in 0..end_step {
        if k == push_step {
            let (_, _, yaw) = sim.world().telemetry().body_orientation.euler_angles();
            direction =
                Rotation3::from_axis_angle(&Vector3::z_axis(), yaw + heading_deg.to_radians())
                    * Vector3::x();
        }
        if (push_step..push_step + push_steps).contains(&k) {
            sim.world_mut()
                .push_body(direction * (impulse_ns / push_steps as f64));
        }
        let tel = *sim.step_injected(still, faults);
        observe(&sim);
        tel.hash_into(&mut trial.telemetry_hash);
        let tilt = tilt_from_vertical_rad(&tel);
        let v = &tel.ball_velocity_m_per_s;
        let speed = v.x.hypot(v.y);
        let failed = failed_at.is_some();
        if !failed {
            let v_yaw = tel.ball_velocity_yaw_frame_m_per_s();
            judge.update(&sim, [v_yaw.x, v_yaw.y], [0.0, 0.0]);
        }
        if k >= push_step && !failed {
            trial.peak_tilt_rad = trial.peak_tilt_rad.max(tilt);
            trial.peak_speed_m_per_s = trial.peak_speed_m_per_s.max(speed);
        }
        if k >= rest_step && !failed {
            trial.rest_speed_m_per_s = trial.rest_speed_m_per_s.max(speed);
            rest_tilt = rest_tilt.max(tilt);
        }
        if k % every == 0 {
            trial.samples.push(PushSample {
                time_secs: tel.time_secs - push_step as f64 * dt,
                tilt_rad: tilt,
                speed_m_per_s: speed,
                ball_velocity_m_per_s: [v.x, v.y],
                max_cone_utilisation: tel
                    .wheels
                    .iter()
                    .map(|w| w.cone_utilisation)
                    .fold(0.0, f64::max),
            });
        }
        match (failed_at, sim.world().failure()) {
            (None, Some(failure)) => {
                trial.outcome = PushOutcome::Failed(failure);
                failed_at = Some(k);
            }
            (Some(at), _) if k >= at + after_failure_steps => break,
            _ => {}
        }
    }
    trial.happened = Happened::of(&sim, &judge);
    if failed_at.is_some() {
        return Ok(trial);
    }
    trial.outcome = if trial.peak_tilt_rad >= params.max_tilt_rad {
        PushOutcome::TiltExceeded
    } else if trial.rest_speed_m_per_s > params.rest_speed_m_per_s
        || rest_tilt > params.rest_tilt_rad
    {
        PushOutcome::NotAtRest
    } else {
        PushOutcome::Recovered
    };
    Ok(trial)
}

/// Search range of [`push_recovery_limit`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PushSearch {
    /// An impulse expected to fail (N s); tried first. Default 100.
    pub upper_ns: f64,
    /// Stop when the bracket is at most this wide (N s). Default 0.5.
    pub resolution_ns: f64,
}

impl PushSearch {
    /// Finest resolution relative to `upper_ns` that [`push_recovery_limit`] accepts (about
    /// 30 halvings of the bracket).
    pub const MIN_RELATIVE_RESOLUTION: f64 = 1e-9;

    /// Checks the range: `upper_ns` and `resolution_ns` finite and > 0, the resolution at
    /// least [`Self::MIN_RELATIVE_RESOLUTION`] of `upper_ns` (a bracket finer than the floats
    /// around `upper_ns` can resolve would never close).
    pub fn validate(&self) -> Result<(), WorldError> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(self.upper_ns) && ok(self.resolution_ns)) {
            return Err(WorldError::InvalidParameter {
                field: "push search",
                requirement: "upper_ns and resolution_ns must be finite and > 0",
            });
        }
        if self.resolution_ns < self.upper_ns * Self::MIN_RELATIVE_RESOLUTION {
            return Err(WorldError::InvalidParameter {
                field: "push search resolution_ns",
                requirement: "must be >= 1e-9 * upper_ns (at most ~30 trials)",
            });
        }
        Ok(())
    }

    /// The search as the driver's bisection: 0 N s assumed recovered, `upper_ns` tried first.
    pub fn bisection(&self) -> Bisection {
        Bisection::new(0.0, self.upper_ns, self.resolution_ns)
    }
}

impl Default for PushSearch {
    fn default() -> Self {
        Self {
            upper_ns: 100.0,
            resolution_ns: 0.5,
        }
    }
}

/// The result of [`push_recovery_limit`] at one heading.
#[derive(Clone, Debug, PartialEq)]
pub struct PushRecovery {
    /// Push direction (deg, body frame).
    pub heading_deg: f64,
    /// Largest impulse recovered (N s); 0 if the search found none above 0.
    pub largest_recovered_ns: f64,
    /// Smallest impulse not recovered (N s); `None` if even `upper_ns` was recovered.
    pub smallest_failing_ns: Option<f64>,
    /// Every trial, in order.
    pub trials: Vec<PushTrial>,
}

impl PushRecovery {
    /// The trial at the largest recovered impulse (absent if it was the untried 0).
    pub fn largest_recovered(&self) -> Option<&PushTrial> {
        self.trials
            .iter()
            .find(|t| t.recovered() && t.impulse_ns == self.largest_recovered_ns)
    }

    /// The trial at the smallest failing impulse.
    pub fn smallest_failing(&self) -> Option<&PushTrial> {
        let f = self.smallest_failing_ns?;
        self.trials.iter().find(|t| t.impulse_ns == f)
    }
}

/// Bisects the impulse at `heading_deg` for the largest push the robot recovers from: tries
/// `upper_ns` first (if recovered, that is the answer), then halves the bracket `[0, upper]`
/// until it is at most `resolution_ns` wide. Assumes recovery is monotone in the impulse
/// (every trial is reported). `on_trial` sees each trial as it finishes.
///
/// This is [`PushStudy`]'s job at one heading, run by the experiment driver
/// ([`driver::run_job`]).
pub fn push_recovery_limit(
    world_params: WorldParams,
    params: &PushParams,
    search: &PushSearch,
    heading_deg: f64,
    on_trial: &mut dyn FnMut(&PushTrial),
) -> Result<PushRecovery, WorldError> {
    search.validate()?;
    let study = PushStudy {
        world: world_params,
        params: *params,
        search: *search,
        headings_deg: vec![heading_deg],
    };
    let record = driver::run_job(&study, 0, &heading_deg, &mut |_, t| on_trial(t))?;
    Ok(study.recovery(heading_deg, record))
}

/// The push-recovery search as a [`Study`]: one job per heading (deg, body frame), the impulse
/// bisected in `(0, search.upper_ns]` (N s), a trial passing when the robot recovered
/// ([`PushTrial::recovered`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PushStudy {
    /// The world (its sensor seed is the runs').
    pub world: WorldParams,
    /// The trials' protocol.
    pub params: PushParams,
    /// The impulse search.
    pub search: PushSearch,
    /// The headings, one job each.
    pub headings_deg: Vec<f64>,
}

impl PushStudy {
    /// A job's record as a [`PushRecovery`].
    pub fn recovery(&self, heading_deg: f64, record: JobRecord<PushTrial>) -> PushRecovery {
        let bracket = record.bracket;
        PushRecovery {
            heading_deg,
            largest_recovered_ns: bracket.and_then(|b| b.passed).unwrap_or(0.0),
            smallest_failing_ns: bracket.and_then(|b| b.failed),
            trials: record.trials.into_iter().map(|(_, t)| t).collect(),
        }
    }
}

impl Study for PushStudy {
    type Job = f64;
    type Trial = PushTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<f64> {
        self.headings_deg.clone()
    }

    fn bisection(&self, _heading_deg: &f64) -> Option<Bisection> {
        Some(self.search.bisection())
    }

    fn trial(
        &self,
        heading_deg: &f64,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<PushTrial, WorldError> {
        let impulse_ns = value.unwrap_or(self.search.upper_ns);
        push_trial_observed(self.world, &self.params, *heading_deg, impulse_ns, observe)
    }

    fn passed(&self, trial: &PushTrial) -> bool {
        trial.recovered()
    }

    fn describe(&self, heading_deg: &f64, _value: Option<f64>, t: &PushTrial) -> String {
        format!(
            "push {heading_deg:.0} deg {:.1} N s: {}",
            t.impulse_ns,
            t.outcome.label()
        )
    }
}

/// [`push_recovery_limit`] with the trial at an impulse (N s) given by `trial`, e.g.
/// [`push_trial_with`] on a robot whose controller was designed for another model, and what
/// counts as recovered given by `recovered` (e.g. staying up without coming to rest).
pub fn push_recovery_limit_by(
    search: &PushSearch,
    heading_deg: f64,
    trial: &mut dyn FnMut(f64) -> Result<PushTrial, WorldError>,
    recovered: &dyn Fn(&PushTrial) -> bool,
    on_trial: &mut dyn FnMut(&PushTrial),
) -> Result<PushRecovery, WorldError> {
    search.validate()?;
    let mut trials = Vec::new();
    let bracket = bisect(&search.bisection(), &mut *trial, recovered, |_, t| {
        on_trial(&t);
        trials.push(t);
    })?;
    Ok(PushRecovery {
        heading_deg,
        // The plain search assumes 0 N s recovered, so a bracket always has a passing end.
        largest_recovered_ns: bracket.passed.unwrap_or(0.0),
        smallest_failing_ns: bracket.failed,
        trials,
    })
}
