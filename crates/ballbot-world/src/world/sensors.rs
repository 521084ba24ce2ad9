//! Sensors: an IMU on the body (tilt, yaw, body rates; [`crate::world::imu`] models it as the
//! truth plus noise or as the VN-100's attitude filter) and one encoder per omniwheel, with
//! seeded Gaussian noise and encoder quantisation. Encoders read the motor (relative to the
//! body, at the gearbox output), not the wheel and not the ball: when a wheel slips, its
//! encoder no longer measures the ball, and the drivetrain's compliance and backlash
//! ([`crate::world::transmission`]) lie between encoder and wheel.

use super::imu::{AttitudeFilter, ImuModel, ImuTruth};
use super::num::floor;
use super::params::SensorParams;
use super::telemetry::StepTelemetry;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// One sample of every sensor.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Measurement {
    /// Time of the sample (s).
    pub time_secs: f64,
    /// IMU tilt `[roll, pitch]` (rad), ZYX Euler angles of the body (as the core's
    /// `ImuSample`): rotation about the body x and y axes, right-handed (pitch > 0 leans
    /// towards +x, OW1).
    pub tilt_rad: [f64; 2],
    /// IMU yaw (rad), ZYX Euler.
    pub yaw_rad: f64,
    /// Gyro: body angular velocity in the body frame (rad/s).
    pub body_rate_rad_per_s: [f64; 3],
    /// Encoder angles of the three motors relative to the body, at the gearbox output
    /// (rotor angle over the gear ratio), quantised (rad).
    pub wheel_angle_rad: [f64; 3],
    /// Motor speeds at the gearbox output (rad/s) as a motor driver measures them: the
    /// quantised angle's change
    /// over the last [`SPEED_WINDOW_STEPS`] physics steps.
    pub wheel_speed_rad_per_s: [f64; 3],
}

/// Length of the encoder speed window, in physics steps (20 at 8 kHz: 2.5 ms, a resolution
/// of about 0.02 rad/s at the wheel with the default encoder).
pub const SPEED_WINDOW_STEPS: usize = 20;

/// The sensor suite with its own seeded noise generator.
#[derive(Clone, Debug)]
pub struct Sensors {
    params: SensorParams,
    wheel_rad_per_count: f64,
    rng: ChaCha8Rng,
    /// Quantised wheel angles of the last steps (ring buffer) and the write index.
    history: [[f64; 3]; SPEED_WINDOW_STEPS],
    next: usize,
    filled: usize,
    /// The speeds from the history as it is ([`Self::wheel_speeds`]), computed when an
    /// encoder sample is recorded: the world and the robot loop read them several times
    /// between two samples.
    speeds: [f64; 3],
    dt_secs: f64,
    /// The attitude filter, with [`ImuModel::AttitudeFilter`].
    filter: Option<AttitudeFilter>,
}

impl Sensors {
    /// Sensors whose encoders count `params.encoder_counts_per_rev` per rotor turn behind a
    /// gear ratio `gear_ratio`.
    /// `dt_secs` is the physics step at which [`Self::record_encoders`] is called.
    pub fn new(params: SensorParams, gear_ratio: f64, dt_secs: f64) -> Self {
        let counts_per_wheel_rev = f64::from(params.encoder_counts_per_rev) * gear_ratio;
        Self {
            params,
            wheel_rad_per_count: core::f64::consts::TAU / counts_per_wheel_rev,
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            history: [[0.0; 3]; SPEED_WINDOW_STEPS],
            next: 0,
            filled: 0,
            speeds: [0.0; 3],
            dt_secs,
            filter: (params.imu.model == ImuModel::AttitudeFilter)
                .then(|| AttitudeFilter::new(params.imu, dt_secs, params.seed)),
        }
    }

    /// Starts the IMU's attitude filter again from the next recorded state (after a pose or
    /// velocity set from outside); its bias carries on.
    pub fn restart_imu(&mut self) {
        if let Some(filter) = &mut self.filter {
            filter.restart();
        }
    }

    /// Records one physics step's true motion, which `truth` gives, for the IMU's own
    /// sampling (only the attitude filter model samples between the controller's reads, and
    /// only it calls `truth`).
    pub fn record_imu(&mut self, truth: impl FnOnce() -> ImuTruth) {
        if let Some(filter) = &mut self.filter {
            filter.record(&truth());
        }
    }

    fn quantise(&self, angle_rad: f64) -> f64 {
        let q = self.wheel_rad_per_count;
        floor(angle_rad / q) * q
    }

    /// Records the true motor angles (at the gearbox output) of one physics step (the
    /// encoders count every step).
    pub fn record_encoders(&mut self, wheel_angle_rad: [f64; 3]) {
        self.history[self.next] = wheel_angle_rad.map(|a| self.quantise(a));
        self.next = (self.next + 1) % SPEED_WINDOW_STEPS;
        self.filled = (self.filled + 1).min(SPEED_WINDOW_STEPS);
        self.speeds = self.speeds_from_history();
    }

    /// The encoder speed estimate of the three wheels (rad/s): see
    /// [`Measurement::wheel_speed_rad_per_s`].
    pub fn wheel_speeds(&self) -> [f64; 3] {
        self.speeds
    }

    fn speeds_from_history(&self) -> [f64; 3] {
        if self.filled < 2 {
            return [0.0; 3];
        }
        let newest = self.history[(self.next + SPEED_WINDOW_STEPS - 1) % SPEED_WINDOW_STEPS];
        let oldest_index = if self.filled < SPEED_WINDOW_STEPS {
            0
        } else {
            self.next
        };
        let oldest = self.history[oldest_index];
        let span_secs = (self.filled - 1) as f64 * self.dt_secs;
        [0, 1, 2].map(|i| (newest[i] - oldest[i]) / span_secs)
    }

    /// Encoder resolution at the wheel (rad per count).
    pub fn wheel_rad_per_count(&self) -> f64 {
        self.wheel_rad_per_count
    }

    fn noise(&mut self, std_dev: f64) -> f64 {
        let z: f64 = StandardNormal.sample(&mut self.rng);
        std_dev * z
    }

    /// Samples every sensor from the true state in `truth`: the IMU as its model has it
    /// ([`crate::world::imu`]), the encoders now.
    pub fn sample(&mut self, truth: &StepTelemetry) -> Measurement {
        let reading = self.filter.as_ref().and_then(AttitudeFilter::reading);
        let (tilt_rad, yaw_rad, body_rate_rad_per_s) = match reading {
            Some(r) => {
                let (roll, pitch, yaw) = r.orientation.euler_angles();
                ([roll, pitch], yaw, r.body_rate_rad_per_s.into())
            }
            None => self.noisy_truth(truth),
        };
        Measurement {
            time_secs: truth.time_secs,
            tilt_rad,
            yaw_rad,
            body_rate_rad_per_s,
            wheel_angle_rad: truth.wheels.map(|w| self.quantise(w.motor_angle_rad)),
            wheel_speed_rad_per_s: self.wheel_speeds(),
        }
    }

    /// The `truth` IMU model (and the filter's before its first sample): the true tilt, yaw
    /// and rates plus white noise.
    fn noisy_truth(&mut self, truth: &StepTelemetry) -> ([f64; 2], f64, [f64; 3]) {
        let tilt = self.params.tilt_noise_rad;
        let gyro = self.params.gyro_noise_rad_per_s;
        let (roll, pitch, yaw) = truth.body_orientation.euler_angles();
        let rate = truth.body_rate_rad_per_s;
        (
            [roll + self.noise(tilt), pitch + self.noise(tilt)],
            yaw + self.noise(tilt),
            [
                rate.x + self.noise(gyro),
                rate.y + self.noise(gyro),
                rate.z + self.noise(gyro),
            ],
        )
    }
}
