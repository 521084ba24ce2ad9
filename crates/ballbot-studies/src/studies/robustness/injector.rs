//! [`FaultInjector`]: the device, timing and link faults of the matrix as a rig
//! [`Injector`]. The world faults (floor patch, bump, payload shift) and the command jump
//! change the world or the command instead; [`super::fault_run`] applies them.

use super::faults::{FaultClass, FaultMagnitudes};
use ballbot_core::ActuatorParams;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::MotorFeedback;
use ballbot_world::rig::{Injector, Tick};
use nalgebra::Vector3;
use std::collections::VecDeque;

/// The wheel whose encoder or motor fails (OW1).
pub const FAULTY_WHEEL: usize = 0;

/// Injects one [`FaultClass`] from `inject_us` on (see [`FaultMagnitudes`] for the sizes).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::estimation::ImuSample;
/// use ballbot_world::rig::Injector;
/// use ballbot_studies::studies::robustness::{FaultClass, FaultInjector, FaultMagnitudes};
/// let actuator = BallbotParams::miapure_60kg().drivetrain.actuator;
/// let mut stale =
///     FaultInjector::new(FaultClass::ImuStale, FaultMagnitudes::fault_matrix(), 1_000_000, actuator);
/// assert!(stale.imu(997_500, ImuSample::upright(997_500)).is_some());
/// assert!(stale.imu(1_000_000, ImuSample::upright(1_000_000)).is_none());
/// ```
#[derive(Clone, Debug)]
pub struct FaultInjector {
    class: FaultClass,
    magnitudes: FaultMagnitudes,
    inject_us: u64,
    actuator: ActuatorParams<f64>,
    /// Faulted outer ticks or samples so far (bursts, overruns, missed ticks).
    count: u32,
    /// The frozen IMU reading.
    frozen: Option<ImuSample<f64>>,
    /// The stuck motor's torque.
    stuck_nm: Option<f64>,
    /// Whether the glitch has hit the outer and the inner sample.
    glitched: (bool, bool),
    /// Delayed samples (oldest first) for the sensor delay.
    imu_queue: VecDeque<ImuSample<f64>>,
    encoder_queue: VecDeque<EncoderSample<f64>>,
}

impl FaultInjector {
    /// The injector of `class`, striking at `inject_us` (world time); `actuator` bounds the
    /// sagging bus's torque.
    pub fn new(
        class: FaultClass,
        magnitudes: FaultMagnitudes,
        inject_us: u64,
        actuator: ActuatorParams<f64>,
    ) -> Self {
        Self {
            class,
            magnitudes,
            inject_us,
            actuator,
            count: 0,
            frozen: None,
            stuck_nm: None,
            glitched: (false, false),
            imu_queue: VecDeque::new(),
            encoder_queue: VecDeque::new(),
        }
    }

    fn active(&self, now_us: u64) -> bool {
        now_us >= self.inject_us
    }

    fn delay_us(&self) -> u64 {
        (self.magnitudes.sensor_delay_secs * 1e6).round() as u64
    }
}

/// The newest sample in `queue` stamped at or before `due_us`, dropping the older ones.
fn delayed<S: Copy>(queue: &mut VecDeque<S>, due_us: u64, stamp: impl Fn(&S) -> u64) -> Option<S> {
    while queue.len() > 1 && queue.get(1).is_some_and(|s| stamp(s) <= due_us) {
        queue.pop_front();
    }
    queue.front().copied().filter(|s| stamp(s) <= due_us)
}

impl Injector for FaultInjector {
    fn imu(&mut self, now_us: u64, sample: ImuSample<f64>) -> Option<ImuSample<f64>> {
        if self.class == FaultClass::SensorDelay {
            self.imu_queue.push_back(sample);
            if !self.active(now_us) {
                return Some(sample);
            }
            let due = now_us.saturating_sub(self.delay_us());
            // Nothing old enough yet: the device has nothing new to give.
            return delayed(&mut self.imu_queue, due, |s| s.timestamp_us);
        }
        if !self.active(now_us) {
            return Some(sample);
        }
        match self.class {
            FaultClass::ImuNanBurst if self.count < self.magnitudes.imu_nan_samples => {
                self.count += 1;
                Some(ImuSample {
                    roll_rad: f64::NAN,
                    pitch_rad: f64::NAN,
                    yaw_rad: f64::NAN,
                    angular_velocity_rad_per_s: Vector3::repeat(f64::NAN),
                    ..sample
                })
            }
            FaultClass::ImuFrozen => {
                let frozen = *self.frozen.get_or_insert(sample);
                Some(ImuSample {
                    timestamp_us: sample.timestamp_us,
                    ..frozen
                })
            }
            FaultClass::ImuStale => None,
            FaultClass::GyroBiasStep => {
                let b = self.magnitudes.gyro_bias_rad_per_s;
                let mut biased = sample;
                biased.angular_velocity_rad_per_s += Vector3::new(b, b, 0.0);
                Some(biased)
            }
            _ => Some(sample),
        }
    }

    fn encoders(
        &mut self,
        now_us: u64,
        sample: EncoderSample<f64>,
        outer: bool,
    ) -> Option<EncoderSample<f64>> {
        // The delay is on the controller's path (IMU and the outer loop's encoder sample);
        // the motor drivers read their own encoders.
        if self.class == FaultClass::SensorDelay && outer {
            self.encoder_queue.push_back(sample);
            if !self.active(now_us) {
                return Some(sample);
            }
            let due = now_us.saturating_sub(self.delay_us());
            return delayed(&mut self.encoder_queue, due, |s| s.timestamp_us);
        }
        if !self.active(now_us) {
            return Some(sample);
        }
        let mut out = sample;
        match self.class {
            FaultClass::EncoderDropout => {
                let end_us = self.inject_us + (self.magnitudes.encoder_dropout_secs * 1e6) as u64;
                if now_us < end_us {
                    out.wheel_speeds_rad_per_s[FAULTY_WHEEL] = 0.0;
                }
            }
            FaultClass::EncoderGlitch => {
                let hit = if outer {
                    &mut self.glitched.0
                } else {
                    &mut self.glitched.1
                };
                if !*hit {
                    *hit = true;
                    out.wheel_speeds_rad_per_s[FAULTY_WHEEL] =
                        self.magnitudes.encoder_glitch_rad_per_s;
                }
            }
            _ => {}
        }
        Some(out)
    }

    fn outer_tick(&mut self, now_us: u64) -> Tick {
        let healthy = Tick::Run { task_us: 0 };
        if !self.active(now_us) {
            return healthy;
        }
        match self.class {
            FaultClass::LoopOverrun if self.count < self.magnitudes.overrun_tasks => {
                self.count += 1;
                Tick::Run {
                    task_us: self.magnitudes.overrun_task_us,
                }
            }
            FaultClass::MissedTicks if self.count < self.magnitudes.missed_ticks => {
                self.count += 1;
                Tick::Skip
            }
            _ => healthy,
        }
    }

    fn command_timestamp_us(&mut self, now_us: u64) -> Option<u64> {
        if self.class == FaultClass::CommandLinkLost && self.active(now_us) {
            // The last command arrived just before the link died.
            Some(self.inject_us.saturating_sub(1))
        } else {
            Some(now_us)
        }
    }

    fn torques(
        &mut self,
        now_us: u64,
        torque_nm: Vector3<f64>,
        wheel_speeds_rad_per_s: Vector3<f64>,
    ) -> Vector3<f64> {
        if !self.active(now_us) {
            return torque_nm;
        }
        let mut out = torque_nm;
        match self.class {
            FaultClass::MotorDead => out[FAULTY_WHEEL] = 0.0,
            FaultClass::MotorStuck => {
                out[FAULTY_WHEEL] = *self.stuck_nm.get_or_insert(torque_nm[FAULTY_WHEEL]);
            }
            FaultClass::TorqueSaturation => {
                let f = self.magnitudes.bus_voltage_fraction;
                for (t, w) in out.iter_mut().zip(wheel_speeds_rad_per_s.iter()) {
                    let (lo, hi) = self.actuator.torque_bounds_nm(w / f);
                    *t = t.clamp(f * lo, f * hi);
                }
            }
            _ => {}
        }
        out
    }

    /// A sagging bus shows in every driver's reported bus voltage.
    fn feedback(
        &mut self,
        now_us: u64,
        feedback: [MotorFeedback<f64>; 3],
    ) -> [MotorFeedback<f64>; 3] {
        if self.class != FaultClass::TorqueSaturation || !self.active(now_us) {
            return feedback;
        }
        let f = self.magnitudes.bus_voltage_fraction;
        feedback.map(|fb| MotorFeedback {
            bus_voltage_v: f * fb.bus_voltage_v,
            ..fb
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use ballbot_core::BallbotParams;

    const AT_US: u64 = 1_000_000;

    fn injector(class: FaultClass) -> FaultInjector {
        let actuator = BallbotParams::miapure_60kg().drivetrain.actuator;
        FaultInjector::new(class, FaultMagnitudes::fault_matrix(), AT_US, actuator)
    }

    fn torque(f: &mut FaultInjector, now_us: u64, t: Vector3<f64>) -> Vector3<f64> {
        f.torques(now_us, t, Vector3::zeros())
    }

    #[test]
    fn motor_faults_act_on_ow1_only_and_only_from_the_fault_on() {
        let t = Vector3::new(5.0, -3.0, 2.0);
        let mut dead = injector(FaultClass::MotorDead);
        assert_eq!(torque(&mut dead, AT_US - 1, t), t);
        assert_eq!(torque(&mut dead, AT_US, t), Vector3::new(0.0, -3.0, 2.0));
        let mut stuck = injector(FaultClass::MotorStuck);
        assert_eq!(torque(&mut stuck, AT_US, t), t);
        let later = torque(&mut stuck, AT_US + 125, Vector3::new(-9.0, 1.0, 1.0));
        assert_eq!(later, Vector3::new(5.0, 1.0, 1.0));
    }

    #[test]
    fn a_sagging_bus_halves_the_envelope() {
        let mut sag = injector(FaultClass::TorqueSaturation);
        let big = Vector3::repeat(100.0);
        let peak = BallbotParams::<f64>::miapure_60kg()
            .drivetrain
            .actuator
            .peak_torque_nm;
        let at_rest = sag.torques(AT_US, big, Vector3::zeros());
        assert!((at_rest[0] - 0.5 * peak).abs() < 1e-9, "{at_rest}");
        // At half the no-load speed the half-voltage line gives nothing more.
        let no_load = sag.actuator.no_load_speed_rad_per_s;
        let fast = sag.torques(AT_US, big, Vector3::repeat(0.5 * no_load));
        assert!(fast[0].abs() < 1e-9, "{fast}");
    }

    #[test]
    fn the_delay_hands_over_samples_ten_ms_old() {
        let mut delay = injector(FaultClass::SensorDelay);
        let mut last = None;
        for k in 0..1000_u64 {
            let now = k * 2500;
            last = delay.imu(now, ImuSample::upright(now));
        }
        let now = 999 * 2500;
        assert_eq!(last.unwrap().timestamp_us, now - 10_000);
        // The drivers' own encoder samples are not delayed.
        let s = EncoderSample::still(now);
        assert_eq!(delay.encoders(now, s, false), Some(s));
    }

    #[test]
    fn bursts_ticks_and_glitches_are_counted() {
        let mut nan = injector(FaultClass::ImuNanBurst);
        let bad = (0..5)
            .filter(|k| {
                let now = AT_US + k * 2500;
                !delay_free_finite(nan.imu(now, ImuSample::upright(now)))
            })
            .count();
        assert_eq!(bad, 3);
        let mut missed = injector(FaultClass::MissedTicks);
        let skipped = (0..6)
            .filter(|k| missed.outer_tick(AT_US + k * 2500) == Tick::Skip)
            .count();
        assert_eq!(skipped, 3);
        let mut glitch = injector(FaultClass::EncoderGlitch);
        let hits = (0..4)
            .filter(|k| {
                let now = AT_US + k * 125;
                let s = glitch.encoders(now, EncoderSample::still(now), k % 2 == 0);
                s.unwrap().wheel_speeds_rad_per_s[FAULTY_WHEEL] > 100.0
            })
            .count();
        // Once at the outer tick, once in the 8 kHz loop.
        assert_eq!(hits, 2);
    }

    fn delay_free_finite(s: Option<ImuSample<f64>>) -> bool {
        s.is_some_and(|s| s.is_finite())
    }
}
