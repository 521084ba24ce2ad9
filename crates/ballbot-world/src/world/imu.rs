//! The IMU as a robot has it: gyro and accelerometer sampled at the sensor's own rate, an
//! accelerometer-aided attitude filter, and the delay with which its estimate reaches the
//! controller.
//!
//! # Models ([`ImuModel`])
//!
//! - **`Truth`**: the true attitude and body rates plus white noise of
//!   [`SensorParams::tilt_noise_rad`](super::SensorParams::tilt_noise_rad) and
//!   [`SensorParams::gyro_noise_rad_per_s`](super::SensorParams::gyro_noise_rad_per_s), read
//!   without delay: the ideal world's IMU, and the earlier releases'.
//! - **`AttitudeFilter`**: what a VN-100-class sensor reports. Every `1 / sample_rate_hz`:
//!   1. **Gyro**: `w_m = w + b + n_g`, with `n_g` white noise of density `N_g`
//!      (`sigma = N_g sqrt(f_s / 2)` per sample) and `b` a first-order Gauss-Markov bias
//!      (standard deviation `sigma_b`, correlation time `T_b`), drawn from its stationary law
//!      at the first sample: a turn-on bias that wanders.
//!   2. **Accelerometer** at the body's centre of mass: the specific force
//!      `f = R^T (dv/dt - g)`, `dv/dt` the centre of mass's velocity change over the sample
//!      period, plus white noise of density `N_a`.
//!   3. **Attitude filter**: the proportional nonlinear complementary filter of Mahony,
//!      Hamel and Pflimlin (IEEE Trans. Automatic Control 53(5), 2008),
//!      `dq/dt = q (w_m + e / tau) / 2` with `e = f / |f| x R_est^T z`: the gyro's integral,
//!      pulled towards the accelerometer's vertical with the time constant `tau`. Yaw is the
//!      gyro's integral alone (no magnetometer, as indoors).
//!   4. **Delay**: the controller reads the newest estimate at least `output_delay_secs` old.
//!
//!   The filter starts at the true attitude (it has converged while the robot stood still).
//!
//! # What the filter does under a sustained acceleration
//!
//! The accelerometer cannot tell an acceleration `a` from gravity: under a constant
//! horizontal `a` its vertical leans `theta_a = atan(a / g)` away from the true one, and the
//! estimate's error `e` towards it obeys `de/dt = -sin(e) / tau` (the cross product's
//! magnitude is the sine of the angle between the two verticals). Its solution
//! `tan(e / 2) = tan(e_0 / 2) exp(-t / tau)` ([`ImuParams::tilt_error_under_acceleration_rad`])
//! goes to 0: after a few `tau` the estimate has left the true tilt by the full `theta_a`. A
//! ballbot accelerating at `a` leans by about `atan(a / g)` to do so, with its body axis
//! along the apparent vertical, so the filter reads that lean as upright.

use super::WorldError;
use super::check::{non_negative, positive};
use nalgebra::{UnitQuaternion, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// Standard gravity (m/s^2), in which datasheets give accelerations (`g`, `mg`).
const STANDARD_GRAVITY_M_PER_S2: f64 = 9.80665;

/// Readings kept for the output delay: at most `HISTORY - 1` samples of delay (78 ms at
/// 800 Hz).
const HISTORY: usize = 64;

/// The noise stream of the filter model's generator (the `Truth` model's noise uses stream
/// 0): changing the model leaves the other sensors' draws alone.
const FILTER_NOISE_STREAM: u64 = 1;

/// Which IMU the controller reads.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum ImuModel {
    /// The true attitude and rates plus white noise, without delay (the other [`ImuParams`]
    /// fields are unused).
    Truth,
    /// Gyro, accelerometer and an accelerometer-aided attitude filter (module documentation).
    AttitudeFilter,
}

/// The IMU's configuration. Values and sources: docs/world-sensing.md.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct ImuParams {
    /// The model: `truth` in the ideal and the default world and when missing from a file,
    /// `attitude_filter` in the VN-100 preset.
    pub model: ImuModel,
    /// Rate at which the sensor samples and its filter steps (Hz); the world step must
    /// divide its period. VN-100: 800.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub sample_rate_hz: f64,
    /// Time from a sample to the controller reading the estimate made from it (s): the
    /// sensor's processing and the serial link. Rounded to whole samples.
    #[schemars(range(min = 0))]
    pub output_delay_secs: f64,
    /// Time constant `tau` of the accelerometer's pull on the attitude estimate (s).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub filter_time_constant_secs: f64,
    /// Gyro white-noise density `N_g` (rad/s per sqrt(Hz)).
    #[schemars(range(min = 0))]
    pub gyro_noise_density_rad_per_s_per_sqrt_hz: f64,
    /// Standard deviation `sigma_b` of each axis's gyro bias (rad/s): what the sensor's own
    /// bias estimate leaves.
    #[schemars(range(min = 0))]
    pub gyro_bias_rad_per_s: f64,
    /// Correlation time `T_b` of the gyro bias (s): how fast it wanders (bias instability).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub gyro_bias_correlation_time_secs: f64,
    /// Accelerometer white-noise density `N_a` (m/s^2 per sqrt(Hz)).
    #[schemars(range(min = 0))]
    pub accel_noise_density_m_per_s2_per_sqrt_hz: f64,
}

impl Default for ImuParams {
    /// [`ImuParams::truth`].
    fn default() -> Self {
        Self::truth()
    }
}

impl ImuParams {
    /// The true attitude plus white noise, without delay (the earlier releases' IMU); the
    /// other fields are [`Self::vn100`]'s.
    pub fn truth() -> Self {
        Self {
            model: ImuModel::Truth,
            ..Self::vn100()
        }
    }

    /// A VectorNav VN-100 as MiaPURE carries it (docs/world-sensing.md gives each value's
    /// source). VectorNav publishes no time constant for its filter: this one is the
    /// steady-state Kalman filter's for the datasheet's noise densities
    /// ([`Self::steady_kalman_time_constant_secs`], 2.3 s).
    pub fn vn100() -> Self {
        let p = Self {
            model: ImuModel::AttitudeFilter,
            sample_rate_hz: 800.0,
            output_delay_secs: 2.5e-3,
            filter_time_constant_secs: 1.0,
            gyro_noise_density_rad_per_s_per_sqrt_hz: 0.0035_f64.to_radians(),
            gyro_bias_rad_per_s: (10.0_f64 / 3600.0).to_radians(),
            gyro_bias_correlation_time_secs: 100.0,
            accel_noise_density_m_per_s2_per_sqrt_hz: 0.14e-3 * STANDARD_GRAVITY_M_PER_S2,
        };
        Self {
            filter_time_constant_secs: p
                .steady_kalman_time_constant_secs(STANDARD_GRAVITY_M_PER_S2),
            ..p
        }
    }

    /// The time constant of the steady-state Kalman filter for a tilt that the gyro's white
    /// noise drives (density `N_g`) and the accelerometer reads through its white noise
    /// (`N_a / g` in angle): its gain is `sqrt(q / r)`, so `tau = N_a / (g N_g)` (s). It weighs
    /// only the sensors' noise, not the accelerations a moving robot adds to the
    /// accelerometer's reading. Infinite without gyro noise.
    ///
    /// ```
    /// use ballbot_world::world::imu::ImuParams;
    /// let tau = ImuParams::vn100().steady_kalman_time_constant_secs(9.80665);
    /// assert!((tau - 2.29).abs() < 0.01, "{tau}");
    /// ```
    pub fn steady_kalman_time_constant_secs(&self, gravity_m_per_s2: f64) -> f64 {
        self.accel_noise_density_m_per_s2_per_sqrt_hz
            / (gravity_m_per_s2 * self.gyro_noise_density_rad_per_s_per_sqrt_hz)
    }

    /// World steps per sensor sample at the world step `dt_secs`.
    pub fn steps_per_sample(&self, dt_secs: f64) -> u32 {
        // A checked whole number below u32::MAX (Self::validate).
        (1.0 / (self.sample_rate_hz * dt_secs)).round() as u32
    }

    /// The output delay in whole samples.
    pub fn delay_samples(&self) -> usize {
        // Checked below HISTORY (Self::validate).
        (self.output_delay_secs * self.sample_rate_hz).round() as usize
    }

    /// The filter's tilt error (rad; estimate minus truth, towards the apparent vertical
    /// positive) `t_secs` after a constant horizontal acceleration `accel_m_per_s2` starts,
    /// the body held upright under gravity `gravity_m_per_s2`: the continuous filter's
    /// solution `2 atan(tan(e_0 / 2) exp(-t / tau))` of `de/dt = -sin(e) / tau` from
    /// `e_0 = -atan(a / g)`, counted from the true vertical (module documentation).
    ///
    /// ```
    /// use ballbot_world::world::imu::ImuParams;
    /// let p = ImuParams::vn100();
    /// let lean = (1.0_f64 / 9.81).atan();
    /// assert!(p.tilt_error_under_acceleration_rad(1.0, 9.81, 0.0).abs() < 1e-15);
    /// let late = p.tilt_error_under_acceleration_rad(1.0, 9.81, 60.0);
    /// assert!((late - lean).abs() < 1e-6 * lean);
    /// ```
    pub fn tilt_error_under_acceleration_rad(
        &self,
        accel_m_per_s2: f64,
        gravity_m_per_s2: f64,
        t_secs: f64,
    ) -> f64 {
        let lean = accel_m_per_s2.atan2(gravity_m_per_s2);
        let decay = (-t_secs / self.filter_time_constant_secs).exp();
        lean + 2.0 * ((-lean / 2.0).tan() * decay).atan()
    }

    /// Checks every field, and for the filter model that its sample period is a whole number
    /// of world steps `dt_secs` (the `truth` model does not sample); the error names the field
    /// and bound.
    pub fn validate(&self, dt_secs: f64) -> Result<(), WorldError> {
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        positive(self.sample_rate_hz, "sensors.imu.sample_rate_hz")?;
        let steps = 1.0 / (self.sample_rate_hz * dt_secs);
        let whole = (1.0 - 1e-9..1e6).contains(&steps) && (steps - steps.round()).abs() < 1e-6;
        if self.model == ImuModel::AttitudeFilter && !whole {
            return invalid(
                "sensors.imu.sample_rate_hz",
                "its period must be a whole number (1 to 1e6) of world steps (dt_secs)",
            );
        }
        non_negative(self.output_delay_secs, "sensors.imu.output_delay_secs")?;
        if self.output_delay_secs * self.sample_rate_hz > (HISTORY - 1) as f64 {
            return invalid(
                "sensors.imu.output_delay_secs",
                "must be at most 63 sensor samples (sample_rate_hz)",
            );
        }
        positive(
            self.filter_time_constant_secs,
            "sensors.imu.filter_time_constant_secs",
        )?;
        non_negative(
            self.gyro_noise_density_rad_per_s_per_sqrt_hz,
            "sensors.imu.gyro_noise_density_rad_per_s_per_sqrt_hz",
        )?;
        non_negative(self.gyro_bias_rad_per_s, "sensors.imu.gyro_bias_rad_per_s")?;
        positive(
            self.gyro_bias_correlation_time_secs,
            "sensors.imu.gyro_bias_correlation_time_secs",
        )?;
        non_negative(
            self.accel_noise_density_m_per_s2_per_sqrt_hz,
            "sensors.imu.accel_noise_density_m_per_s2_per_sqrt_hz",
        )
    }
}

/// What the IMU reports: an attitude estimate and the gyro's rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuReading {
    /// When the sensor sampled (s).
    pub time_secs: f64,
    /// Estimated orientation, world from body.
    pub orientation: UnitQuaternion<f64>,
    /// Gyro rates in the body frame, with bias and noise (rad/s).
    pub body_rate_rad_per_s: Vector3<f64>,
}

/// The true motion the IMU senses at one world step.
#[derive(Clone, Copy, Debug)]
pub struct ImuTruth {
    /// Time at the end of the step (s).
    pub time_secs: f64,
    /// Body orientation, world from body.
    pub orientation: UnitQuaternion<f64>,
    /// Body angular velocity in the body frame (rad/s).
    pub body_rate_rad_per_s: Vector3<f64>,
    /// Velocity of the body's centre of mass in the world frame (m/s).
    pub velocity_m_per_s: Vector3<f64>,
    /// Gravity in the world frame (m/s^2, `[0, 0, -g]`).
    pub gravity_m_per_s2: Vector3<f64>,
}

/// What the filter carries from one sample to the next.
#[derive(Clone, Copy, Debug)]
struct FilterState {
    estimate: UnitQuaternion<f64>,
    time_secs: f64,
    velocity_m_per_s: Vector3<f64>,
}

/// The filter model's state: gyro bias, attitude estimate and the delay line.
#[derive(Clone, Debug)]
pub struct AttitudeFilter {
    params: ImuParams,
    sample_secs: f64,
    steps_per_sample: u64,
    steps: u64,
    rng: ChaCha8Rng,
    bias_rad_per_s: Vector3<f64>,
    bias_drawn: bool,
    /// The estimate, and the time and velocity of the last sample; `None` before the first.
    state: Option<FilterState>,
    history: [ImuReading; HISTORY],
    samples: usize,
}

impl AttitudeFilter {
    /// The filter for world steps of `dt_secs`, its noise seeded with `seed`. `params` must
    /// have passed [`ImuParams::validate`] for `dt_secs`.
    ///
    /// ```
    /// use ballbot_world::world::imu::{AttitudeFilter, ImuParams, ImuTruth};
    /// use nalgebra::{UnitQuaternion, Vector3};
    /// let mut imu = AttitudeFilter::new(ImuParams::vn100(), 1.0 / 8000.0, 7);
    /// let still = |t| ImuTruth {
    ///     time_secs: t,
    ///     orientation: UnitQuaternion::identity(),
    ///     body_rate_rad_per_s: Vector3::zeros(),
    ///     velocity_m_per_s: Vector3::zeros(),
    ///     gravity_m_per_s2: Vector3::new(0.0, 0.0, -9.81),
    /// };
    /// for k in 1..=8000 {
    ///     imu.record(&still(f64::from(k) / 8000.0));
    /// }
    /// let r = imu.reading().unwrap();
    /// assert!(r.orientation.angle() < 1e-3);
    /// assert!((r.time_secs - (1.0 - 2.5e-3)).abs() < 1e-9);
    /// ```
    pub fn new(params: ImuParams, dt_secs: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(FILTER_NOISE_STREAM);
        let steps_per_sample = u64::from(params.steps_per_sample(dt_secs).max(1));
        let empty = ImuReading {
            time_secs: 0.0,
            orientation: UnitQuaternion::identity(),
            body_rate_rad_per_s: Vector3::zeros(),
        };
        Self {
            params,
            sample_secs: steps_per_sample as f64 * dt_secs,
            steps_per_sample,
            steps: 0,
            rng,
            bias_rad_per_s: Vector3::zeros(),
            bias_drawn: false,
            state: None,
            history: [empty; HISTORY],
            samples: 0,
        }
    }

    /// Records one world step's true motion. The sensor samples at the first step recorded
    /// and then at every `steps_per_sample`-th world step (with the default rates, at the
    /// rigid steps), and the filter steps.
    pub fn record(&mut self, truth: &ImuTruth) {
        self.steps += 1;
        let reading = match self.state {
            None => self.start(truth),
            Some(last) if self.steps.is_multiple_of(self.steps_per_sample) => {
                self.sample(truth, last)
            }
            Some(_) => return,
        };
        self.history[self.samples % HISTORY] = reading;
        self.samples += 1;
    }

    /// Starts the filter again at the next recorded step, from the truth then, and forgets
    /// the readings so far (after a pose set from outside); the gyro bias carries on.
    pub fn restart(&mut self) {
        self.state = None;
        self.samples = 0;
    }

    /// The newest reading at least the output delay old, or the oldest kept while the
    /// sensor has run for less than the delay; `None` before the first sample.
    pub fn reading(&self) -> Option<ImuReading> {
        let newest = self.samples.checked_sub(1)?;
        let index = newest.saturating_sub(self.params.delay_samples());
        Some(self.history[index % HISTORY])
    }

    /// The first sample (or the first after [`Self::restart`]): the estimate at the truth;
    /// at the very first, the bias drawn from its stationary law.
    fn start(&mut self, truth: &ImuTruth) -> ImuReading {
        if !self.bias_drawn {
            self.bias_drawn = true;
            self.bias_rad_per_s = self.gaussian() * self.params.gyro_bias_rad_per_s;
        }
        self.state = Some(FilterState {
            estimate: truth.orientation,
            time_secs: truth.time_secs,
            velocity_m_per_s: truth.velocity_m_per_s,
        });
        ImuReading {
            time_secs: truth.time_secs,
            orientation: truth.orientation,
            body_rate_rad_per_s: self.gyro(truth),
        }
    }

    /// One sample: gyro and accelerometer with their errors, then the filter's step.
    fn sample(&mut self, truth: &ImuTruth, last: FilterState) -> ImuReading {
        let span_secs = (truth.time_secs - last.time_secs).max(f64::MIN_POSITIVE);
        self.wander_bias();
        let rate = self.gyro(truth);
        let specific_force = self.accelerometer(truth, &last, span_secs);
        let up_estimated = last.estimate.inverse_transform_vector(&Vector3::z());
        let correction = match specific_force.try_normalize(1e-9) {
            Some(up_measured) => up_measured.cross(&up_estimated),
            None => Vector3::zeros(),
        };
        let turn = (rate + correction / self.params.filter_time_constant_secs) * span_secs;
        let estimate = last.estimate * UnitQuaternion::from_scaled_axis(turn);
        self.state = Some(FilterState {
            estimate,
            time_secs: truth.time_secs,
            velocity_m_per_s: truth.velocity_m_per_s,
        });
        ImuReading {
            time_secs: truth.time_secs,
            orientation: estimate,
            body_rate_rad_per_s: rate,
        }
    }

    /// The gyro: the true rate plus bias and white noise.
    fn gyro(&mut self, truth: &ImuTruth) -> Vector3<f64> {
        let sigma = self.white_noise_std(self.params.gyro_noise_density_rad_per_s_per_sqrt_hz);
        truth.body_rate_rad_per_s + self.bias_rad_per_s + self.gaussian() * sigma
    }

    /// The accelerometer: the specific force in the body frame plus white noise.
    /// The acceleration is the velocity's change over the `span_secs` since the last sample.
    fn accelerometer(
        &mut self,
        truth: &ImuTruth,
        last: &FilterState,
        span_secs: f64,
    ) -> Vector3<f64> {
        let accel = (truth.velocity_m_per_s - last.velocity_m_per_s) / span_secs;
        let force_world = accel - truth.gravity_m_per_s2;
        let sigma = self.white_noise_std(self.params.accel_noise_density_m_per_s2_per_sqrt_hz);
        truth.orientation.inverse_transform_vector(&force_world) + self.gaussian() * sigma
    }

    /// One Gauss-Markov step of the bias: `b <- phi b + sigma sqrt(1 - phi^2) z`.
    fn wander_bias(&mut self) {
        let phi = (-self.sample_secs / self.params.gyro_bias_correlation_time_secs).exp();
        let kick = self.params.gyro_bias_rad_per_s * (1.0 - phi * phi).sqrt();
        self.bias_rad_per_s = self.bias_rad_per_s * phi + self.gaussian() * kick;
    }

    /// A sample's standard deviation for the noise density `density`, over the bandwidth
    /// up to half the sample rate.
    fn white_noise_std(&self, density: f64) -> f64 {
        density * (0.5 * self.params.sample_rate_hz).sqrt()
    }

    /// Three independent standard normal draws.
    fn gaussian(&mut self) -> Vector3<f64> {
        let mut draw = || -> f64 { StandardNormal.sample(&mut self.rng) };
        Vector3::new(draw(), draw(), draw())
    }
}

#[cfg(test)]
mod tests;
