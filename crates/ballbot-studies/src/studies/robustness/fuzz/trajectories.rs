//! The commands of the fuzz episodes: valid and random trajectories, and how a command is
//! described in a finding.

use super::hostile::{chance, index, log_uniform_f64, symmetric, unit};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, Trajectory, TrajectoryLimits};
use ballbot_core::wip::WipState;
use rand_chacha::ChaCha8Rng;

/// A valid trajectory: along a random heading, the ball speeds up to a random speed with a
/// quintic profile, cruises, and slows down to rest, the body leaning by the equilibrium lean
/// of the acceleration (`lean = (b + c0) / (m_U g l) * a / r`, see
/// [`TrajectoryLimits::lean_per_ball_accel_s2`]) with its derivative as the tilt rate. The
/// speed and the duration are scaled until [`Trajectory::new`] accepts it against `limits`
/// (the last try, slow and long, is accepted in practice).
pub(super) fn valid_trajectory(
    rng: &mut ChaCha8Rng,
    config: &BallbotControllerConfig<f64>,
    limits: &TrajectoryLimits<f64>,
    start: u64,
) -> (Vec<WipState<f64>>, f64, f64, u64) {
    let r = config.robot.sagittal.ball_radius_m;
    let k = limits.lean_per_ball_accel_s2;
    let top = (limits.max_ball_rate_rad_per_s * r).min(config.shaping.translation.max_value);
    let mut speed = top * (0.05 + 0.75 * unit(rng));
    let mut ramp_secs = 0.5 + 3.0 * unit(rng);
    let cruise_secs = 3.0 * unit(rng);
    let heading = std::f64::consts::TAU * unit(rng);
    let mut best = (Vec::new(), 1.0);
    for _ in 0..12 {
        let period = (ramp_secs / 25.0).max(limits.min_sample_period_secs);
        let total = 2.0 * ramp_secs + cruise_secs;
        let n = (total / period).ceil() as usize + 1;
        let mut phi = 0.0;
        let samples: Vec<WipState<f64>> = (0..n)
            .map(|i| {
                let t = (i as f64 * period).min(total);
                // Speed, acceleration and jerk of the ramp up or down at `t`.
                let (v, a, j) = if t < ramp_secs {
                    quintic(speed, ramp_secs, t)
                } else if t < ramp_secs + cruise_secs {
                    (speed, 0.0, 0.0)
                } else {
                    let (v, a, j) = quintic(speed, ramp_secs, t - ramp_secs - cruise_secs);
                    (speed - v, -a, -j)
                };
                let state = WipState::new(k * a / r, phi, k * j / r, v / r);
                phi += v / r * period;
                state
            })
            .collect();
        let ok = Trajectory::new(&samples, period, heading, limits).is_ok();
        best = (samples, period);
        if ok {
            break;
        }
        speed *= 0.7;
        ramp_secs *= 1.5;
    }
    (best.0, best.1, heading, start)
}

/// A quintic ramp from rest to `speed` over `secs`: speed, acceleration and jerk at `t`.
fn quintic(speed: f64, secs: f64, t: f64) -> (f64, f64, f64) {
    let x = (t / secs).clamp(0.0, 1.0);
    (
        speed * (10.0 * x.powi(3) - 15.0 * x.powi(4) + 6.0 * x.powi(5)),
        speed * (30.0 * x * x - 60.0 * x.powi(3) + 30.0 * x.powi(4)) / secs,
        speed * (60.0 * x - 180.0 * x * x + 120.0 * x.powi(3)) / (secs * secs),
    )
}

/// A trajectory the API accepts (or not: [`Trajectory::new`] decides): 1 to 40 finite
/// samples, gentle to absurd (half the time any finite value, [`log_uniform_f64`]), a sample
/// period from a list (1 us to 1e6 s) or any positive finite value down to the smallest
/// subnormal.
pub(super) fn random_trajectory(
    rng: &mut ChaCha8Rng,
    start: u64,
) -> (Vec<WipState<f64>>, f64, f64, u64) {
    let n = 1 + index(rng, 40);
    let scale = [0.1, 1.0, 10.0, 1e4][index(rng, 4)];
    let wild = chance(rng, 0.5);
    let value = |rng: &mut ChaCha8Rng, gentle: f64| {
        if wild && chance(rng, 0.5) {
            log_uniform_f64(rng)
        } else {
            symmetric(rng, gentle)
        }
    };
    let samples = (0..n)
        .map(|_| {
            WipState::new(
                value(rng, 0.1 * scale),
                value(rng, 10.0 * scale),
                value(rng, scale),
                value(rng, 10.0 * scale),
            )
        })
        .collect();
    let period = if chance(rng, 0.5) {
        [1e-6, 1e-3, 0.0025, 0.1, 10.0, 1e6][index(rng, 6)]
    } else {
        log_uniform_f64(rng).abs()
    };
    (samples, period, symmetric(rng, 10.0), start)
}

/// A short description of a command for a violation's record.
pub(super) fn describe(command: &Command<'_, f64>) -> String {
    match command {
        Command::Stop => "stop".to_owned(),
        Command::Velocity(v) => format!(
            "velocity {:.3e} {:.3e} {:.3e}",
            v.vx_m_per_s, v.vy_m_per_s, v.yaw_rate_rad_per_s
        ),
        Command::Lean(l) => format!(
            "lean {:.3e} {:.3e} {:.3e}",
            l.towards_x_rad, l.towards_y_rad, l.yaw_rate_rad_per_s
        ),
        Command::Trajectory { time_secs, .. } => format!("trajectory at {time_secs:.2} s"),
    }
}
