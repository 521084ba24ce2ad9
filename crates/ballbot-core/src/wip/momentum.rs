//! The WIP's generalised momentum `p = (a + c(theta)) theta_dot + (c(theta) + b) phi_dot` and
//! its rate, which the input torque does not enter: the basis of wheel-slip detection
//! ([`crate::traction`]).
//!
//! `p` is the sum of the two rows of `M(theta) q_dot`. Adding the two equations of motion
//! cancels the input torque `tau` and the drivetrain friction `b_m` (both act between body
//! and ball), and with `dc/dt = -m_U r l sin(theta) theta_dot`:
//!
//! ```text
//! dp/dt = m_U l sin(theta) (g - r theta_dot phi_dot) - b_k phi_dot
//! ```
//!
//! Gravity (and the ball's floor friction) is the only outside cause. The torque the
//! omniwheels transmit is internal: however hard they drive, `p` changes only as gravity
//! says, as long as the wheels do not slip on the ball. A slipping wheel makes the encoders
//! report a ball rate the ball does not have, and `p` computed from them leaves that law.

use super::{BALL_RATE, TILT_RATE, Wip, WipState};
use nalgebra::RealField;

impl<T: RealField + Copy> Wip<T> {
    /// The generalised momentum `p = (a + c(theta)) theta_dot + (c(theta) + b) phi_dot`
    /// (kg m^2/s), with `c(theta)` from `cos_tilt = cos(theta)`: the sum of the two rows of
    /// `M(theta) q_dot`. Adding the two equations of motion cancels the input torque and the
    /// drivetrain friction (both act between body and ball), so `p` changes only as gravity
    /// and the floor friction say ([`Self::momentum_rate`]) as long as the wheels do not slip:
    /// the basis of slip detection ([`crate::traction::SlipMonitor`]).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // Upright, rolling at 1 rad/s: (c0 + b) = 4.2537 + 1.0683 kg m^2/s.
    /// let s = Vector4::new(0.0, 0.0, 0.0, 1.0);
    /// approx::assert_relative_eq!(wip.momentum(&s, 1.0), 5.3220, epsilon = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn momentum(&self, s: &WipState<T>, cos_tilt: T) -> T {
        let c = self.mrl * cos_tilt - self.params.wheel_inertia_kg_m2;
        (self.a + c) * s[TILT_RATE] + (c + self.b) * s[BALL_RATE]
    }

    /// Its per-unit ball-rate weight `c(theta) + b` (kg m^2): how much `p` changes per rad/s
    /// of ball rate, e.g. the ball-rate error a slipping wheel puts into the measured `p`.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let s = Vector4::new(0.1, 0.0, 0.3, 2.0);
    /// let faster = Vector4::new(0.1, 0.0, 0.3, 2.5);
    /// let cos = 0.1f64.cos();
    /// approx::assert_relative_eq!(
    ///     wip.momentum(&faster, cos) - wip.momentum(&s, cos),
    ///     0.5 * wip.momentum_per_ball_rate(cos),
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn momentum_per_ball_rate(&self, cos_tilt: T) -> T {
        self.mrl * cos_tilt - self.params.wheel_inertia_kg_m2 + self.b
    }

    /// The momentum's rate `dp/dt = m_U l sin(theta) (g - r theta_dot phi_dot) - b_k phi_dot`
    /// (N m), with `sin_tilt = sin(theta)`; independent of the input torque (see
    /// [`Self::momentum`]).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams, rk4_step};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // Whatever the torque, p changes as gravity says: 0.1 s under 30 N m.
    /// let (mut s, dt) = (Vector4::new(0.05, 0.0, 0.2, 3.0), 1e-4);
    /// let p0 = wip.momentum(&s, s[0].cos());
    /// let mut integral = 0.0;
    /// for _ in 0..1000 {
    ///     let next = rk4_step(|x| wip.derivative(x, 30.0), &s, dt);
    ///     let rate = |x: &Vector4<f64>| wip.momentum_rate(x, x[0].sin());
    ///     integral += 0.5 * dt * (rate(&s) + rate(&next));
    ///     s = next;
    /// }
    /// approx::assert_relative_eq!(wip.momentum(&s, s[0].cos()) - p0, integral, max_relative = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn momentum_rate(&self, s: &WipState<T>, sin_tilt: T) -> T {
        let p = &self.params;
        let gravity = self.mgl * sin_tilt;
        let coriolis = self.mrl * sin_tilt * s[TILT_RATE] * s[BALL_RATE];
        gravity - coriolis - p.ball_damping_nm_s_per_rad * s[BALL_RATE]
    }
}

#[cfg(test)]
mod tests {
    use crate::{Wip, WipParams, rk4_step};
    use nalgebra::Vector4;
    use proptest::prelude::*;

    fn rough() -> WipParams<f64> {
        WipParams {
            wheel_inertia_kg_m2: 0.05,
            ball_damping_nm_s_per_rad: 0.3,
            drive_damping_nm_s_per_rad: 0.8,
            ..WipParams::miapure_60kg()
        }
    }

    proptest! {
        /// dp/dt from the formula equals the momentum's change along the true dynamics, for
        /// any state and torque, with wheel inertia and both frictions (checked by mutation:
        /// flipping the sign of the Coriolis or the damping term fails it).
        #[test]
        fn momentum_rate_matches_the_dynamics(
            tilt in -0.5f64..0.5, tilt_rate in -2.0f64..2.0, ball_rate in -30.0f64..30.0,
            torque in -80.0f64..80.0,
        ) {
            let wip = Wip::new(rough()).unwrap();
            let s = Vector4::new(tilt, 0.0, tilt_rate, ball_rate);
            let h = 1e-6;
            let p = |x: &Vector4<f64>| wip.momentum(x, x[0].cos());
            let ahead = rk4_step(|x| wip.derivative(x, torque), &s, h);
            let behind = rk4_step(|x| wip.derivative(x, torque), &s, -h);
            let numeric = (p(&ahead) - p(&behind)) / (2.0 * h);
            let analytic = wip.momentum_rate(&s, tilt.sin());
            prop_assert!((numeric - analytic).abs() <= 1e-5 * (1.0 + analytic.abs()),
                "numeric {numeric} analytic {analytic}");
        }
    }

    /// The input torque changes the accelerations but not dp/dt.
    #[test]
    fn torque_does_not_enter_the_momentum_rate() {
        let wip = Wip::new(rough()).unwrap();
        let s = Vector4::new(0.1, 0.0, 0.4, 5.0);
        let p_dot = |tau: f64| {
            let acc = wip.accelerations(&s, tau);
            let m = wip.mass_matrix(s[0]);
            // d/dt (row sums of M q_dot) = row sums of (M q_ddot + M_dot q_dot).
            let c_dot = -74.3 * 0.1145 * 0.5 * s[0].sin() * s[2];
            (m[(0, 0)] + m[(1, 0)]) * acc[0]
                + (m[(0, 1)] + m[(1, 1)]) * acc[1]
                + c_dot * (s[2] + s[3])
        };
        approx::assert_relative_eq!(p_dot(0.0), p_dot(50.0), epsilon = 1e-9);
        approx::assert_relative_eq!(
            p_dot(0.0),
            wip.momentum_rate(&s, s[0].sin()),
            epsilon = 1e-9
        );
    }
}
