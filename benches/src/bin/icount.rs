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
