//! Prints every gain of the 3D controller designed from a robot's parameters: how to get
//! gains for a new robot.
//!
//! ```text
//! cargo run -p ballbot-examples --example gains -- examples/params/miapure_60kg.toml
//! cargo run -p ballbot-examples --example gains -- --preset miapure_unloaded
//! cargo run -p ballbot-examples --example gains -- --dump miapure_60kg > my_robot.toml
//! ```
//!
//! The file is a `BallbotParams` in TOML (the core's `serde` feature; unknown fields are
//! rejected): `[sagittal]` and `[frontal]` WIP planes, `[spin]`, `[drivetrain]` with its
//! `[drivetrain.actuator]`. The design is `BallbotControllerConfig::design`: discrete LQR at
//! 400 Hz with MODEL.md's weights on each plane's upright linearisation and on the spin model,
//! the per-motor speed PI for a 30 rad/s double pole, the continuous LQR for comparison with
//! the paper, and the closed-loop poles.

use anyhow::{Context, bail};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
use ballbot_core::{BallbotParams, OmniKinematics, Wip, WipParams};

fn preset(name: &str) -> anyhow::Result<BallbotParams<f64>> {
    Ok(match name {
        "miapure_60kg" => BallbotParams::miapure_60kg(),
        "miapure_unloaded" => BallbotParams::miapure_unloaded(),
        other => bail!("unknown preset `{other}` (miapure_60kg, miapure_unloaded)"),
    })
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (robot, source) = match args.as_slice() {
        [flag, name] if flag == "--dump" => {
            print!("{}", toml::to_string(&preset(name)?)?);
            return Ok(());
        }
        [flag, name] if flag == "--preset" => (preset(name)?, format!("preset {name}")),
        [path] => {
            let text = std::fs::read_to_string(path).with_context(|| format!("reading {path}"))?;
            let robot: BallbotParams<f64> =
                toml::from_str(&text).with_context(|| format!("parsing {path}"))?;
            (robot, path.clone())
        }
        _ => bail!("usage: gains PARAMS.toml | --preset NAME | --dump NAME"),
    };
    robot
        .validate()
        .with_context(|| format!("validating {source}"))?;
    let config = BallbotControllerConfig::design(&robot)
        .with_context(|| format!("designing the controller for {source}"))?;
    let kin = OmniKinematics::from_ballbot(&robot)?;
    let capacity = kin.planar_torque_capacity_nm();
    println!("gains for {source}");
    println!(
        "outer loop {:.0} Hz; planar torque capacity x {:.1}, y {:.1}, z {:.1} N m",
        1.0 / config.outer_dt_secs,
        capacity[0],
        capacity[1],
        capacity[2]
    );
    println!();
    println!(
        "LQR planes, tau = k1 (theta_c - theta) + k2 (theta_dot_c - theta_dot) + k3 (phi_dot_c - phi_dot)"
    );
    println!(
        "{:<10} {:>10} {:>10} {:>10} {:>9} {:>12} {:>12}  continuous design (paper)",
        "plane", "k1 Nm/rad", "k2 Nms/rad", "k3 Nms/rad", "max Nm", "open pole/s", "anchor rad/s"
    );
    for (name, params, plane) in [
        ("sagittal", robot.sagittal, &config.sagittal),
        ("frontal", robot.frontal, &config.frontal),
    ] {
        let wip = Wip::new(params)?;
        let cont = wip_lqr(&wip, &WipLqrWeights::model_default())?.reduced_gains();
        let k = &plane.lqr;
        println!(
            "{name:<10} {:>10.2} {:>10.3} {:>10.4} {:>9.1} {:>12.3} {:>12.3}  [{:.2}, {:.3}, {:.4}]",
            k.tilt_nm_per_rad,
            k.tilt_rate_nm_s_per_rad,
            k.ball_rate_nm_s_per_rad,
            k.max_torque_nm,
            wip.upright_unstable_pole_rad_per_s(),
            plane.max_speed_error_rad_per_s,
            cont[0],
            cont[1],
            cont[2]
        );
        closed_loop_poles(
            &params,
            [
                k.tilt_nm_per_rad,
                k.tilt_rate_nm_s_per_rad,
                k.ball_rate_nm_s_per_rad,
            ],
        )?;
    }
    println!();
    let s = &config.spin;
    println!(
        "spin: tau_z = {:.3} N m/rad (theta_zc - theta_z) + {:.3} N m s/rad (rate error), max {:.1} N m",
        s.gains.heading_nm_per_rad, s.gains.rate_nm_s_per_rad, s.gains.max_torque_nm
    );
    let m = &config.motor;
    println!(
        "motor speed PI (per omniwheel, torques at the omniwheel): kp {:.4} N m s/rad, ki {:.4} N m/rad, anti-windup {:.1} 1/s, max {:.1} N m",
        m.proportional_nm_s_per_rad, m.integral_nm_per_rad, m.anti_windup_per_s, m.max_torque_nm
    );
    let a = &robot.drivetrain.actuator;
    println!(
        "actuator: peak {:.1} N m, no-load {:.1} rad/s at the omniwheel; wheel-speed limit {:.1} rad/s",
        a.peak_torque_nm, a.no_load_speed_rad_per_s, config.safety.wheel_speed_limit_rad_per_s
    );
    Ok(())
}

/// Prints the continuous closed-loop poles of the plane with these gains (a check that the
/// discrete design also stabilises the continuous linearisation).
fn closed_loop_poles(params: &WipParams<f64>, k: [f64; 3]) -> anyhow::Result<()> {
    // tau = k (s_c - s): with s_c = 0 the closed loop is A - B k.
    let (a, b) = Wip::new(*params)?.linearize_upright().reduced();
    let kv = nalgebra::RowVector3::new(k[0], k[1], k[2]);
    let closed = a - b * kv;
    let poles = ballbot_core::linalg::eigenvalues(&closed).context("eigenvalues")?;
    let text: Vec<String> = poles
        .iter()
        .map(|p| format!("{:.2}{:+.2}i", p.re, p.im))
        .collect();
    let stable = poles.iter().all(|p| p.re < 0.0);
    println!(
        "{:<10} closed-loop poles (1/s): {}{}",
        "",
        text.join(", "),
        if stable { "" } else { "  UNSTABLE" }
    );
    Ok(())
}
