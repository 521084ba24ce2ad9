//! The Monte Carlo's falls isolated on one factor: the push recovery limit (counted by falls:
//! the world's slip and lift-off stop rules relaxed) of the shipped controller, designed for
//! the nominal 60 kg, on robots whose payload alone is off, pushed towards a wheel (0 deg,
//! OW1) and between two (60 deg). Tests the hypothesis behind the Monte Carlo's 19 falls
//! (light robots pushed towards a wheel) with nothing else mismatched.
//!
//! ```text
//! cargo run --release -p ballbot-sim --example mc_payload
//! ```

use ballbot_sim::rig::{NoFaults, WorldRobot};
use ballbot_sim::studies::push::{PushTrial, push_recovery_limit_by, push_trial_with};
use ballbot_sim::studies::robustness::Mismatch;
use ballbot_sim::studies::robustness::monte_carlo::{MonteCarloCount, MonteCarloSettings};
use ballbot_sim::studies::runner::run_jobs;
use ballbot_sim::world::{WorldError, WorldParams};
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let nominal = WorldParams::miapure_60kg();
    let settings = MonteCarloSettings::full();
    let config = settings.controller.config(&nominal)?;
    let count = MonteCarloCount::Falls;
    let payloads = [0.8, 0.85, 0.9, 1.0, 1.2];
    let headings = [0.0, 60.0];
    let jobs: Vec<(f64, f64)> = payloads
        .iter()
        .flat_map(|&p| headings.iter().map(move |&h| (p, h)))
        .collect();
    println!(
        "push recovery limit by falls, {} controller designed for 60 kg, sensors nominal (seed {})",
        settings.controller.as_str(),
        settings.seed
    );
    let limits = run_jobs(
        &jobs,
        0,
        |&(payload, heading_deg)| -> Result<f64, WorldError> {
            let mismatch = Mismatch {
                payload_mass: payload,
                ..Mismatch::none(heading_deg)
            };
            let mut world = mismatch.apply(&nominal);
            world.sensors.seed = settings.seed;
            let params = ballbot_sim::studies::push::PushParams {
                settle_secs: settings.settle_secs,
                stop_rules: count.stop_rules(),
                ..Default::default()
            };
            let mut trial_at = |impulse_ns: f64| -> Result<PushTrial, WorldError> {
                let sim = WorldRobot::with_config(world, config)?;
                push_trial_with(
                    sim,
                    &mut NoFaults,
                    &params,
                    heading_deg,
                    impulse_ns,
                    &mut |_| {},
                )
            };
            let search = push_recovery_limit_by(
                &settings.search,
                heading_deg,
                &mut trial_at,
                &|t: &PushTrial| count.stayed_up(t),
                &mut |_| {},
            )?;
            Ok(search.largest_recovered_ns)
        },
        &|done| eprint!("\r{done}/{} searches", jobs.len()),
    )?;
    eprintln!();
    println!("payload factor | towards OW1 (0 deg) | between OW1 and OW2 (60 deg)");
    for (i, payload) in payloads.iter().enumerate() {
        println!(
            "{payload:>14.2} | {:>16.1} N s | {:>21.1} N s",
            limits[2 * i],
            limits[2 * i + 1]
        );
    }
    Ok(())
}
