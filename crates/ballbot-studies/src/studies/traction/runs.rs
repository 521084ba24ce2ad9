//! The runs of the traction study: a velocity ramp, a stop from cruise, a friction patch and
//! a rider's lean, each with traction-aware control on or off.

use super::probe::{Probe, RunRecord};
use crate::studies::max_speed::ShaperLimits;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, LeanInput, LeanToDriveParams, VelocityCommand};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::{WorldError, WorldParams};

/// Sample period of every run's series (s).
pub const SAMPLE_PERIOD_SECS: f64 = 0.01;

/// Which controller a run uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Control {
    /// The paper's configuration ([`BallbotControllerConfig::paper`]) with traction-aware
    /// control on and the study's shaper caps lifted (the envelope alone limits).
    TractionOn,
    /// The same without traction-aware control.
    TractionOff,
    /// The controller as shipped ([`BallbotControllerConfig::design`]): default shaping
    /// (1 m/s^2, 2 m/s^3), traction-aware control and balance-point estimation on.
    Shipped,
}

impl Control {
    /// The name in JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::TractionOn => "on",
            Self::TractionOff => "off",
            Self::Shipped => "shipped",
        }
    }

    /// The controller configuration for `params`' robot.
    pub fn config(
        self,
        params: &WorldParams,
        caps: &ShaperLimits,
    ) -> Result<BallbotControllerConfig<f64>, WorldError> {
        if self == Self::Shipped {
            return Ok(BallbotControllerConfig::design(&params.robot)?);
        }
        let mut config = BallbotControllerConfig::paper(&params.robot)?;
        caps.apply(&mut config);
        if self == Self::TractionOn {
            config = config.with_traction_control();
        }
        Ok(config)
    }
}

fn velocity_along(heading_deg: f64, speed_m_per_s: f64) -> Command<'static, f64> {
    let (s, c) = heading_deg.to_radians().sin_cos();
    Command::Velocity(VelocityCommand {
        vx_m_per_s: speed_m_per_s * c,
        vy_m_per_s: speed_m_per_s * s,
        yaw_rate_rad_per_s: 0.0,
    })
}

/// The shaped command along `heading_deg` (m/s): `r` times the planar commanded ball rates.
fn shaped_m_per_s(sim: &WorldRobot, heading_deg: f64) -> f64 {
    let r = sim.world().params().robot.ball_radius_m();
    let (s, c) = heading_deg.to_radians().sin_cos();
    sim.last_outer().map_or(0.0, |o| {
        r * o.commands.sagittal[3] * c - r * o.commands.frontal[3] * s
    })
}

fn probe_for(params: &WorldParams, heading_deg: f64) -> Probe {
    let every = (SAMPLE_PERIOD_SECS / params.dt_secs).round() as u64;
    Probe::new(
        heading_deg,
        every,
        params.failure.slip_speed_threshold_m_per_s,
    )
}

/// A velocity ramp towards `heading_deg` at `accel_m_per_s2` to `top_m_per_s` after 0.5 s at
/// rest (the failing-acceleration protocol's ramp), held until 1 s after the *shaped* command
/// has reached the top too (a limited command gets there later than the ramp), at most 15 s.
pub fn ramp(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    top_m_per_s: f64,
) -> Result<RunRecord, WorldError> {
    ramp_observed(
        params,
        config,
        heading_deg,
        accel_m_per_s2,
        top_m_per_s,
        &mut |_| {},
    )
}

/// [`ramp`] calling `observe` after every physics step (e.g. a [`ballbot_log::WorldLogger`]).
/// The run is the same with or without an observer.
pub fn ramp_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    top_m_per_s: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<RunRecord, WorldError> {
    let mut sim = WorldRobot::with_config(params, config)?;
    let mut probe = probe_for(&params, heading_deg);
    let settle = 0.5;
    let ramp_end = settle + top_m_per_s / accel_m_per_s2;
    let steps = (15.0 / params.dt_secs).ceil() as u64;
    let mut hold_from = None;
    for k in 0..steps {
        let t = k as f64 * params.dt_secs;
        let v = ((t - settle).max(0.0) * accel_m_per_s2).min(top_m_per_s);
        sim.step(velocity_along(heading_deg, v));
        observe(&sim);
        if probe.observe(&sim, v) {
            break;
        }
        if hold_from.is_none() && t >= ramp_end && shaped_m_per_s(&sim, heading_deg) >= v - 1e-3 {
            hold_from = Some(t);
        }
        if hold_from.is_some_and(|h| t >= h + 1.0) {
            break;
        }
    }
    Ok(probe.finish(&sim, SAMPLE_PERIOD_SECS))
}

/// Cruise towards `heading_deg` at `speed_m_per_s` for `cruise_secs` (reached under the
/// controller's own shaping), then the command 0: the record's `supervisor_stop_secs` stays
/// the supervisor's, the stop's start is `cruise_secs` and its end the first time the ball is
/// below `rest_m_per_s` along the heading (returned, s after the stop command; `None` if not
/// within `timeout_secs`).
pub fn stop_from_cruise(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    speed_m_per_s: f64,
    cruise_secs: f64,
    rest_m_per_s: f64,
    timeout_secs: f64,
) -> Result<(RunRecord, Option<f64>), WorldError> {
    stop_from_cruise_observed(
        params,
        config,
        heading_deg,
        speed_m_per_s,
        cruise_secs,
        rest_m_per_s,
        timeout_secs,
        &mut |_| {},
    )
}

/// [`stop_from_cruise`] calling `observe` after every physics step. The run is the same with
/// or without an observer.
#[allow(clippy::too_many_arguments)]
pub fn stop_from_cruise_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    speed_m_per_s: f64,
    cruise_secs: f64,
    rest_m_per_s: f64,
    timeout_secs: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<(RunRecord, Option<f64>), WorldError> {
    let mut sim = WorldRobot::with_config(params, config)?;
    let mut probe = probe_for(&params, heading_deg);
    let steps = ((cruise_secs + timeout_secs) / params.dt_secs).ceil() as u64;
    let mut stopped_after = None;
    for k in 0..steps {
        let t = k as f64 * params.dt_secs;
        let v = if t < cruise_secs { speed_m_per_s } else { 0.0 };
        sim.step(velocity_along(heading_deg, v));
        observe(&sim);
        if probe.observe(&sim, v) {
            break;
        }
        if t >= cruise_secs && stopped_after.is_none() {
            if probe.speed_m_per_s(&sim) < rest_m_per_s {
                stopped_after = Some(sim.world().time_secs() - cruise_secs);
            }
        } else if stopped_after.is_some() {
            break;
        }
    }
    let mut record = probe.finish(&sim, SAMPLE_PERIOD_SECS);
    // Only the stop's deceleration counts: the samples before it are the cruise's start.
    record.max_decel_m_per_s2 = decel_after(&record, cruise_secs);
    Ok((record, stopped_after))
}

fn decel_after(record: &RunRecord, from_secs: f64) -> f64 {
    let s: Vec<_> = record
        .samples
        .iter()
        .filter(|x| x.time_secs >= from_secs)
        .collect();
    let window = (0.1 / SAMPLE_PERIOD_SECS).round() as usize;
    (0..s.len().saturating_sub(window))
        .map(|i| {
            let (a, b) = (s[i], s[i + window]);
            (a.speed_m_per_s - b.speed_m_per_s) / (b.time_secs - a.time_secs)
        })
        .fold(0.0, f64::max)
}

/// A friction patch on the floor along the path: where it starts, how long it is, and what it
/// sets while the ball's centre is on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionPatch {
    /// Length along the heading (m).
    pub length_m: f64,
    /// Ball-floor friction on the patch.
    pub floor_friction: f64,
    /// Wheel-ball friction while the ball is on the patch (`None`: unchanged): a wet patch
    /// that wets the ball.
    pub wheel_ball_friction: Option<f64>,
}

/// When the ball was on a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchCrossing {
    /// When the ball's centre reached the patch (s).
    pub entered_secs: f64,
    /// When it left it (s); `None` when the run ended on the patch.
    pub left_secs: Option<f64>,
}

/// Crosses `patch` towards `heading_deg`: the command ramps at `accel_m_per_s2` to
/// `top_m_per_s` (after 0.5 s at rest); the patch starts where the ball first reaches 98 % of
/// `at_speed_m_per_s`, plus `lead_secs` of travel at that speed; the run ends `after_secs` after
/// the ball has left the patch (or at 20 s, or when the body tilts beyond the world's fall
/// limit): the run goes on past a slip failure, to see whether the robot stays up. Returns the
/// record and when the ball was on the patch, `None` if it never got there.
#[allow(clippy::too_many_arguments)]
pub fn cross_patch(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    top_m_per_s: f64,
    at_speed_m_per_s: f64,
    lead_secs: f64,
    patch: &FrictionPatch,
    after_secs: f64,
) -> Result<(RunRecord, Option<PatchCrossing>), WorldError> {
    cross_patch_observed(
        params,
        config,
        heading_deg,
        accel_m_per_s2,
        top_m_per_s,
        at_speed_m_per_s,
        lead_secs,
        patch,
        after_secs,
        &mut |_| {},
    )
}

/// [`cross_patch`] calling `observe` after every physics step (before the patch's friction
/// is set for the next one). The run is the same with or without an observer.
#[allow(clippy::too_many_arguments)]
pub fn cross_patch_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    top_m_per_s: f64,
    at_speed_m_per_s: f64,
    lead_secs: f64,
    patch: &FrictionPatch,
    after_secs: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<(RunRecord, Option<PatchCrossing>), WorldError> {
    let mut sim = WorldRobot::with_config(params, config)?;
    let mut probe = probe_for(&params, heading_deg).past_stop_rules();
    let (s, c) = heading_deg.to_radians().sin_cos();
    let along = |sim: &WorldRobot| {
        let p = sim.world().telemetry().ball_position_m;
        p.x * c + p.y * s
    };
    let base = params.robot.drivetrain;
    let (mut start_m, mut entered, mut left) = (None, None, None);
    let mut was_on = false;
    let steps = (20.0 / params.dt_secs).ceil() as u64;
    for k in 0..steps {
        let t = k as f64 * params.dt_secs;
        let v = ((t - 0.5).max(0.0) * accel_m_per_s2).min(top_m_per_s);
        sim.step(velocity_along(heading_deg, v));
        observe(&sim);
        let x = along(&sim);
        // Within 2 %: a filtered reference approaches its cruise speed without reaching it.
        if start_m.is_none() && probe.speed_m_per_s(&sim) >= 0.98 * at_speed_m_per_s {
            start_m = Some(x + at_speed_m_per_s * lead_secs);
        }
        let on = start_m.is_some_and(|x0| x >= x0 && x < x0 + patch.length_m);
        let time = sim.world().time_secs();
        if on && entered.is_none() {
            entered = Some(time);
        }
        if !on && entered.is_some() && left.is_none() {
            left = Some(time);
        }
        if on != was_on {
            let world = sim.world_mut();
            world.set_floor_friction(if on {
                patch.floor_friction
            } else {
                base.ball_floor_friction
            })?;
            let wheel_ball = patch.wheel_ball_friction.filter(|_| on);
            world.set_wheel_ball_friction(wheel_ball.unwrap_or(base.wheel_ball_friction))?;
            was_on = on;
        }
        // On past a slip failure: whether the robot stays up is the question.
        probe.observe(&sim, v);
        let fallen = probe_tilt_exceeded(&sim, &params);
        if fallen || left.is_some_and(|l| time > l + after_secs) {
            break;
        }
    }
    let window = entered.map(|entered_secs| PatchCrossing {
        entered_secs,
        left_secs: left,
    });
    Ok((probe.finish(&sim, SAMPLE_PERIOD_SECS), window))
}

/// Whether the body is tilted beyond the world's fall limit (`FailureParams::max_tilt_rad`).
fn probe_tilt_exceeded(sim: &WorldRobot, params: &WorldParams) -> bool {
    tilt_from_vertical_rad(sim.world().telemetry()) > params.failure.max_tilt_rad
}

/// A rider leaning by `lean_rad` towards `heading_deg` (relative to the body) from 0.5 s for
/// `lean_secs`, then upright for `upright_secs`, with the lean-to-drive settings `rider`
/// (the controller's shaping otherwise).
pub fn rider_lean(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    rider: LeanToDriveParams<f64>,
    heading_deg: f64,
    lean_rad: f64,
    lean_secs: f64,
    upright_secs: f64,
) -> Result<RunRecord, WorldError> {
    rider_lean_observed(
        params,
        config,
        rider,
        heading_deg,
        lean_rad,
        lean_secs,
        upright_secs,
        &mut |_| {},
    )
}

/// [`rider_lean`] calling `observe` after every physics step. The run is the same with or
/// without an observer.
#[allow(clippy::too_many_arguments)]
pub fn rider_lean_observed(
    params: WorldParams,
    mut config: BallbotControllerConfig<f64>,
    rider: LeanToDriveParams<f64>,
    heading_deg: f64,
    lean_rad: f64,
    lean_secs: f64,
    upright_secs: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<RunRecord, WorldError> {
    config.shaping.lean_to_drive = rider;
    let mut sim = WorldRobot::with_config(params, config)?;
    let mut probe = probe_for(&params, heading_deg);
    let (s, c) = heading_deg.to_radians().sin_cos();
    let steps = ((0.5 + lean_secs + upright_secs) / params.dt_secs).ceil() as u64;
    for k in 0..steps {
        let t = k as f64 * params.dt_secs;
        let lean = if (0.5..0.5 + lean_secs).contains(&t) {
            lean_rad
        } else {
            0.0
        };
        sim.step(Command::Lean(LeanInput {
            towards_x_rad: lean * c,
            towards_y_rad: lean * s,
            yaw_rate_rad_per_s: 0.0,
        }));
        observe(&sim);
        if probe.observe(&sim, 0.0) {
            break;
        }
    }
    Ok(probe.finish(&sim, SAMPLE_PERIOD_SECS))
}
