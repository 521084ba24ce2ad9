//! Sensors: an IMU with noise and bias on tilt and tilt rate, and a quantised motor encoder
//! whose speed is estimated by differencing and a first-order low-pass. All noise comes from one
//! seeded ChaCha8 generator, so a seed fixes every sample bit for bit.

use super::PlanarError;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::TAU;

/// Sensor imperfections. Noise levels are standard deviations per sample.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct SensorParams {
    /// White noise on the IMU's tilt estimate (rad, 1 sigma per sample).
    #[schemars(range(min = 0))]
    pub tilt_noise_rad: f64,
    /// Constant tilt offset, e.g. IMU mounting misalignment (rad).
    pub tilt_bias_rad: f64,
    /// White noise on the gyro's tilt rate (rad/s, 1 sigma per sample).
    #[schemars(range(min = 0))]
    pub tilt_rate_noise_rad_per_s: f64,
    /// Constant gyro bias (rad/s).
    pub tilt_rate_bias_rad_per_s: f64,
    /// Motor encoder counts per rotor revolution. The resolution at the wheel is
    /// `2 pi / (counts * gear_ratio)`, and speed is estimated from the counts. 0 is an ideal
    /// encoder that reads the exact angle and the exact rate (no difference quotient).
    pub encoder_counts_per_rev: u32,
    /// Cut-off of the first-order low-pass on the differenced encoder speed (Hz); 0 disables
    /// the filter (raw difference quotient).
    #[schemars(range(min = 0))]
    pub speed_filter_cutoff_hz: f64,
}

impl Default for SensorParams {
    /// Ideal sensors ([`SensorParams::ideal`]).
    fn default() -> Self {
        Self::ideal()
    }
}

impl SensorParams {
    /// Perfect sensors: no noise, no bias, no quantisation, no filter.
    pub fn ideal() -> Self {
        Self {
            tilt_noise_rad: 0.0,
            tilt_bias_rad: 0.0,
            tilt_rate_noise_rad_per_s: 0.0,
            tilt_rate_bias_rad_per_s: 0.0,
            encoder_counts_per_rev: 0,
            speed_filter_cutoff_hz: 0.0,
        }
    }

    /// The PIPTB's sensors (estimates from datasheet-class MEMS parts; see `docs/piptb.md`).
    ///
    /// - Tilt: the IMU's fused (gyro plus accelerometer) estimate, white noise 0.01 deg per
    ///   sample (accelerometer noise of about 175 ug/sqrt(Hz) through a 0.5 Hz complementary
    ///   crossover) and 0.2 deg of mounting misalignment.
    /// - Tilt rate: the gyro at its full bandwidth, 0.2 deg/s per sample (a noise density of
    ///   0.014 deg/s/sqrt(Hz) over 200 Hz) and a 0.05 deg/s residual bias.
    /// - Motor encoder: 14 bits (16384 counts) per rotor turn behind the 7.5:1 gearbox, speed
    ///   differenced and low-passed at 250 Hz.
    pub fn piptb() -> Self {
        let deg = std::f64::consts::PI / 180.0;
        Self {
            tilt_noise_rad: 0.01 * deg,
            tilt_bias_rad: 0.2 * deg,
            tilt_rate_noise_rad_per_s: 0.2 * deg,
            tilt_rate_bias_rad_per_s: 0.05 * deg,
            encoder_counts_per_rev: 16384,
            speed_filter_cutoff_hz: 250.0,
        }
    }

    /// Checks every field; the error names the key as in a scenario's `[sensors]`.
    pub fn validate(&self) -> Result<(), PlanarError> {
        let non_negative = |v: f64, key: &'static str| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(PlanarError::invalid(key, "must be finite and >= 0"))
            }
        };
        let finite = |v: f64, key: &'static str| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(PlanarError::invalid(key, "must be finite"))
            }
        };
        non_negative(self.tilt_noise_rad, "sensors.tilt_noise_rad")?;
        finite(self.tilt_bias_rad, "sensors.tilt_bias_rad")?;
        non_negative(
            self.tilt_rate_noise_rad_per_s,
            "sensors.tilt_rate_noise_rad_per_s",
        )?;
        finite(
            self.tilt_rate_bias_rad_per_s,
            "sensors.tilt_rate_bias_rad_per_s",
        )?;
        non_negative(
            self.speed_filter_cutoff_hz,
            "sensors.speed_filter_cutoff_hz",
        )?;
        Ok(())
    }
}

/// One IMU sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample {
    /// Measured tilt (rad).
    pub tilt_rad: f64,
    /// Measured tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
}

/// The seeded sensor suite.
#[derive(Clone, Debug)]
pub struct Sensors {
    params: SensorParams,
    rng: ChaCha8Rng,
    /// Encoder resolution at the wheel (rad per count); 0 when ideal.
    count_rad: f64,
}

impl Sensors {
    /// Sensors with `params`, noise drawn from a ChaCha8 stream seeded with `seed`, and an
    /// encoder behind a gearbox of `gear_ratio`.
    pub fn new(params: SensorParams, gear_ratio: f64, seed: u64) -> Result<Self, PlanarError> {
        params.validate()?;
        let count_rad = if params.encoder_counts_per_rev == 0 {
            0.0
        } else {
            TAU / (f64::from(params.encoder_counts_per_rev) * gear_ratio)
        };
        Ok(Self {
            params,
            rng: ChaCha8Rng::seed_from_u64(seed),
            count_rad,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &SensorParams {
        &self.params
    }

    /// The encoder's resolution at the wheel (rad per count); 0 for an ideal encoder.
    pub fn encoder_resolution_rad(&self) -> f64 {
        self.count_rad
    }

    fn gaussian(&mut self, sigma: f64) -> f64 {
        if sigma == 0.0 {
            return 0.0;
        }
        let z: f64 = StandardNormal.sample(&mut self.rng);
        sigma * z
    }

    /// Samples the IMU at true tilt and tilt rate (draws two noise values).
    pub fn imu(&mut self, tilt_rad: f64, tilt_rate_rad_per_s: f64) -> ImuSample {
        let p = self.params;
        let tilt = tilt_rad + p.tilt_bias_rad + self.gaussian(p.tilt_noise_rad);
        let rate = tilt_rate_rad_per_s
            + p.tilt_rate_bias_rad_per_s
            + self.gaussian(p.tilt_rate_noise_rad_per_s);
        ImuSample {
            tilt_rad: tilt,
            tilt_rate_rad_per_s: rate,
        }
    }

    /// The encoder's reading of the joint angle `phi - theta` (rad at the wheel), truncated
    /// to whole counts towards minus infinity.
    pub fn encoder_angle_rad(&self, joint_angle_rad: f64) -> f64 {
        if self.count_rad == 0.0 {
            joint_angle_rad
        } else {
            (joint_angle_rad / self.count_rad).floor() * self.count_rad
        }
    }
}

/// Speed from successive encoder angles: backward difference, then an optional first-order
/// low-pass `y += alpha (x - y)` with `alpha = 1 - exp(-2 pi f_c dt)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedEstimator {
    alpha: f64,
    dt_secs: f64,
    last_angle_rad: Option<f64>,
    speed_rad_per_s: f64,
}

impl SpeedEstimator {
    /// An estimator sampled every `dt_secs` with low-pass cut-off `cutoff_hz` (0: none).
    pub fn new(dt_secs: f64, cutoff_hz: f64) -> Self {
        let alpha = if cutoff_hz > 0.0 {
            1.0 - (-TAU * cutoff_hz * dt_secs).exp()
        } else {
            1.0
        };
        Self {
            alpha,
            dt_secs,
            last_angle_rad: None,
            speed_rad_per_s: 0.0,
        }
    }

    /// Starts from a known angle and speed (a robot that was already running).
    pub fn reset(&mut self, angle_rad: f64, speed_rad_per_s: f64) {
        self.last_angle_rad = Some(angle_rad);
        self.speed_rad_per_s = speed_rad_per_s;
    }

    /// Feeds the angle read this sample; returns the speed estimate (rad/s).
    pub fn update(&mut self, angle_rad: f64) -> f64 {
        if let Some(last) = self.last_angle_rad {
            let raw = (angle_rad - last) / self.dt_secs;
            self.speed_rad_per_s += self.alpha * (raw - self.speed_rad_per_s);
        }
        self.last_angle_rad = Some(angle_rad);
        self.speed_rad_per_s
    }

    /// The present estimate (rad/s).
    pub fn speed_rad_per_s(&self) -> f64 {
        self.speed_rad_per_s
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_noise_other_seed_other_noise() {
        let p = SensorParams::piptb();
        let mut a = Sensors::new(p, 7.5, 1).unwrap();
        let mut b = Sensors::new(p, 7.5, 1).unwrap();
        let mut c = Sensors::new(p, 7.5, 2).unwrap();
        let xa: Vec<_> = (0..100).map(|_| a.imu(0.0, 0.0)).collect();
        let xb: Vec<_> = (0..100).map(|_| b.imu(0.0, 0.0)).collect();
        let xc: Vec<_> = (0..100).map(|_| c.imu(0.0, 0.0)).collect();
        assert_eq!(xa, xb);
        assert_ne!(xa, xc);
    }

    #[test]
    fn imu_noise_has_the_configured_bias_and_spread() {
        let p = SensorParams::piptb();
        let mut s = Sensors::new(p, 7.5, 3).unwrap();
        let n = 20_000;
        let tilts: Vec<f64> = (0..n).map(|_| s.imu(0.0, 0.0).tilt_rad).collect();
        let mean = tilts.iter().sum::<f64>() / n as f64;
        let var = tilts.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / n as f64;
        assert!((mean - p.tilt_bias_rad).abs() < 4.0 * p.tilt_noise_rad / (n as f64).sqrt());
        assert!((var.sqrt() / p.tilt_noise_rad - 1.0).abs() < 0.03);
    }

    #[test]
    fn encoder_quantises_to_whole_counts() {
        let s = Sensors::new(SensorParams::piptb(), 7.5, 0).unwrap();
        let q = s.encoder_resolution_rad();
        assert!((q - TAU / (16384.0 * 7.5)).abs() < 1e-18);
        assert_eq!(s.encoder_angle_rad(2.4 * q), 2.0 * q);
        assert_eq!(s.encoder_angle_rad(-0.5 * q), -q);
    }

    #[test]
    fn speed_estimator_tracks_a_ramp_without_bias() {
        let dt = 1.0 / 8000.0;
        let mut est = SpeedEstimator::new(dt, 250.0);
        let mut y = 0.0;
        for k in 0..8000 {
            y = est.update(3.0 * k as f64 * dt);
        }
        assert!((y - 3.0).abs() < 1e-9);
    }
}
