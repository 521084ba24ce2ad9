//! Single-input LQR gain design for the WIP (reduced state) and the spin model.
//!
//! Sign convention (MODEL.md, the paper's form): the controller is
//! `tau = k . (s_c - s)`, `s_c` the reference state. With `s_c = 0` this is the textbook
//! `u = -K s`, so `k` is the Riccati gain `K` itself. For the WIP on
//! `[theta, theta_dot, phi_dot]` all three gains come out negative: a forward lean
//! (`theta > 0`) gives a positive torque, which rolls the ball forward under the body.

use super::riccati::{RiccatiSettings, RiccatiSolution, RiccatiStatus, solve_care, solve_dare};
use crate::check::lit;
use crate::linalg::{eigenvalues, is_finite, zoh};
use crate::rates::OUTER_LOOP_DT_SECS;
use crate::{Error, Spin, Wip};
use nalgebra::allocator::Allocator;
use nalgebra::{
    Complex, Const, DefaultAllocator, DimDiff, DimSub, Matrix1, RealField, SMatrix, SVector, U1,
    Vector4,
};

/// The outer-loop sample time `1 / 400` s, in `T`.
///
/// ```
/// use ballbot_core::lqr::outer_loop_dt_secs;
/// assert_eq!(outer_loop_dt_secs::<f64>(), 0.0025);
/// assert_eq!(outer_loop_dt_secs::<f32>(), 0.0025);
/// ```
pub fn outer_loop_dt_secs<T: RealField + Copy>() -> T {
    lit(OUTER_LOOP_DT_SECS)
}

/// LQR weights for a single-input plant with `N` states: cost
/// `integral (s^T q s + r u^2) dt` (continuous) or `sum (s^T q s + r u^2)` (discrete).
///
/// ```
/// use ballbot_core::lqr::{LqrWeights, wip_lqr};
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// // Cheaper torque (smaller r) buys a faster, more aggressive loop.
/// let soft = wip_lqr(&wip, &LqrWeights::diagonal([100.0, 10.0, 1.0], 1.0))?;
/// let hard = wip_lqr(&wip, &LqrWeights::diagonal([100.0, 10.0, 1.0], 0.01))?;
/// assert!(hard.gain[0].abs() > soft.gain[0].abs());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrWeights<T: RealField + Copy, const N: usize> {
    /// State weight `Q` (symmetric positive semidefinite), in (input unit / state unit)^2
    /// relative to `r`.
    pub q: SMatrix<T, N, N>,
    /// Input weight `R` (> 0).
    pub r: T,
}

/// Weights on the WIP reduced state `[theta, theta_dot, phi_dot]` and the torque.
///
/// ```
/// use ballbot_core::lqr::WipLqrWeights;
/// // Weights on [theta, theta_dot, phi_dot] and the torque.
/// let w = WipLqrWeights::<f64>::model_default();
/// assert_eq!(
///     (w.q[(0, 0)], w.q[(1, 1)], w.q[(2, 2)], w.r),
///     (100.0, 10.0, 1.0, 0.1)
/// );
/// ```
pub type WipLqrWeights<T> = LqrWeights<T, 3>;
/// Weights on the spin state `[theta_z, theta_z_dot]` and the yaw torque.
///
/// ```
/// use ballbot_core::lqr::{SpinLqrWeights, spin_lqr};
/// use ballbot_core::{Spin, SpinParams};
/// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let weights: SpinLqrWeights<f64> = SpinLqrWeights::diagonal([25.0, 1.0], 1.0);
/// // Heading gain sqrt(q_theta / r) = 5.
/// approx::assert_relative_eq!(spin_lqr(&spin, &weights)?.gain[0], 5.0, max_relative = 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub type SpinLqrWeights<T> = LqrWeights<T, 2>;

impl<T: RealField + Copy, const N: usize> LqrWeights<T, N> {
    /// Full state weight `q` and input weight `r` (validated by the design functions).
    ///
    /// ```
    /// use ballbot_core::lqr::{LqrWeights, spin_lqr};
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Matrix2;
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// // A full Q with a cross term; diagonal Q is the special case.
    /// let q = Matrix2::new(4.0, 1.0, 1.0, 2.0);
    /// let full = spin_lqr(&spin, &LqrWeights::new(q, 1.0))?;
    /// let diagonal = spin_lqr(
    ///     &spin,
    ///     &LqrWeights::new(Matrix2::from_diagonal(&q.diagonal()), 1.0),
    /// )?;
    /// assert_ne!(full.gain, diagonal.gain);
    /// assert_eq!(
    ///     LqrWeights::new(Matrix2::from_diagonal(&q.diagonal()), 1.0),
    ///     LqrWeights::diagonal([4.0, 2.0], 1.0)
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(q: SMatrix<T, N, N>, r: T) -> Self {
        Self { q, r }
    }

    /// Diagonal state weight `diag(q_diag)` and input weight `r`.
    ///
    /// ```
    /// use ballbot_core::lqr::LqrWeights;
    /// use nalgebra::Matrix3;
    /// let w = LqrWeights::diagonal([100.0, 10.0, 1.0], 0.1);
    /// assert_eq!(
    ///     w.q,
    ///     Matrix3::from_diagonal(&nalgebra::Vector3::new(100.0, 10.0, 1.0))
    /// );
    /// assert_eq!(w.r, 0.1);
    /// ```
    pub fn diagonal(q_diag: [T; N], r: T) -> Self {
        Self {
            q: SMatrix::from_diagonal(&SVector::from(q_diag)),
            r,
        }
    }

    /// Checks `q` (finite, symmetric, positive semidefinite) and `r` (finite, > 0); the
    /// error names the field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::lqr::LqrWeights;
    /// use nalgebra::Matrix2;
    /// assert_eq!(LqrWeights::diagonal([1.0, 0.0], 1.0).validate(), Ok(()));
    /// // A negative state weight, or a free input, has no meaningful optimum.
    /// assert_eq!(
    ///     LqrWeights::diagonal([1.0, -1.0], 1.0).validate(),
    ///     Err(Error::invalid("q", "must be positive semidefinite"))
    /// );
    /// assert_eq!(
    ///     LqrWeights::diagonal([1.0, 1.0], 0.0).validate(),
    ///     Err(Error::invalid("r", "must be finite and > 0"))
    /// );
    /// assert!(
    ///     LqrWeights::new(Matrix2::new(1.0, 2.0, 0.0, 1.0), 1.0)
    ///         .validate()
    ///         .is_err()
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.r.is_finite() && self.r > T::zero()) {
            return Err(Error::invalid("r", "must be finite and > 0"));
        }
        super::riccati::validate_weights(&self.q, &Matrix1::new(self.r))
    }
}

impl<T: RealField + Copy> LqrWeights<T, 3> {
    /// MODEL.md's design weights for the WIP: `Q = diag(100, 10, 1)` on
    /// `[theta, theta_dot, phi_dot]`, `R = 0.1`. For MiaPURE with 60 kg the continuous
    /// gains are `k = [-234.8, -45.70, -3.162]`.
    ///
    /// ```
    /// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
    /// // MODEL.md section 6: k = [-234.8, -45.70, -3.162]; k3 = -sqrt(q3 / r) exactly.
    /// let [k1, k2, k3] = lqr.reduced_gains();
    /// approx::assert_relative_eq!(k1, -234.8, epsilon = 0.05);
    /// approx::assert_relative_eq!(k2, -45.70, epsilon = 0.005);
    /// approx::assert_relative_eq!(k3, -10f64.sqrt(), epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn model_default() -> Self {
        Self::diagonal([lit(100.0), lit(10.0), lit(1.0)], lit(0.1))
    }
}

/// A single-input LQR design: the gain, the closed loop it gives, and how the Riccati solve
/// went.
///
/// ```
/// use ballbot_core::Error;
/// use ballbot_core::lqr::RiccatiStatus;
/// use ballbot_core::lqr::{Lqr, LqrWeights};
/// use nalgebra::{Matrix2, Vector2};
/// // A double integrator: heading and rate, torque input.
/// let (a, b) = (Matrix2::new(0.0, 1.0, 0.0, 0.0), Vector2::new(0.0, 1.0));
/// let lqr = Lqr::continuous(&a, &b, &LqrWeights::diagonal([1.0, 0.0], 1.0))?;
/// // Known optimum for Q = diag(1, 0), R = 1: k = [1, sqrt(2)], cost-to-go X[0][0] = sqrt(2).
/// approx::assert_relative_eq!(lqr.gain, Vector2::new(1.0, 2f64.sqrt()), epsilon = 1e-9);
/// approx::assert_relative_eq!(lqr.cost_to_go[(0, 0)], 2f64.sqrt(), epsilon = 1e-9);
/// assert_eq!(lqr.dt_secs, None);
/// assert!(lqr.residual < 1e-12);
/// // An unstable mode the input cannot reach has no stabilising gain.
/// let stuck = Lqr::continuous(
///     &Matrix2::new(1.0, 0.0, 0.0, 0.0),
///     &b,
///     &LqrWeights::diagonal([1.0, 1.0], 1.0),
/// );
/// assert_eq!(
///     stuck,
///     Err(Error::NoStabilizingGain {
///         status: RiccatiStatus::NotStabilizable
///     })
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lqr<T: RealField + Copy, const N: usize> {
    /// The gain `k` in `u = k . (s_c - s)` (so `u = -k . s` regulates to zero).
    pub gain: SVector<T, N>,
    /// The closed-loop matrix `A - B k^T`: continuous (`s_dot = ...`), or for a discrete
    /// design the sampled one (`s[n+1] = ...`).
    pub closed_loop: SMatrix<T, N, N>,
    /// The Riccati solution `X` (cost-to-go `s^T X s`).
    pub cost_to_go: SMatrix<T, N, N>,
    /// The sample time of a discrete design (s); `None` for a continuous design.
    pub dt_secs: Option<T>,
    /// Doubling steps the Riccati solve took.
    pub iterations: u32,
    /// The Riccati solve's relative residual.
    pub residual: T,
}

/// LQR on the WIP reduced state `[theta, theta_dot, phi_dot]`.
///
/// ```
/// use ballbot_core::lqr::{WipLqr, WipLqrWeights, wip_lqr};
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr: WipLqr<f64> = wip_lqr(&wip, &WipLqrWeights::model_default())?;
/// // Closed-loop poles -19.5, -4.78, -2.06 rad/s (MODEL.md section 6).
/// let poles = lqr.closed_loop.complex_eigenvalues().map(|p| p.re);
/// let mut poles = [poles[0], poles[1], poles[2]];
/// poles.sort_by(f64::total_cmp);
/// approx::assert_relative_eq!(poles[0], -19.46, epsilon = 0.005);
/// approx::assert_relative_eq!(poles[1], -4.78, epsilon = 0.005);
/// approx::assert_relative_eq!(poles[2], -2.06, epsilon = 0.005);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub type WipLqr<T> = Lqr<T, 3>;
/// LQR on the spin state `[theta_z, theta_z_dot]`.
///
/// ```
/// use ballbot_core::lqr::{SpinLqr, SpinLqrWeights, spin_lqr};
/// use ballbot_core::{Spin, SpinParams};
/// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let lqr: SpinLqr<f64> = spin_lqr(&spin, &SpinLqrWeights::diagonal([100.0, 1.0], 1.0))?;
/// // Both closed-loop poles in the left half plane.
/// assert!(
///     lqr.closed_loop
///         .complex_eigenvalues()
///         .iter()
///         .all(|p| p.re < 0.0)
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub type SpinLqr<T> = Lqr<T, 2>;

impl<T: RealField + Copy, const N: usize> Lqr<T, N> {
    /// Continuous-time LQR for `s_dot = A s + B u` (CARE).
    ///
    /// Errors: invalid weights (naming `q` or `r`), a non-finite plant (`a`, `b`), or
    /// [`Error::NoStabilizingGain`] when the Riccati solve does not converge to a stabilising
    /// solution.
    ///
    /// ```
    /// use ballbot_core::lqr::{Lqr, LqrWeights};
    /// use nalgebra::{Matrix1, Vector1};
    /// // x_dot = x + u, Q = R = 1: the CARE gives k = 1 + sqrt(2), closed loop -sqrt(2).
    /// let lqr = Lqr::continuous(
    ///     &Matrix1::new(1.0),
    ///     &Vector1::new(1.0),
    ///     &LqrWeights::diagonal([1.0], 1.0),
    /// )?;
    /// approx::assert_relative_eq!(lqr.gain[0], 1.0 + 2f64.sqrt(), epsilon = 1e-9);
    /// approx::assert_relative_eq!(lqr.closed_loop[(0, 0)], -2f64.sqrt(), epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[allow(non_snake_case)]
    pub fn continuous(
        A: &SMatrix<T, N, N>,
        B: &SVector<T, N>,
        weights: &LqrWeights<T, N>,
    ) -> Result<Self, Error> {
        weights.validate()?;
        let sol = solve_care(
            A,
            B,
            &weights.q,
            &Matrix1::new(weights.r),
            &RiccatiSettings::default(),
        )?;
        Self::from_solution(A, B, &sol, None)
    }

    /// Discrete-time LQR at `dt_secs` for `s_dot = A s + B u` with the input held
    /// (zero-order hold): DARE on `(Ad, Bd)` with the same `Q`, `R` per sample. Scaling
    /// `Q` and `R` alike leaves the gain unchanged, so as `dt_secs -> 0` the gain tends to
    /// the continuous one (with an `O(dt)` difference).
    ///
    /// Errors: as [`Self::continuous`], plus `dt_secs` not finite and > 0.
    ///
    /// ```
    /// use ballbot_core::lqr::{Lqr, LqrWeights};
    /// use nalgebra::{Matrix1, Vector1};
    /// // x_dot = x + u, Q = R = 1: continuous gain 1 + sqrt(2). Sampled at 1 kHz the discrete
    /// // gain is within O(dt) of it.
    /// let (a, b, w) = (
    ///     Matrix1::new(1.0),
    ///     Vector1::new(1.0),
    ///     LqrWeights::diagonal([1.0], 1.0),
    /// );
    /// let lqr = Lqr::discrete(&a, &b, &w, 1e-3)?;
    /// assert_eq!(lqr.dt_secs, Some(1e-3));
    /// approx::assert_relative_eq!(lqr.gain[0], 1.0 + 2f64.sqrt(), max_relative = 1e-3);
    /// // The sampled closed loop is inside the unit circle.
    /// assert!(lqr.closed_loop[(0, 0)].abs() < 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[allow(non_snake_case)]
    pub fn discrete(
        A: &SMatrix<T, N, N>,
        B: &SVector<T, N>,
        weights: &LqrWeights<T, N>,
        dt_secs: T,
    ) -> Result<Self, Error> {
        weights.validate()?;
        let d = zoh(A, B, dt_secs)?;
        let sol = solve_dare(
            &d.a,
            &d.b,
            &weights.q,
            &Matrix1::new(weights.r),
            &RiccatiSettings::default(),
        )?;
        Self::from_solution(&d.a, &d.b, &sol, Some(dt_secs))
    }

    #[allow(non_snake_case)]
    fn from_solution(
        A: &SMatrix<T, N, N>,
        B: &SVector<T, N>,
        sol: &RiccatiSolution<T, N, 1>,
        dt_secs: Option<T>,
    ) -> Result<Self, Error> {
        if sol.status != RiccatiStatus::Converged {
            return Err(Error::NoStabilizingGain { status: sol.status });
        }
        let gain = sol.gain.transpose();
        let closed_loop = A - B * sol.gain;
        if !(is_finite(&gain) && is_finite(&closed_loop)) {
            return Err(Error::NoStabilizingGain {
                status: RiccatiStatus::NonFinite,
            });
        }
        Ok(Self {
            gain,
            closed_loop,
            cost_to_go: sol.x,
            dt_secs,
            iterations: sol.iterations,
            residual: sol.residual,
        })
    }

    /// The control `u = k . (reference - measured)`.
    ///
    /// ```
    /// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector3;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
    /// // tau = k . (s_c - s): leaning 0.01 rad forward asks for 2.348 N m forward.
    /// let tau_nm = lqr.control(&Vector3::zeros(), &Vector3::new(0.01, 0.0, 0.0));
    /// approx::assert_relative_eq!(tau_nm, 2.348, epsilon = 1e-3);
    /// // Only the error counts: the same offset in reference and measurement gives no torque.
    /// let offset = Vector3::new(0.1, 0.2, 3.0);
    /// approx::assert_abs_diff_eq!(lqr.control(&offset, &offset), 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn control(&self, reference: &SVector<T, N>, measured: &SVector<T, N>) -> T {
        self.gain.dot(&(reference - measured))
    }

    /// Eigenvalues of [`Self::closed_loop`]: poles in rad/s for a continuous design,
    /// z-plane eigenvalues for a discrete one. `None` if the bounded Schur iteration fails.
    ///
    /// ```
    /// use ballbot_core::lqr::{WipLqrWeights, outer_loop_dt_secs, wip_lqr, wip_lqr_discrete};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let weights = WipLqrWeights::model_default();
    /// let continuous = wip_lqr(&wip, &weights)?.closed_loop_eigenvalues();
    /// let discrete =
    ///     wip_lqr_discrete(&wip, &weights, outer_loop_dt_secs())?.closed_loop_eigenvalues();
    /// // Continuous: the slowest pole is -2.06 rad/s. Discrete at 400 Hz: every z inside the
    /// // unit circle, the slowest near exp(-2.06 / 400).
    /// let slowest_secs = continuous.map_or(f64::NAN, |p| {
    ///     p.iter().map(|z| z.re).fold(f64::MIN, f64::max)
    /// });
    /// approx::assert_relative_eq!(slowest_secs, -2.06, epsilon = 0.005);
    /// let largest_z = discrete.map_or(f64::NAN, |p| {
    ///     p.iter().map(|z| z.re.hypot(z.im)).fold(0.0, f64::max)
    /// });
    /// approx::assert_relative_eq!(largest_z, (-2.06f64 / 400.0).exp(), epsilon = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn closed_loop_eigenvalues(&self) -> Option<SVector<Complex<T>, N>>
    where
        Const<N>: DimSub<U1>,
        DefaultAllocator:
            Allocator<Const<N>, DimDiff<Const<N>, U1>> + Allocator<DimDiff<Const<N>, U1>>,
    {
        eigenvalues(&self.closed_loop)
    }
}

impl<T: RealField + Copy> Lqr<T, 3> {
    /// The WIP gains `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]`.
    ///
    /// ```
    /// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let [k1, k2, k3] = wip_lqr(&wip, &WipLqrWeights::model_default())?.reduced_gains();
    /// // All negative: a forward lean (theta > 0) pushes the ball forward (tau > 0).
    /// assert!(k1 < 0.0 && k2 < 0.0 && k3 < 0.0);
    /// approx::assert_relative_eq!(k1, -234.85, epsilon = 0.01);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reduced_gains(&self) -> [T; 3] {
        [self.gain[0], self.gain[1], self.gain[2]]
    }

    /// The paper's 4-vector `k = [k1, 0, k2, k3]` on the full state
    /// `[theta, phi, theta_dot, phi_dot]` (the ball angle is not fed back).
    ///
    /// ```
    /// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
    /// let k = lqr.paper_gains();
    /// // [k1, 0, k2, k3]: the ball angle phi is not fed back, so its gain is 0.
    /// assert_eq!(k[1], 0.0);
    /// let [k1, k2, k3] = lqr.reduced_gains();
    /// assert_eq!(k, Vector4::new(k1, 0.0, k2, k3));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn paper_gains(&self) -> Vector4<T> {
        Vector4::new(self.gain[0], T::zero(), self.gain[1], self.gain[2])
    }
}

/// Continuous LQR for the WIP on the reduced state `[theta, theta_dot, phi_dot]`, designed
/// on the linearisation about upright.
///
/// ```
/// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
/// let [k1, k2, k3] = lqr.reduced_gains();
/// approx::assert_relative_eq!(k1, -234.8, max_relative = 1e-3);
/// approx::assert_relative_eq!(k2, -45.70, max_relative = 1e-3);
/// approx::assert_relative_eq!(k3, -3.162, max_relative = 1e-3);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
pub fn wip_lqr<T: RealField + Copy>(
    wip: &Wip<T>,
    weights: &WipLqrWeights<T>,
) -> Result<WipLqr<T>, Error> {
    let (A, B) = wip.linearize_upright().reduced();
    Lqr::continuous(&A, &B, weights)
}

/// Discrete LQR for the WIP on the reduced state at `dt_secs` (the paper runs it at 400 Hz,
/// [`outer_loop_dt_secs`]), on the zero-order-hold discretisation of the upright
/// linearisation.
///
/// ```
/// use ballbot_core::lqr::{WipLqrWeights, outer_loop_dt_secs, wip_lqr_discrete};
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr = wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), outer_loop_dt_secs())?;
/// let poles = lqr.closed_loop_eigenvalues().unwrap();
/// assert!(poles.iter().all(|z| z.re.hypot(z.im) < 1.0));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
pub fn wip_lqr_discrete<T: RealField + Copy>(
    wip: &Wip<T>,
    weights: &WipLqrWeights<T>,
    dt_secs: T,
) -> Result<WipLqr<T>, Error> {
    let (A, B) = wip.linearize_upright().reduced();
    Lqr::discrete(&A, &B, weights, dt_secs)
}

/// Continuous LQR for the spin model on `[theta_z, theta_z_dot]`.
///
/// ```
/// use ballbot_core::lqr::{SpinLqrWeights, spin_lqr};
/// use ballbot_core::{Spin, SpinParams};
/// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let lqr = spin_lqr(&spin, &SpinLqrWeights::diagonal([100.0, 1.0], 1.0))?;
/// // Heading weight 100, R = 1: the heading gain is sqrt(100 / 1) = 10.
/// approx::assert_relative_eq!(lqr.gain[0], 10.0, max_relative = 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
pub fn spin_lqr<T: RealField + Copy>(
    spin: &Spin<T>,
    weights: &SpinLqrWeights<T>,
) -> Result<SpinLqr<T>, Error> {
    let (A, B) = spin.state_space();
    Lqr::continuous(&A, &B, weights)
}

/// Discrete LQR for the spin model at `dt_secs` (zero-order hold).
///
/// ```
/// use ballbot_core::lqr::{SpinLqrWeights, outer_loop_dt_secs, spin_lqr, spin_lqr_discrete};
/// use ballbot_core::{Spin, SpinParams};
/// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let weights = SpinLqrWeights::diagonal([100.0, 1.0], 1.0);
/// // At 400 Hz the heading gain is 9.96, within 0.4 % of the continuous 10.
/// let discrete = spin_lqr_discrete(&spin, &weights, outer_loop_dt_secs())?;
/// let continuous = spin_lqr(&spin, &weights)?;
/// approx::assert_relative_eq!(discrete.gain[0], 9.964, epsilon = 1e-3);
/// approx::assert_relative_eq!(discrete.gain[0], continuous.gain[0], max_relative = 4e-3);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
pub fn spin_lqr_discrete<T: RealField + Copy>(
    spin: &Spin<T>,
    weights: &SpinLqrWeights<T>,
    dt_secs: T,
) -> Result<SpinLqr<T>, Error> {
    let (A, B) = spin.state_space();
    Lqr::discrete(&A, &B, weights, dt_secs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SpinParams, WipParams};
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    #[test]
    fn diagonal_weights() {
        let w = LqrWeights::<f64, 3>::diagonal([1.0, 2.0, 3.0], 0.5);
        assert_eq!(w.q, Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 3.0)));
        assert_eq!(w.r, 0.5);
        assert!(w.validate().is_ok());
        assert_eq!(LqrWeights::new(w.q, w.r), w);
        assert_eq!(
            WipLqrWeights::<f64>::model_default(),
            LqrWeights::diagonal([100.0, 10.0, 1.0], 0.1)
        );
    }

    #[test]
    fn paper_gains_leave_the_ball_angle_out() {
        let wip = Wip::new(WipParams::<f64>::piptb()).unwrap();
        let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).unwrap();
        let k = lqr.paper_gains();
        assert_eq!(k[1], 0.0);
        assert_eq!([k[0], k[2], k[3]], lqr.reduced_gains());
        // u = k . (s_c - s) on the full state equals the reduced-state control.
        let s = Vector4::new(0.02, 5.0, -0.1, 3.0);
        let reduced = Vector3::new(s[0], s[2], s[3]);
        let full = k.dot(&(-s));
        assert!((lqr.control(&Vector3::zeros(), &reduced) - full).abs() < 1e-12);
    }

    #[test]
    fn discrete_design_records_its_sample_time() {
        let spin = Spin::new(SpinParams::<f64>::miapure_60kg()).unwrap();
        let w = SpinLqrWeights::diagonal([100.0, 10.0], 1.0);
        let d = spin_lqr_discrete(&spin, &w, 0.0025).unwrap();
        assert_eq!(d.dt_secs, Some(0.0025));
        assert!(d.iterations > 0 && d.residual < 1e-12);
        let c = spin_lqr(&spin, &w).unwrap();
        assert_eq!(c.dt_secs, None);
        // Closed form of the CARE for I theta_ddot + D theta_dot = u, Q = diag(q1, q2),
        // R = 1: k1 = sqrt(q1), k2 = -D + sqrt(D^2 + 2 I k1 + q2).
        let p = spin.params();
        let (i, d_z) = (p.inertia_kg_m2, p.damping_nm_s_per_rad);
        let k1 = 10.0;
        let k2 = -d_z + (d_z * d_z + 2.0 * i * k1 + 10.0).sqrt();
        assert!((c.gain - Vector2::new(k1, k2)).norm() < 1e-9, "{}", c.gain);
    }

    #[test]
    fn unstabilisable_design_is_an_error() {
        // An unstable mode the input does not reach.
        let a = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        let b = Vector2::new(0.0, 1.0);
        let w = LqrWeights::diagonal([1.0, 1.0], 1.0);
        assert_eq!(
            Lqr::continuous(&a, &b, &w),
            Err(Error::NoStabilizingGain {
                status: RiccatiStatus::NotStabilizable
            })
        );
        assert_eq!(
            Lqr::discrete(&a, &b, &w, 0.01),
            Err(Error::NoStabilizingGain {
                status: RiccatiStatus::NotStabilizable
            })
        );
    }
}
