//! `RobotLoop` (the shipped runtime, `ballbot-runtime`) on the fuzz plant behind devices that
//! fail at random: IMU and encoder reads and motor writes return `Err` in bursts, and now and
//! then one device fails for good for 0.2 to 2 s. The loop arms itself (start-up), the operator
//! sends accepted commands and resets after a fault.
//!
//! Invariants ([`super::invariants`]): every torque the loop writes is finite and within the
//! peak and the torque-speed line at the speed it read ([`inv::RUNTIME_LIMITS`]); reads failing
//! for longer than their timeout leave the motors off ([`inv::RUNTIME_READ_ERRORS`]); writes
//! failing for longer than the motor health monitor's persistence (plus two periods) leave
//! the motors off too ([`inv::RUNTIME_WRITE_ERRORS`]: `Fault::MotorUnanswered`).

use super::episode::EpisodeCounts;
use super::hostile::{accepted_command, chance, index, symmetric, unit};
use super::invariants as inv;
use super::plant::Plant;
use super::rig::INNER_PER_OUTER;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::Command;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::{
    DeviceErrorKind, Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders,
};
use ballbot_core::safety::{MIAPURE_NOMINAL_BUS_VOLTAGE_V, Mode, ModeRequest, SafetyParams};
use ballbot_runtime::{LoopConfig, OperatorInput, RobotLoop};
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

/// A sensor that hands out the sample set by the fuzzer, or fails.
#[derive(Clone, Copy, Debug)]
pub struct FlakySensor<S> {
    /// The sample of the next read.
    pub sample: S,
    /// Whether the next read fails.
    pub fail: bool,
}

impl Imu<f64> for FlakySensor<ImuSample<f64>> {
    type Error = DeviceErrorKind;
    fn read(&mut self) -> Result<ImuSample<f64>, DeviceErrorKind> {
        if self.fail {
            Err(DeviceErrorKind::Bus)
        } else {
            Ok(self.sample)
        }
    }
}

impl WheelEncoders<f64> for FlakySensor<EncoderSample<f64>> {
    type Error = DeviceErrorKind;
    fn read(&mut self) -> Result<EncoderSample<f64>, DeviceErrorKind> {
        if self.fail {
            Err(DeviceErrorKind::Timeout)
        } else {
            Ok(self.sample)
        }
    }
}

/// Motor drivers whose writes may fail: a failed write leaves the driver on its previous
/// torque (the worst case: it keeps what it had).
#[derive(Clone, Copy, Debug, Default)]
pub struct FlakyMotors {
    /// What the drivers apply (N m).
    pub applied_nm: Vector3<f64>,
    /// What the loop asked for in its last call (`None`: disable).
    pub commanded_nm: Option<Vector3<f64>>,
    /// Whether the next write fails.
    pub fail: bool,
    /// A dead wheel: its driver applies nothing and reports nothing (0 N m), error-free.
    pub dead: Option<usize>,
}

impl MotorTorques<f64> for FlakyMotors {
    type Error = DeviceErrorKind;
    fn apply(
        &mut self,
        torque_nm: &Vector3<f64>,
    ) -> Result<[MotorFeedback<f64>; 3], DeviceErrorKind> {
        self.commanded_nm = Some(*torque_nm);
        if self.fail {
            return Err(DeviceErrorKind::Device);
        }
        self.applied_nm = *torque_nm;
        if let Some(w) = self.dead {
            self.applied_nm[w % 3] = 0.0;
        }
        // The drivers report the torque they deliver (the wheel speeds are the plant's, which
        // the health monitor does not need for its verdicts).
        Ok([0, 1, 2].map(|i| {
            MotorFeedback::healthy(self.applied_nm[i], 0.0, MIAPURE_NOMINAL_BUS_VOLTAGE_V)
        }))
    }
    fn disable(&mut self) -> Result<(), DeviceErrorKind> {
        self.commanded_nm = None;
        if self.fail {
            return Err(DeviceErrorKind::Device);
        }
        self.applied_nm = Vector3::zeros();
        Ok(())
    }
}

/// The loop's clock, set by the fuzzer.
#[derive(Clone, Copy, Debug)]
pub struct SetClock(pub u64);

impl MonotonicClock for SetClock {
    fn now_us(&mut self) -> u64 {
        self.0
    }
}

/// Failures scheduled for one device: a burst (outer periods left) or a persistent failure.
#[derive(Clone, Copy, Debug, Default)]
struct Schedule {
    left: u32,
    /// Consecutive outer periods in which every call failed.
    failing_periods: u64,
}

/// Runs one episode of `outer_steps` outer periods of `RobotLoop` on failing devices.
pub fn run_runtime_episode(
    config: BallbotControllerConfig<f64>,
    seed: u64,
    outer_steps: u64,
) -> Result<EpisodeCounts, ballbot_core::Error> {
    run_runtime_episode_judged(
        config,
        LoopConfig::miapure(),
        config.safety,
        seed,
        outer_steps,
    )
}

/// [`run_runtime_episode`] on a loop configured with `loop_config`, with the timeouts of the
/// read-error invariant taken from `judge` instead of the controller's own, and the
/// write-error invariant's from [`LoopConfig::miapure`] (to show that the invariants fire on a
/// lax supervisor or a lax motor health monitor).
pub fn run_runtime_episode_judged(
    config: BallbotControllerConfig<f64>,
    loop_config: LoopConfig<f64>,
    judge: SafetyParams<f64>,
    seed: u64,
    outer_steps: u64,
) -> Result<EpisodeCounts, ballbot_core::Error> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut plant = Plant::new(&config.robot)?;
    let (imu0, enc0) = plant.sensors(0);
    let mut robot = RobotLoop::new(
        config,
        loop_config,
        FlakySensor {
            sample: imu0,
            fail: false,
        },
        FlakySensor {
            sample: enc0,
            fail: false,
        },
        FlakyMotors::default(),
        SetClock(0),
    )?;
    let actuator = config.robot.drivetrain.actuator;
    let period_us = 2_500;
    let imu_ticks = judge.imu_timeout_us.div_ceil(period_us) + 2;
    let enc_ticks = judge.encoder_timeout_us.div_ceil(period_us) + 2;
    // The health monitor's persistence (5 ms: 2 periods) plus two.
    let persistence_us =
        (LoopConfig::<f64>::miapure().motor_health.persistence_secs * 1e6).ceil() as u64;
    let write_ticks = persistence_us.div_ceil(period_us) + 2;
    let mut counts = EpisodeCounts::default();
    let mut schedules = [Schedule::default(); 3];
    let mut command: Command<'static, f64> = Command::Stop;
    let mut last_read_speeds = enc0.wheel_speeds_rad_per_s;
    let mut broken = [false; 4];
    let mut unanswered_on: u64 = 0;
    // A dead wheel (periods left), and the inner steps in a row it has been commanded
    // beyond three times the health monitor's absolute tolerance with the motors on.
    let mut dead_left: u32 = 0;
    let mut dead_commanded: u64 = 0;
    let health = LoopConfig::<f64>::miapure().motor_health;
    let persistence_steps = (health.persistence_secs * 8000.0).ceil() as u64;
    let mut now_us = 1_000_000;
    for k in 0..outer_steps {
        now_us += period_us;
        // Failures: bursts of 1 to 20 periods (one every 0.25 s on average), or one device
        // for good for 0.2 to 2 s (one every 5 s).
        if chance(&mut rng, 0.01) {
            schedules[index(&mut rng, 3)].left = 1 + index(&mut rng, 20) as u32;
        }
        if chance(&mut rng, 0.0005) {
            schedules[index(&mut rng, 3)].left = 80 + (unit(&mut rng) * 720.0) as u32;
        }
        // A wheel dies for 0.2 to 2 s (one every 5 s).
        if dead_left == 0 && chance(&mut rng, 0.0005) {
            dead_left = 80 + (unit(&mut rng) * 720.0) as u32;
            robot.devices_mut().2.dead = Some(index(&mut rng, 3));
        } else if dead_left > 0 {
            dead_left -= 1;
            if dead_left == 0 {
                robot.devices_mut().2.dead = None;
            }
        }
        let failing: [bool; 3] = core::array::from_fn(|d| schedules[d].left > 0);
        for s in &mut schedules {
            s.failing_periods = if s.left > 0 { s.failing_periods + 1 } else { 0 };
            s.left = s.left.saturating_sub(1);
        }
        let (mut imu, enc) = plant.sensors(now_us);
        imu.angular_velocity_rad_per_s[0] += symmetric(&mut rng, 1e-6);
        {
            let (i, e, m, c) = robot.devices_mut();
            *i = FlakySensor {
                sample: imu,
                fail: failing[0],
            };
            *e = FlakySensor {
                sample: enc,
                fail: failing[1],
            };
            m.fail = failing[2];
            c.0 = now_us;
        }
        if !failing[1] {
            last_read_speeds = enc.wheel_speeds_rad_per_s;
        }
        if chance(&mut rng, 0.004) {
            command = accepted_command(&mut rng);
        }
        let request = match robot.mode() {
            Mode::Fault => ModeRequest::Reset,
            Mode::ControlledStop if chance(&mut rng, 0.01) => ModeRequest::Resume,
            _ => ModeRequest::None,
        };
        robot.outer_task(&OperatorInput {
            command,
            command_timestamp_us: Some(now_us),
            request,
        });
        counts.outer_steps += 1;
        let mut found = [None, None, None, None];
        for i in 0..INNER_PER_OUTER {
            let stamp = now_us + 125 * i as u64;
            let sample = EncoderSample {
                timestamp_us: stamp,
                wheel_speeds_rad_per_s: plant.wheel_speeds(),
            };
            // Single failed reads and writes in the 8 kHz loop too.
            let enc_fail = failing[1] || chance(&mut rng, 0.01);
            let motor_fail = failing[2] || chance(&mut rng, 0.01);
            {
                let (_, e, m, c) = robot.devices_mut();
                *e = FlakySensor {
                    sample,
                    fail: enc_fail,
                };
                m.fail = motor_fail;
                c.0 = stamp;
            }
            if !enc_fail {
                last_read_speeds = sample.wheel_speeds_rad_per_s;
            }
            let report = robot.inner_task();
            counts.inner_steps += 1;
            let motors = robot.devices().2;
            dead_commanded = match motors.dead {
                Some(w)
                    if report.applied
                        && !motor_fail
                        && report.output.torque_nm[w % 3].abs()
                            > 3.0 * health.torque_tolerance_nm =>
                {
                    dead_commanded + 1
                }
                _ => 0,
            };
            if dead_commanded > persistence_steps + 2 * INNER_PER_OUTER as u64 && found[3].is_none()
            {
                found[3] = Some(format!(
                    "motors still on {} inner steps after OW{} died, commanded beyond {:.1} N m",
                    dead_commanded,
                    motors.dead.map_or(0, |w| w % 3 + 1),
                    3.0 * health.torque_tolerance_nm
                ));
            }
            if let Some(t) = motors.commanded_nm
                && found[0].is_none()
                && let Some(what) = torque_broken(&actuator, &t, &last_read_speeds)
            {
                found[0] = Some(what);
            }
            let applied = motors.applied_nm;
            plant.step(&applied, 1.0 / 8000.0);
        }
        let enabled = robot.mode().motors_enabled();
        let read_errors = (schedules[0].failing_periods > imu_ticks)
            || (schedules[1].failing_periods > enc_ticks);
        if read_errors && enabled {
            found[1] = Some(format!(
                "motors on after {} periods of failed IMU reads, {} of failed encoder reads",
                schedules[0].failing_periods, schedules[1].failing_periods
            ));
        }
        // Periods with the motors on while every write fails (the operator's reset after the
        // fault lets the loop arm again, onto drivers that still do not answer: the count
        // starts again there).
        unanswered_on = if failing[2] && enabled {
            unanswered_on + 1
        } else {
            0
        };
        if unanswered_on > write_ticks {
            found[2] = Some(format!(
                "still {:?} after {} periods with the motors on and every write failing",
                robot.mode(),
                unanswered_on
            ));
        }
        let invariants = [
            inv::RUNTIME_LIMITS,
            inv::RUNTIME_READ_ERRORS,
            inv::RUNTIME_WRITE_ERRORS,
            inv::MOTOR_HEALTH,
        ];
        for (j, what) in found.into_iter().enumerate() {
            let now = what.is_some();
            if let Some(what) = what
                && !broken[j]
            {
                counts.record(invariants[j], seed, k, what);
            }
            broken[j] = now;
        }
        if plant.fallen(0.6) {
            plant.reset();
        }
    }
    Ok(counts)
}

/// A torque written to the drivers: finite, within the peak and the torque-speed line at the
/// speed the loop last read.
fn torque_broken(
    a: &ballbot_core::ActuatorParams<f64>,
    torque: &Vector3<f64>,
    speeds: &Vector3<f64>,
) -> Option<String> {
    for (t, w) in torque.iter().zip(speeds.iter()) {
        let (lo, hi) = a.torque_bounds_nm(*w);
        if !t.is_finite() || t.abs() > a.peak_torque_nm + 1e-9 || *t < lo - 1e-9 || *t > hi + 1e-9 {
            return Some(format!(
                "RobotLoop wrote {torque:?} N m at measured speeds {speeds:?}"
            ));
        }
    }
    None
}
