//! Fault injection between the world and the robot loop: an [`Injector`] sees every sample the
//! world's devices hand the loop, every outer tick, the command link, the torque the motor
//! drivers apply and what they report, and may change, delay, drop or skip them.
//! [`WorldRobot::step_injected`](super::WorldRobot::step_injected) runs a step through one;
//! [`NoFaults`] changes nothing.
//!
//! The loop and the controller are the shipped ones: an injected fault reaches them exactly as a
//! failing device, a late task or a dead link would on the robot.

use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::MotorFeedback;
use nalgebra::Vector3;

/// What happens at an outer tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tick {
    /// The outer task runs; the clock advances `task_us` while it runs (a task longer than the
    /// period is an overrun).
    Run {
        /// How long the task takes on the loop's clock (us).
        task_us: u64,
    },
    /// The tick is missed: the outer task does not run.
    Skip,
}

/// Changes what the robot loop sees and does (see the module docs). Every method's default
/// passes its input through unchanged; `now_us` is the world's time.
///
/// ```
/// use ballbot_core::command::{Command, VelocityCommand};
/// use ballbot_core::estimation::ImuSample;
/// use ballbot_world::rig::{Injector, WorldRobot};
/// use ballbot_world::world::WorldParams;
/// /// The IMU stops answering after 1 s.
/// struct ImuDies;
/// impl Injector for ImuDies {
///     fn imu(&mut self, now_us: u64, sample: ImuSample<f64>) -> Option<ImuSample<f64>> {
///         (now_us < 1_000_000).then_some(sample)
///     }
/// }
/// let mut sim = WorldRobot::new(WorldParams::miapure_60kg())?;
/// let stand = Command::Velocity(VelocityCommand::default());
/// for _ in 0..9_000 {
///     sim.step_injected(stand, &mut ImuDies);
/// }
/// // 20 ms without a fresh sample: the supervisor switched the motors off.
/// assert!(!sim.mode().motors_enabled());
/// # Ok::<(), ballbot_world::world::WorldError>(())
/// ```
pub trait Injector {
    /// The IMU sample of an outer tick; `None` drops it (the device keeps its last sample).
    fn imu(&mut self, now_us: u64, sample: ImuSample<f64>) -> Option<ImuSample<f64>> {
        let _ = now_us;
        Some(sample)
    }

    /// The encoder sample of an outer tick (`outer`) or of an inner step; `None` drops it.
    fn encoders(
        &mut self,
        now_us: u64,
        sample: EncoderSample<f64>,
        outer: bool,
    ) -> Option<EncoderSample<f64>> {
        let _ = (now_us, outer);
        Some(sample)
    }

    /// Whether the outer task runs at this tick, and how long it takes.
    fn outer_tick(&mut self, now_us: u64) -> Tick {
        let _ = now_us;
        Tick::Run { task_us: 0 }
    }

    /// When the command was last received (us); `None`: never.
    fn command_timestamp_us(&mut self, now_us: u64) -> Option<u64> {
        Some(now_us)
    }

    /// The omniwheel torques the motor drivers apply, given the loop's (N m) and the wheel
    /// speeds the drivers measure (rad/s). Called only while the drivers are enabled: a
    /// disabled driver's power stage is off (the HAL's `disable`), whatever the fault.
    fn torques(
        &mut self,
        now_us: u64,
        torque_nm: Vector3<f64>,
        wheel_speeds_rad_per_s: Vector3<f64>,
    ) -> Vector3<f64> {
        let _ = (now_us, wheel_speeds_rad_per_s);
        torque_nm
    }

    /// What the motor drivers report after a physics step (the world's driver model's
    /// delivered torque, speed, bus voltage and trips): a fault that changes what a driver
    /// measures, such as a sagging bus, changes it here.
    fn feedback(
        &mut self,
        now_us: u64,
        feedback: [MotorFeedback<f64>; 3],
    ) -> [MotorFeedback<f64>; 3] {
        let _ = now_us;
        feedback
    }
}

/// The injector that changes nothing: [`WorldRobot::step`](super::WorldRobot::step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoFaults;

impl Injector for NoFaults {}
