//! The world suite's braking studies alone, with and without the planner's normal-force
//! margin (`WorldSuiteSettings::paper`'s braking jobs with the full feedforward: margins 0,
//! 100, 200, 250 N at 180, 0 and 90 deg, descent and bisection, and the planar minimum
//! braking time per margin). Prints the suite's braking tables and writes the summary's
//! `world_braking` record to `OUT` (default `world_braking_margin.json`). `MARGINS` (N,
//! comma-separated, each > 0) replaces the suite's margins.
//!
//! ```text
//! MARGINS=200,250 cargo run --release -p ballbot-sim --example world_braking_margin
//! ```

use ballbot_sim::studies::world_braking::{BrakingStudyParams, TrajectoryFeedforward};
use ballbot_sim::studies::world_suite::{SuiteJob, WorldSuiteSettings, run_world_suite};
use ballbot_sim::world::StopRules;
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let mut settings = WorldSuiteSettings::paper();
    if let Ok(text) = std::env::var("MARGINS") {
        let margins = text
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<Vec<_>, _>>()?;
        settings.jobs.retain(|j| {
            matches!(
                j,
                SuiteJob::Braking {
                    normal_force_margin_n: 0.0,
                    ..
                }
            )
        });
        for &m in &margins {
            for heading_deg in [180.0, 0.0, 90.0] {
                settings.jobs.push(SuiteJob::Braking {
                    heading_deg,
                    feedforward: TrajectoryFeedforward::Full,
                    study: BrakingStudyParams {
                        bisection_resolution_secs: Some(0.05),
                        ..BrakingStudyParams::paper()
                    },
                    normal_force_margin_n: m,
                    stop_rules: StopRules::all(),
                });
            }
        }
        settings.normal_force_margins_n = margins;
    }
    settings.jobs.retain(|j| {
        matches!(
            j,
            SuiteJob::Braking {
                feedforward: TrajectoryFeedforward::Full,
                ..
            }
        )
    });
    let suite = run_world_suite(&settings, &|what| eprintln!("{what}"))?;
    println!("{}", suite.table());
    let mut summary = serde_json::Map::new();
    suite.add_to_summary(&mut summary);
    let out = std::env::var("OUT").unwrap_or_else(|_| "world_braking_margin.json".to_owned());
    let text = serde_json::to_string_pretty(&summary.get("world_braking"))?;
    std::fs::write(&out, format!("{text}\n"))?;
    eprintln!("wrote {out}");
    Ok(())
}
