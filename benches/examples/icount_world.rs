//! Instruction-count harness of the rapier3d world (see `scripts/icount.sh`), like
//! `src/bin/icount.rs` for the core; the simulator is only a dev-dependency of this package
//! (so the core's harness stays a small build), hence an example.
//!
//! Usage: `icount_world <operation> <iterations>`; `icount_world list` prints the operations.

#[path = "../benches/common/world_drive.rs"]
mod world_drive;
use ballbot_core::BallbotParams;
use ballbot_sim::world::{WorldError, WorldParams};
use std::hint::black_box;
use std::process::ExitCode;
use world_drive::WorldDrive;

/// One world step at 8 kHz in the default world (the realistic contact: rubber coating, roller
/// gaps, axle losses; the ODrive driver; rapier at every 10th step, `rigid_step_ratio` 10) with
/// the core's controller in the loop (outer loop every 20th step), the robot balancing while
/// driving (the criterion bench `world_step`'s scenario), after a warm-up of 1 s. The counted steps (up to 4000 after the warm-up) end
/// before the drive cycle's reversal at 2 s, where OW1 slips for longer than 0.1 s in this
/// world (a failure this harness would report).
fn world_step_with_controller(n: u64) -> Result<(), String> {
    run_drive(WorldDrive::new(), n)
}

/// [`world_step_with_controller`] in the single-rate default world (`rigid_step_ratio` 1: rapier
/// at every step), the default before the multi-rate world.
fn world_step_single_rate(n: u64) -> Result<(), String> {
    let mut params = WorldParams::miapure_60kg();
    params.rigid_step_ratio = 1;
    run_drive(WorldDrive::with_params(params), n)
}

/// [`world_step_with_controller`] in the ideal world (stiff continuous-rim contacts, no axle
/// forces, the straight torque-speed line): the default world before the realistic one.
fn world_step_ideal(n: u64) -> Result<(), String> {
    run_drive(
        WorldDrive::with_params(WorldParams::ideal(BallbotParams::miapure_60kg())),
        n,
    )
}

fn run_drive(drive: Result<WorldDrive, WorldError>, n: u64) -> Result<(), String> {
    let mut drive = drive.map_err(|e| e.to_string())?;
    for _ in 0..n {
        black_box(drive.step().map_err(|e| e.to_string())?);
    }
    if drive.restarts > 0 || drive.sim().world().failure().is_some() {
        return Err(format!("the robot failed ({} restarts)", drive.restarts));
    }
    Ok(())
}

type Run = fn(u64) -> Result<(), String>;

const OPERATIONS: &[(&str, Run)] = &[
    ("world_step_with_controller", world_step_with_controller),
    ("world_step_single_rate", world_step_single_rate),
    ("world_step_ideal", world_step_ideal),
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    match args.as_slice() {
        [_, cmd] if cmd == "list" => {
            for (name, _) in OPERATIONS {
                println!("{name}");
            }
            ExitCode::SUCCESS
        }
        [_, name, iterations] => {
            let Ok(n) = iterations.parse::<u64>() else {
                eprintln!("iterations must be a whole number, got `{iterations}`");
                return ExitCode::from(2);
            };
            let Some((_, run)) = OPERATIONS.iter().find(|(op, _)| op == name) else {
                eprintln!("unknown operation `{name}`; `icount_world list` prints them");
                return ExitCode::from(2);
            };
            match run(n) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("{name}: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        _ => {
            eprintln!("usage: icount_world <operation> <iterations> | icount_world list");
            ExitCode::from(2)
        }
    }
}
