//! A robot's control loop on the core's hardware traits ([`ballbot_core::hal`]): the code a
//! firmware calls from its timer interrupts.
//!
//! - [`RobotLoop::new`] at start-up: designs nothing (hand it a validated
//!   [`BallbotControllerConfig`]), owns the four devices.
//! - [`RobotLoop::outer_task`] at 400 Hz: reads the clock, IMU and encoders, runs the
//!   [`BallbotController`] (supervisor, estimation, command shaping, LQR-PI planes, kinematics)
//!   and hands the new [`ballbot_core::ballbot::MotorReferences`] to the inner loop.
//! - [`RobotLoop::inner_task`] at 8 kHz: reads the encoders, runs the three motor speed PIs
//!   ([`MotorSpeedLoop`]) and applies the torques, or switches the motors off; checks the
//!   drivers' feedback ([`MotorHealthMonitor`]).
//! - [`RobotLoop::shutdown`]: a controlled stop, then disarm once at rest.
//!
//! **Start-up.** The loop starts in [`Phase::StartingUp`]: it requests
//! [`ModeRequest::Arm`] only after the IMU has reported the body upright and still
//! (within the supervisor's arming limits) without interruption for
//! [`LoopConfig::settle_us`]; the supervisor checks the same limits again and refuses while any
//! fault is active. Once balancing, the phase is [`Phase::Running`] and the operator's
//! requests pass through. If the controller falls back to [`Mode::Idle`] (operator disarm, or
//! `Reset` after a fault) the loop starts up again.
//!
//! **Faults.** Failed device reads keep the last sample; the supervisor declares it stale
//! after its timeout (an unrecoverable fault: motors off). A late or slow outer task is
//! reported as [`Fault::LoopOverrun`] (recoverable: controlled stop). The inner loop's encoder
//! guards report [`Fault::EncoderImplausible`] (or [`Fault::EncoderStale`] once it lasts the
//! encoder timeout; see [`ballbot_core::ballbot::SpeedGuard`]). Every other fault comes
//! from the [`ballbot_core::safety::SafetySupervisor`] inside the controller, except the
//! motor-health faults: the inner task compares each driver's reported torque with its
//! setpoint ([`MotorHealthMonitor`], [`LoopConfig::motor_health`]) and reports a dead, stuck or
//! tripped driver ([`Fault::MotorDead`], [`Fault::MotorStuck`], [`Fault::MotorTripped`]) at
//! once: the motors go off at the next inner step (a protective stop: a 3-wheel ballbot with a
//! wheel gone cannot balance; docs/robustness.md measures the alternatives). Failed motor
//! writes are counted in [`DeviceErrorCounts`]; once they have failed for the health
//! monitor's persistence in a row (5 ms, the latency of a dead motor), the drivers do not
//! answer and the loop reports [`Fault::MotorUnanswered`]: the motors go off too (the
//! disable is sent, and a driver whose link is gone stops on its own watchdog, ODrive's
//! `axis.config.watchdog_timeout`, which the firmware should set).
//!
//! The loop holds no heap data and never panics; it is `#![no_std]` and linked by the
//! workspace's no_std check (`nostd-check/`), so the same code runs on a microcontroller.

use ballbot_core::Error;
use ballbot_core::ballbot::{
    BallbotController, BallbotControllerConfig, InnerOutput, MotorSpeedLoop, OuterInput,
    OuterOutput,
};
use ballbot_core::command::Command;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::{
    DeviceError, DeviceErrorKind, Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders,
};
use ballbot_core::rates::{INNER_LOOP_DT_SECS, OUTER_LOOP_PERIOD_US};
use ballbot_core::safety::{
    Fault, Mode, ModeRequest, MotorHealthMonitor, MotorHealthParams, MotorVerdict,
};
use ballbot_core::wip::BALL_RATE;
use nalgebra::RealField;

/// Loop timing and start-up settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopConfig<T> {
    /// Outer-loop period (us): must match the controller's `outer_dt_secs` to 1 us.
    pub outer_period_us: u64,
    /// Inner-loop period (s): 1/8000 on MiaPURE.
    pub inner_dt_secs: T,
    /// How long the body must be upright and still before arming (us).
    pub settle_us: u64,
    /// Shutdown disarms only once the estimated ball speed in both planes is below this
    /// (m/s), the body upright and still, and the shaped command at rest.
    pub rest_speed_m_per_s: T,
    /// The motor-health monitor's model of the drivers and its thresholds.
    pub motor_health: MotorHealthParams<T>,
}

impl<T: RealField + Copy> LoopConfig<T> {
    /// MiaPURE: a 400 Hz outer and an 8 kHz inner loop, arming after 0.25 s upright and still;
    /// ODrive v3.6 drivers on MiaPURE's actuator ([`MotorHealthParams::miapure`]).
    pub fn miapure() -> Self {
        Self {
            outer_period_us: OUTER_LOOP_PERIOD_US,
            inner_dt_secs: nalgebra::convert(INNER_LOOP_DT_SECS),
            settle_us: 250_000,
            rest_speed_m_per_s: nalgebra::convert(0.02),
            motor_health: MotorHealthParams::miapure(),
        }
    }
}

/// Where the loop is in the robot's life.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Motors off, waiting for the body to be upright and still before arming.
    StartingUp,
    /// Armed: the operator's requests and commands pass through (whatever the mode, including
    /// a controlled stop or a fault).
    Running,
    /// Coming to rest in a controlled stop, to disarm once at rest.
    ShuttingDown,
    /// Shut down: motors off until [`RobotLoop::start_up`].
    Off,
}

/// What the operator (a remote, a rider interface, a planner) provides each outer period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatorInput<'a, T: nalgebra::Scalar> {
    /// The command.
    pub command: Command<'a, T>,
    /// When the command was last received (us, on the loop's clock); `None`: never.
    pub command_timestamp_us: Option<u64>,
    /// The operator's mode request; `Arm` is issued by the loop itself during start-up.
    pub request: ModeRequest,
}

/// Failed device calls since start-up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceErrorCounts {
    /// Failed IMU reads.
    pub imu: u32,
    /// Failed encoder reads.
    pub encoders: u32,
    /// Failed motor writes.
    pub motors: u32,
    /// The kind of the most recent failure.
    pub last: Option<DeviceErrorKind>,
}

/// One outer period's result, for logging and telemetry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OuterReport<T: nalgebra::Scalar> {
    /// When the task ran (us).
    pub now_us: u64,
    /// The loop's phase after the task.
    pub phase: Phase,
    /// The request the loop passed to the supervisor.
    pub request: ModeRequest,
    /// The controller's output (mode, faults, states, references).
    pub output: OuterOutput<T>,
}

/// One inner step's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnerReport<T: nalgebra::Scalar> {
    /// The motor PIs' output (zero torque when disabled).
    pub output: InnerOutput<T>,
    /// Whether torque was applied (else the motors were disabled).
    pub applied: bool,
    /// The motor driver's error, if the write failed.
    pub motor_error: Option<DeviceErrorKind>,
    /// The drivers' feedback, when torque was applied and the write succeeded.
    pub motor_feedback: Option<[MotorFeedback<T>; 3]>,
    /// The motor-health verdict of this step (reported to the supervisor), if any.
    pub motor_verdict: Option<MotorVerdict>,
}

/// The robot's control loop (see the module docs).
#[derive(Debug)]
pub struct RobotLoop<T: RealField + Copy, I, E, M, C> {
    controller: BallbotController<T>,
    inner: MotorSpeedLoop<T>,
    health: MotorHealthMonitor<T>,
    config: LoopConfig<T>,
    imu: I,
    encoders: E,
    motors: M,
    clock: C,
    last_imu: ImuSample<T>,
    last_encoders: EncoderSample<T>,
    phase: Phase,
    still_since_us: Option<u64>,
    last_outer: Option<OuterOutput<T>>,
    errors: DeviceErrorCounts,
}

impl<T, I, E, M, C> RobotLoop<T, I, E, M, C>
where
    T: RealField + Copy,
    I: Imu<T>,
    E: WheelEncoders<T>,
    M: MotorTorques<T>,
    C: MonotonicClock,
{
    /// Builds the controller and the motor loop from `controller` (validated here) and takes
    /// the devices. Starts in [`Phase::StartingUp`] with the motors off.
    pub fn new(
        controller: BallbotControllerConfig<T>,
        config: LoopConfig<T>,
        imu: I,
        encoders: E,
        motors: M,
        clock: C,
    ) -> Result<Self, Error> {
        if !(config.inner_dt_secs.is_finite() && config.inner_dt_secs > T::zero()) {
            return Err(Error::InvalidParameter {
                field: "inner_dt_secs",
                requirement: "must be finite and > 0",
            });
        }
        let period_secs: T = nalgebra::convert(config.outer_period_us as f64 * 1e-6);
        if (period_secs - controller.outer_dt_secs).abs() > nalgebra::convert(1e-6) {
            return Err(Error::InvalidParameter {
                field: "outer_period_us",
                requirement: "must equal the controller's outer_dt_secs",
            });
        }
        Ok(Self {
            controller: BallbotController::new(controller)?,
            inner: MotorSpeedLoop::new(&controller)?,
            health: MotorHealthMonitor::new(config.motor_health, config.inner_dt_secs)?,
            config,
            imu,
            encoders,
            motors,
            clock,
            last_imu: ImuSample::upright(0),
            last_encoders: EncoderSample::still(0),
            phase: Phase::StartingUp,
            still_since_us: None,
            last_outer: None,
            errors: DeviceErrorCounts::default(),
        })
    }

    /// The loop's phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The controller's mode.
    pub fn mode(&self) -> Mode {
        self.controller.mode()
    }

    /// The controller (configuration, supervisor and its latched faults).
    pub fn controller(&self) -> &BallbotController<T> {
        &self.controller
    }

    /// Failed device calls since start-up.
    pub fn device_errors(&self) -> DeviceErrorCounts {
        self.errors
    }

    /// The devices, e.g. to inspect a simulated robot.
    pub fn devices(&self) -> (&I, &E, &M, &C) {
        (&self.imu, &self.encoders, &self.motors, &self.clock)
    }

    /// The devices, mutably: a simulator behind the traits hands them its samples and reads
    /// the applied torques back between tasks (`ballbot-sim`'s world robot does).
    pub fn devices_mut(&mut self) -> (&mut I, &mut E, &mut M, &mut C) {
        (
            &mut self.imu,
            &mut self.encoders,
            &mut self.motors,
            &mut self.clock,
        )
    }

    /// Starts a shutdown: a controlled stop (still balancing), then `Disarm` once at rest; the
    /// phase becomes [`Phase::Off`] when the motors are off. Before arming it is immediate.
    /// On a rideable robot, call it only when the robot can be supported after disarming.
    pub fn shutdown(&mut self) {
        self.phase = match self.phase {
            Phase::StartingUp | Phase::Off => Phase::Off,
            Phase::Running | Phase::ShuttingDown => Phase::ShuttingDown,
        };
    }

    /// Leaves [`Phase::Off`]: start-up (arming when upright and still) begins again.
    pub fn start_up(&mut self) {
        if self.phase == Phase::Off {
            self.phase = Phase::StartingUp;
            self.still_since_us = None;
        }
    }

    fn note(&mut self, kind: DeviceErrorKind) {
        self.errors.last = Some(kind);
    }

    fn read_sensors(&mut self) -> bool {
        let imu_fresh = match self.imu.read() {
            Ok(s) => {
                self.last_imu = s;
                true
            }
            Err(e) => {
                self.errors.imu = self.errors.imu.saturating_add(1);
                self.note(e.kind());
                false
            }
        };
        self.read_encoders();
        imu_fresh
    }

    fn read_encoders(&mut self) {
        match self.encoders.read() {
            Ok(s) => self.last_encoders = s,
            Err(e) => {
                self.errors.encoders = self.errors.encoders.saturating_add(1);
                self.note(e.kind());
            }
        }
    }

    /// Whether `imu` shows the body within the supervisor's arming limits.
    fn upright_and_still(&self, imu: &ImuSample<T>) -> bool {
        let supervisor = self.controller.supervisor();
        let p = supervisor.params();
        imu.is_finite()
            && supervisor.within_arm_tilt(imu.roll_rad, imu.pitch_rad)
            && imu
                .angular_velocity_rad_per_s
                .iter()
                .all(|w| w.abs() <= p.arm_rate_limit_rad_per_s)
    }

    /// Whether a shutdown may disarm: the shaped command at rest (last outer step), the body
    /// upright and still, the estimated ball speeds below [`LoopConfig::rest_speed_m_per_s`].
    fn at_rest(&self, imu_fresh: bool) -> bool {
        let Some(last) = &self.last_outer else {
            return false;
        };
        let robot = &self.controller.config().robot;
        let slow = |rate: T, radius_m: T| (rate * radius_m).abs() <= self.config.rest_speed_m_per_s;
        last.stopped
            && imu_fresh
            && self.upright_and_still(&self.last_imu)
            && slow(last.states.frontal[BALL_RATE], robot.frontal.ball_radius_m)
            && slow(
                last.states.sagittal[BALL_RATE],
                robot.sagittal.ball_radius_m,
            )
    }

    /// The 400 Hz task: sensors, controller, references for the inner loop.
    pub fn outer_task(&mut self, operator: &OperatorInput<'_, T>) -> OuterReport<T> {
        let start_us = self.clock.now_us();
        let imu_fresh = self.read_sensors();
        let mode = self.controller.mode();
        let request = match self.phase {
            Phase::StartingUp => {
                if imu_fresh && self.upright_and_still(&self.last_imu) {
                    let since = *self.still_since_us.get_or_insert(start_us);
                    if start_us.saturating_sub(since) >= self.config.settle_us {
                        ModeRequest::Arm
                    } else {
                        ModeRequest::None
                    }
                } else {
                    self.still_since_us = None;
                    ModeRequest::None
                }
            }
            Phase::Running => match operator.request {
                // Arming belongs to start-up.
                ModeRequest::Arm => ModeRequest::None,
                r => r,
            },
            Phase::ShuttingDown => match mode {
                Mode::Balancing => ModeRequest::Stop,
                Mode::ControlledStop if self.at_rest(imu_fresh) => ModeRequest::Disarm,
                _ => ModeRequest::None,
            },
            Phase::Off => ModeRequest::None,
        };
        let output = self.controller.step(&OuterInput {
            now_us: start_us,
            imu: self.last_imu,
            encoders: self.last_encoders,
            command: operator.command,
            command_timestamp_us: operator.command_timestamp_us,
            request,
        });
        self.inner.set_references(&output.motors);
        self.last_outer = Some(output);
        let mode = output.safety.mode;
        self.phase = match (self.phase, mode) {
            (Phase::StartingUp, Mode::Balancing) => Phase::Running,
            (Phase::Running, Mode::Idle) => {
                self.still_since_us = None;
                Phase::StartingUp
            }
            (Phase::ShuttingDown, Mode::Idle | Mode::Fault) => Phase::Off,
            (phase, _) => phase,
        };
        // A task that took longer than its period starves the next one.
        if self.clock.now_us().saturating_sub(start_us) > self.config.outer_period_us {
            self.controller.report(Fault::LoopOverrun);
        }
        OuterReport {
            now_us: start_us,
            phase: self.phase,
            request,
            output,
        }
    }

    /// The 8 kHz task: encoders, motor speed PIs, torques (or motors off), the drivers'
    /// health.
    pub fn inner_task(&mut self) -> InnerReport<T> {
        self.read_encoders();
        let output = self.inner.step(
            &self.last_encoders.wheel_speeds_rad_per_s,
            self.config.inner_dt_secs,
        );
        // The drivers' encoder guards saw an encoder they cannot trust: the supervisor
        // decides (a controlled stop, or the motors off once it lasts the encoder timeout).
        if let Some(fault) = output.encoder_fault {
            self.controller.report(fault);
        }
        let applied = self.controller.mode().motors_enabled() && !output.timed_out;
        let (motor_feedback, motor_error) = if applied {
            match self.motors.apply(&output.torque_nm) {
                Ok(feedback) => (Some(feedback), None),
                Err(e) => (None, Some(e.kind())),
            }
        } else {
            self.health.reset();
            (None, self.motors.disable().err().map(|e| e.kind()))
        };
        if let Some(kind) = motor_error {
            self.errors.motors = self.errors.motors.saturating_add(1);
            self.note(kind);
        }
        let motor_verdict = if applied && motor_error.is_some() {
            // No answer from the drivers: after the health monitor's persistence, that is a
            // fault of its own (the motors go off at the next inner step).
            if let Some(fault) = self.health.unanswered() {
                self.controller.report(fault);
            }
            None
        } else {
            self.check_motors(&output.torque_nm, motor_feedback.as_ref())
        };
        InnerReport {
            output,
            applied,
            motor_error,
            motor_feedback,
            motor_verdict,
        }
    }

    /// Checks the drivers' feedback against the setpoints; a verdict goes to the supervisor
    /// at once (the motors go off at the next inner step).
    fn check_motors(
        &mut self,
        torque_nm: &nalgebra::Vector3<T>,
        feedback: Option<&[MotorFeedback<T>; 3]>,
    ) -> Option<MotorVerdict> {
        let verdict = self.health.step(torque_nm, feedback?);
        if let Some(v) = verdict {
            self.controller.report(v.fault);
        }
        verdict
    }
}
