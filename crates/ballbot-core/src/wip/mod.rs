//! The planar wheeled inverted pendulum (WIP): one plane of a ballbot, or the PIPTB.
//!
//! Generalised coordinates `q = [theta, phi]`: body tilt and ball rotation, both absolute
//! angles about the same horizontal axis, positive `phi` rolling the ball towards +travel and
//! positive `theta` leaning the body towards +travel. State `s = [theta, phi, theta_dot,
//! phi_dot]`. Input `tau`: the torque the body applies to the ball (the body feels `-tau`).
//!
//! ```text
//! M(theta) q_ddot + c(q, q_dot) + G(q) + D(q_dot) = [-1, 1]^T tau
//! M = [[a, c(theta)], [c(theta), b]]
//! a = I_U + m_U l^2 + I_W,  b = I_S + (m_S + m_U) r^2 + I_W,  c(theta) = m_U r l cos(theta) - I_W
//! ```
//!
//! Closed form with `Delta = a b - c^2`:
//!
//! ```text
//! g1 = m_U g l sin(theta) - tau + b_m (phi_dot - theta_dot)
//! g2 = m_U r l sin(theta) theta_dot^2 + tau - b_m (phi_dot - theta_dot) - b_k phi_dot
//! theta_ddot = (b g1 - c g2) / Delta,   phi_ddot = (a g2 - c g1) / Delta
//! ```
//!
//! ```
//! use ballbot_core::{Wip, WipParams};
//! use nalgebra::Vector4;
//! let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
//! // Leaning forward with no torque, the body falls forward and the ball rolls back.
//! let q_ddot = wip.accelerations(&Vector4::new(0.1, 0.0, 0.0, 0.0), 0.0);
//! assert!(q_ddot[0] > 0.0 && q_ddot[1] < 0.0);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use crate::check::lit;
use crate::{Error, WipParams};
use nalgebra::{Matrix2, Matrix3, Matrix4, RealField, Vector2, Vector3, Vector4};

/// WIP state `[theta (rad), phi (rad), theta_dot (rad/s), phi_dot (rad/s)]`.
///
/// ```
/// use ballbot_core::WipState;
/// use ballbot_core::wip::{BALL_RATE, TILT};
/// // Leaning 0.05 rad forward while the ball rolls at 10 rad/s.
/// let s: WipState<f64> = WipState::new(0.05, 0.0, 0.0, 10.0);
/// assert_eq!((s[TILT], s[BALL_RATE]), (0.05, 10.0));
/// ```
pub type WipState<T> = Vector4<T>;

/// Reduced WIP state `[theta (rad), theta_dot (rad/s), phi_dot (rad/s)]`: the paper does not
/// feed back the ball angle `phi`, so controllers are designed on this state.
///
/// ```
/// use ballbot_core::WipReducedState;
/// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
/// use ballbot_core::{Wip, WipParams};
/// // The LQR acts on [theta, theta_dot, phi_dot]: the ball angle is not fed back.
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
/// let measured: WipReducedState<f64> = WipReducedState::new(0.0, 0.0, 1.0);
/// // Ball rolling forward at 1 rad/s, reference at rest: k3 = -3.162 asks for 3.162 N m.
/// approx::assert_relative_eq!(
///     lqr.control(&WipReducedState::zeros(), &measured),
///     3.162,
///     epsilon = 1e-3
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub type WipReducedState<T> = Vector3<T>;

/// Index of `theta` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::TILT;
/// assert_eq!(nalgebra::Vector4::new(0.1, 2.0, 0.0, 0.0)[TILT], 0.1);
/// ```
pub const TILT: usize = 0;
/// Index of `phi` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::BALL_ANGLE;
/// assert_eq!(nalgebra::Vector4::new(0.1, 2.0, 0.0, 0.0)[BALL_ANGLE], 2.0);
/// ```
pub const BALL_ANGLE: usize = 1;
/// Index of `theta_dot` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::TILT_RATE;
/// assert_eq!(nalgebra::Vector4::new(0.0, 0.0, 0.3, 9.0)[TILT_RATE], 0.3);
/// ```
pub const TILT_RATE: usize = 2;
/// Index of `phi_dot` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::BALL_RATE;
/// assert_eq!(nalgebra::Vector4::new(0.0, 0.0, 0.3, 9.0)[BALL_RATE], 9.0);
/// ```
pub const BALL_RATE: usize = 3;

/// A validated WIP model with its constant inertia terms precomputed.
///
/// ```
/// use ballbot_core::{Wip, WipParams, rk4_step};
/// use nalgebra::Vector4;
/// // Without control the upright is unstable: a 1 mrad lean grows about e-fold every
/// // 1 / 8.04 s, so it is 20 times larger after 0.37 s.
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut s = Vector4::new(1e-3, 0.0, 0.0, 0.0);
/// for _ in 0..370 {
///     s = rk4_step(|x| wip.derivative(x, 0.0), &s, 1e-3);
/// }
/// approx::assert_relative_eq!(s[0], 1e-3 * (8.04f64 * 0.37).cosh(), max_relative = 0.01);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wip<T> {
    params: WipParams<T>,
    /// `a = I_U + m_U l^2 + I_W`.
    a: T,
    /// `b = I_S + (m_S + m_U) r^2 + I_W`.
    b: T,
    /// `m_U r l`.
    mrl: T,
    /// `m_U g l`.
    mgl: T,
}

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
    /// Validates `params` and precomputes the model's constants.
    ///
    /// ```
    /// use ballbot_core::{Error, Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f32>::miapure_60kg())?;
    /// assert_eq!(wip.params().com_height_m, 0.5);
    /// // Invalid parameters are rejected once, here, naming the field.
    /// let bad = WipParams {
    ///     com_height_m: 0.0,
    ///     ..WipParams::<f32>::miapure_60kg()
    /// };
    /// assert_eq!(
    ///     Wip::new(bad),
    ///     Err(Error::invalid("com_height_m", "must be finite and > 0"))
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: WipParams<T>) -> Result<Self, Error> {
        params.validate()?;
        let p = &params;
        let r = p.ball_radius_m;
        let l = p.com_height_m;
        let a = p.body_inertia_kg_m2 + p.body_mass_kg * l * l + p.wheel_inertia_kg_m2;
        let b = p.ball_inertia_kg_m2
            + (p.ball_mass_kg + p.body_mass_kg) * r * r
            + p.wheel_inertia_kg_m2;
        let mrl = p.body_mass_kg * r * l;
        let mgl = p.body_mass_kg * p.gravity_m_per_s2 * l;
        // M is positive definite at every tilt for any valid parameters: with a0 = I_U + m_U l^2
        // and b0 = I_S + (m_S + m_U) r^2, a0 b0 > (m_U r l)^2 and a0 + b0 > 2 m_U r l, so
        // Delta = a0 b0 - (m_U r l cos)^2 + I_W (a0 + b0 - 2 m_U r l cos) > 0 (tested).
        Ok(Self {
            params,
            a,
            b,
            mrl,
            mgl,
        })
    }

    /// The parameters this model was built from.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// assert_eq!(*wip.params(), WipParams::piptb());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &WipParams<T> {
        &self.params
    }

    /// Off-diagonal inertia `c(theta) = m_U r l cos(theta) - I_W` (kg m^2).
    #[inline]
    fn coupling(&self, tilt_rad: T) -> T {
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
    fn forces(&self, s: &WipState<T>, torque_nm: T) -> (T, T) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rk4_step;
    use approx::assert_relative_eq;

    /// MiaPURE with friction and wheel inertia switched on, so that every term of the
    /// Jacobian is exercised.
    fn lossy_params() -> WipParams<f64> {
        WipParams {
            wheel_inertia_kg_m2: 0.05,
            ball_damping_nm_s_per_rad: 0.7,
            drive_damping_nm_s_per_rad: 0.3,
            ..WipParams::miapure_60kg()
        }
    }

    /// Relative energy error `(final, worst over the run)` of the frictionless, unforced WIP
    /// released from a 20 deg tilt.
    fn energy_drift<T: RealField + Copy>(params: WipParams<T>, steps: usize, dt: T) -> (T, T) {
        let wip = Wip::new(params).unwrap();
        let mut s = Vector4::new(
            lit::<T>(20.0_f64.to_radians()),
            T::zero(),
            T::zero(),
            T::zero(),
        );
        let e0 = wip.energy_j(&s);
        let mut worst = T::zero();
        for _ in 0..steps {
            s = rk4_step(|x| wip.derivative(x, T::zero()), &s, dt);
            worst = worst.max(((wip.energy_j(&s) - e0) / e0).abs());
        }
        (((wip.energy_j(&s) - e0) / e0).abs(), worst)
    }

    #[test]
    fn energy_is_conserved_without_friction_or_torque() {
        // 10 s at 1 kHz from a 20 deg tilt: the body falls through the bottom and swings back
        // (the potential's zero is at the ball centre, so E0 = m_U g l cos 20 deg). Measured:
        // MiaPURE final 9.4e-9, worst 1.7e-8 (at the fastest point of the swing).
        // The PIPTB swings about twice as fast (l = 0.25 m), so it gets a 2 kHz step for the
        // same bound (at 1 kHz its final drift is 3.5e-8).
        for (params, steps, dt) in [
            (WipParams::<f64>::miapure_60kg(), 10_000, 1e-3),
            (WipParams::piptb(), 20_000, 5e-4),
        ] {
            let (last, worst) = energy_drift(params, steps, dt);
            assert!(last < 1e-8, "relative energy drift after 10 s {last:e}");
            assert!(worst < 2e-8, "worst relative energy drift {worst:e}");
        }
        // The error is RK4's: halving the step shrinks it about 2^4 times.
        let (coarse, _) = energy_drift(WipParams::<f64>::miapure_60kg(), 5_000, 2e-3);
        let (fine, _) = energy_drift(WipParams::<f64>::miapure_60kg(), 10_000, 1e-3);
        assert!(coarse / fine > 8.0, "ratio {}", coarse / fine);
    }

    #[test]
    fn energy_is_conserved_in_f32_to_its_precision() {
        let (last, worst) = energy_drift(WipParams::<f32>::miapure_60kg(), 10_000, 1e-3);
        assert!(
            last < 5e-5 && worst < 5e-5,
            "relative energy drift {last:e} {worst:e}"
        );
    }

    #[test]
    fn friction_dissipates_exactly_the_damping_power() {
        // d/dt E = tau (phi_dot - theta_dot) - b_m (phi_dot - theta_dot)^2 - b_k phi_dot^2.
        let wip = Wip::new(lossy_params()).unwrap();
        let s = Vector4::new(0.2, 1.0, -0.7, 3.0);
        let tau = 12.0;
        let sd = wip.derivative(&s, tau);
        let h = 1e-6;
        let de = (wip.energy_j(&(s + sd * h)) - wip.energy_j(&(s - sd * h))) / (2.0 * h);
        let rel = s[BALL_RATE] - s[TILT_RATE];
        let p = wip.params();
        let expected = wip.input_power_w(&s, tau)
            - p.drive_damping_nm_s_per_rad * rel * rel
            - p.ball_damping_nm_s_per_rad * s[BALL_RATE] * s[BALL_RATE];
        assert_relative_eq!(de, expected, max_relative = 1e-6);
    }

    fn check_jacobians(wip: &Wip<f64>, s: &WipState<f64>, tau: f64) {
        let lin = wip.linearize(s, tau);
        let h = 1e-6;
        for j in 0..4 {
            let mut e = Vector4::zeros();
            e[j] = h;
            let fd = (wip.derivative(&(s + e), tau) - wip.derivative(&(s - e), tau)) / (2.0 * h);
            for i in 0..4 {
                assert!(
                    (lin.A[(i, j)] - fd[i]).abs() < 1e-6 * (1.0 + fd[i].abs()),
                    "A[{i},{j}] = {} but finite differences give {}",
                    lin.A[(i, j)],
                    fd[i]
                );
            }
        }
        let fd = (wip.derivative(s, tau + h) - wip.derivative(s, tau - h)) / (2.0 * h);
        for i in 0..4 {
            assert!(
                (lin.B[i] - fd[i]).abs() < 1e-6 * (1.0 + fd[i].abs()),
                "B[{i}]"
            );
        }
    }

    #[test]
    fn analytic_jacobians_match_central_differences() {
        let states = [
            Vector4::zeros(),
            Vector4::new(0.3, 2.0, -1.1, 4.0),
            Vector4::new(-0.8, -5.0, 2.5, -9.0),
            Vector4::new(1.4, 0.0, 0.2, 12.0),
        ];
        for params in [
            WipParams::miapure_60kg(),
            WipParams::piptb(),
            lossy_params(),
        ] {
            let wip = Wip::new(params).unwrap();
            for s in &states {
                for tau in [0.0, 17.0, -40.0] {
                    check_jacobians(&wip, s, tau);
                }
            }
        }
    }

    #[test]
    fn upright_linearisation_matches_model_md() {
        // MODEL.md section 6: A31 = 64.64, A41 = -257.39, B3 = -0.8836, B4 = 4.4545.
        let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
        let m = wip.mass_matrix(0.0);
        assert_relative_eq!(m[(0, 0)], 22.575, max_relative = 1e-4);
        assert_relative_eq!(m[(0, 1)], 4.2537, max_relative = 1e-4);
        assert_relative_eq!(m[(1, 1)], 1.0683, max_relative = 1e-4);
        let lin = wip.linearize_upright();
        assert_relative_eq!(lin.A[(2, 0)], 64.64, max_relative = 1e-3);
        assert_relative_eq!(lin.A[(3, 0)], -257.39, max_relative = 1e-3);
        assert_relative_eq!(lin.B[2], -0.8836, max_relative = 1e-3);
        assert_relative_eq!(lin.B[3], 4.4545, max_relative = 1e-3);
        // Non-minimum phase: a forward ball torque first tips the body back.
        assert!(lin.B[2] < 0.0 && lin.B[3] > 0.0);
    }

    #[test]
    fn open_loop_poles_match_model_md() {
        let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
        assert_relative_eq!(wip.upright_unstable_pole_rad_per_s(), 8.04, epsilon = 5e-3);
        // The eigenvalues of the full linearisation are 0, 0, +-8.04.
        let eig = wip.linearize_upright().A.complex_eigenvalues();
        let mut re: [f64; 4] = core::array::from_fn(|i| eig[i].re);
        re.sort_by(f64::total_cmp);
        assert_relative_eq!(re[0], -8.04, epsilon = 5e-3);
        assert_relative_eq!(re[3], 8.04, epsilon = 5e-3);
        assert!(re[1].abs() < 1e-9 && re[2].abs() < 1e-9);
        assert!(eig.iter().all(|z| z.im.abs() < 1e-9));
        // And in f32.
        let wip32 = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
        assert_relative_eq!(
            wip32.upright_unstable_pole_rad_per_s(),
            8.04,
            epsilon = 5e-3
        );
    }

    #[test]
    fn reduced_linearisation_keeps_tilt_and_rates() {
        let wip = Wip::new(lossy_params()).unwrap();
        let lin = wip.linearize(&Vector4::new(0.1, 0.0, 0.2, 3.0), 5.0);
        let (a, b) = lin.reduced();
        assert_eq!(a[(0, 1)], 1.0);
        assert_eq!(a[(1, 0)], lin.A[(2, 0)]);
        assert_eq!(a[(2, 2)], lin.A[(3, 3)]);
        assert_eq!(b[1], lin.B[2]);
        assert_eq!(b[2], lin.B[3]);
    }

    #[test]
    fn cruise_equilibrium_is_an_equilibrium() {
        let wip = Wip::new(lossy_params()).unwrap();
        let (s, tau) = wip.cruise_equilibrium(10.0).unwrap();
        let sd = wip.derivative(&s, tau);
        assert!(
            sd[TILT_RATE].abs() < 1e-12 && sd[BALL_RATE].abs() < 1e-12,
            "{sd:?}"
        );
        assert!(s[TILT] > 0.0, "ball friction needs a forward lean");
        // Frictionless: upright, zero torque, and the same linearisation as upright.
        let ideal = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
        assert_eq!(ideal.cruise_equilibrium(12.0).unwrap().1, 0.0);
        assert_eq!(
            ideal.linearize_cruise(12.0).unwrap().A,
            ideal.linearize_upright().A
        );
        assert!(wip.cruise_equilibrium(1e9).is_none());
    }

    #[test]
    fn invalid_parameters_name_the_field() {
        let bad = WipParams {
            body_mass_kg: -1.0,
            ..WipParams::<f64>::miapure_60kg()
        };
        assert_eq!(
            Wip::new(bad).unwrap_err(),
            Error::invalid("body_mass_kg", "must be finite and > 0")
        );
        let bad = WipParams {
            com_height_m: f64::NAN,
            ..WipParams::<f64>::miapure_60kg()
        };
        assert!(matches!(
            Wip::new(bad),
            Err(Error::InvalidParameter {
                field: "com_height_m",
                ..
            })
        ));
        let bad = WipParams {
            wheel_inertia_kg_m2: -0.1,
            ..WipParams::<f64>::miapure_60kg()
        };
        assert!(matches!(
            Wip::new(bad),
            Err(Error::InvalidParameter {
                field: "wheel_inertia_kg_m2",
                ..
            })
        ));
        // Any non-negative wheel inertia keeps the mass matrix positive definite at every tilt.
        let heavy = WipParams {
            wheel_inertia_kg_m2: 50.0,
            ..WipParams::<f64>::miapure_60kg()
        };
        let wip = Wip::new(heavy).unwrap();
        for tilt in [0.0, 1.0, core::f64::consts::PI] {
            assert!(wip.mass_matrix(tilt).determinant() > 0.0);
        }
    }
}
