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

/// A finite `f64` drawn log-uniformly over the whole range: a random sign, a biased exponent
/// uniform over every finite one (0, the subnormals, up to 2046, the binade of `f64::MAX`)
/// and a random mantissa; one draw in eight is an edge value instead (zero of either sign,
/// the smallest subnormal, the smallest normal, the largest finite, one).
///
/// ```
/// use ballbot_studies::studies::robustness::fuzz::hostile::log_uniform_f64;
/// use rand_chacha::{ChaCha8Rng, rand_core::SeedableRng};
/// let mut rng = ChaCha8Rng::seed_from_u64(1);
/// let draws: Vec<f64> = (0..10_000).map(|_| log_uniform_f64(&mut rng)).collect();
/// assert!(draws.iter().all(|x| x.is_finite()));
/// assert!(draws.iter().any(|x| x.abs() > 1e300) && draws.iter().any(|x| x.is_subnormal()));
/// assert!(draws.iter().any(|x| *x < 0.0) && draws.iter().any(|x| *x > 0.0));
/// ```
pub fn log_uniform_f64(rng: &mut ChaCha8Rng) -> f64 {
    if chance(rng, 0.125) {
        let edge = [0.0, 5e-324, f64::MIN_POSITIVE, f64::MAX, 1.0][index(rng, 5)];
        return if chance(rng, 0.5) { -edge } else { edge };
    }
    let sign = rng.next_u64() & (1 << 63);
    let exponent = rng.next_u64() % 2047;
    let mantissa = rng.next_u64() & ((1 << 52) - 1);
    f64::from_bits(sign | exponent << 52 | mantissa)
}

/// A finite `f32` drawn log-uniformly over the whole `f32` range, as [`log_uniform_f64`]
/// (biased exponents 0 to 254).
///
/// ```
/// use ballbot_studies::studies::robustness::fuzz::hostile::log_uniform_f32;
/// use rand_chacha::{ChaCha8Rng, rand_core::SeedableRng};
/// let mut rng = ChaCha8Rng::seed_from_u64(1);
/// let draws: Vec<f32> = (0..10_000).map(|_| log_uniform_f32(&mut rng)).collect();
/// assert!(draws.iter().all(|x| x.is_finite()));
/// assert!(draws.iter().any(|x| x.abs() > 1e37) && draws.iter().any(|x| x.is_subnormal()));
/// ```
pub fn log_uniform_f32(rng: &mut ChaCha8Rng) -> f32 {
    if chance(rng, 0.125) {
        let edge = [0.0, 1e-45, f32::MIN_POSITIVE, f32::MAX, 1.0][index(rng, 5)];
        return if chance(rng, 0.5) { -edge } else { edge };
    }
    let bits = rng.next_u64();
    let sign = (bits as u32) & (1 << 31);
    let exponent = ((bits >> 32) % 255) as u32;
    let mantissa = ((bits >> 8) as u32) & ((1 << 23) - 1);
    f32::from_bits(sign | exponent << 23 | mantissa)
}

/// A value a broken sensor or link might deliver: NaN or an infinity (one draw in four),
/// any finite `f64` ([`log_uniform_f64`], three in eight), any finite `f32` widened (one in
/// eight: what an `f32` driver or link delivers), or something merely wrong (one in four:
/// up to 3 or 100 in size).
pub fn hostile(rng: &mut ChaCha8Rng) -> f64 {
    match index(rng, 16) {
        0 | 1 => f64::NAN,
        2 => f64::INFINITY,
        3 => f64::NEG_INFINITY,
        4..=9 => log_uniform_f64(rng),
        10 | 11 => f64::from(log_uniform_f32(rng)),
        12 | 13 => symmetric(rng, 100.0),
        _ => symmetric(rng, 3.0),
    }
}

/// A finite value for a command field: gentle (up to `gentle`) half the time, else any finite
/// `f64` ([`log_uniform_f64`]), up to the largest finite value.
pub fn command_value(rng: &mut ChaCha8Rng, gentle: f64) -> f64 {
    if chance(rng, 0.5) {
        symmetric(rng, gentle)
    } else {
        log_uniform_f64(rng)
    }
}

/// A command the API accepts (finite), from gentle to the largest finite values: velocity,
/// lean, or stop. (Trajectories borrow their samples; the fuzzer builds them itself.)
pub fn accepted_command(rng: &mut ChaCha8Rng) -> Command<'static, f64> {
    let scale = [0.5, 2.0, 10.0][index(rng, 3)];
    match index(rng, 3) {
        0 => Command::Velocity(VelocityCommand {
            vx_m_per_s: command_value(rng, scale),
            vy_m_per_s: command_value(rng, scale),
            yaw_rate_rad_per_s: command_value(rng, scale),
        }),
        1 => Command::Lean(LeanInput {
            towards_x_rad: command_value(rng, 0.1 * scale),
            towards_y_rad: command_value(rng, 0.1 * scale),
            yaw_rate_rad_per_s: command_value(rng, scale),
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
