//! A simulated robot behind the [`ballbot_core::hal`] traits, for running the
//! [`ballbot_runtime::RobotLoop`] on a PC (and in tests).
//!
//! The plant is the decoupled 3D model of MODEL.md section 4: the nonlinear sagittal and
//! frontal WIP planes and the spin model, integrated with the core's RK4 at the inner-loop
//! rate, coupled only through the omniwheel kinematics (the loop reads omniwheel speeds and
//! applies omniwheel torques, as on the robot). Motor torques are held between inner steps.
//!
//! The four device handles share one [`SimPlant`] through a `RefCell` (no allocation: the
//! module is `no_std` like the loop). The IMU adds a tiny deterministic dither, because a real
//! IMU never repeats a reading bit for bit and the supervisor's frozen-IMU check stays on.
//! Faults are injected by setting [`SimPlant::faults`].

use ballbot_core::estimation::{EncoderSample, ImuSample, PlanarStates, synthesize_sensors};
use ballbot_core::hal::{
    DeviceError, DeviceErrorKind, Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders,
};
use ballbot_core::kinematics::relative_rate_from_planar;
use ballbot_core::wip::{BALL_RATE, TILT_RATE};
use ballbot_core::{BallbotParams, Error, OmniKinematics, Spin, Wip, rk4_step};
use ballbot_runtime::{LoopConfig, OperatorInput, OuterReport, RobotLoop};
use core::cell::RefCell;
use nalgebra::Vector3;

/// Faults to inject into the simulated devices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InjectedFaults {
    /// The IMU stops answering (every read times out).
    pub imu_silent: bool,
    /// The IMU returns NaN angles.
    pub imu_nan: bool,
    /// The encoders stop answering.
    pub encoders_silent: bool,
}

/// A simulated device's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimError {
    /// The device was told not to answer ([`InjectedFaults`]).
    Silent,
    /// The shared plant was already borrowed (a re-entrant call: a bug in the caller).
    Busy,
    /// The inner period is zero or does not divide the outer period ([`run_until`]).
    Timing,
}

impl DeviceError for SimError {
    fn kind(&self) -> DeviceErrorKind {
        match self {
            Self::Silent => DeviceErrorKind::Timeout,
            Self::Busy | Self::Timing => DeviceErrorKind::Other,
        }
    }
}

/// The simulated robot: decoupled planar plants, the motor torques being applied, the clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimPlant {
    kinematics: OmniKinematics<f64>,
    sagittal: Wip<f64>,
    frontal: Wip<f64>,
    spin: Spin<f64>,
    /// The planar states (frontal, sagittal, spin); set them to start from a disturbance.
    pub states: PlanarStates<f64>,
    /// Simulated time (us).
    pub now_us: u64,
    /// Omniwheel torques being applied (N m); zero while the motors are disabled.
    pub torque_nm: Vector3<f64>,
    /// Whether the motors are enabled.
    pub motors_enabled: bool,
    /// Faults to inject.
    pub faults: InjectedFaults,
    dither: u64,
}

impl SimPlant {
    /// The robot upright and at rest at time 0, motors off.
    pub fn new(robot: &BallbotParams<f64>) -> Result<Self, Error> {
        Ok(Self {
            kinematics: OmniKinematics::from_ballbot(robot)?,
            sagittal: Wip::new(robot.sagittal)?,
            frontal: Wip::new(robot.frontal)?,
            spin: Spin::new(robot.spin)?,
            states: PlanarStates::zeros(),
            now_us: 0,
            torque_nm: Vector3::zeros(),
            motors_enabled: false,
            faults: InjectedFaults::default(),
            dither: 0x2545_f491_4f6c_dd1d,
        })
    }

    /// Advances the plant by `dt_us` with the applied torques held (RK4).
    pub fn advance(&mut self, dt_us: u64) {
        let dt = dt_us as f64 * 1e-6;
        let torque = if self.motors_enabled {
            self.torque_nm
        } else {
            Vector3::zeros()
        };
        let tau = self.kinematics.planar_torque_nm(&torque);
        let (fro, sag, spin) = (self.frontal, self.sagittal, self.spin);
        let s = &mut self.states;
        s.frontal = rk4_step(|x| fro.derivative(x, tau[0]), &s.frontal, dt);
        s.sagittal = rk4_step(|x| sag.derivative(x, tau[1]), &s.sagittal, dt);
        s.spin = rk4_step(|x| spin.derivative(x, tau[2]), &s.spin, dt);
        self.now_us += dt_us;
    }

    /// The body velocity in body coordinates `(vx, vy)` (m/s): `vx = r phi_dot_y`,
    /// `vy = -r phi_dot_x` (MODEL.md section 4).
    pub fn body_velocity_m_per_s(&self) -> (f64, f64) {
        let r = self.sagittal.params().ball_radius_m;
        (
            r * self.states.sagittal[BALL_RATE],
            -r * self.states.frontal[BALL_RATE],
        )
    }

    /// The omniwheel speeds the encoders measure (rad/s).
    pub fn wheel_speeds_rad_per_s(&self) -> Vector3<f64> {
        let s = &self.states;
        self.kinematics
            .wheel_speeds_rad_per_s(&relative_rate_from_planar(
                [s.frontal[BALL_RATE], s.sagittal[BALL_RATE]],
                [s.frontal[TILT_RATE], s.sagittal[TILT_RATE]],
                s.spin[1],
            ))
    }

    fn noise_rad(&mut self) -> f64 {
        self.dither ^= self.dither << 13;
        self.dither ^= self.dither >> 7;
        self.dither ^= self.dither << 17;
        ((self.dither >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-6
    }

    fn imu_sample(&mut self) -> Result<ImuSample<f64>, SimError> {
        if self.faults.imu_silent {
            return Err(SimError::Silent);
        }
        let (mut imu, _) = synthesize_sensors(&self.kinematics, &self.states, self.now_us);
        imu.roll_rad += self.noise_rad();
        imu.angular_velocity_rad_per_s[1] += self.noise_rad();
        if self.faults.imu_nan {
            imu.roll_rad = f64::NAN;
        }
        Ok(imu)
    }

    fn encoder_sample(&self) -> Result<EncoderSample<f64>, SimError> {
        if self.faults.encoders_silent {
            return Err(SimError::Silent);
        }
        Ok(EncoderSample {
            timestamp_us: self.now_us,
            wheel_speeds_rad_per_s: self.wheel_speeds_rad_per_s(),
        })
    }
}

/// The demo drivers' bus voltage (V): MiaPURE's 45 V.
const DEMO_BUS_VOLTAGE_V: f64 = 45.0;

/// The simulated IMU.
#[derive(Clone, Copy, Debug)]
pub struct SimImu<'a>(pub &'a RefCell<SimPlant>);
/// The simulated encoders.
#[derive(Clone, Copy, Debug)]
pub struct SimEncoders<'a>(pub &'a RefCell<SimPlant>);
/// The simulated motor drivers.
#[derive(Clone, Copy, Debug)]
pub struct SimMotors<'a>(pub &'a RefCell<SimPlant>);
/// The simulated clock.
#[derive(Clone, Copy, Debug)]
pub struct SimClock<'a>(pub &'a RefCell<SimPlant>);

/// The four device handles on one plant.
pub fn devices(
    plant: &RefCell<SimPlant>,
) -> (SimImu<'_>, SimEncoders<'_>, SimMotors<'_>, SimClock<'_>) {
    (
        SimImu(plant),
        SimEncoders(plant),
        SimMotors(plant),
        SimClock(plant),
    )
}

impl Imu<f64> for SimImu<'_> {
    type Error = SimError;
    fn read(&mut self) -> Result<ImuSample<f64>, SimError> {
        self.0
            .try_borrow_mut()
            .map_err(|_| SimError::Busy)?
            .imu_sample()
    }
}

impl WheelEncoders<f64> for SimEncoders<'_> {
    type Error = SimError;
    fn read(&mut self) -> Result<EncoderSample<f64>, SimError> {
        self.0
            .try_borrow()
            .map_err(|_| SimError::Busy)?
            .encoder_sample()
    }
}

impl MotorTorques<f64> for SimMotors<'_> {
    type Error = SimError;
    /// Returns what the drivers delivered in the last plant step (the reply to the previous
    /// setpoint, as over a bus), at the demo's 45 V bus.
    fn apply(&mut self, torque_nm: &Vector3<f64>) -> Result<[MotorFeedback<f64>; 3], SimError> {
        let mut p = self.0.try_borrow_mut().map_err(|_| SimError::Busy)?;
        let delivered = if p.motors_enabled {
            p.torque_nm
        } else {
            Vector3::zeros()
        };
        let speeds = p.wheel_speeds_rad_per_s();
        let feedback =
            [0, 1, 2].map(|i| MotorFeedback::healthy(delivered[i], speeds[i], DEMO_BUS_VOLTAGE_V));
        p.torque_nm = *torque_nm;
        p.motors_enabled = true;
        Ok(feedback)
    }
    fn disable(&mut self) -> Result<(), SimError> {
        let mut p = self.0.try_borrow_mut().map_err(|_| SimError::Busy)?;
        p.torque_nm = Vector3::zeros();
        p.motors_enabled = false;
        Ok(())
    }
}

impl MonotonicClock for SimClock<'_> {
    fn now_us(&mut self) -> u64 {
        // A borrow conflict cannot happen in the single-threaded loop; report time 0 (which
        // the supervisor flags as a clock fault) rather than panic if it ever does.
        self.0.try_borrow().map_or(0, |p| p.now_us)
    }
}

/// The robot loop on the simulated devices.
pub type SimLoop<'a> = RobotLoop<f64, SimImu<'a>, SimEncoders<'a>, SimMotors<'a>, SimClock<'a>>;

/// Runs the simulation until `until_us`: every inner period (from `config`) one
/// [`RobotLoop::inner_task`] then one plant step, and an [`RobotLoop::outer_task`] first at
/// every outer period, with the operator input `operator(now_us, plant)`. `on_outer` sees each
/// outer report with the plant after it.
pub fn run_until<'a>(
    plant: &'a RefCell<SimPlant>,
    robot_loop: &mut SimLoop<'a>,
    config: &LoopConfig<f64>,
    until_us: u64,
    mut operator: impl FnMut(u64, &SimPlant, &mut SimLoop<'a>) -> OperatorInput<'static, f64>,
    mut on_outer: impl FnMut(&OuterReport<f64>, &SimPlant),
) -> Result<(), SimError> {
    let outer_us = config.outer_period_us;
    let inner_us = (config.inner_dt_secs * 1e6 + 0.5) as u64;
    if inner_us == 0 || !outer_us.is_multiple_of(inner_us) {
        return Err(SimError::Timing);
    }
    loop {
        let now_us = plant.try_borrow().map_err(|_| SimError::Busy)?.now_us;
        if now_us >= until_us {
            return Ok(());
        }
        if now_us.is_multiple_of(outer_us) {
            let input = {
                let p = plant.try_borrow().map_err(|_| SimError::Busy)?;
                operator(now_us, &p, robot_loop)
            };
            let report = robot_loop.outer_task(&input);
            on_outer(&report, &*plant.try_borrow().map_err(|_| SimError::Busy)?);
        }
        robot_loop.inner_task();
        plant
            .try_borrow_mut()
            .map_err(|_| SimError::Busy)?
            .advance(inner_us);
    }
}
