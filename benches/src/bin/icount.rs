//! Instruction-count harness: runs one core operation a given number of times, for
//! `valgrind --tool=callgrind` to count (see `scripts/icount.sh`). Two runs with different
//! iteration counts give the per-call instruction count with start-up cost cancelled:
//! `(I(2n) - I(n)) / n`. Instruction counts are repeatable on a shared, noisy machine where
//! wall time is not.
//!
//! Usage: `icount <operation> <iterations>`; `icount list` prints the operations.

use ballbot_core::kinematics::OmniKinematics;
use ballbot_core::{BallbotParams, Wip, WipParams, rk4_step};
use nalgebra::{Vector3, Vector4};
use std::hint::black_box;
use std::process::ExitCode;

/// One benchmarked operation: its name and a closure running it `n` times.
struct Operation {
    name: &'static str,
    run: fn(u64) -> Result<(), String>,
}

fn wip_rk4_step_f64(n: u64) -> Result<(), String> {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).map_err(|e| e.to_string())?;
    let mut s = Vector4::new(0.05, 0.0, 0.0, 1.0);
    for _ in 0..n {
        s = rk4_step(
            |x| wip.derivative(x, black_box(3.0)),
            black_box(&s),
            1.25e-4,
        );
    }
    black_box(s);
    Ok(())
}

fn wip_rk4_step_f32(n: u64) -> Result<(), String> {
    let wip = Wip::new(WipParams::<f32>::miapure_60kg()).map_err(|e| e.to_string())?;
    let mut s = Vector4::new(0.05f32, 0.0, 0.0, 1.0);
    for _ in 0..n {
        s = rk4_step(
            |x| wip.derivative(x, black_box(3.0)),
            black_box(&s),
            1.25e-4,
        );
    }
    black_box(s);
    Ok(())
}

fn kinematics_speeds_and_torques(n: u64) -> Result<(), String> {
    let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())
        .map_err(|e| e.to_string())?;
    let mut acc = Vector3::zeros();
    for i in 0..n {
        let rel = black_box(Vector3::new(1.0, -2.0, 0.5 + i as f64 * 1e-9));
        let psi = kin.wheel_speeds_rad_per_s(&rel);
        let back = kin.relative_rate_rad_per_s(&psi);
        let tau = kin.wheel_torques_nm(&black_box(Vector3::new(10.0, -5.0, 2.0)));
        acc += back + tau;
    }
    black_box(acc);
    Ok(())
}

/// MiaPURE's inner speed PI (8 kHz, on the motor driver), fed a varying speed.
fn speed_pi_step<T: nalgebra::RealField + Copy>(n: u64) -> Result<(), String> {
    use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).map_err(|e| e.to_string())?;
    let gains =
        SpeedPiGains::for_wip_ball_rate(&wip, nalgebra::convert(30.0), nalgebra::convert(43.2))
            .map_err(|e| e.to_string())?;
    let mut pi = SpeedPi::new(gains).map_err(|e| e.to_string())?;
    let cmd = SpeedCommand {
        speed_rad_per_s: nalgebra::convert(2.0),
        feedforward_torque_nm: nalgebra::convert(5.0),
    };
    let dt: T = nalgebra::convert(1.0 / 8000.0);
    let speeds: [T; 8] = core::array::from_fn(|i| nalgebra::convert(1.9 + i as f64 * 0.01));
    let mut acc = T::zero();
    for i in 0..n {
        let speed = speeds[(i & 7) as usize];
        acc += pi.step(black_box(speed), black_box(&cmd), dt).torque_nm;
    }
    black_box(acc);
    Ok(())
}

fn speed_pi_step_f32(n: u64) -> Result<(), String> {
    speed_pi_step::<f32>(n)
}

fn speed_pi_step_f64(n: u64) -> Result<(), String> {
    speed_pi_step::<f64>(n)
}

/// MiaPURE's LQR-PI outer step (400 Hz): LQR, the reference model, the anchored integral.
fn lqr_pi_outer_step_f64(n: u64) -> Result<(), String> {
    use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedPiGains};
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).map_err(|e| e.to_string())?;
    let inner = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9).map_err(|e| e.to_string())?;
    let lqr = LqrGains::for_wip(&wip, 83.9).map_err(|e| e.to_string())?;
    let config = LqrPiOuterConfig::new(lqr, &inner).map_err(|e| e.to_string())?;
    let mut outer = LqrPiOuter::new(wip, config).map_err(|e| e.to_string())?;
    let command = Vector4::new(0.0, 0.0, 0.0, 5.0);
    let mut acc = 0.0;
    for i in 0..n {
        let s = Vector4::new(0.02 + (i % 5) as f64 * 1e-3, 0.0, 0.1, 4.0);
        acc += outer
            .step(black_box(&s), black_box(&command), 0.0025)
            .reference_torque_nm;
    }
    black_box(acc);
    Ok(())
}

/// The 3D controller's operations, in their own module: rustc partitions code into codegen
/// units by module, and these large steps in the same unit as the small ones above changed how
/// the speed PI's step was inlined there (50 -> 62 instructions) without any change to it.
mod three_d {
    use super::*;

    /// The 3D controller's outer step (400 Hz) in the paper's configuration
    /// (`BallbotControllerConfig::paper`: traction-aware control and the balance point off):
    /// safety, estimation, shaping, two LQR-PI planes and the spin plane, the kinematic mapping. Armed and balancing, following a velocity command,
    /// with IMU readings that change every step (as real ones do).
    fn ballbot_outer_step<T: nalgebra::RealField + Copy>(n: u64) -> Result<(), String> {
        use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
        use ballbot_core::command::{Command, VelocityCommand};
        use ballbot_core::estimation::{EncoderSample, ImuSample};
        use ballbot_core::safety::ModeRequest;
        let c = |x: f64| -> T { nalgebra::convert(x) };
        let config = BallbotControllerConfig::paper(&BallbotParams::<T>::miapure_60kg())
            .map_err(|e| e.to_string())?;
        let mut outer = BallbotController::new(config).map_err(|e| e.to_string())?;
        let command = Command::Velocity(VelocityCommand {
            vx_m_per_s: c(0.8),
            vy_m_per_s: c(-0.3),
            yaw_rate_rad_per_s: c(0.2),
        });
        let mut input = OuterInput {
            now_us: 0,
            imu: ImuSample::upright(0),
            encoders: EncoderSample::still(0),
            command,
            command_timestamp_us: Some(0),
            request: ModeRequest::Arm,
        };
        outer.step(&input);
        input.request = ModeRequest::None;
        let mut acc = T::zero();
        for i in 0..n {
            let t = (i + 1) * 2500;
            let wobble = c((i % 7) as f64 * 1e-4);
            input.now_us = t;
            input.imu.timestamp_us = t;
            input.imu.roll_rad = wobble;
            input.imu.pitch_rad = c(0.01) - wobble;
            input.imu.angular_velocity_rad_per_s = Vector3::new(wobble, c(0.02), c(0.2));
            input.encoders.timestamp_us = t;
            input.encoders.wheel_speeds_rad_per_s = Vector3::new(c(1.0) + wobble, c(-3.0), c(2.5));
            input.command_timestamp_us = Some(t);
            let out = outer.step(black_box(&input));
            acc += out.motors.feedforward_torque_nm[0];
        }
        if outer.mode() != ballbot_core::safety::Mode::Balancing {
            return Err(format!(
                "left balancing: {:?}",
                outer.supervisor().latched_faults()
            ));
        }
        black_box(acc);
        Ok(())
    }

    pub(crate) fn ballbot_outer_step_f64(n: u64) -> Result<(), String> {
        ballbot_outer_step::<f64>(n)
    }

    /// [`ballbot_outer_step`] with traction-aware control on (the envelope in the command
    /// shaper, the slip monitor with its normal-force prediction): the same step, with sensor
    /// readings that agree with each other (a ball rolling at the encoders' rates below an
    /// upright body turning at the gyro's yaw rate), so the monitor finds no slip and the
    /// controller keeps balancing.
    pub(crate) fn ballbot_outer_step_traction_f64(n: u64) -> Result<(), String> {
        use ballbot_core::OmniKinematics;
        use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
        use ballbot_core::command::{Command, VelocityCommand};
        use ballbot_core::estimation::{EncoderSample, ImuSample};
        use ballbot_core::safety::ModeRequest;
        let robot = BallbotParams::<f64>::miapure_60kg();
        let config = BallbotControllerConfig::paper(&robot)
            .map_err(|e| e.to_string())?
            .with_traction_control();
        let kin = OmniKinematics::from_ballbot(&robot).map_err(|e| e.to_string())?;
        let mut outer = BallbotController::new(config).map_err(|e| e.to_string())?;
        let command = Command::Velocity(VelocityCommand {
            vx_m_per_s: 0.8,
            vy_m_per_s: -0.3,
            yaw_rate_rad_per_s: 0.2,
        });
        // Already rolling when armed: the monitor's observers start from these readings.
        let relative = |wobble: f64| Vector3::new(2.6 - wobble, 7.0, -0.2);
        let mut input = OuterInput {
            now_us: 0,
            imu: ImuSample::upright(0),
            encoders: EncoderSample::still(0),
            command,
            command_timestamp_us: Some(0),
            request: ModeRequest::Arm,
        };
        input.imu.angular_velocity_rad_per_s = Vector3::new(0.0, 0.0, 0.2);
        input.encoders.wheel_speeds_rad_per_s = kin.wheel_speeds_rad_per_s(&relative(0.0));
        outer.step(&input);
        input.request = ModeRequest::None;
        let mut acc = 0.0;
        for i in 0..n {
            let t = (i + 1) * 2500;
            let wobble = (i % 7) as f64 * 1e-4;
            input.now_us = t;
            input.imu.timestamp_us = t;
            input.imu.roll_rad = wobble;
            input.imu.pitch_rad = -wobble;
            input.imu.angular_velocity_rad_per_s = Vector3::new(wobble, 0.0, 0.2);
            input.encoders.timestamp_us = t;
            input.encoders.wheel_speeds_rad_per_s = kin.wheel_speeds_rad_per_s(&relative(wobble));
            input.command_timestamp_us = Some(t);
            let out = outer.step(black_box(&input));
            acc += out.motors.feedforward_torque_nm[0];
            if out.traction.is_none_or(|t| t.slip.any_slipping()) {
                return Err(format!("the slip monitor fired: {:?}", out.traction));
            }
        }
        if outer.mode() != ballbot_core::safety::Mode::Balancing {
            return Err(format!(
                "left balancing: {:?}",
                outer.supervisor().latched_faults()
            ));
        }
        black_box(acc);
        Ok(())
    }

    pub(crate) fn ballbot_outer_step_f32(n: u64) -> Result<(), String> {
        ballbot_outer_step::<f32>(n)
    }

    /// The command shaper's step alone (part of `ballbot_outer_step`): a velocity command held
    /// after its ramp, as in the outer-step benchmark.
    pub(crate) fn command_shaper_step_f64(n: u64) -> Result<(), String> {
        use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
        let robot = BallbotParams::<f64>::miapure_60kg();
        let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)
            .map_err(|e| e.to_string())?;
        let command = Command::Velocity(VelocityCommand {
            vx_m_per_s: 0.8,
            vy_m_per_s: -0.3,
            yaw_rate_rad_per_s: 0.2,
        });
        let mut acc = 0.0;
        for _ in 0..n {
            acc += shaper.step(black_box(&command), 0.0025).planar.sagittal[0];
        }
        black_box(acc);
        Ok(())
    }

    /// One motor driver's inner step (8 kHz) as the 3D controller runs it: the speed PI within the
    /// actuator's torque-speed limits at the measured speed.
    pub(crate) fn motor_pi_step_f64(n: u64) -> Result<(), String> {
        use ballbot_core::ballbot::{BallbotControllerConfig, MotorSpeedPi};
        let robot = BallbotParams::<f64>::miapure_60kg();
        let config = BallbotControllerConfig::paper(&robot).map_err(|e| e.to_string())?;
        let mut motor = MotorSpeedPi::new(config.motor, &robot.drivetrain.actuator)
            .map_err(|e| e.to_string())?;
        let speeds: [f64; 8] = core::array::from_fn(|i| 1.9 + i as f64 * 0.01);
        let mut acc = 0.0;
        for i in 0..n {
            let speed = speeds[(i & 7) as usize];
            let (torque, _) = motor.step(black_box(2.0), black_box(5.0), black_box(speed), 1.25e-4);
            acc += torque;
        }
        black_box(acc);
        Ok(())
    }

    /// The motor-health monitor's 8 kHz step over the three drivers' feedback (healthy drivers
    /// following a varying setpoint, so every check runs to the end).
    pub(crate) fn motor_health_step_f64(n: u64) -> Result<(), String> {
        use ballbot_core::hal::MotorFeedback;
        use ballbot_core::safety::{MotorHealthMonitor, MotorHealthParams};
        let mut monitor = MotorHealthMonitor::new(MotorHealthParams::<f64>::miapure(), 1.25e-4)
            .map_err(|e| e.to_string())?;
        let mut flagged = 0_u64;
        for i in 0..n {
            let c = 5.0 + (i & 7) as f64 * 0.01;
            let command = Vector3::new(c, -c, 0.5 * c);
            let fb = [0, 1, 2].map(|w| MotorFeedback::healthy(command[w], w as f64, 45.0));
            flagged += u64::from(monitor.step(black_box(&command), black_box(&fb)).is_some());
        }
        black_box(flagged);
        Ok(())
    }
}

use three_d::{
    ballbot_outer_step_f32, ballbot_outer_step_f64, ballbot_outer_step_traction_f64,
    command_shaper_step_f64, motor_health_step_f64, motor_pi_step_f64,
};

const OPERATIONS: &[Operation] = &[
    Operation {
        name: "wip_rk4_step_f64",
        run: wip_rk4_step_f64,
    },
    Operation {
        name: "wip_rk4_step_f32",
        run: wip_rk4_step_f32,
    },
    Operation {
        name: "kinematics_speeds_and_torques",
        run: kinematics_speeds_and_torques,
    },
    Operation {
        name: "speed_pi_step_f32",
        run: speed_pi_step_f32,
    },
    Operation {
        name: "speed_pi_step_f64",
        run: speed_pi_step_f64,
    },
    Operation {
        name: "lqr_pi_outer_step_f64",
        run: lqr_pi_outer_step_f64,
    },
    Operation {
        name: "ballbot_outer_step_f64",
        run: ballbot_outer_step_f64,
    },
    Operation {
        name: "ballbot_outer_step_traction_f64",
        run: ballbot_outer_step_traction_f64,
    },
    Operation {
        name: "ballbot_outer_step_f32",
        run: ballbot_outer_step_f32,
    },
    Operation {
        name: "command_shaper_step_f64",
        run: command_shaper_step_f64,
    },
    Operation {
        name: "motor_health_step_f64",
        run: motor_health_step_f64,
    },
    Operation {
        name: "motor_pi_step_f64",
        run: motor_pi_step_f64,
    },
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    match args.as_slice() {
        [_, cmd] if cmd == "list" => {
            for op in OPERATIONS {
                println!("{}", op.name);
            }
            ExitCode::SUCCESS
        }
        [_, name, iterations] => {
            let Ok(n) = iterations.parse::<u64>() else {
                eprintln!("iterations must be a whole number, got `{iterations}`");
                return ExitCode::from(2);
            };
            let Some(op) = OPERATIONS.iter().find(|op| op.name == name) else {
                eprintln!("unknown operation `{name}`; `icount list` prints them");
                return ExitCode::from(2);
            };
            match (op.run)(n) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("{name}: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        _ => {
            eprintln!("usage: icount <operation> <iterations> | icount list");
            ExitCode::from(2)
        }
    }
}
