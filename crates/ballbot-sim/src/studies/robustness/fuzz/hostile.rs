//! Hostile values and events for the fuzzer, drawn from a seeded generator.

use ballbot_core::command::{Command, LeanInput, VelocityCommand};
use ballbot_core::safety::ModeRequest;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::Rng;

/// A uniform draw in `[0, 1)`.
pub fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Whether an event of probability `p` happens.
pub fn chance(rng: &mut ChaCha8Rng, p: f64) -> bool {
    unit(rng) < p
}

/// A uniform index below `n` (`n > 0`).
pub fn index(rng: &mut ChaCha8Rng, n: usize) -> usize {
    (rng.next_u64() % n.max(1) as u64) as usize
}

/// A uniform draw in `[-bound, bound]`.
pub fn symmetric(rng: &mut ChaCha8Rng, bound: f64) -> f64 {
    (2.0 * unit(rng) - 1.0) * bound
}

/// A value a broken sensor or link might deliver: NaN, infinities, subnormals, zero of
/// either sign, huge and negative values, the extremes of f64, or something merely wrong.
pub fn hostile(rng: &mut ChaCha8Rng) -> f64 {
    const SUBNORMAL: f64 = f64::MIN_POSITIVE / 4.0;
    match index(rng, 14) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => SUBNORMAL,
        4 => -SUBNORMAL,
        5 => -0.0,
        6 => 1e300,
        7 => -1e300,
        8 => f64::MAX,
        9 => f64::MIN,
        10 => symmetric(rng, 1e6),
        11 => symmetric(rng, 100.0),
        _ => symmetric(rng, 3.0),
    }
}

/// A command the API accepts (finite), from gentle to absurd: velocity, lean, or stop.
/// (Trajectories borrow their samples; the fuzzer builds them itself.)
pub fn accepted_command(rng: &mut ChaCha8Rng) -> Command<'static, f64> {
    let scale = [0.5, 2.0, 10.0, 1e6][index(rng, 4)];
    match index(rng, 3) {
        0 => Command::Velocity(VelocityCommand {
            vx_m_per_s: symmetric(rng, scale),
            vy_m_per_s: symmetric(rng, scale),
            yaw_rate_rad_per_s: symmetric(rng, scale),
        }),
        1 => Command::Lean(LeanInput {
            towards_x_rad: symmetric(rng, 0.1 * scale),
            towards_y_rad: symmetric(rng, 0.1 * scale),
            yaw_rate_rad_per_s: symmetric(rng, scale),
        }),
        _ => Command::Stop,
    }
}

/// A mode request an operator might send at any time.
pub fn request(rng: &mut ChaCha8Rng) -> ModeRequest {
    [
        ModeRequest::Stop,
        ModeRequest::Resume,
        ModeRequest::Disarm,
        ModeRequest::Reset,
        ModeRequest::Arm,
    ][index(rng, 5)]
}
