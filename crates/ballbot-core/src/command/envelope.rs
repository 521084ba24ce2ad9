//! Phase 2 of the [`CommandShaper`](super::CommandShaper)'s step: the traction envelope's acceleration bound on the
//! command's direction, eased within the jerk limit where it falls below the present
//! acceleration; and the phase's input, the command's [`Targets`].

use super::{AccelLimit, AxisLimits, JerkLimiter};
use crate::check::lit;
use crate::num::{direction, hypot, min};
use nalgebra::RealField;

/// The shaper's two speed limiters, body x and y.
pub(super) type Speeds<'a, T> = (&'a JerkLimiter<T>, &'a JerkLimiter<T>);

/// Phase 2: the traction envelope's acceleration bound along the direction the command
/// accelerates in, split over the two axes' rate limits, for the speed limiters `speeds`
/// (body x and y) as they are before the step.
#[inline(always)]
pub(super) fn envelope<T: RealField + Copy, L: AccelLimit<T>>(
    target: &Targets<T>,
    limit: &L,
    speeds: Speeds<'_, T>,
    dt_secs: T,
) -> Envelope<T> {
    let zero = T::zero();
    let translation = &target.translation;
    let mut envelope = Envelope::open(translation);
    let (vx0, vy0) = (speeds.0.value(), speeds.1.value());
    // The direction the command accelerates in: a trajectory's own acceleration while
    // it has one (its tracking error is rounding, and a direction taken from rounding
    // starved the axis it drives: the shaped speed swung 0.12 m/s about a braking
    // trajectory at 0.7 s), else the way to the target.
    let (ex, ey) = if target.feed.0 != zero || target.feed.1 != zero {
        target.feed
    } else {
        (target.x - vx0, target.y - vy0)
    };
    // On target (cruising, standing): nothing to limit, no square root. The direction
    // is scaled before squaring: a huge error (components beyond sqrt(T::MAX)) still
    // has one, and the envelope still applies.
    let unit = if ex == zero && ey == zero {
        None
    } else {
        direction(ex, ey)
    };
    if let Some(((dx, dy), _)) = unit {
        let braking = dx * vx0 + dy * vy0 < zero;
        let allowed = limit.accel_limit_m_per_s2(dx, dy, braking);
        let allowed = if allowed >= zero { allowed } else { zero };
        let allowed = eased(allowed, translation, speeds, dt_secs);
        envelope.binding = allowed < translation.max_rate_per_s;
        let rate = min(allowed, translation.max_rate_per_s);
        envelope.x.max_rate_per_s = rate * dx.abs();
        envelope.y.max_rate_per_s = rate * dy.abs();
        envelope.accel_limit_m_per_s2 = Some(allowed);
    }
    envelope
}

/// An envelope below the acceleration the limiters have now is reached within the jerk
/// limit: the bound falls by at most `max_jerk_per_s2 * dt_secs` a step. Cut at once, the
/// lean of the acceleration would have to go at once, and righting the body needs the
/// ball to accelerate harder first: the traction the cut was meant to spare.
#[inline(always)]
fn eased<T: RealField + Copy>(
    allowed: T,
    translation: &AxisLimits<T>,
    speeds: Speeds<'_, T>,
    dt_secs: T,
) -> T {
    let (ax, ay) = (speeds.0.rate_per_s(), speeds.1.rate_per_s());
    // Squares compared first: the square root only where the bound falls below the
    // acceleration (the rates are finite and within the translation limits, no overflow;
    // `allowed` is not NaN).
    if ax * ax + ay * ay <= allowed * allowed {
        return allowed;
    }
    let step = translation.max_jerk_per_s2 * dt_secs;
    let floor = hypot(ax, ay) - step;
    if floor > allowed && floor.is_finite() {
        floor
    } else {
        allowed
    }
}

/// Whether the envelope bound the step: it was below the command's own limit and the
/// shaped acceleration reached it.
#[inline(always)]
pub(super) fn held_back<T: RealField + Copy>(
    translation: &AxisLimits<T>,
    envelope: &Envelope<T>,
    speeds: Speeds<'_, T>,
) -> bool {
    envelope.binding && {
        let (ax, ay) = (speeds.0.rate_per_s(), speeds.1.rate_per_s());
        let rate = min(
            envelope.accel_limit_m_per_s2.unwrap_or(T::zero()),
            translation.max_rate_per_s,
        );
        hypot(ax, ay) >= rate * lit(0.999)
    }
}

/// The traction envelope on one step (phase 2 of [`CommandShaper::step`](super::CommandShaper::step)).
pub(super) struct Envelope<T> {
    /// The two speed limiters' limits, their rates split along the acceleration's direction.
    pub(super) x: AxisLimits<T>,
    pub(super) y: AxisLimits<T>,
    /// The envelope's acceleration bound in m/s^2 along that direction, if one applied.
    pub(super) accel_limit_m_per_s2: Option<T>,
    /// Whether that bound is below the command's own rate limit.
    pub(super) binding: bool,
}

impl<T: Copy> Envelope<T> {
    /// No envelope: both axes keep the command's limits.
    #[inline(always)]
    pub(super) fn open(translation: &AxisLimits<T>) -> Self {
        Self {
            x: *translation,
            y: *translation,
            accel_limit_m_per_s2: None,
            binding: false,
        }
    }
}

/// What a command asks the shaper for (phase 1 of [`CommandShaper::step`](super::CommandShaper::step)).
pub(super) struct Targets<T> {
    /// The speed targets in m/s and the yaw-rate target in rad/s.
    pub(super) x: T,
    pub(super) y: T,
    pub(super) yaw: T,
    /// The speed targets' own rates in m/s^2 (nonzero only for a trajectory).
    pub(super) feed: (T, T),
    /// A trajectory's tilt, tilt rate and tilt acceleration along its heading, with the
    /// heading's (sin, cos).
    pub(super) trajectory_tilt: Option<(T, T, T, T, T)>,
    /// The translation limits this command is shaped with (a lean command lowers the rate).
    pub(super) translation: AxisLimits<T>,
}
