//! Simulated seconds per wall second of the rapier3d world with the core's controller in the
//! loop (no logging), for the side-by-side benchmark against a MuJoCo roller-omniwheel ballbot
//! (`benches/mujoco/run.sh`), which calls this twice:
//!
//! * `world_speed params`: the robot's masses, geometry, friction and the core's LQR gains as
//!   JSON, from which `benches/mujoco/roller_ballbot.py` writes the MuJoCo model and its
//!   controller;
//! * `world_speed run SECONDS RATIO`: drives the world through the `world_step` bench's cycle
//!   (`benches/common/world_drive.rs`) for SECONDS of simulated time with
//!   `rigid_step_ratio = RATIO` (`default` for the default world's) and prints one JSON line with
//!   the wall time on this thread; `world_speed run SECONDS RATIO rigid` runs the default world
//!   with a rigid drivetrain (`TransmissionParams::rigid`), the baseline of the drivetrain's
//!   cost in the same session.

#[path = "../benches/common/world_drive.rs"]
#[allow(dead_code)]
mod world_drive;
use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
use ballbot_core::{OmniKinematics, Wip};
use ballbot_sim::world::{TransmissionParams, WorldParams};
use std::process::ExitCode;
use std::time::Instant;
use world_drive::WorldDrive;

fn params_json() -> Result<String, String> {
    let p = WorldParams::miapure_60kg();
    let r = &p.robot;
    let gains = |plane| -> Result<[f64; 3], String> {
        let wip = Wip::new(plane).map_err(|e| e.to_string())?;
        let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).map_err(|e| e.to_string())?;
        Ok(lqr.reduced_gains())
    };
    let kin = OmniKinematics::from_ballbot(r).map_err(|e| e.to_string())?;
    let m = kin.wheel_torque_matrix();
    let rows: Vec<[f64; 3]> = (0..3).map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]).collect();
    let d = &r.drivetrain;
    let json = serde_json::json!({
        "ball_radius_m": r.ball_radius_m(),
        "ball_mass_kg": r.sagittal.ball_mass_kg,
        "ball_inertia_kg_m2": r.sagittal.ball_inertia_kg_m2,
        "body_mass_kg": r.sagittal.body_mass_kg,
        "com_height_m": r.sagittal.com_height_m,
        "body_inertia_kg_m2": [
            r.frontal.body_inertia_kg_m2,
            r.sagittal.body_inertia_kg_m2,
            r.spin.inertia_kg_m2
        ],
        "wheel_radius_m": d.wheel_radius_m,
        "contact_angle_rad": d.contact_angle_rad,
        "wheel_azimuths_rad": d.wheel_azimuths_rad,
        "wheel_ball_friction": d.wheel_ball_friction,
        "ball_floor_friction": d.ball_floor_friction,
        "wheel_inertia_kg_m2": p.wheel_inertia_kg_m2,
        "rotor_inertia_kg_m2": p.rotor_inertia_kg_m2,
        "gear_ratio": d.actuator.gear_ratio,
        "peak_wheel_torque_nm": d.actuator.peak_torque_nm,
        "wheel_damping_nm_s_per_rad": p.wheel_damping_nm_s_per_rad,
        "gains_sagittal": gains(r.sagittal)?,
        "gains_frontal": gains(r.frontal)?,
        "wheel_torque_matrix": rows,
        "rigid_step_ratio_default": p.rigid_step_ratio,
    });
    serde_json::to_string_pretty(&json).map_err(|e| e.to_string())
}

fn run(seconds: f64, ratio: &str, rigid: bool) -> Result<String, String> {
    let mut params = WorldParams::miapure_60kg();
    if rigid {
        params.transmission = TransmissionParams::rigid();
    }
    if ratio != "default" {
        params.rigid_step_ratio = ratio
            .parse()
            .map_err(|_| format!("RATIO must be a whole number or `default`, got `{ratio}`"))?;
    }
    let steps = (seconds / params.dt_secs).round() as u64;
    // Built and warmed up (1 s) before the clock starts.
    let mut drive = WorldDrive::with_params(params).map_err(|e| e.to_string())?;
    let start = Instant::now();
    for _ in 0..steps {
        std::hint::black_box(drive.step().map_err(|e| e.to_string())?);
    }
    let wall = start.elapsed().as_secs_f64();
    let simulated = steps as f64 * params.dt_secs;
    Ok(serde_json::json!({
        "rigid_step_ratio": params.rigid_step_ratio,
        "drivetrain": if rigid { "rigid" } else { "default" },
        "simulated_secs": simulated,
        "wall_secs": wall,
        "sim_secs_per_wall_sec": simulated / wall,
        "restarts": drive.restarts,
    })
    .to_string())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let result = match args.as_slice() {
        [_, cmd] if cmd == "params" => params_json(),
        [_, cmd, secs, ratio, rest @ ..] if cmd == "run" && rest.len() <= 1 => {
            let rigid = match rest.first().map(String::as_str) {
                None => Ok(false),
                Some("rigid") => Ok(true),
                Some(other) => Err(format!(
                    "the drivetrain must be `rigid` or absent, got `{other}`"
                )),
            };
            match (secs.parse::<f64>(), rigid) {
                (_, Err(e)) => Err(e),
                (Ok(s), Ok(rigid)) if s.is_finite() && s > 0.0 => run(s, ratio, rigid),
                _ => Err(format!("SECONDS must be a positive number, got `{secs}`")),
            }
        }
        _ => {
            Err("usage: world_speed params | world_speed run SECONDS RATIO|default [rigid]".into())
        }
    };
    match result {
        Ok(out) => {
            println!("{out}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("world_speed: {e}");
            ExitCode::FAILURE
        }
    }
}
