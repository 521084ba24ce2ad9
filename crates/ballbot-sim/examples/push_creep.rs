//! Push recovery of the shipped controller with and without balance-point estimation: the
//! ball's speed after the push and the learnt offset.
//!
//! ```text
//! cargo run --release -p ballbot-sim --example push_creep
//! ```

use ballbot_core::ballbot::{BalancePointParams, BallbotControllerConfig};
use ballbot_sim::rig::{NoFaults, WorldRobot};
use ballbot_sim::studies::push::{PushParams, push_trial_with};
use ballbot_sim::world::WorldParams;
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let world = WorldParams::miapure_60kg();
    let design = BallbotControllerConfig::design(&world.robot)?;
    let no_bp = BallbotControllerConfig {
        balance_point: BalancePointParams::off(),
        ..design
    };
    let params = PushParams {
        observe_secs: 6.0,
        ..PushParams::default()
    };
    for (name, config) in [("design", design), ("design, no balance point", no_bp)] {
        for heading_deg in [0.0, 90.0, 180.0] {
            for impulse_ns in [25.0, 40.0, 50.0] {
                let sim = WorldRobot::with_config(world, config)?;
                let t = push_trial_with(
                    sim,
                    &mut NoFaults,
                    &params,
                    heading_deg,
                    impulse_ns,
                    &mut |_| {},
                )?;
                let at = |s: f64| {
                    t.samples
                        .iter()
                        .find(|p| p.time_secs >= s)
                        .map_or(f64::NAN, |p| p.speed_m_per_s)
                };
                println!(
                    "{name:<26} {heading_deg:>5} deg {impulse_ns:>4} N s: {:<12} peak {:.2} m/s, speed at 1/2/3/4/6 s {:.3} {:.3} {:.3} {:.3} {:.3}",
                    t.outcome.label(),
                    t.peak_speed_m_per_s,
                    at(1.0),
                    at(2.0),
                    at(3.0),
                    at(4.0),
                    at(5.95)
                );
            }
        }
    }
    Ok(())
}
