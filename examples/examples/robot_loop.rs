//! The robot loop (`ballbot_examples::robot_loop`) on a simulated MiaPURE with 60 kg: start-up,
//! driving, a lost command link (controlled stop), resume, shutdown. Prints every mode change
//! and a status line every half second.
//!
//! `cargo run -p ballbot-examples --example robot_loop [--release]`

use ballbot_core::BallbotParams;
use ballbot_core::safety::Mode;
use ballbot_examples::demo::{self, Timeline};
use ballbot_runtime::Phase;

fn main() -> anyhow::Result<()> {
    let robot = BallbotParams::miapure_60kg();
    let timeline = Timeline::DEFAULT;
    println!("MiaPURE 60 kg, decoupled planar plants, outer 400 Hz, inner 8 kHz");
    println!(
        "{:>6} {:>13} {:>15} {:>7} {:>7} {:>8} {:>7} {:>7} {:>9}",
        "t (s)", "phase", "mode", "vx m/s", "vy m/s", "yaw r/s", "pitch°", "roll°", "|tau| Nm"
    );
    let mut last: Option<(Phase, Mode)> = None;
    let mut peak_torque_nm: f64 = 0.0;
    demo::run(&robot, &timeline, |report, plant| {
        let out = &report.output;
        let t = report.now_us as f64 * 1e-6;
        peak_torque_nm = peak_torque_nm.max(out.motors.feedforward_torque_nm.amax());
        if last != Some((report.phase, out.safety.mode)) {
            let faults = out.safety.faults;
            println!(
                "{t:6.3}  -> phase {:?}, mode {:?} (request {:?}){}{faults}",
                report.phase,
                out.safety.mode,
                report.request,
                if faults.is_empty() { "" } else { "; " },
            );
            last = Some((report.phase, out.safety.mode));
        }
        if report.now_us % 500_000 == 0 {
            let (vx, vy) = plant.body_velocity_m_per_s();
            println!(
                "{t:6.2} {:>13} {:>15} {vx:7.3} {vy:7.3} {:8.3} {:7.2} {:7.2} {:9.2}",
                format!("{:?}", report.phase),
                format!("{:?}", out.safety.mode),
                plant.states.spin[1],
                plant.states.sagittal[0].to_degrees(),
                plant.states.frontal[0].to_degrees(),
                plant.torque_nm.amax(),
            );
        }
    })
    .map_err(|e| anyhow::anyhow!("demo failed: {e:?}"))?;
    println!("peak feedforward omniwheel torque {peak_torque_nm:.1} N m (limit 43.2)");
    Ok(())
}
