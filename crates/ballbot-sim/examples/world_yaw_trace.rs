//! A slow velocity ramp in the 3D world with the core's controller in the loop (command
//! shaper caps lifted), traced every `EVERY` seconds: the body's yaw and yaw rate against the
//! lean and the rolling ball's rate about the body's z axis, which the omniwheels measure like
//! a yaw rate (docs/world-reproduce.md, "Yaw at speed").
//!
//! ```text
//! HEAD=0 ACC=0.25 TOP=3 TEND=14 EVERY=0.2 \
//!   cargo run --release -p ballbot-sim --example world_yaw_trace
//! ```
//! Columns: time (s), commanded and actual speed along the heading (m/s), yaw (deg), body yaw
//! rate (rad/s, gyro), roll and pitch (deg), the ball's rate about the body z axis and about
//! the world vertical (rad/s), the spin plane's reference yaw rate (rad/s) and torque (N m),
//! the fastest wheel (rad/s) and the controller's mode. The last line: the highest speed along
//! the heading before any failure, the largest |yaw|, and the failure.

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::WorldParams;
use nalgebra::{Rotation3, Vector3};
use std::error::Error;

fn env(name: &str, default: f64) -> Result<f64, Box<dyn Error>> {
    Ok(match std::env::var(name) {
        Ok(text) => text.trim().parse()?,
        Err(_) => default,
    })
}

fn main() -> Result<(), Box<dyn Error>> {
    let heading_deg = env("HEAD", 0.0)?;
    let accel = env("ACC", 0.25)?;
    let top = env("TOP", 3.0)?;
    let end_secs = env("TEND", 14.0)?;
    let every_secs = env("EVERY", 0.2)?;
    let params = WorldParams::miapure_60kg();
    let mut config = BallbotControllerConfig::paper(&params.robot)?;
    config.shaping.translation.max_value = top.max(5.0);
    config.shaping.translation.max_rate_per_s = 20.0;
    config.shaping.max_tilt_command_rad = 0.5;
    config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
    let mut sim = WorldRobot::with_config(params, config)?;
    let (s, c) = heading_deg.to_radians().sin_cos();
    let dt = params.dt_secs;
    let every = (every_secs / dt).round().max(1.0) as u64;
    println!(
        "t_secs v_cmd speed yaw_deg yaw_rate roll_deg pitch_deg ball_wz_body ball_wz_world \
         spin_ref_rate spin_torque_nm max_wheel_rad_per_s mode"
    );
    let (mut max_speed, mut max_yaw_deg): (f64, f64) = (0.0, 0.0);
    let mut end = None;
    for k in 0..(end_secs / dt).round() as u64 {
        let t = k as f64 * dt;
        let v = ((t - 0.5).max(0.0) * accel).min(top);
        let tel = *sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: v * c,
            vy_m_per_s: v * s,
            yaw_rate_rad_per_s: 0.0,
        }));
        let failure = sim.world().failure();
        let (roll, pitch, yaw) = tel.body_orientation.euler_angles();
        let v_body =
            Rotation3::from_axis_angle(&Vector3::z_axis(), -yaw) * tel.ball_velocity_m_per_s;
        if failure.is_none() {
            max_speed = max_speed.max(v_body.dot(&Vector3::new(c, s, 0.0)));
            max_yaw_deg = max_yaw_deg.max(yaw.to_degrees().abs());
        }
        if k.is_multiple_of(every) || failure.is_some() {
            let ball_body = tel.body_orientation.inverse() * tel.ball_angular_velocity_rad_per_s;
            let (ref_rate, ref_torque) = sim.last_outer().map_or((0.0, 0.0), |o| {
                (o.reference_rate_rad_per_s[2], o.reference_torque_nm[2])
            });
            let max_wheel = tel
                .wheels
                .iter()
                .map(|w| w.speed_rad_per_s.abs())
                .fold(0.0, f64::max);
            println!(
                "{t:.2} {v:.3} {:.3} {:.2} {:.4} {:.3} {:.3} {:.4} {:.4} {ref_rate:.4} {ref_torque:.3} \
                 {max_wheel:.2} {:?}",
                v_body.dot(&Vector3::new(c, s, 0.0)),
                yaw.to_degrees(),
                tel.body_rate_rad_per_s.z,
                roll.to_degrees(),
                pitch.to_degrees(),
                ball_body.z,
                tel.ball_angular_velocity_rad_per_s.z,
                sim.mode(),
            );
        }
        if failure.is_some() {
            end = failure;
            break;
        }
    }
    println!(
        "heading {heading_deg} deg: max speed {max_speed:.3} m/s, max |yaw| {max_yaw_deg:.2} deg, failure {end:?}"
    );
    Ok(())
}
