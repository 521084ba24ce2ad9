//! How much the IMU's attitude filter costs, by its time constant: MiaPURE with 60 kg in the
//! default world with the VN-100 model (`SensorParams::miapure`), a ramp at 0.5 m/s^2 to a
//! top speed, held to 5 s, then a step command to rest. Per heading, top speed and filter
//! time constant (`truth`: the default world's IMU): the largest tilt error the controller
//! read (sampled every 10 ms), the speed 2 s after the stop command, and any failure; then the
//! same with the controller correcting the filter's lean
//! (`BallbotControllerConfig::with_imu_lean_correction` at the filter's time constant).
//!
//! ```text
//! cargo run --release -p ballbot-sim --example imu_time_constant
//! ```

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::studies::runner::run_jobs;
use ballbot_sim::world::{SensorParams, WorldError, WorldParams};

/// Steps at 8 kHz.
const STEPS_PER_SECOND: u64 = 8000;

/// One run's readings.
struct Outcome {
    max_tilt_error_deg: f64,
    speed_after_stop_m_per_s: f64,
    failure: String,
}

/// The commanded speed at `t` (m/s): hold, a 0.5 m/s^2 ramp to `top`, then 0 from 5 s.
fn commanded_speed(t: f64, top: f64) -> f64 {
    if (0.5..5.0).contains(&t) {
        ((t - 0.5) * 0.5).min(top)
    } else {
        0.0
    }
}

/// One run; `correct`: the controller corrects the filter's lean.
fn run(
    heading_deg: f64,
    top: f64,
    tau_secs: Option<f64>,
    correct: bool,
) -> Result<Outcome, WorldError> {
    let mut params = WorldParams {
        sensors: SensorParams::miapure(),
        ..WorldParams::miapure_60kg()
    };
    match tau_secs {
        None => params.sensors = SensorParams::default(),
        Some(tau) => params.sensors.imu.filter_time_constant_secs = tau,
    }
    let mut config = BallbotControllerConfig::design(&params.robot)?;
    if let (Some(tau), true) = (tau_secs, correct) {
        config = config.with_imu_lean_correction(tau);
    }
    let mut sim = WorldRobot::with_config(params, config)?;
    let (c, s) = (
        heading_deg.to_radians().cos(),
        heading_deg.to_radians().sin(),
    );
    let mut out = Outcome {
        max_tilt_error_deg: 0.0,
        speed_after_stop_m_per_s: f64::NAN,
        failure: String::new(),
    };
    for k in 0..10 * STEPS_PER_SECOND {
        let v = commanded_speed(k as f64 / STEPS_PER_SECOND as f64, top);
        sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: v * c,
            vy_m_per_s: v * s,
            yaw_rate_rad_per_s: 0.0,
        }));
        if k % 80 == 0 {
            let truth = *sim.world().telemetry();
            let m = sim.world_mut().measure();
            let (roll, pitch, _) = truth.body_orientation.euler_angles();
            let error = (m.tilt_rad[0] - roll)
                .abs()
                .max((m.tilt_rad[1] - pitch).abs());
            out.max_tilt_error_deg = out.max_tilt_error_deg.max(error.to_degrees());
        }
        if k == 7 * STEPS_PER_SECOND {
            out.speed_after_stop_m_per_s = sim.world().telemetry().ball_velocity_m_per_s.norm();
        }
        if let Some(f) = sim.world().failure() {
            out.failure = format!("{:?} at {:.2} s", f.kind, f.time_secs);
            break;
        }
    }
    Ok(out)
}

fn main() -> Result<(), WorldError> {
    let taus = [
        None,
        Some(1.0),
        Some(2.29),
        Some(5.0),
        Some(10.0),
        Some(30.0),
    ];
    let mut jobs = Vec::new();
    for heading in [0.0, 90.0, 180.0] {
        for top in [0.5, 1.4] {
            jobs.extend(taus.iter().map(|&tau| (heading, top, tau)));
        }
    }
    let outcomes = run_jobs(&jobs, 0, |&(h, top, tau)| run(h, top, tau, false), &|_| {})?;
    let corrected = run_jobs(&jobs, 0, |&(h, top, tau)| run(h, top, tau, true), &|_| {})?;
    println!(
        "| heading (deg) | top speed (m/s) | tau (s) | largest tilt error read (deg) | \
         speed 2 s after the stop (m/s) | the same, corrected | failure |"
    );
    println!("|---|---|---|---|---|---|---|");
    for ((&(h, top, tau), o), c) in jobs.iter().zip(outcomes).zip(corrected) {
        let tau = tau.map_or("truth".to_string(), |t| format!("{t}"));
        println!(
            "| {h} | {top} | {tau} | {:.2} | {:.3} | {:.3} | {}{} |",
            o.max_tilt_error_deg,
            o.speed_after_stop_m_per_s,
            c.speed_after_stop_m_per_s,
            o.failure,
            c.failure
        );
    }
    Ok(())
}
