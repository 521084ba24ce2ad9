//! Host tests of `RobotLoop` on mock devices: start-up and arming, shutdown, read and write
//! errors, dead drivers, clocks. The devices are scripted, the robot does not move (no
//! plant): what is checked is what the loop does with its devices, which needs no physics.

#![allow(clippy::expect_used, clippy::panic)] // test helpers, not only #[test] functions

use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::{
    DeviceErrorKind, Imu, MonotonicClock, MotorFeedback, MotorTorques, WheelEncoders,
};
use ballbot_core::safety::{Fault, MIAPURE_NOMINAL_BUS_VOLTAGE_V, Mode, ModeRequest};
use ballbot_runtime::{InnerReport, LoopConfig, OperatorInput, OuterReport, Phase, RobotLoop};
use nalgebra::Vector3;

/// An IMU reading the sample the bench sets, or failing.
#[derive(Debug)]
struct TestImu {
    sample: ImuSample<f64>,
    fail: bool,
}

impl Imu<f64> for TestImu {
    type Error = DeviceErrorKind;
    fn read(&mut self) -> Result<ImuSample<f64>, DeviceErrorKind> {
        if self.fail {
            Err(DeviceErrorKind::Bus)
        } else {
            Ok(self.sample)
        }
    }
}

/// Encoders reading the sample the bench sets, or failing.
#[derive(Debug)]
struct TestEncoders {
    sample: EncoderSample<f64>,
    fail: bool,
}

impl WheelEncoders<f64> for TestEncoders {
    type Error = DeviceErrorKind;
    fn read(&mut self) -> Result<EncoderSample<f64>, DeviceErrorKind> {
        if self.fail {
            Err(DeviceErrorKind::Bus)
        } else {
            Ok(self.sample)
        }
    }
}

/// Drivers that record every call; writes may fail, and a wheel may be dead (it applies and
/// reports nothing).
#[derive(Debug, Default)]
struct TestMotors {
    /// What the last call asked for (`None`: disable).
    last: Option<Vector3<f64>>,
    applies: u64,
    disables: u64,
    fail: bool,
    dead: Option<usize>,
}

impl MotorTorques<f64> for TestMotors {
    type Error = DeviceErrorKind;
    fn apply(
        &mut self,
        torque_nm: &Vector3<f64>,
    ) -> Result<[MotorFeedback<f64>; 3], DeviceErrorKind> {
        self.last = Some(*torque_nm);
        self.applies += 1;
        if self.fail {
            return Err(DeviceErrorKind::Bus);
        }
        let dead = self.dead;
        Ok([0, 1, 2].map(|i| {
            let delivered = if dead == Some(i) { 0.0 } else { torque_nm[i] };
            MotorFeedback::healthy(delivered, 0.0, MIAPURE_NOMINAL_BUS_VOLTAGE_V)
        }))
    }
    fn disable(&mut self) -> Result<(), DeviceErrorKind> {
        self.last = None;
        self.disables += 1;
        if self.fail {
            Err(DeviceErrorKind::Bus)
        } else {
            Ok(())
        }
    }
}

/// A clock the bench sets; each read adds `per_read_us` (a slow task).
#[derive(Debug, Default)]
struct TestClock {
    now_us: u64,
    per_read_us: u64,
}

impl MonotonicClock for TestClock {
    fn now_us(&mut self) -> u64 {
        let now = self.now_us;
        self.now_us += self.per_read_us;
        now
    }
}

type Loop = RobotLoop<f64, TestImu, TestEncoders, TestMotors, TestClock>;

/// The loop on MiaPURE's shipped configuration, its devices healthy, the body upright and
/// still, and the clock that `period` advances.
struct Bench {
    robot: Loop,
    now_us: u64,
    /// Whether the clock advances with each period (a stalled clock does not).
    clock_runs: bool,
    /// Added to the IMU's tilt (rad): where the body is.
    tilt_rad: f64,
}

const PERIOD_US: u64 = 2_500;

impl Bench {
    fn new() -> Self {
        Self::with_loop(LoopConfig::miapure())
    }

    fn with_loop(loop_config: LoopConfig<f64>) -> Self {
        let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())
            .expect("the shipped configuration");
        let robot = RobotLoop::new(
            config,
            loop_config,
            TestImu {
                sample: ImuSample::upright(0),
                fail: false,
            },
            TestEncoders {
                sample: EncoderSample::still(0),
                fail: false,
            },
            TestMotors::default(),
            TestClock::default(),
        )
        .expect("a valid loop");
        Self {
            robot,
            now_us: 1_000_000,
            clock_runs: true,
            tilt_rad: 0.0,
        }
    }

    /// One 400 Hz period: fresh samples stamped now (a real IMU never repeats a sample bit for
    /// bit: the gyro carries a little noise), the outer task, then 20 inner tasks.
    fn period(&mut self, command: Command<'static, f64>, request: ModeRequest) -> Period {
        if self.clock_runs {
            self.now_us += PERIOD_US;
        }
        let now = self.now_us;
        let noise = if (now / PERIOD_US).is_multiple_of(2) {
            1e-6
        } else {
            -1e-6
        };
        let tilt = self.tilt_rad;
        {
            let (imu, enc, _, clock) = self.robot.devices_mut();
            imu.sample = ImuSample::upright(now);
            imu.sample.pitch_rad = tilt;
            imu.sample.angular_velocity_rad_per_s[0] = noise;
            enc.sample = EncoderSample::still(now);
            clock.now_us = now;
        }
        let outer = self.robot.outer_task(&OperatorInput {
            command,
            command_timestamp_us: Some(now),
            request,
        });
        let inner = core::array::from_fn(|i| {
            let stamp = now + 125 * i as u64;
            let (_, enc, _, clock) = self.robot.devices_mut();
            enc.sample = EncoderSample::still(stamp);
            clock.now_us = if self.clock_runs { stamp } else { now };
            self.robot.inner_task()
        });
        Period { outer, inner }
    }

    fn stop(&mut self) -> Period {
        self.period(Command::Stop, ModeRequest::None)
    }

    /// Runs stop periods until the loop balances (at most 2 s).
    fn arm(&mut self) -> u32 {
        for k in 1..=800 {
            if self.stop().outer.output.safety.mode == Mode::Balancing {
                return k;
            }
        }
        panic!(
            "did not arm in 2 s: {:?}",
            self.robot.controller().supervisor()
        );
    }

    fn motors(&mut self) -> &mut TestMotors {
        self.robot.devices_mut().2
    }

    fn latched(&self, fault: Fault) -> bool {
        self.robot
            .controller()
            .supervisor()
            .latched_faults()
            .contains(fault)
    }
}

struct Period {
    outer: OuterReport<f64>,
    inner: [InnerReport<f64>; 20],
}

#[test]
fn it_arms_only_after_the_body_has_been_upright_and_still_for_the_settle_time() {
    let mut bench = Bench::new();
    let periods = bench.arm();
    // 250 ms of upright and still samples: 100 periods, then the arm request's own.
    assert_eq!(periods, 101, "armed after {periods} periods");
    assert_eq!(bench.robot.phase(), Phase::Running);
    // Before, the drivers were only told to stay off.
    let motors = &bench.robot.devices().2;
    assert!(motors.disables >= 100 * 20, "{motors:?}");
    assert!(motors.applies <= 20, "{motors:?}");
}

#[test]
fn a_tilted_body_is_never_armed() {
    let mut bench = Bench::new();
    bench.tilt_rad = 0.2; // 11.5 deg: beyond the arming limit
    for _ in 0..800 {
        let p = bench.stop();
        assert_eq!(p.outer.output.safety.mode, Mode::Idle);
        assert!(p.inner.iter().all(|r| !r.applied));
    }
    assert_eq!(bench.robot.phase(), Phase::StartingUp);
    assert_eq!(bench.robot.devices().2.applies, 0);
}

#[test]
fn shutdown_stops_then_disarms_at_rest_and_turns_the_motors_off() {
    let mut bench = Bench::new();
    bench.arm();
    bench.robot.shutdown();
    assert_eq!(bench.robot.phase(), Phase::ShuttingDown);
    let mut periods = 0;
    while bench.robot.phase() != Phase::Off {
        bench.stop();
        periods += 1;
        assert!(periods < 4_000, "no rest in 10 s");
    }
    assert_eq!(bench.robot.mode(), Mode::Idle);
    assert_eq!(
        bench.robot.devices().2.last,
        None,
        "the drivers were left on"
    );
    // Off stays off, whatever the operator asks.
    for _ in 0..200 {
        assert_eq!(
            bench
                .period(Command::Stop, ModeRequest::Arm)
                .outer
                .output
                .safety
                .mode,
            Mode::Idle
        );
    }
}

#[test]
fn imu_read_errors_keep_the_last_sample_then_turn_the_motors_off_at_the_timeout() {
    let mut bench = Bench::new();
    bench.arm();
    let timeout_us = bench.robot.controller().config().safety.imu_timeout_us;
    bench.robot.devices_mut().0.fail = true;
    let mut off_after = None;
    for k in 1..=400u64 {
        let p = bench.stop();
        if !p.outer.output.motors.enabled {
            off_after = Some(k);
            break;
        }
    }
    let periods = off_after.expect("the motors stayed on with the IMU silent for 1 s");
    // Off within the timeout plus one period, not before it.
    let bound = timeout_us.div_ceil(PERIOD_US) + 1;
    assert!(
        periods <= bound,
        "off after {periods} periods, bound {bound}"
    );
    assert!(
        periods * PERIOD_US >= timeout_us,
        "off after {periods} periods"
    );
    assert!(bench.latched(Fault::ImuStale));
    assert!(bench.robot.device_errors().imu >= periods as u32);
}

#[test]
fn motor_writes_failing_for_5_ms_are_a_fault_and_a_single_failure_is_not() {
    let mut bench = Bench::new();
    bench.arm();
    // One failed write in every 20: counted, no fault.
    for _ in 0..400 {
        bench.motors().fail = true;
        bench.robot.inner_task();
        bench.motors().fail = false;
        bench.stop();
    }
    assert_eq!(bench.robot.mode(), Mode::Balancing);
    assert!(bench.robot.device_errors().motors >= 400);
    // Every write fails: MotorUnanswered at the health monitor's persistence (40 inner
    // steps), the motors off at the next step.
    bench.motors().fail = true;
    let mut steps = 0;
    while bench.robot.mode() == Mode::Balancing {
        bench.robot.inner_task();
        steps += 1;
        assert!(
            steps <= 40,
            "still balancing after {steps} unanswered steps"
        );
    }
    assert_eq!(steps, 40);
    assert!(bench.latched(Fault::MotorUnanswered));
    let next = bench.robot.inner_task();
    assert!(!next.applied);
    assert_eq!(bench.robot.devices().2.last, None, "no disable was sent");
}

#[test]
fn a_dead_driver_is_found_from_its_feedback_and_the_motors_go_off() {
    // The robot does not move here, so a velocity command winds the wheel speed PIs up
    // against the still encoders: a torque well above the health monitor's tolerance on the
    // wheels that drive towards 0 deg, OW2 and OW3.
    let mut bench = Bench::new();
    bench.arm();
    let go = Command::Velocity(VelocityCommand {
        vx_m_per_s: 1.0,
        ..VelocityCommand::zero()
    });
    let tolerance = LoopConfig::<f64>::miapure()
        .motor_health
        .torque_tolerance_nm;
    let mut commanded = false;
    for _ in 0..400 {
        let p = bench.period(go, ModeRequest::None);
        if p.inner
            .iter()
            .all(|r| r.output.torque_nm[1].abs() > 3.0 * tolerance)
        {
            commanded = true;
            break;
        }
    }
    assert!(
        commanded,
        "OW2 was never commanded beyond {} N m",
        3.0 * tolerance
    );
    bench.motors().dead = Some(1);
    let mut steps = 0;
    let verdict = loop {
        let p = bench.period(go, ModeRequest::None);
        if let Some((i, v)) = p
            .inner
            .iter()
            .enumerate()
            .find_map(|(i, r)| r.motor_verdict.map(|v| (i, v)))
        {
            steps += i + 1;
            break v;
        }
        steps += 20;
        assert!(steps < 400, "a dead OW2 went unnoticed for 50 ms");
    };
    assert_eq!((verdict.fault, verdict.wheel), (Fault::MotorDead, 1));
    // 5 ms plus the feedback's one-step delay (docs: 5.1 ms), plus the current loop's rise.
    assert!(
        (40..=45).contains(&steps),
        "found after {steps} inner steps"
    );
    assert_eq!(bench.robot.mode(), Mode::Fault);
    assert!(!bench.stop().inner.iter().any(|r| r.applied));
}

#[test]
fn a_stalled_clock_starts_a_controlled_stop_and_its_samples_go_stale_by_ticks() {
    let mut bench = Bench::new();
    bench.arm();
    bench.clock_runs = false;
    let p = bench.stop();
    assert_eq!(p.outer.output.safety.mode, Mode::ControlledStop);
    assert!(bench.latched(Fault::ClockStalled));
    // The samples carry the stalled clock's stamp: stale after the IMU timeout in ticks.
    let ticks = bench
        .robot
        .controller()
        .config()
        .safety
        .timeout_ticks(bench.robot.controller().config().safety.imu_timeout_us);
    let mut off_after = None;
    for k in 1..=u64::from(ticks) + 2 {
        if !bench.stop().outer.output.motors.enabled {
            off_after = Some(k);
            break;
        }
    }
    assert!(
        off_after.is_some(),
        "motors on {ticks} ticks into a stalled clock"
    );
}

#[test]
fn an_outer_task_longer_than_its_period_is_an_overrun() {
    let mut bench = Bench::new();
    bench.arm();
    // Each clock read takes 2 ms: the task's end is read 2 ms after its start, within the
    // period; at 3 ms it is not.
    bench.robot.devices_mut().3.per_read_us = 2_000;
    bench.stop();
    assert!(!bench.latched(Fault::LoopOverrun));
    bench.robot.devices_mut().3.per_read_us = 3_000;
    let p = bench.stop();
    assert!(bench.latched(Fault::LoopOverrun));
    // A controlled stop, the motors still on.
    assert_eq!(bench.robot.mode(), Mode::ControlledStop);
    assert!(p.outer.output.motors.enabled);
}
