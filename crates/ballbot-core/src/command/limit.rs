//! [`AccelLimit`]: a direction-dependent acceleration limit for the
//! [`CommandShaper`](super::CommandShaper) ([`CommandShaper::step_within`](super::CommandShaper::step_within)).

use crate::check::lit;
use nalgebra::RealField;

/// The largest acceleration the robot may take in a direction, as
/// [`CommandShaper::step_within`](super::CommandShaper::step_within) asks it (e.g. the traction envelope,
/// [`crate::traction`]).
///
/// ```
/// use ballbot_core::command::AccelLimit;
/// // Half as much towards -x as towards +x; never below 0.5 m/s^2 when braking.
/// struct Lopsided;
/// impl AccelLimit<f64> for Lopsided {
///     fn accel_limit_m_per_s2(&self, dir_x: f64, _dir_y: f64, braking: bool) -> f64 {
///         let limit: f64 = if dir_x < 0.0 { 0.5 } else { 1.0 };
///         if braking { limit.max(0.5) } else { limit }
///     }
/// }
/// assert_eq!(Lopsided.accel_limit_m_per_s2(-1.0, 0.0, false), 0.5);
/// ```
pub trait AccelLimit<T> {
    /// The largest acceleration (m/s^2, > 0) along the unit body-frame direction
    /// `(dir_x, dir_y)`; `braking` when that direction is against the present velocity.
    fn accel_limit_m_per_s2(&self, dir_x: T, dir_y: T, braking: bool) -> T;
}

/// No acceleration limit: [`CommandShaper::step`]'s (never asked).
pub(super) struct NoLimit;

impl<T: RealField + Copy> AccelLimit<T> for NoLimit {
    fn accel_limit_m_per_s2(&self, _dir_x: T, _dir_y: T, _braking: bool) -> T {
        lit(f64::INFINITY)
    }
}
