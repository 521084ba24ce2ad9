//! The traction study's controlled ramp (3 m/s^2 to 3 m/s, traction-aware control on, the
//! shaper's caps lifted so that only the envelope limits) per heading and sensor seed, or the
//! shipped controller at its own caps (`CONTROL=shipped`, 1 m/s^2 to 2 m/s): whether it fails,
//! whether the slip monitor flags a slip the world does not have (detection before the world's
//! first slip above 0.05 m/s, or without one), the friction it learns, the ball's mean and
//! peak acceleration against the envelope, the largest cone use and tilt.
//!
//! ```text
//! HEADS=45,315 SEEDS=1,2,3,4,5,6,7,8 cargo run --release -p ballbot-sim --example traction_diagonals
//! ```
//! Environment: `HEADS` (deg), `SEEDS` (sensor seeds), `CONTROL` (`on`, the study's; or
//! `shipped`), `ACCEL` and `TOP` (m/s^2, m/s; default 3 and 3 for `on`, 1 and 2 for `shipped`).
//! `THRESHOLD` (m/s) and `ESTIMATE_FRICTION=0` override the slip monitor's threshold and
//! its friction learning. Runs use every core. Prints one line per run and a summary line.
//! `TRACE=heading,seed,from,to` prints the outer steps of one run instead (see `trace`).

use ballbot_core::BallbotParams;
use ballbot_core::traction::{TractionEnvelope, TractionParams};
use ballbot_sim::studies::max_speed::ShaperLimits;
use ballbot_sim::studies::runner::run_jobs;
use ballbot_sim::studies::traction::Control;
use ballbot_sim::studies::traction::runs::{ramp, ramp_observed};
use ballbot_sim::world::{WorldError, WorldParams};
use std::error::Error;

fn list(name: &str, default: &str) -> Result<Vec<f64>, Box<dyn Error>> {
    let text = std::env::var(name).unwrap_or_else(|_| default.to_owned());
    Ok(text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()?)
}

fn env_f64(name: &str) -> Option<f64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// The default world for sensor seed `seed`, with the world's parts that the environment names
/// made ideal (to find which one a finding needs): `RIGID_DRIVETRAIN=1` (no coupling, backlash
/// or gearbox friction), `NO_BACKLASH=1`, `NO_GEARBOX_FRICTION=1` (stiction and
/// Coulomb friction), `IDEAL_CONTACT=1` (the rigid wheel contacts), `NO_ROLLING_RESISTANCE=1`.
fn world(seed: u64) -> WorldParams {
    let mut params = WorldParams::with_robot(BallbotParams::miapure_60kg());
    params.sensors.seed = seed;
    let on = |name: &str| env_f64(name) == Some(1.0);
    if on("RIGID_DRIVETRAIN") {
        params.transmission = ballbot_sim::world::TransmissionParams::rigid();
    }
    if on("NO_BACKLASH") {
        params.transmission.backlash_rad = 0.0;
    }
    if on("NO_GEARBOX_FRICTION") {
        params.transmission.stiction_torque_nm = 0.0;
        params.transmission.coulomb_torque_nm = 0.0;
    }
    if on("IDEAL_CONTACT") {
        params.contact = ballbot_sim::world::ContactParams::ideal();
    }
    if on("NO_ROLLING_RESISTANCE") {
        params.rolling_resistance = 0.0;
    }
    params
}

struct Line {
    failed: bool,
    false_flag: bool,
    text: String,
}

fn run(
    control: Control,
    heading_deg: f64,
    seed: u64,
    accel: f64,
    top: f64,
) -> Result<Line, WorldError> {
    let params = world(seed);
    let mut config = control.config(&params, &ShaperLimits::default())?;
    if let Some(threshold) = env_f64("THRESHOLD") {
        config.traction.slip_speed_threshold_m_per_s = threshold;
    }
    if env_f64("ESTIMATE_FRICTION") == Some(0.0) {
        config.traction.estimate_friction = false;
    }
    let envelope =
        TractionEnvelope::new(&params.robot, &TractionParams::recommended(&params.robot))?;
    let h = heading_deg.to_radians();
    let env = envelope.friction_limit_m_per_s2(h.cos(), h.sin());
    let r = ramp(params, config, heading_deg, accel, top)?;
    let false_flag = match (r.first_detection_secs, r.first_world_slip_secs) {
        (Some(d), Some(w)) => d < w,
        (Some(_), None) => true,
        _ => false,
    };
    let failure = r.failure.as_ref().map_or("-".to_owned(), |f| {
        format!("{}@{:.3}", f.kind.as_str(), f.time_secs)
    });
    let text = format!(
        "{heading_deg:>5.0} {seed:>4} {failure:>18} {:>8} {:>8} {:>3} {:>6} {:>6} {:>6} {:>6.2} {:>6.2} {:>5.1}",
        r.first_detection_secs
            .map_or("-".into(), |t| format!("{t:.3}")),
        r.first_world_slip_secs
            .map_or("-".into(), |t| format!("{t:.3}")),
        r.slip_events,
        r.min_friction_estimate
            .map_or("-".into(), |m| format!("{m:.2}")),
        r.mean_accel_m_per_s2()
            .map_or("-".into(), |a| format!("{a:.2}")),
        format!("{env:.2}"),
        r.max_accel_m_per_s2,
        r.peak_cone_utilisation,
        r.max_tilt_rad.to_degrees(),
    );
    Ok(Line {
        failed: r.failure.is_some(),
        false_flag,
        text,
    })
}

/// `TRACE=heading,seed,from,to`: every outer step of that run between `from` and `to` (s), per
/// wheel: the monitor's slip evidence and flag, its predicted and the world's normal force, the
/// coupling torque, the motor side's speed minus the wheel's (the drivetrain's wind-up and
/// backlash as the encoder sees them, rad/s) and the world's slip speed.
fn trace(control: Control, spec: &str, accel: f64, top: f64) -> Result<(), Box<dyn Error>> {
    let v: Vec<f64> = spec.split(',').map(str::parse).collect::<Result<_, _>>()?;
    let [heading_deg, seed, from, to] = v[..] else {
        return Err("TRACE=heading,seed,from,to".into());
    };
    let params = world(seed as u64);
    let config = control.config(&params, &ShaperLimits::default())?;
    let mut last = f64::NAN;
    ramp_observed(params, config, heading_deg, accel, top, &mut |sim| {
        let Some(o) = sim.last_outer() else { return };
        let t = sim.world().telemetry();
        let now = t.time_secs;
        if now < from || now > to || (now - last) < 0.0024 {
            return;
        }
        last = now;
        let Some(tr) = &o.traction else { return };
        let slip = &tr.slip;
        let mut row = format!(
            "{now:.4} mu {:.2} sc {:.2} lim {:.2} tilt_c {:+.4} {:+.4} tau {:+5.1} {:+5.1} |",
            slip.friction_estimate,
            slip.accel_scale,
            tr.accel_limit_m_per_s2.unwrap_or(f64::NAN),
            o.commands.frontal[0],
            o.commands.sagittal[0],
            o.reference_torque_nm.x,
            o.reference_torque_nm.y,
        );
        for i in 0..3 {
            let w = &t.wheels[i];
            row += &format!(
                " ev {:+.3}{} N {:>5.0}/{:>5.0} tq {:+5.1} wind {:+.2} ws {:.3} |",
                slip.slip_speed_m_per_s[i],
                if slip.slipping[i] { "*" } else { " " },
                slip.predicted_normal_force_n[i],
                w.normal_force_n,
                w.coupling_torque_nm,
                w.motor_speed_rad_per_s - w.speed_rad_per_s,
                w.slip_speed_m_per_s,
            );
        }
        println!("{row}");
    })?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let control = match std::env::var("CONTROL").as_deref() {
        Ok("shipped") => Control::Shipped,
        Ok("on") | Err(_) => Control::TractionOn,
        Ok(other) => return Err(format!("CONTROL={other}: on or shipped").into()),
    };
    let (accel_default, top_default) = if control == Control::Shipped {
        ("1", "2")
    } else {
        ("3", "3")
    };
    if let Ok(spec) = std::env::var("TRACE") {
        let accel = list("ACCEL", accel_default)?[0];
        let top = list("TOP", top_default)?[0];
        return trace(control, &spec, accel, top);
    }
    let heads = list("HEADS", "45,315")?;
    let seeds: Vec<u64> = list("SEEDS", "1,2,3,4,5,6,7,8")?
        .into_iter()
        .map(|s| s as u64)
        .collect();
    let accel = list("ACCEL", accel_default)?[0];
    let top = list("TOP", top_default)?[0];
    let jobs: Vec<(f64, u64)> = heads
        .iter()
        .flat_map(|&h| seeds.iter().map(move |&s| (h, s)))
        .collect();
    println!(
        "control {} ramp {accel} m/s^2 to {top} m/s, {} runs",
        control.as_str(),
        jobs.len()
    );
    println!(
        "heading seed            failure detected  w_slip  ev  mu_est  mean   env   peak  cone  tilt"
    );
    let lines = run_jobs(&jobs, 0, |&(h, s)| run(control, h, s, accel, top), &|_| {})?;
    for l in &lines {
        println!("{}", l.text);
    }
    let failed = lines.iter().filter(|l| l.failed).count();
    let flagged = lines.iter().filter(|l| l.false_flag).count();
    println!(
        "summary: {failed} of {} runs fail, {flagged} flag a slip before the world's first",
        lines.len()
    );
    Ok(())
}
