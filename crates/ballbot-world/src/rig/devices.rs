//! The world's devices behind the core's hardware traits.
//!
//! A simulator cannot hand a device a reference to the world it is stepping, so each device is
//! a port: [`WorldRobot`](super::WorldRobot) writes the world's sample into it before a task
//! (the IMU and encoders as [`BallbotWorld::measure`](crate::world::BallbotWorld::measure) and
//! the encoder speed estimate give them, the clock as the world's time), reads the motor
//! drivers' torque back after the inner task and writes their feedback after the physics
//! step. The loop reads and writes them through the `hal` traits exactly as on the robot. The
//! simulated devices never fail to answer (a failing motor shows in its feedback).

use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::{Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders};
use core::convert::Infallible;
use nalgebra::Vector3;

/// The world's IMU: the last sample written by the rig.
///
/// ```
/// use ballbot_core::estimation::ImuSample;
/// use ballbot_core::hal::Imu;
/// use ballbot_world::rig::WorldImu;
/// let mut imu = WorldImu::default();
/// imu.sample = ImuSample::upright(2500);
/// assert_eq!(imu.read().unwrap().timestamp_us, 2500);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldImu {
    /// What the next read returns.
    pub sample: ImuSample<f64>,
}

impl Default for WorldImu {
    fn default() -> Self {
        Self {
            sample: ImuSample::upright(0),
        }
    }
}

impl Imu<f64> for WorldImu {
    type Error = Infallible;

    fn read(&mut self) -> Result<ImuSample<f64>, Infallible> {
        Ok(self.sample)
    }
}

/// The world's wheel encoders: the last sample written by the rig.
///
/// ```
/// use ballbot_core::estimation::EncoderSample;
/// use ballbot_core::hal::WheelEncoders;
/// use ballbot_world::rig::WorldEncoders;
/// let mut encoders = WorldEncoders::default();
/// encoders.sample = EncoderSample::still(125);
/// assert_eq!(encoders.read().unwrap().timestamp_us, 125);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldEncoders {
    /// What the next read returns.
    pub sample: EncoderSample<f64>,
}

impl Default for WorldEncoders {
    fn default() -> Self {
        Self {
            sample: EncoderSample::still(0),
        }
    }
}

impl WheelEncoders<f64> for WorldEncoders {
    type Error = Infallible;

    fn read(&mut self) -> Result<EncoderSample<f64>, Infallible> {
        Ok(self.sample)
    }
}

/// The world's motor drivers: the torque the loop applied, zero while disabled, and what the
/// drivers reported after the last physics step ([`WorldRobot`](super::WorldRobot) writes it:
/// the world's driver model's delivered torque, the wheel's encoder speed, the bus voltage and
/// the driver's trips), which the next `apply` returns, as a bus reply would.
///
/// ```
/// use ballbot_core::hal::{MotorFeedback, MotorTorques};
/// use ballbot_world::rig::WorldMotors;
/// use nalgebra::Vector3;
/// let mut motors = WorldMotors::default();
/// motors.feedback[1] = MotorFeedback::healthy(-2.0, 0.0, 45.0);
/// let feedback = motors.apply(&Vector3::new(1.0, -2.0, 0.5)).unwrap();
/// assert!(motors.enabled);
/// assert_eq!(feedback[1].torque_nm, -2.0);
/// motors.disable().unwrap();
/// assert_eq!((motors.torque_nm, motors.enabled), (Vector3::zeros(), false));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorldMotors {
    /// Omniwheel torques being applied (N m); zero while disabled.
    pub torque_nm: Vector3<f64>,
    /// Whether the drivers are enabled.
    pub enabled: bool,
    /// The drivers' latest report, returned by the next `apply`.
    pub feedback: [MotorFeedback<f64>; 3],
}

impl MotorTorques<f64> for WorldMotors {
    type Error = Infallible;

    fn apply(&mut self, torque_nm: &Vector3<f64>) -> Result<[MotorFeedback<f64>; 3], Infallible> {
        self.torque_nm = *torque_nm;
        self.enabled = true;
        Ok(self.feedback)
    }

    fn disable(&mut self) -> Result<(), Infallible> {
        self.torque_nm = Vector3::zeros();
        self.enabled = false;
        Ok(())
    }
}

/// The world's clock (us), set by the rig to the simulated time. Each read advances it by
/// `task_us`: the outer task reads it at its start and end, so a `task_us` longer than the
/// period is a task that overran (fault injection, [`super::Tick::Run`]); 0 on a healthy rig.
///
/// ```
/// use ballbot_core::hal::MonotonicClock;
/// use ballbot_world::rig::WorldClock;
/// let mut clock = WorldClock { now_us: 2500, task_us: 0 };
/// assert_eq!((clock.now_us(), clock.now_us()), (2500, 2500));
/// let mut slow = WorldClock { now_us: 2500, task_us: 3000 };
/// assert_eq!((slow.now_us(), slow.now_us()), (2500, 5500));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorldClock {
    /// The simulated time (us).
    pub now_us: u64,
    /// How far each read advances the clock (us).
    pub task_us: u64,
}

impl MonotonicClock for WorldClock {
    fn now_us(&mut self) -> u64 {
        let now = self.now_us;
        self.now_us = now.saturating_add(self.task_us);
        now
    }
}
