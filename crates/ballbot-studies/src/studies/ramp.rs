//! The MiaPURE benchmarks of the paper's Sec. V in the 3D world, with the core's controller:
//! maximum speed per heading (slow velocity ramp until failure) and push recovery.

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::Mode;
use ballbot_core::wip::BALL_RATE;
use ballbot_world::rig::{Happened, OutcomeTracker, WorldRobot};
use ballbot_world::world::WorldError;
use ballbot_world::world::failure::{Failure, tilt_from_vertical_rad};
use ballbot_world::world::params::WorldParams;
use nalgebra::Vector3;

/// One sample of a ramp run, decimated for plots.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, schemars::JsonSchema)]
pub struct RampSample {
    /// Time (s).
    pub time_secs: f64,
    /// Commanded speed along the heading (m/s): the ramp given to the controller.
    pub command_m_per_s: f64,
    /// The command after the core's shaper (speed, acceleration and jerk limits) along the
    /// heading (m/s): `r` times the planar commanded ball rates (0 before the first outer step).
    pub shaped_command_m_per_s: f64,
    /// Ball speed along the heading (m/s).
    pub speed_m_per_s: f64,
    /// Body tilt from the vertical (rad).
    pub tilt_rad: f64,
    /// Normal force of each omniwheel (N).
    pub normal_force_n: [f64; 3],
    /// Largest friction-cone utilisation of the three wheels.
    pub max_cone_utilisation: f64,
    /// Friction-cone utilisation `|F_i| / (mu N_i)` of each omniwheel.
    pub cone_utilisation: [f64; 3],
}

/// A velocity ramp at a fixed heading until failure (or the end of the ramp).
#[derive(Clone, Debug, PartialEq)]
pub struct RampResult {
    /// Heading of travel in the body frame (deg; 0 is towards OW1).
    pub heading_deg: f64,
    /// Highest ball speed along the heading before failure (m/s).
    pub max_speed_m_per_s: f64,
    /// The failure that ended the run; `None` if the ramp ended first.
    pub failure: Option<Failure>,
    /// When the controller's safety supervisor left balancing (e.g. a controlled stop at a
    /// wheel's speed limit) (s); `None` if it balanced to the end. A failure after it is the
    /// stop's, not the ramp's.
    pub supervisor_stop_secs: Option<f64>,
    /// Samples every `sample_every_secs`.
    pub samples: Vec<RampSample>,
    /// How the run ended (ended by a stop rule: the world's first failure ends a ramp) and
    /// its contact events up to there.
    pub happened: Happened,
}

/// Parameters of the maximum-speed ramp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RampParams {
    /// Ramp acceleration (m/s^2). Default 0.25 ("a slowly ramping velocity").
    pub accel_m_per_s2: f64,
    /// The ramp stops rising at this speed (m/s). Default 3.5.
    pub max_command_m_per_s: f64,
    /// Hold time before the ramp starts (s). Default 0.5.
    pub settle_secs: f64,
    /// Sample period of the returned series (s). Default 0.01.
    pub sample_every_secs: f64,
}

impl Default for RampParams {
    fn default() -> Self {
        Self {
            accel_m_per_s2: 0.25,
            max_command_m_per_s: 3.5,
            settle_secs: 0.5,
            sample_every_secs: 0.01,
        }
    }
}

/// Drives the robot with a velocity ramp towards `heading_deg` (body frame) under the core's
/// controller until the world detects a failure or the ramp has held its top speed for 1 s.
///
/// The controller is designed from the robot with its default command shaping, which caps the
/// commanded speed at 2.0 m/s and the acceleration at 1.0 m/s^2; use
/// [`max_speed_ramp_with_config`] to lift those limits.
pub fn max_speed_ramp(
    params: WorldParams,
    heading_deg: f64,
    ramp: &RampParams,
) -> Result<RampResult, WorldError> {
    let config = BallbotControllerConfig::paper(&params.robot)?;
    max_speed_ramp_with_config(params, config, heading_deg, ramp)
}

/// [`max_speed_ramp`] with a given controller configuration, e.g. with the command shaper's
/// speed and acceleration limits raised so that the ramp, not the shaper, sets the command.
pub fn max_speed_ramp_with_config(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    ramp: &RampParams,
) -> Result<RampResult, WorldError> {
    max_speed_ramp_observed(params, config, heading_deg, ramp, &mut |_, _| {})
}

/// [`max_speed_ramp_with_config`] calling `observe` after every physics step with the loop and
/// the velocity command of that step (e.g. to write an MCAP log with
/// [`ballbot_log::WorldLogger`]). The run is the same with or without an observer.
pub fn max_speed_ramp_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    heading_deg: f64,
    ramp: &RampParams,
    observe: &mut dyn FnMut(&WorldRobot, &VelocityCommand<f64>),
) -> Result<RampResult, WorldError> {
    if !(ramp.accel_m_per_s2 > 0.0
        && ramp.max_command_m_per_s > 0.0
        && ramp.sample_every_secs > 0.0)
    {
        return Err(WorldError::InvalidParameter {
            field: "ramp",
            requirement: "accel, top speed and sample period must be > 0",
        });
    }
    let mut sim = WorldRobot::with_config(params, config)?;
    let (s, c) = heading_deg.to_radians().sin_cos();
    let dir = Vector3::new(c, s, 0.0);
    let dt = params.dt_secs;
    let ramp_secs = ramp.max_command_m_per_s / ramp.accel_m_per_s2;
    let end_secs = ramp.settle_secs + ramp_secs + 1.0;
    let steps = (end_secs / dt).ceil() as u64;
    let every = (ramp.sample_every_secs / dt).round().max(1.0) as u64;
    let mut samples = Vec::with_capacity((steps / every + 1) as usize);
    let mut max_speed: f64 = 0.0;
    let mut supervisor_stop_secs = None;
    let mut judge = OutcomeTracker::default();
    for k in 0..steps {
        let t = k as f64 * dt;
        let v =
            ((t - ramp.settle_secs).max(0.0) * ramp.accel_m_per_s2).min(ramp.max_command_m_per_s);
        let cmd = VelocityCommand {
            vx_m_per_s: v * c,
            vy_m_per_s: v * s,
            yaw_rate_rad_per_s: 0.0,
        };
        let tel = *sim.step(Command::Velocity(cmd));
        observe(&sim, &cmd);
        if supervisor_stop_secs.is_none()
            && matches!(sim.mode(), Mode::ControlledStop | Mode::Fault)
        {
            supervisor_stop_secs = Some(tel.time_secs);
        }
        // Ball velocity expressed in the body's yaw frame, along the heading.
        let v_body = tel.ball_velocity_yaw_frame_m_per_s();
        let speed = v_body.dot(&dir);
        if sim.world().failure().is_some() {
            break;
        }
        judge.update(&sim, [v_body.x, v_body.y], [cmd.vx_m_per_s, cmd.vy_m_per_s]);
        max_speed = max_speed.max(speed);
        if k.is_multiple_of(every) {
            // x = r phi_y (sagittal), y = -r phi_x (frontal), see ballbot_core::command.
            let radius_m = params.robot.ball_radius_m();
            let shaped = sim.last_outer().map_or(0.0, |out| {
                let vx = radius_m * out.commands.sagittal[BALL_RATE];
                let vy = -radius_m * out.commands.frontal[BALL_RATE];
                vx * c + vy * s
            });
            samples.push(RampSample {
                shaped_command_m_per_s: shaped,
                time_secs: tel.time_secs,
                command_m_per_s: v,
                speed_m_per_s: speed,
                tilt_rad: tilt_from_vertical_rad(&tel),
                normal_force_n: tel.wheels.map(|w| w.normal_force_n),
                max_cone_utilisation: tel
                    .wheels
                    .iter()
                    .map(|w| w.cone_utilisation)
                    .fold(0.0, f64::max),
                cone_utilisation: tel.wheels.map(|w| w.cone_utilisation),
            });
        }
    }
    Ok(RampResult {
        heading_deg,
        max_speed_m_per_s: max_speed,
        failure: sim.world().failure(),
        supervisor_stop_secs,
        samples,
        happened: Happened::of(&sim, &judge),
    })
}
