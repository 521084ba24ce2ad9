//! The core's 3D controller in the loop: [`BallbotController`] (cascaded LQR-PI outer loop,
//! 400 Hz) reads the simulated IMU and encoders; [`MotorSpeedLoop`] (per-motor speed PIs,
//! 8 kHz) reads the encoder speeds every physics step and drives the actuators.

use super::WorldError;
use super::params::WorldParams;
use super::sim::BallbotWorld;
use super::telemetry::StepTelemetry;
use ballbot_core::ballbot::{
    BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput, OuterOutput,
};
use ballbot_core::command::Command;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::safety::{Mode, ModeRequest};
use nalgebra::Vector3;

/// The world driven by the core's controller at its two rates.
///
/// ```
/// use ballbot_core::command::{Command, VelocityCommand};
/// use ballbot_sim::world::{CoreLoop, WorldParams};
/// let mut sim = CoreLoop::new(WorldParams::miapure_60kg())?;
/// let cmd = VelocityCommand { vx_m_per_s: 0.3, vy_m_per_s: 0.0, yaw_rate_rad_per_s: 0.0 };
/// for _ in 0..8000 {
///     sim.step(Command::Velocity(cmd));
/// }
/// assert!(sim.world().failure().is_none());
/// assert!((sim.world().telemetry().ball_velocity_m_per_s.x - 0.3).abs() < 0.1);
/// # Ok::<(), ballbot_sim::world::WorldError>(())
/// ```
pub struct CoreLoop {
    world: BallbotWorld,
    outer: BallbotController<f64>,
    inner: MotorSpeedLoop<f64>,
    steps_per_outer: u64,
    step_index: u64,
    last_outer: Option<OuterOutput<f64>>,
}

impl CoreLoop {
    /// The world with the controller designed from its robot
    /// ([`BallbotControllerConfig::design`]).
    pub fn new(params: WorldParams) -> Result<Self, WorldError> {
        let config = BallbotControllerConfig::design(&params.robot)?;
        Self::with_config(params, config)
    }

    /// The world with a given controller configuration (e.g. designed for a different model
    /// than the simulated robot).
    pub fn with_config(
        params: WorldParams,
        config: BallbotControllerConfig<f64>,
    ) -> Result<Self, WorldError> {
        let world = BallbotWorld::new(params)?;
        let ratio = config.outer_dt_secs / params.dt_secs;
        if !(ratio.is_finite() && ratio >= 1.0 && (ratio - ratio.round()).abs() < 1e-9) {
            return Err(WorldError::InvalidParameter {
                field: "outer_dt_secs",
                requirement: "must be a whole multiple of the physics step dt_secs",
            });
        }
        Ok(Self {
            world,
            outer: BallbotController::new(config)?,
            inner: MotorSpeedLoop::new(&config)?,
            steps_per_outer: ratio.round() as u64,
            step_index: 0,
            last_outer: None,
        })
    }

    /// The simulated world.
    pub fn world(&self) -> &BallbotWorld {
        &self.world
    }

    /// The simulated world, e.g. to push the body.
    pub fn world_mut(&mut self) -> &mut BallbotWorld {
        &mut self.world
    }

    /// The last outer-loop output (references, estimated states, safety status).
    pub fn last_outer(&self) -> Option<&OuterOutput<f64>> {
        self.last_outer.as_ref()
    }

    /// The controller's mode (Idle before the first step arms it).
    pub fn mode(&self) -> Mode {
        self.outer.mode()
    }

    /// One physics step (8 kHz); every `outer_dt / dt` steps the outer loop runs first on a
    /// fresh sensor sample. The first outer step requests arming.
    pub fn step(&mut self, command: Command<'_, f64>) -> &StepTelemetry {
        let dt = self.world.params().dt_secs;
        if self.step_index.is_multiple_of(self.steps_per_outer) {
            let m = self.world.measure();
            let now_us = (m.time_s * 1e6).round() as u64;
            let imu = ImuSample {
                timestamp_us: now_us,
                roll_rad: m.tilt_rad[0],
                pitch_rad: m.tilt_rad[1],
                yaw_rad: m.yaw_rad,
                angular_velocity_rad_per_s: Vector3::from(m.body_rate_rad_per_s),
            };
            let encoders = EncoderSample {
                timestamp_us: now_us,
                wheel_speeds_rad_per_s: Vector3::from(m.wheel_speed_rad_per_s),
            };
            let request = if self.outer.mode() == Mode::Idle {
                ModeRequest::Arm
            } else {
                ModeRequest::None
            };
            let out = self.outer.step(&OuterInput {
                now_us,
                imu,
                encoders,
                command,
                command_timestamp_us: Some(now_us),
                request,
            });
            self.inner.set_references(&out.motors);
            self.last_outer = Some(out);
        }
        self.step_index += 1;
        let speeds = Vector3::from(self.world.encoder_speeds_rad_per_s());
        let torque = self.inner.step(&speeds, dt).torque_nm;
        self.world.step([torque.x, torque.y, torque.z])
    }
}
