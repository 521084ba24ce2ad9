//! Sensors: an IMU on the body (tilt, yaw, body rates) and one encoder per omniwheel, with
//! seeded Gaussian noise and encoder quantisation. Encoders read the wheel (relative to the
//! body), not the ball: when a wheel slips, its encoder no longer measures the ball.

use super::params::SensorParams;
use super::telemetry::StepTelemetry;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// One sample of every sensor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurement {
    /// Time of the sample (s).
    pub time_s: f64,
    /// IMU tilt `[theta_x, theta_y]` (rad): rotation of the body about its own horizontal
    /// axes, right-handed (theta_y > 0 leans towards +x, OW1).
    pub tilt_rad: [f64; 2],
    /// IMU yaw `theta_z` (rad).
    pub yaw_rad: f64,
    /// Gyro: body angular velocity in the body frame (rad/s).
    pub body_rate_rad_per_s: [f64; 3],
    /// Encoder angles of the three wheels relative to the body, quantised (rad).
    pub wheel_angle_rad: [f64; 3],
}

/// The sensor suite with its own seeded noise generator.
#[derive(Clone, Debug)]
pub struct Sensors {
    params: SensorParams,
    wheel_rad_per_count: f64,
    rng: ChaCha8Rng,
}

impl Sensors {
    /// Sensors whose encoders count `params.encoder_counts_per_rev` per rotor turn behind a
    /// gear ratio `gear_ratio`.
    pub fn new(params: SensorParams, gear_ratio: f64) -> Self {
        let counts_per_wheel_rev = f64::from(params.encoder_counts_per_rev) * gear_ratio;
        Self {
            params,
            wheel_rad_per_count: core::f64::consts::TAU / counts_per_wheel_rev,
            rng: ChaCha8Rng::seed_from_u64(params.seed),
        }
    }

    /// Encoder resolution at the wheel (rad per count).
    pub fn wheel_rad_per_count(&self) -> f64 {
        self.wheel_rad_per_count
    }

    fn noise(&mut self, std_dev: f64) -> f64 {
        let z: f64 = StandardNormal.sample(&mut self.rng);
        std_dev * z
    }

    /// Samples every sensor from the true state in `truth`.
    pub fn sample(&mut self, truth: &StepTelemetry) -> Measurement {
        let tilt = self.params.tilt_noise_rad;
        let gyro = self.params.gyro_noise_rad_per_s;
        let (_, _, yaw) = truth.body_orientation.euler_angles();
        let rate = truth.body_rate_rad_per_s;
        let q = self.wheel_rad_per_count;
        Measurement {
            time_s: truth.time_s,
            tilt_rad: [
                truth.tilt_rad[0] + self.noise(tilt),
                truth.tilt_rad[1] + self.noise(tilt),
            ],
            yaw_rad: yaw + self.noise(tilt),
            body_rate_rad_per_s: [
                rate.x + self.noise(gyro),
                rate.y + self.noise(gyro),
                rate.z + self.noise(gyro),
            ],
            wheel_angle_rad: truth.wheels.map(|w| (w.angle_rad / q).floor() * q),
        }
    }
}
