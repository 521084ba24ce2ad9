//! Linearisations of the WIP: the analytic Jacobian about any state, upright, and about a
//! cruise equilibrium.

use crate::check::lit;
use nalgebra::{Matrix3, Matrix4, RealField, Vector3, Vector4};

use super::{BALL_RATE, TILT, TILT_RATE, Wip, WipState};

/// Linearisation `s_dot ~ A (s - s0) + B (tau - tau0)` about a point.
///
/// ```
/// use ballbot_core::{Wip, WipParams};
/// let lin = Wip::new(WipParams::<f64>::miapure_60kg())?.linearize_upright();
/// // MODEL.md section 6: A31 = 64.64, A41 = -257.39, B3 = -0.8836, B4 = 4.4545.
/// approx::assert_relative_eq!(lin.A[(2, 0)], 64.64, epsilon = 0.005);
/// approx::assert_relative_eq!(lin.A[(3, 0)], -257.39, epsilon = 0.005);
/// approx::assert_relative_eq!(lin.B[2], -0.8836, epsilon = 5e-5);
/// approx::assert_relative_eq!(lin.B[3], 4.4545, epsilon = 5e-5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WipLinearization<T> {
    /// State Jacobian `A = d f / d s` (4 x 4).
    pub A: Matrix4<T>,
    /// Input Jacobian `B = d f / d tau` (4).
    pub B: Vector4<T>,
}

impl<T: RealField + Copy> WipLinearization<T> {
    /// The same linearisation on the reduced state `[theta, theta_dot, phi_dot]` (drops
    /// `phi`, which no right-hand side depends on).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let lin = Wip::new(WipParams::<f64>::miapure_60kg())?.linearize_upright();
    /// let (a, b) = lin.reduced();
    /// // theta_ddot = A31 theta + B3 tau sits in row 1 of the reduced system.
    /// assert_eq!((a[(1, 0)], b[1]), (lin.A[(2, 0)], lin.B[2]));
    /// // The reduced system keeps the unstable pair +-8.04 rad/s and drops one zero pole.
    /// approx::assert_relative_eq!(a.determinant(), 0.0, epsilon = 1e-9);
    /// approx::assert_relative_eq!(a[(1, 0)].sqrt(), 8.04, epsilon = 0.005);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[allow(non_snake_case)]
    pub fn reduced(&self) -> (Matrix3<T>, Vector3<T>) {
        const KEEP: [usize; 3] = [TILT, TILT_RATE, BALL_RATE];
        let A = Matrix3::from_fn(|i, j| self.A[(KEEP[i], KEEP[j])]);
        let B = Vector3::from_fn(|i, _| self.B[KEEP[i]]);
        (A, B)
    }
}

impl<T: RealField + Copy> Wip<T> {
    /// Analytic Jacobians of [`Self::derivative`] at any state and torque.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// // The analytic Jacobian against a central difference, away from upright.
    /// let (s, tau, h) = (Vector4::new(0.3, 0.0, -0.4, 2.0), 12.0, 1e-6);
    /// let lin = wip.linearize(&s, tau);
    /// for j in 0..4 {
    ///     let e = Vector4::ith(j, h);
    ///     let diff = wip.derivative(&(s + e), tau) - wip.derivative(&(s - e), tau);
    ///     let column = diff / (2.0 * h);
    ///     approx::assert_relative_eq!(lin.A.column(j).into_owned(), column, epsilon = 1e-5);
    /// }
    /// let column_b = (wip.derivative(&s, tau + h) - wip.derivative(&s, tau - h)) / (2.0 * h);
    /// approx::assert_relative_eq!(lin.B, column_b, epsilon = 1e-6);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[allow(non_snake_case)]
    pub fn linearize(&self, s: &WipState<T>, torque_nm: T) -> WipLinearization<T> {
        let p = &self.params;
        let (sin, cos) = s[TILT].sin_cos();
        let bm = p.drive_damping_nm_s_per_rad;
        let bk = p.ball_damping_nm_s_per_rad;
        let (g1, g2) = self.forces(s, torque_nm);
        let c = self.coupling(s[TILT]);
        let dc = -self.mrl * sin;
        let delta = self.a * self.b - c * c;
        let d_delta = lit::<T>(-2.0) * c * dc;
        let n1 = self.b * g1 - c * g2;
        let n2 = self.a * g2 - c * g1;
        // d/dtheta of the generalised forces.
        let dg1_dth = self.mgl * cos;
        let dg2_dth = self.mrl * cos * s[TILT_RATE] * s[TILT_RATE];
        let dn1_dth = self.b * dg1_dth - dc * g2 - c * dg2_dth;
        let dn2_dth = self.a * dg2_dth - dc * g1 - c * dg1_dth;
        let delta2 = delta * delta;
        let dth_dth = (dn1_dth * delta - n1 * d_delta) / delta2;
        let dph_dth = (dn2_dth * delta - n2 * d_delta) / delta2;
        // Other variables leave c and Delta unchanged.
        let per = |dg1: T, dg2: T| {
            (
                (self.b * dg1 - c * dg2) / delta,
                (self.a * dg2 - c * dg1) / delta,
            )
        };
        let (dth_dthd, dph_dthd) = per(-bm, lit::<T>(2.0) * self.mrl * sin * s[TILT_RATE] + bm);
        let (dth_dphd, dph_dphd) = per(bm, -bm - bk);
        let (dth_dtau, dph_dtau) = per(-T::one(), T::one());
        let z = T::zero();
        let o = T::one();
        let A = Matrix4::new(
            z, z, o, z, //
            z, z, z, o, //
            dth_dth, z, dth_dthd, dth_dphd, //
            dph_dth, z, dph_dthd, dph_dphd,
        );
        let B = Vector4::new(z, z, dth_dtau, dph_dtau);
        WipLinearization { A, B }
    }

    /// Linearisation about upright at rest with zero torque.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lin = wip.linearize_upright();
    /// // Open-loop poles 0, 0, +-8.04 rad/s: the characteristic polynomial is s^2 (s^2 - A31).
    /// let poles = lin.A.complex_eigenvalues();
    /// let fastest = poles.iter().map(|p| p.re).fold(f64::MIN, f64::max);
    /// approx::assert_relative_eq!(fastest, 8.04, epsilon = 0.005);
    /// approx::assert_relative_eq!(
    ///     fastest,
    ///     wip.upright_unstable_pole_rad_per_s(),
    ///     epsilon = 1e-9
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn linearize_upright(&self) -> WipLinearization<T> {
        self.linearize(&WipState::zeros(), T::zero())
    }

    /// The steady cruise at ball rate `ball_rate_rad_per_s`: the tilt and torque that hold it
    /// (`theta_dot = 0`, no acceleration) as `(state, torque_nm)`. Without ball-floor friction
    /// the body cruises upright with zero torque. `None` when friction would need the body to
    /// lean beyond 90 deg.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// // Frictionless: cruising at 10 rad/s needs neither lean nor torque.
    /// let ideal = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let (s, tau) = ideal.cruise_equilibrium(10.0).unwrap_or_default();
    /// assert_eq!((s[0], s[3], tau), (0.0, 10.0, 0.0));
    /// // With 2 N m s/rad of ball-floor friction the body leans into it and the motor pushes
    /// // 20 N m: sin(theta) = b_k phi_dot / (m_U g l) = 20 / 364.4.
    /// let params = WipParams {
    ///     ball_damping_nm_s_per_rad: 2.0,
    ///     ..WipParams::<f64>::miapure_60kg()
    /// };
    /// let (s, tau) = Wip::new(params)?
    ///     .cruise_equilibrium(10.0)
    ///     .unwrap_or_default();
    /// approx::assert_relative_eq!(s[0].sin(), 20.0 / 364.4415, epsilon = 1e-12);
    /// assert_eq!(tau, 20.0);
    /// // No lean holds 400 rad/s against that friction.
    /// assert!(Wip::new(params)?.cruise_equilibrium(400.0).is_none());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn cruise_equilibrium(&self, ball_rate_rad_per_s: T) -> Option<(WipState<T>, T)> {
        let p = &self.params;
        let torque =
            (p.drive_damping_nm_s_per_rad + p.ball_damping_nm_s_per_rad) * ball_rate_rad_per_s;
        let sin = p.ball_damping_nm_s_per_rad * ball_rate_rad_per_s / self.mgl;
        // `is_finite` also rejects NaN, which no comparison would.
        if !sin.is_finite() || sin.abs() >= T::one() {
            return None;
        }
        let s = Vector4::new(sin.asin(), T::zero(), T::zero(), ball_rate_rad_per_s);
        Some((s, torque))
    }

    /// Linearisation about the steady cruise at `ball_rate_rad_per_s` (see
    /// [`Self::cruise_equilibrium`]).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// // Frictionless, cruising is the same as standing still: the linearisation is upright's.
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// assert_eq!(wip.linearize_cruise(10.0), Some(wip.linearize_upright()));
    /// // With ball-floor friction, the forward lean changes the linearisation.
    /// let params = WipParams {
    ///     ball_damping_nm_s_per_rad: 2.0,
    ///     ..WipParams::<f64>::miapure_60kg()
    /// };
    /// let rough = Wip::new(params)?;
    /// assert_ne!(
    ///     rough.linearize_cruise(10.0),
    ///     Some(rough.linearize_upright())
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn linearize_cruise(&self, ball_rate_rad_per_s: T) -> Option<WipLinearization<T>> {
        let (s, torque) = self.cruise_equilibrium(ball_rate_rad_per_s)?;
        Some(self.linearize(&s, torque))
    }

    /// Growth rate of the unstable upright mode of the frictionless model,
    /// `sqrt(m_U g l b / Delta0)` (rad/s): the open-loop poles are `0, 0, +-` this.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// // MODEL.md section 6: +-8.04 rad/s for MiaPURE with 60 kg; the unloaded chassis falls
    /// // slower (6.89 rad/s), the smaller PIPTB faster (10.50 rad/s).
    /// let pole = |p| Wip::new(p).map(|w| w.upright_unstable_pole_rad_per_s());
    /// approx::assert_relative_eq!(
    ///     pole(WipParams::<f64>::miapure_60kg())?,
    ///     8.04,
    ///     epsilon = 0.005
    /// );
    /// approx::assert_relative_eq!(pole(WipParams::miapure_unloaded())?, 6.89, epsilon = 0.005);
    /// approx::assert_relative_eq!(pole(WipParams::piptb())?, 10.50, epsilon = 0.005);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn upright_unstable_pole_rad_per_s(&self) -> T {
        let c0 = self.coupling(T::zero());
        (self.mgl * self.b / (self.a * self.b - c0 * c0)).sqrt()
    }
}
