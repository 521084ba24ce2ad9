//! The WIP's mechanical energy and the power its input torque delivers (for conservation
//! checks).

use crate::check::lit;
use nalgebra::{RealField, Vector2};

use super::{BALL_RATE, TILT, TILT_RATE, Wip, WipState};

impl<T: RealField + Copy> Wip<T> {
    /// Total mechanical energy `1/2 q_dot^T M q_dot + m_U g l cos(theta)` (J), zero potential
    /// at the ball centre's height.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // Upright at rest: only the potential m_U g l = 74.3 * 9.81 * 0.5 J.
    /// approx::assert_relative_eq!(wip.energy_j(&Vector4::zeros()), 364.4415, epsilon = 1e-9);
    /// // Rolling at 1 rad/s adds b / 2 = 0.534 J of kinetic energy.
    /// let rolling = wip.energy_j(&Vector4::new(0.0, 0.0, 0.0, 1.0));
    /// approx::assert_relative_eq!(rolling - 364.4415, 1.0683 / 2.0, epsilon = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn energy_j(&self, s: &WipState<T>) -> T {
        let q_dot = Vector2::new(s[TILT_RATE], s[BALL_RATE]);
        let kinetic = (q_dot.transpose() * self.mass_matrix(s[TILT]) * q_dot)[0] * lit(0.5);
        kinetic + self.mgl * s[TILT].cos()
    }

    /// Power flowing into the mechanism from the input torque (W): `tau (phi_dot - theta_dot)`.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams, rk4_step};
    /// use nalgebra::Vector4;
    /// // Energy balance: with no friction, the input power integrates to the energy change.
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let (mut s, tau, dt) = (Vector4::new(0.05, 0.0, 0.0, 2.0), 5.0, 1e-4);
    /// let (e0, mut work_j) = (wip.energy_j(&s), 0.0);
    /// for _ in 0..1000 {
    ///     let next = rk4_step(|x| wip.derivative(x, tau), &s, dt);
    ///     // Trapezoidal rule on the power.
    ///     work_j += 0.5 * dt * (wip.input_power_w(&s, tau) + wip.input_power_w(&next, tau));
    ///     s = next;
    /// }
    /// approx::assert_relative_eq!(wip.energy_j(&s) - e0, work_j, max_relative = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn input_power_w(&self, s: &WipState<T>, torque_nm: T) -> T {
        torque_nm * (s[BALL_RATE] - s[TILT_RATE])
    }
}
