//! Velocity ramps per heading in the 3D world with the core's controller in the loop, with the
//! command shaper's speed and acceleration caps lifted (its jerk limit is kept unless `JERK` is
//! set). Prints, per ramp acceleration and heading: the highest speed, the smallest wheel normal
//! force, the largest friction-cone utilisation, the largest tilt and the failure.
//!
//! ```text
//! ACCELS=1.6,1.7,1.8,1.9,2 HEADS=0,90,180 TOP=3 \
//!   cargo run --release -p ballbot-sim --example world_ramp_sweep
//! ```
//! Environment: `ACCELS` (m/s^2, comma-separated), `HEADS` (deg), `TOP` (m/s, ramp end),
//! `JERK` (m/s^3, shaper jerk limit; default: the core's).

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_sim::studies::ramp::{RampParams, max_speed_ramp_with_config};
use ballbot_sim::world::WorldParams;
use std::error::Error;

fn list(name: &str, default: &str) -> Result<Vec<f64>, Box<dyn Error>> {
    let text = std::env::var(name).unwrap_or_else(|_| default.to_owned());
    Ok(text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()?)
}

fn main() -> Result<(), Box<dyn Error>> {
    let accels = list("ACCELS", "0.25,1,1.6,1.7,1.8,1.9,2")?;
    let heads = list("HEADS", "0,90,180")?;
    let top = list("TOP", "3")?.first().copied().unwrap_or(3.0);
    let jerk = list("JERK", "0")?.first().copied().unwrap_or(0.0);
    println!(
        "accel_m_per_s2 heading_deg max_speed_m_per_s min_normal_n max_cone_util max_tilt_deg failure"
    );
    for &accel_m_per_s2 in &accels {
        for &heading_deg in &heads {
            let params = WorldParams::miapure_60kg();
            let mut config = BallbotControllerConfig::paper(&params.robot)?;
            config.shaping.translation.max_value = 5.0;
            config.shaping.translation.max_rate_per_s = 20.0;
            if jerk > 0.0 {
                config.shaping.translation.max_jerk_per_s2 = jerk;
            }
            config.shaping.max_tilt_command_rad = 0.5;
            config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
            let ramp = RampParams {
                accel_m_per_s2,
                max_command_m_per_s: top,
                settle_secs: 0.5,
                sample_every_secs: 0.0025,
            };
            let r = max_speed_ramp_with_config(params, config, heading_deg, &ramp)?;
            let min_n = r
                .samples
                .iter()
                .flat_map(|s| s.normal_force_n)
                .fold(f64::INFINITY, f64::min);
            let max_u = r
                .samples
                .iter()
                .map(|s| s.max_cone_utilisation)
                .fold(0.0, f64::max);
            let max_tilt = r.samples.iter().map(|s| s.tilt_rad).fold(0.0, f64::max);
            println!(
                "{accel_m_per_s2} {heading_deg} {:.3} {min_n:.1} {max_u:.3} {:.2} {:?}",
                r.max_speed_m_per_s,
                max_tilt.to_degrees(),
                r.failure
            );
        }
    }
    Ok(())
}
