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
