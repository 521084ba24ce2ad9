//! The model mismatch of one Monte Carlo run: how the simulated robot differs from the one the
//! controller was designed for, sampled from a seed.
//!
//! Ranges (chosen before the first run, not changed after):
//! - payload mass, COM height, body inertia (both planes), ball inertia, wheel-ball ("roller")
//!   friction, drive friction (the wheels' viscous damping) and IMU noise (tilt and gyro
//!   standard deviations): each scaled by a factor uniform in `1 +- fraction` (the
//!   campaign's: 0.2), independently;
//! - gyro bias: uniform in +-1 deg/s on each axis, the zero-rate offset of the Bosch BMI088
//!   (datasheet BST-BMI088-DS001, "zero-rate offset +-1 deg/s");
//! - tilt bias (the IMU's roll and pitch): uniform in +-0.02 rad on each axis, the BMI088
//!   accelerometer's zero-g offset of +-20 mg (atan(0.02) = 0.02 rad);
//! - push heading: uniform in [0, 360) deg.
//!
//! The payload is the 60 kg on top of MiaPURE's 14.3 kg chassis: its factor scales the body
//! mass's payload part only. The body inertia is scaled by its own factor, not with the mass
//! (a heavier payload sitting lower is as likely as one sitting higher).

use ballbot_core::estimation::ImuSample;
use ballbot_world::rig::Injector;
use ballbot_world::world::WorldParams;
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};
use serde::Serialize;

/// Mass of MiaPURE's payload (kg): the part of the body mass the payload factor scales.
pub const PAYLOAD_KG: f64 = 60.0;

/// Gyro bias bound per axis (rad/s): the BMI088's +-1 deg/s zero-rate offset.
pub const GYRO_BIAS_RAD_PER_S: f64 = 1.0 * core::f64::consts::PI / 180.0;

/// Tilt bias bound per axis (rad): the BMI088's +-20 mg zero-g offset.
pub const TILT_BIAS_RAD: f64 = 0.02;

/// One run's mismatch: factors on the nominal values, biases, and the push heading.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Mismatch {
    /// Factor on the payload mass.
    pub payload_mass: f64,
    /// Factor on the COM height.
    pub com_height: f64,
    /// Factor on the body inertia (both planes).
    pub body_inertia: f64,
    /// Factor on the ball inertia.
    pub ball_inertia: f64,
    /// Factor on the wheel-ball friction coefficient.
    pub roller_friction: f64,
    /// Factor on the drive friction: the viscous wheel damping and the gearbox's stiction and
    /// Coulomb torques ([`ballbot_world::world::TransmissionParams`]).
    pub drive_friction: f64,
    /// Factor on the IMU noise (tilt and gyro standard deviations).
    pub imu_noise: f64,
    /// Gyro bias `[x, y, z]` (rad/s).
    pub gyro_bias_rad_per_s: [f64; 3],
    /// Tilt bias `[roll, pitch]` (rad).
    pub tilt_bias_rad: [f64; 2],
    /// Push heading (deg, body frame).
    pub heading_deg: f64,
}

impl Mismatch {
    /// No mismatch, pushing towards `heading_deg`.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::Mismatch;
    /// assert_eq!(Mismatch::none(90.0).payload_mass, 1.0);
    /// ```
    pub fn none(heading_deg: f64) -> Self {
        Self {
            payload_mass: 1.0,
            com_height: 1.0,
            body_inertia: 1.0,
            ball_inertia: 1.0,
            roller_friction: 1.0,
            drive_friction: 1.0,
            imu_noise: 1.0,
            gyro_bias_rad_per_s: [0.0; 3],
            tilt_bias_rad: [0.0; 2],
            heading_deg,
        }
    }

    /// The mismatch of the run seeded `seed`: every factor uniform in `1 +- fraction`, the
    /// biases and the heading as in the module docs.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::Mismatch;
    /// let m = Mismatch::sample(7, 0.2);
    /// assert_eq!(m, Mismatch::sample(7, 0.2));
    /// assert!((0.8..=1.2).contains(&m.com_height));
    /// ```
    pub fn sample(seed: u64, fraction: f64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let fraction = if fraction.is_finite() {
            fraction.clamp(0.0, 0.99)
        } else {
            0.0
        };
        let mut factor = || {
            if fraction == 0.0 {
                1.0
            } else {
                Uniform::new_inclusive(1.0 - fraction, 1.0 + fraction)
                    .map_or(1.0, |u| u.sample(&mut rng))
            }
        };
        let (payload_mass, com_height, body_inertia, ball_inertia) =
            (factor(), factor(), factor(), factor());
        let (roller_friction, drive_friction, imu_noise) = (factor(), factor(), factor());
        let mut symmetric =
            |bound: f64| Uniform::new_inclusive(-bound, bound).map_or(0.0, |u| u.sample(&mut rng));
        let gyro_bias_rad_per_s = [
            symmetric(GYRO_BIAS_RAD_PER_S),
            symmetric(GYRO_BIAS_RAD_PER_S),
            symmetric(GYRO_BIAS_RAD_PER_S),
        ];
        let tilt_bias_rad = [symmetric(TILT_BIAS_RAD), symmetric(TILT_BIAS_RAD)];
        let heading_deg = Uniform::new(0.0, 360.0).map_or(0.0, |u| u.sample(&mut rng));
        Self {
            payload_mass,
            com_height,
            body_inertia,
            ball_inertia,
            roller_friction,
            drive_friction,
            imu_noise,
            gyro_bias_rad_per_s,
            tilt_bias_rad,
            heading_deg,
        }
    }

    /// `nominal` with this mismatch applied (the biases act through [`Self::sensor_bias`]).
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::Mismatch;
    /// use ballbot_world::world::WorldParams;
    /// let nominal = WorldParams::miapure_60kg();
    /// let heavy = Mismatch { payload_mass: 1.2, ..Mismatch::none(0.0) }.apply(&nominal);
    /// let added = heavy.robot.sagittal.body_mass_kg - nominal.robot.sagittal.body_mass_kg;
    /// assert!((added - 12.0).abs() < 1e-9);
    /// ```
    pub fn apply(&self, nominal: &WorldParams) -> WorldParams {
        let mut w = *nominal;
        for plane in [&mut w.robot.sagittal, &mut w.robot.frontal] {
            plane.body_mass_kg += PAYLOAD_KG * (self.payload_mass - 1.0);
            plane.com_height_m *= self.com_height;
            plane.body_inertia_kg_m2 *= self.body_inertia;
            plane.ball_inertia_kg_m2 *= self.ball_inertia;
        }
        w.robot.drivetrain.wheel_ball_friction *= self.roller_friction;
        w.wheel_damping_nm_s_per_rad *= self.drive_friction;
        w.transmission.stiction_torque_nm *= self.drive_friction;
        w.transmission.coulomb_torque_nm *= self.drive_friction;
        w.sensors.tilt_noise_rad *= self.imu_noise;
        w.sensors.gyro_noise_rad_per_s *= self.imu_noise;
        w
    }

    /// The IMU biases as a rig [`Injector`].
    pub fn sensor_bias(&self) -> SensorBias {
        SensorBias {
            gyro_rad_per_s: Vector3::from(self.gyro_bias_rad_per_s),
            tilt_rad: self.tilt_bias_rad,
        }
    }
}

/// Constant IMU biases added to every sample.
///
/// ```
/// use ballbot_core::estimation::ImuSample;
/// use ballbot_world::rig::Injector;
/// use ballbot_studies::studies::robustness::Mismatch;
/// let m = Mismatch { tilt_bias_rad: [0.01, -0.02], ..Mismatch::none(0.0) };
/// let s = m.sensor_bias().imu(0, ImuSample::upright(0)).unwrap();
/// assert_eq!((s.roll_rad, s.pitch_rad), (0.01, -0.02));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorBias {
    /// Gyro bias (rad/s).
    pub gyro_rad_per_s: Vector3<f64>,
    /// Roll and pitch bias (rad).
    pub tilt_rad: [f64; 2],
}

impl Injector for SensorBias {
    fn imu(&mut self, _now_us: u64, sample: ImuSample<f64>) -> Option<ImuSample<f64>> {
        Some(ImuSample {
            roll_rad: sample.roll_rad + self.tilt_rad[0],
            pitch_rad: sample.pitch_rad + self.tilt_rad[1],
            angular_velocity_rad_per_s: sample.angular_velocity_rad_per_s + self.gyro_rad_per_s,
            ..sample
        })
    }
}
