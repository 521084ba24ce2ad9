//! The mechanism study of `ballbot reproduce` on its own: slow ramps per world
//! mechanism, controller and heading, the ramp-acceleration sweep and the contact-load ripple.
//! Prints the tables and writes the three summary records to `OUT` (default
//! `mechanisms.json`).
//!
//! ```text
//! QUICK=1 OUT=/tmp/mechanisms.json cargo run --release -p ballbot-sim --example mechanism_study
//! ```

use ballbot_core::BallbotParams;
use ballbot_sim::studies::mechanisms::{MechanismStudySettings, run_study};
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let settings = if std::env::var("QUICK").is_ok_and(|v| v == "1") {
        MechanismStudySettings::quick()
    } else {
        MechanismStudySettings::paper()
    };
    let out = std::env::var("OUT").unwrap_or_else(|_| "mechanisms.json".to_owned());
    let study = run_study(BallbotParams::miapure_60kg(), &settings, &|what| {
        eprintln!("done: {what}")
    })?;
    print!("{}", study.table());
    let json = serde_json::json!({
        "slow_ramp_mechanisms": study.slow_ramp_json(),
        "ramp_accel_sweep": study.sweep_json(),
        "contact_ripple": study.ripple_json(),
    });
    std::fs::write(&out, serde_json::to_string_pretty(&json)?)?;
    Ok(())
}
