//! The WIP's equations of motion: mass matrix, generalised forces, accelerations and the
//! state derivative (see the [module](super) doc for the closed form).

use nalgebra::{Matrix2, RealField, Vector2, Vector4};

use super::{BALL_RATE, TILT, TILT_RATE, Wip, WipState};

impl<T: RealField + Copy> Wip<T> {
    /// Off-diagonal inertia `c(theta) = m_U r l cos(theta) - I_W` (kg m^2).
    #[inline]
    pub(super) fn coupling(&self, tilt_rad: T) -> T {
        self.mrl * tilt_rad.cos() - self.params.wheel_inertia_kg_m2
    }

    /// The mass matrix `M(theta)` (kg m^2).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // MODEL.md section 6: M0 = [[22.575, 4.2537], [4.2537, 1.0683]].
    /// let m0 = wip.mass_matrix(0.0);
    /// approx::assert_relative_eq!(m0[(0, 0)], 22.575, epsilon = 1e-9);
    /// approx::assert_relative_eq!(m0[(0, 1)], 4.2537, epsilon = 1e-4);
    /// approx::assert_relative_eq!(m0[(1, 1)], 1.0683, epsilon = 1e-4);
    /// // Leaning reduces the coupling by cos(theta); M stays positive definite.
    /// assert!(wip.mass_matrix(1.0)[(0, 1)] < m0[(0, 1)]);
    /// assert!(wip.mass_matrix(1.0).cholesky().is_some());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn mass_matrix(&self, tilt_rad: T) -> Matrix2<T> {
        let c = self.coupling(tilt_rad);
        Matrix2::new(self.a, c, c, self.b)
    }

    /// The generalised forces `[g1, g2]` of the closed form (N m), so that
    /// `M(theta) q_ddot = [g1, g2]`.
    #[inline]
    pub(super) fn forces(&self, s: &WipState<T>, torque_nm: T) -> (T, T) {
        self.forces_with_sin(s, s[TILT].sin(), torque_nm)
    }

    /// [`Self::forces`] with `sin(theta)` already computed.
    #[inline]
    fn forces_with_sin(&self, s: &WipState<T>, sin: T, torque_nm: T) -> (T, T) {
        let p = &self.params;
        let rel = s[BALL_RATE] - s[TILT_RATE];
        let g1 = self.mgl * sin - torque_nm + p.drive_damping_nm_s_per_rad * rel;
        let g2 = self.mrl * sin * s[TILT_RATE] * s[TILT_RATE] + torque_nm
            - p.drive_damping_nm_s_per_rad * rel
            - p.ball_damping_nm_s_per_rad * s[BALL_RATE];
        (g1, g2)
    }

    /// Forward dynamics `q_ddot = f_d(s, tau)`: `[theta_ddot, phi_ddot]` (rad/s^2).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // Upright at rest, a forward ball torque tips the body back and rolls the ball forward:
    /// // [theta_ddot, phi_ddot] = tau [B3, B4].
    /// let q_ddot = wip.accelerations(&Vector4::zeros(), 10.0);
    /// approx::assert_relative_eq!(q_ddot[0], -8.836, epsilon = 1e-3);
    /// approx::assert_relative_eq!(q_ddot[1], 44.545, epsilon = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn accelerations(&self, s: &WipState<T>, torque_nm: T) -> Vector2<T> {
        // One sin_cos serves both the forces and the coupling inertia (hot path: the LQR-PI
        // reference model and every simulator step).
        let (sin, cos) = s[TILT].sin_cos();
        self.accelerations_with_sin_cos(s, sin, cos, torque_nm)
    }

    /// [`Self::accelerations`] with `sin(theta)`, `cos(theta)` of the state's tilt already
    /// computed (the 3D controller needs them for its wheel mapping too).
    #[inline]
    pub(crate) fn accelerations_with_sin_cos(
        &self,
        s: &WipState<T>,
        sin: T,
        cos: T,
        torque_nm: T,
    ) -> Vector2<T> {
        let (g1, g2) = self.forces_with_sin(s, sin, torque_nm);
        let c = self.mrl * cos - self.params.wheel_inertia_kg_m2;
        let delta = self.a * self.b - c * c;
        Vector2::new(
            (self.b * g1 - c * g2) / delta,
            (self.a * g2 - c * g1) / delta,
        )
    }

    /// State derivative `s_dot = [theta_dot, phi_dot, theta_ddot, phi_ddot]`.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams, rk4_step};
    /// use nalgebra::Vector4;
    /// // The frictionless WIP conserves energy: 1 s of a large swing at 1 kHz drifts by < 1e-6 J.
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let mut s = Vector4::new(0.2, 0.0, -0.5, 1.0);
    /// let e0 = wip.energy_j(&s);
    /// for _ in 0..1000 {
    ///     s = rk4_step(|x| wip.derivative(x, 0.0), &s, 1e-3);
    /// }
    /// assert!(s[0] > 0.2);
    /// approx::assert_abs_diff_eq!(wip.energy_j(&s), e0, epsilon = 1e-6);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn derivative(&self, s: &WipState<T>, torque_nm: T) -> WipState<T> {
        let q_ddot = self.accelerations(s, torque_nm);
        Vector4::new(s[TILT_RATE], s[BALL_RATE], q_ddot[0], q_ddot[1])
    }
}
