//! [`WorldRobot`]: the world stepped together with the shipped robot loop.

use super::devices::{WorldClock, WorldEncoders, WorldImu, WorldMotors};
use super::events::EventLog;
use super::inject::{Injector, NoFaults, Tick};
use crate::world::driver::DriverFault;
use crate::world::num::round_to_u64;
use crate::world::{BallbotWorld, Measurement, StepTelemetry, WorldError, WorldParams};
use ballbot_core::ballbot::{BallbotControllerConfig, OuterOutput};
use ballbot_core::command::Command;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::{DriverErrors, MotorFeedback};
use ballbot_core::safety::{Mode, ModeRequest, MotorHealthParams};
use ballbot_runtime::{LoopConfig, OperatorInput, Phase, RobotLoop};
use nalgebra::Vector3;

/// The robot loop that drives the world: [`RobotLoop`] on the world's devices.
pub type WorldRobotLoop = RobotLoop<f64, WorldImu, WorldEncoders, WorldMotors, WorldClock>;

/// The rapier3d world driven by the shipped robot loop ([`RobotLoop`]) at its two rates.
///
/// Every physics step (8 kHz) the loop's inner task runs the motor speed PIs on the encoders'
/// speed estimate and the motor drivers apply its torque (or nothing while the motors are
/// off); every `outer_dt / dt` steps the sensors are sampled (the IMU as its model has it,
/// the encoders) and the outer task runs on that sample once the link latency
/// ([`crate::world::SensorParams::link_latency_secs`]) has passed, before the inner task. The loop arms itself at the first outer step once the body is
/// upright and still (settling time 0: an experiment starts from a balanced robot) and passes
/// the command with a fresh timestamp, as a healthy command link would.
///
/// ```
/// use ballbot_core::command::{Command, VelocityCommand};
/// use ballbot_world::rig::WorldRobot;
/// use ballbot_world::world::WorldParams;
/// let mut sim = WorldRobot::new(WorldParams::miapure_60kg())?;
/// let cmd = VelocityCommand { vx_m_per_s: 0.3, vy_m_per_s: 0.0, yaw_rate_rad_per_s: 0.0 };
/// for _ in 0..8000 {
///     sim.step(Command::Velocity(cmd));
/// }
/// assert!(sim.world().failure().is_none());
/// assert!((sim.world().telemetry().ball_velocity_m_per_s.x - 0.3).abs() < 0.1);
/// # Ok::<(), ballbot_world::world::WorldError>(())
/// ```
pub struct WorldRobot {
    world: BallbotWorld,
    robot: WorldRobotLoop,
    steps_per_outer: u64,
    /// [`crate::world::SensorParams::link_latency_secs`] in world steps.
    latency_steps: u64,
    step_index: u64,
    /// The outer task's sensor sample waiting for the link latency: the step it was taken
    /// at and the sample.
    pending: Option<(u64, Measurement)>,
    last_outer: Option<OuterOutput<f64>>,
    events: EventLog,
}

impl WorldRobot {
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
        let steps_per_outer = ratio.round() as u64;
        let latency_steps = (params.sensors.link_latency_secs / params.dt_secs).round() as u64;
        if latency_steps >= steps_per_outer {
            return Err(WorldError::InvalidParameter {
                field: "sensors.link_latency_secs",
                requirement: "must be below one control period (outer_dt_secs)",
            });
        }
        let outer_period_us = (config.outer_dt_secs * 1e6).round();
        if (outer_period_us * 1e-6 - config.outer_dt_secs).abs() > 1e-9 {
            return Err(WorldError::InvalidParameter {
                field: "outer_dt_secs",
                requirement: "must be a whole number of microseconds",
            });
        }
        let loop_config = LoopConfig {
            // A whole number of microseconds, checked above.
            outer_period_us: outer_period_us as u64,
            inner_dt_secs: params.dt_secs,
            settle_us: 0,
            motor_health: MotorHealthParams::for_actuator(&config.robot.drivetrain.actuator),
            ..LoopConfig::miapure()
        };
        let robot = RobotLoop::new(
            config,
            loop_config,
            WorldImu::default(),
            WorldEncoders::default(),
            WorldMotors {
                feedback: [MotorFeedback::healthy(0.0, 0.0, params.driver.bus_voltage_v); 3],
                ..WorldMotors::default()
            },
            WorldClock::default(),
        )?;
        Ok(Self {
            world,
            robot,
            steps_per_outer,
            latency_steps,
            step_index: 0,
            pending: None,
            last_outer: None,
            events: EventLog::default(),
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

    /// The robot loop (its controller, supervisor, phase and device error counts).
    pub fn robot(&self) -> &WorldRobotLoop {
        &self.robot
    }

    /// What happened so far: slips, lift-offs, driver trips, controller faults, traction
    /// limits, each with its onset, duration and peak ([`EventLog`]), whatever the world's stop
    /// rules.
    pub fn events(&self) -> &EventLog {
        &self.events
    }

    /// The last outer-loop output (references, estimated states, safety status).
    pub fn last_outer(&self) -> Option<&OuterOutput<f64>> {
        self.last_outer.as_ref()
    }

    /// The controller's mode (Idle before the first step arms it).
    pub fn mode(&self) -> Mode {
        self.robot.mode()
    }

    /// The loop's phase (starting up, running, shutting down, off).
    pub fn phase(&self) -> Phase {
        self.robot.phase()
    }

    /// Starts the loop's shutdown: a controlled stop, then disarm once at rest.
    pub fn shutdown(&mut self) {
        self.robot.shutdown();
    }

    /// One physics step (8 kHz): every `outer_dt / dt` steps the outer task first, on a fresh
    /// sensor sample, then the inner task, whose torque the world applies for this step.
    pub fn step(&mut self, command: Command<'_, f64>) -> &StepTelemetry {
        self.step_injected(command, &mut NoFaults)
    }

    /// [`Self::step`] with the samples, ticks, command link and torques passing through
    /// `faults` (see [`Injector`]).
    pub fn step_injected<F: Injector + ?Sized>(
        &mut self,
        command: Command<'_, f64>,
        faults: &mut F,
    ) -> &StepTelemetry {
        if self.step_index.is_multiple_of(self.steps_per_outer) {
            self.pending = Some((self.step_index, self.world.measure()));
        }
        if let Some((taken_at, m)) = self.pending
            && self.step_index == taken_at + self.latency_steps
        {
            self.pending = None;
            self.outer_step(&m, command, faults);
        }
        self.step_index += 1;
        let speeds = Vector3::from(self.world.encoder_speeds_rad_per_s());
        let now_us = round_to_u64(self.world.time_secs() * 1e6);
        let fresh = EncoderSample {
            timestamp_us: now_us,
            wheel_speeds_rad_per_s: speeds,
        };
        if let Some(sample) = faults.encoders(now_us, fresh, false) {
            self.robot.devices_mut().1.sample = sample;
        }
        self.robot.inner_task();
        let motors = self.robot.devices().2;
        let torque = if motors.enabled {
            faults.torques(now_us, motors.torque_nm, speeds)
        } else {
            Vector3::zeros()
        };
        self.world.step([torque.x, torque.y, torque.z]);
        let params = self.world.params();
        self.events
            .observe_world(self.world.telemetry(), &params.failure, params.dt_secs);
        let feedback = faults.feedback(now_us, self.driver_feedback());
        self.robot.devices_mut().2.feedback = feedback;
        self.world.telemetry()
    }

    /// The outer task on the sensor sample `m`, as the controller computed it at the sample's
    /// time; it runs once the link latency has passed, when its output reaches the drivers.
    fn outer_step<F: Injector + ?Sized>(
        &mut self,
        m: &Measurement,
        command: Command<'_, f64>,
        faults: &mut F,
    ) {
        let now_us = (m.time_secs * 1e6).round() as u64;
        let Tick::Run { task_us } = faults.outer_tick(now_us) else {
            return;
        };
        let (imu, encoders, _, clock) = self.robot.devices_mut();
        let fresh_imu = ImuSample {
            timestamp_us: now_us,
            roll_rad: m.tilt_rad[0],
            pitch_rad: m.tilt_rad[1],
            yaw_rad: m.yaw_rad,
            angular_velocity_rad_per_s: Vector3::from(m.body_rate_rad_per_s),
        };
        if let Some(sample) = faults.imu(now_us, fresh_imu) {
            imu.sample = sample;
        }
        let fresh_encoders = EncoderSample {
            timestamp_us: now_us,
            wheel_speeds_rad_per_s: Vector3::from(m.wheel_speed_rad_per_s),
        };
        if let Some(sample) = faults.encoders(now_us, fresh_encoders, true) {
            encoders.sample = sample;
        }
        *clock = WorldClock { now_us, task_us };
        let command_timestamp_us = faults.command_timestamp_us(now_us);
        let report = self.robot.outer_task(&OperatorInput {
            command,
            command_timestamp_us,
            request: ModeRequest::None,
        });
        self.last_outer = Some(report.output);
        let outer_dt = self.world.params().dt_secs * self.steps_per_outer as f64;
        self.events
            .observe_controller(m.time_secs, &report.output, outer_dt);
    }

    /// What the world's motor drivers report after the step just taken: the torque their
    /// model delivered (its current times `N K_t`), the wheel's encoder speed, the bus voltage,
    /// and a trip as the ODrive's error flags.
    fn driver_feedback(&self) -> [MotorFeedback<f64>; 3] {
        let tel = self.world.telemetry();
        let speeds = self.world.encoder_speeds_rad_per_s();
        let bus_v = self.world.params().driver.bus_voltage_v;
        let trips = self.world.driver_faults();
        [0, 1, 2].map(|i| MotorFeedback {
            torque_nm: tel.wheels[i].motor_torque_nm,
            speed_rad_per_s: speeds[i],
            bus_voltage_v: bus_v,
            errors: match trips[i] {
                None => DriverErrors::NONE,
                Some(DriverFault::Overspeed) => {
                    DriverErrors::OVERSPEED.union(DriverErrors::DISARMED)
                }
                Some(DriverFault::CurrentLimitViolation) => {
                    DriverErrors::OVER_CURRENT.union(DriverErrors::DISARMED)
                }
            },
        })
    }
}
