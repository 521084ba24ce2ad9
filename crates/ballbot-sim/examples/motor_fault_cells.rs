//! The fault matrix's cells for a chosen set of classes (default: the dead and the stuck
//! motor), full protocol, headings 0, 90 and 180 deg, both controllers: the numbers of
//! docs/robustness.md's motor-health section (outcome, detection latency, peak tilt, path).
//!
//! ```text
//! cargo run --release -p ballbot-sim --example motor_fault_cells
//! CLASSES=all QUICK=1 cargo run --release -p ballbot-sim --example motor_fault_cells
//! ```
//! `CLASSES`: comma-separated class names or `all`; `QUICK=1`: the quick matrix's protocol and
//! heading 0 only. One line per cell: controller, class, condition, heading, observed state
//! (`ok` when expected), whether it fell, the faults raised in order, the time from the
//! injection to the first (ms), the peak tilt from the vertical (deg), the ball's path (m)
//! and its speed at the injection (m/s); then the counts.

use ballbot_sim::studies::robustness::{FaultClass, FaultMatrixSettings, run_fault_matrix};
use ballbot_sim::world::WorldParams;
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let quick = std::env::var("QUICK").is_ok_and(|v| v == "1");
    let mut settings = if quick {
        FaultMatrixSettings::quick()
    } else {
        FaultMatrixSettings::full()
    };
    let classes = std::env::var("CLASSES").unwrap_or_else(|_| "motor_dead,motor_stuck".into());
    if classes != "all" {
        settings.classes = classes
            .split(',')
            .map(|name| {
                FaultClass::ALL
                    .into_iter()
                    .find(|c| c.as_str() == name)
                    .ok_or_else(|| format!("unknown fault class {name}"))
            })
            .collect::<Result<_, _>>()?;
    }
    let matrix = run_fault_matrix(&WorldParams::miapure_60kg(), &settings, 0, &|_, _| {})?;
    for c in &matrix.cells {
        println!(
            "{:13} {:18} {:8} {:5.0} {:4} {:16} fell={:5} detect_ms={:>8} [{}] tilt={:5.1} path={:5.2} v0={:4.2} before=[{}]",
            c.cell.controller.as_str(),
            c.cell.class.as_str(),
            c.cell.condition.as_str(),
            c.cell.heading_deg,
            c.mark(),
            c.observed.as_str(),
            c.fell,
            c.time_to_detect_ms
                .map_or("-".to_owned(), |t| format!("{t:.2}")),
            c.detected.join(","),
            c.peak_tilt_deg,
            c.distance_m,
            c.speed_at_injection_m_per_s,
            c.faults_before_injection.join(","),
        );
    }
    println!("{:?}", matrix.summary);
    Ok(())
}
