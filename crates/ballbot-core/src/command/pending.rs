//! A one-step bound on the reference filter's pending acceleration
//! ([`CommandShaper::bound_pending_acceleration`]), for applications that want one.

use super::{AccelLimit, CommandShaper, JerkLimiter};
use crate::num::{clamp_sym, direction};
use nalgebra::RealField;

impl<T: RealField + Copy> CommandShaper<T> {
    /// Bounds the acceleration the reference filter still has pending (the filtered speed
    /// chases the jerk-limited speed `v` with `a_f = (v - v_f) / tau`, see
    /// [`CommandShaperParams::reference_filter_secs`](super::CommandShaperParams::reference_filter_secs)) by `limit` in its direction: `v` moves
    /// towards `v_f` until `|a_f|` is within it, and the limiters' accelerations are bounded
    /// the same way: a lower limit alone stops `v` but leaves the reference accelerating for
    /// about `tau`. The controller's slip reaction no longer calls it: cutting the lean in one
    /// step made the ball accelerate harder to right the body, and on the diagonals the
    /// least-loaded wheel lifted off (docs/traction.md, section 2). Nothing to do without the
    /// filter.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{AccelLimit, Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// struct Cap(f64);
    /// impl AccelLimit<f64> for Cap {
    ///     fn accel_limit_m_per_s2(&self, _x: f64, _y: f64, _braking: bool) -> f64 { self.0 }
    /// }
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let params = CommandShaperParams { reference_filter_secs: 0.3, ..CommandShaperParams::miapure() };
    /// let mut shaper = CommandShaper::new(params, &robot)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 2.0, ..Default::default() });
    /// for _ in 0..400 {
    ///     shaper.step(&go, 0.0025);
    /// }
    /// // Mid-ramp the filtered reference accelerates at about 1 m/s^2; bound it to 0.3 (and
    /// // shape on within the same limit).
    /// shaper.bound_pending_acceleration(&Cap(0.3));
    /// let a = shaper.step_within(&go, 0.0025, &Cap(0.3)).acceleration.x;
    /// assert!(a <= 0.3 * 1.01, "{a}"); // within one step's advance of the bound
    /// assert!(a >= 0.29, "{a}");
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn bound_pending_acceleration<L: AccelLimit<T>>(&mut self, limit: &L) {
        let tau = self.params.reference_filter_secs;
        let (fx, fy) = self.filtered_m_per_s;
        let (dx, dy) = (self.vx.value() - fx, self.vy.value() - fy);
        // Scaled before squaring (see `crate::num::direction`): no overflow for any finite
        // difference.
        let Some(((ux, uy), norm)) = direction(dx, dy).filter(|_| tau > T::zero()) else {
            return;
        };
        let braking = ux * fx + uy * fy < T::zero();
        let allowed = limit.accel_limit_m_per_s2(ux, uy, braking);
        // NaN or negative: no acceleration.
        let allowed = if allowed >= T::zero() {
            allowed
        } else {
            T::zero()
        };
        if norm <= allowed * tau {
            return;
        }
        let keep = allowed * tau / norm;
        let bound = |limiter: &JerkLimiter<T>, filtered: T, cap: T| {
            let value = filtered + (limiter.value() - filtered) * keep;
            (value, clamp_sym(limiter.rate_per_s(), cap))
        };
        let (x, ax) = bound(&self.vx, fx, allowed * ux.abs());
        let (y, ay) = bound(&self.vy, fy, allowed * uy.abs());
        self.vx.reset(x, ax);
        self.vy.reset(y, ay);
    }
}
