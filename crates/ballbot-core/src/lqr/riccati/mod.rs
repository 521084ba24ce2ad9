//! Discrete and continuous algebraic Riccati equations by the structure-preserving doubling
//! algorithm (SDA).
//!
//! Symbols (this module allows `non_snake_case` for them): `A` (N x N) and `B` (N x M) the
//! plant, `Q` (N x N, symmetric positive semidefinite) and `R` (M x M, symmetric positive
//! definite) the weights, `X` the stabilising solution, `K` the optimal gain, `u = -K x`.
//!
//! # DARE
//!
//! `X = A^T X A - A^T X B (R + B^T X B)^-1 B^T X A + Q`, `K = (R + B^T X B)^-1 B^T X A`.
//! With `G = B R^-1 B^T` this is `X = Q + A^T X (I + G X)^-1 A`. The SDA (Chu, Fan, Lin,
//! Wang 2004) starts from `A_0 = A`, `G_0 = G`, `H_0 = Q` and iterates
//!
//! ```text
//! W_k     = I + G_k H_k
//! A_{k+1} = A_k W_k^-1 A_k
//! G_{k+1} = G_k + A_k W_k^-1 G_k A_k^T
//! H_{k+1} = H_k + A_k^T H_k W_k^-1 A_k
//! ```
//!
//! `H_k` increases monotonically to `X`; each step doubles the horizon, so the error falls
//! like `rho^(2^(k+1))`, `rho` the closed-loop spectral radius: quadratic convergence with one
//! `N x N` inverse per step and no `(N + M)` or `2N` sized matrix. `W_k` is never singular
//! (`G_k H_k` is similar to a positive semidefinite matrix). The increment
//! `A_k^T H_k W_k^-1 A_k` is computed directly, not as a difference, so the stopping test
//! has no round-off floor.
//!
//! # CARE
//!
//! `A^T X + X A - X B R^-1 B^T X + Q = 0`, `K = R^-1 B^T X`. Solved by SDA-1 (Chu, Fan, Lin
//! 2005): a Cayley transform with shift `g > 0` maps the Hamiltonian's stable eigenvalues
//! `lambda` to `(lambda + g) / (lambda - g)` inside the unit disc, giving a DARE-form start
//!
//! ```text
//! A_g = A - g I,  W_g = A_g^T + Q A_g^-1 G,  V_g = A_g + G A_g^-T Q
//! A_0 = I + 2 g V_g^-1,  G_0 = 2 g A_g^-1 G W_g^-1,  H_0 = 2 g W_g^-1 Q A_g^-1
//! ```
//!
//! for the same doubling iteration, whose `H_k` converges to the CARE's stabilising `X`.
//! The shift is `g = max(||A||_F, sqrt(||G||_F ||Q||_F))` (enlarged by 3/2 if `A_g` is
//! singular).
//!
//! # Outcome
//!
//! Malformed input (non-finite entries, `Q` not symmetric positive semidefinite, `R` not
//! symmetric positive definite) is an [`Error`] naming the argument. The numerical outcome is
//! a [`RiccatiStatus`] in the [`RiccatiSolution`]: the closed loop `A - B K` is certified
//! stable before `Converged` is reported, by the Lyapunov theorem when it applies (`X > 0`
//! and `X - A_cl^T X A_cl > 0`, resp. `-(A_cl^T X + X A_cl) > 0`, both with a round-off
//! margin; the Riccati equation makes the latter `Q + K^T R K`), otherwise by
//! [`is_schur_stable`] or [`is_hurwitz`]. No stabilising
//! solution (an unstable mode that `B` cannot move, or that `Q` does not weight) gives
//! `NotStabilizable`, detected either by the doubling diverging or by the closed-loop check.
#![allow(non_snake_case)]

use crate::Error;
use crate::check::lit;
use crate::linalg::{
    entry_norm, is_finite, is_hurwitz, is_schur_stable, mul, mul_nt, mul_sym, mul_tn_sym, norm1,
    symmetrize,
};
use core::fmt;
use nalgebra::{Cholesky, RealField, SMatrix};

/// The numerical outcome of a Riccati solve.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, RiccatiStatus, solve_care};
/// use nalgebra::{Matrix1, Matrix2, Vector2};
/// let (q, r, settings) = (
///     Matrix2::identity(),
///     Matrix1::new(1.0),
///     RiccatiSettings::default(),
/// );
/// // A double integrator is stabilisable ...
/// let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
/// assert_eq!(
///     solve_care(&a, &Vector2::new(0.0, 1.0), &q, &r, &settings)?.status,
///     RiccatiStatus::Converged
/// );
/// // ... a second, unstable mode that the input cannot reach is not: a status, not an Err.
/// let a = Matrix2::new(0.0, 0.0, 0.0, 1.0);
/// let sol = solve_care(&a, &Vector2::new(1.0, 0.0), &q, &r, &settings)?;
/// assert_eq!(sol.status, RiccatiStatus::NotStabilizable);
/// assert_eq!(
///     sol.status.to_string(),
///     "no stabilising solution (unstabilisable or undetectable)"
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RiccatiStatus {
    /// Converged to the tolerance, and the closed loop `A - B K` is certified asymptotically
    /// stable.
    Converged,
    /// Stopped at the iteration limit before the tolerance; the closed loop of the last
    /// iterate is stable, but the solution is not accurate to the tolerance.
    MaxIterations,
    /// No stabilising solution: an unstable (or, for the DARE, unit-circle; for the CARE,
    /// imaginary-axis) mode is not stabilisable through `B`, or is not weighted by `Q`
    /// (not detectable). The doubling diverged or the closed loop is not stable.
    NotStabilizable,
    /// A non-finite number appeared (overflow in the setup or the gain).
    NonFinite,
}

impl RiccatiStatus {
    /// `true` for [`RiccatiStatus::Converged`].
    ///
    /// ```
    /// use ballbot_core::lqr::RiccatiStatus;
    /// assert!(RiccatiStatus::Converged.is_converged());
    /// assert!(!RiccatiStatus::MaxIterations.is_converged());
    /// ```
    pub fn is_converged(self) -> bool {
        self == Self::Converged
    }
}

impl fmt::Display for RiccatiStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Converged => "converged",
            Self::MaxIterations => "iteration limit reached",
            Self::NotStabilizable => "no stabilising solution (unstabilisable or undetectable)",
            Self::NonFinite => "non-finite numbers",
        })
    }
}

/// Stopping rules of the Riccati solvers.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, RiccatiStatus, solve_dare};
/// use nalgebra::{Matrix1, Matrix2, Vector2};
/// assert_eq!(RiccatiSettings::<f64>::default().max_iterations, 64);
/// // The doubling converges quadratically: a sampled double integrator needs a handful of
/// // steps, and one step alone stops short of the tolerance.
/// let (a, b) = (Matrix2::new(1.0, 0.1, 0.0, 1.0), Vector2::new(0.005, 0.1));
/// let (q, r) = (Matrix2::identity(), Matrix1::new(1.0));
/// let full = solve_dare(&a, &b, &q, &r, &RiccatiSettings::default())?;
/// assert!(full.is_converged() && full.iterations < 12);
/// let one_step = RiccatiSettings {
///     max_iterations: 1,
///     ..RiccatiSettings::default()
/// };
/// assert_ne!(
///     solve_dare(&a, &b, &q, &r, &one_step)?.status,
///     RiccatiStatus::Converged
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RiccatiSettings<T> {
    /// Stop when the 1-norm of the last increment of `X` is at most this times `||X||_1`
    /// (dimensionless) and `||A_k||_1 <= 1`. Default `sqrt(eps)` (`1.5e-8` in `f64`,
    /// `3.5e-4` in `f32`): the convergence is quadratic, the next increment is about the
    /// square of this one, so the error left is at round-off level.
    pub tolerance: T,
    /// Iteration limit. Default 64: each doubling step doubles the horizon, so 64 steps
    /// cover `2^64` samples.
    pub max_iterations: u32,
}

impl<T: RealField + Copy> Default for RiccatiSettings<T> {
    fn default() -> Self {
        Self {
            tolerance: T::default_epsilon().sqrt(),
            max_iterations: 64,
        }
    }
}

impl<T: RealField + Copy> RiccatiSettings<T> {
    /// Checks the settings; the error names the field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::lqr::RiccatiSettings;
    /// assert_eq!(RiccatiSettings::<f32>::default().validate(), Ok(()));
    /// let never = RiccatiSettings {
    ///     max_iterations: 0,
    ///     ..RiccatiSettings::<f64>::default()
    /// };
    /// assert_eq!(
    ///     never.validate(),
    ///     Err(Error::invalid("max_iterations", "must be > 0"))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.tolerance.is_finite() && self.tolerance > T::zero()) {
            return Err(Error::invalid("tolerance", "must be finite and > 0"));
        }
        if self.max_iterations == 0 {
            return Err(Error::invalid("max_iterations", "must be > 0"));
        }
        Ok(())
    }
}

/// The result of a Riccati solve: the solution, the optimal gain and how the solve went.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, solve_dare};
/// use nalgebra::{Matrix1, Vector1};
/// // Scalar DARE x = a^2 x - (a b x)^2 / (r + b^2 x) + q with a = 2, b = q = r = 1:
/// // x^2 - 4 x - 1 = 0, so x = 2 + sqrt(5), gain k = 2 x / (1 + x).
/// let sol = solve_dare(
///     &Matrix1::new(2.0),
///     &Vector1::new(1.0),
///     &Matrix1::new(1.0),
///     &Matrix1::new(1.0),
///     &RiccatiSettings::default(),
/// )?;
/// assert!(sol.is_converged());
/// let x = 2.0 + 5f64.sqrt();
/// approx::assert_relative_eq!(sol.x[(0, 0)], x, epsilon = 1e-10);
/// approx::assert_relative_eq!(sol.gain[(0, 0)], 2.0 * x / (1.0 + x), epsilon = 1e-10);
/// // The closed loop 2 - k is stable.
/// assert!((2.0 - sol.gain[(0, 0)]).abs() < 1.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[must_use = "check `status` before using the gain"]
pub struct RiccatiSolution<T: RealField + Copy, const N: usize, const M: usize> {
    /// The solution `X` (symmetric): `x^T X x` is the optimal cost-to-go.
    pub x: SMatrix<T, N, N>,
    /// The optimal gain `K` for `u = -K x`.
    pub gain: SMatrix<T, M, N>,
    /// How the solve ended; use `x` and `gain` only when it is `Converged`.
    pub status: RiccatiStatus,
    /// Doubling steps taken.
    pub iterations: u32,
    /// Relative residual: the 1-norm of the Riccati equation's residual at `x` over
    /// `max(||X||_1, ||Q||_1)`.
    pub residual: T,
}

impl<T: RealField + Copy, const N: usize, const M: usize> RiccatiSolution<T, N, M> {
    /// `true` when the status is [`RiccatiStatus::Converged`].
    ///
    /// ```
    /// use ballbot_core::lqr::{RiccatiSettings, solve_care};
    /// use nalgebra::{Matrix1, Vector1};
    /// // x_dot = x + u: one CARE solve, converged, gain 1 + sqrt(2).
    /// let sol = solve_care(
    ///     &Matrix1::new(1.0),
    ///     &Vector1::new(1.0),
    ///     &Matrix1::new(1.0),
    ///     &Matrix1::new(1.0),
    ///     &RiccatiSettings::default(),
    /// )?;
    /// assert!(sol.is_converged());
    /// approx::assert_relative_eq!(sol.gain[(0, 0)], 1.0 + 2f64.sqrt(), epsilon = 1e-10);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn is_converged(&self) -> bool {
        self.status.is_converged()
    }

    fn failed(status: RiccatiStatus, iterations: u32) -> Self {
        Self {
            x: SMatrix::zeros(),
            gain: SMatrix::zeros(),
            status,
            iterations,
            residual: T::max_value().unwrap_or(T::one()),
        }
    }
}

/// Checks that `q` is finite, symmetric and positive semidefinite (to round-off), and that
/// `r` is symmetric positive definite. Errors name `q` or `r`.
///
/// ```
/// use ballbot_core::Error;
/// use ballbot_core::lqr::validate_weights;
/// use nalgebra::{Matrix1, Matrix2};
/// let r = Matrix1::new(0.1);
/// assert_eq!(
///     validate_weights(&Matrix2::new(1.0, 0.5, 0.5, 1.0), &r),
///     Ok(())
/// );
/// // Positive diagonal but indefinite (eigenvalues 3 and -1).
/// assert_eq!(
///     validate_weights(&Matrix2::new(1.0, 2.0, 2.0, 1.0), &r),
///     Err(Error::invalid("q", "must be positive semidefinite"))
/// );
/// assert_eq!(
///     validate_weights(&Matrix2::identity(), &Matrix1::new(0.0)),
///     Err(Error::invalid("r", "must be positive definite"))
/// );
/// ```
pub fn validate_weights<T: RealField + Copy, const N: usize, const M: usize>(
    q: &SMatrix<T, N, N>,
    r: &SMatrix<T, M, M>,
) -> Result<(), Error> {
    check_symmetric(q, "q")?;
    let scale = norm1(q);
    if scale > T::zero() {
        // Positive semidefinite up to a round-off shift.
        let shift = scale * T::default_epsilon() * lit(1000.0);
        let shifted = q + SMatrix::<T, N, N>::identity() * shift;
        if Cholesky::new(symmetrize(&shifted)).is_none() {
            return Err(Error::invalid("q", "must be positive semidefinite"));
        }
    }
    check_symmetric(r, "r")?;
    if Cholesky::new(symmetrize(r)).is_none() {
        return Err(Error::invalid("r", "must be positive definite"));
    }
    Ok(())
}

fn check_symmetric<T: RealField + Copy, const N: usize>(
    m: &SMatrix<T, N, N>,
    field: &'static str,
) -> Result<(), Error> {
    if !is_finite(m) {
        return Err(Error::invalid(field, "must be finite"));
    }
    let tol = norm1(m) * T::default_epsilon() * lit(100.0);
    for i in 0..N {
        for j in 0..i {
            if (m[(i, j)] - m[(j, i)]).abs() > tol {
                return Err(Error::invalid(field, "must be symmetric"));
            }
        }
    }
    Ok(())
}

/// Validates everything and returns `(Q, R, G = B R^-1 B^T)`, symmetrised.
#[allow(clippy::type_complexity)]
fn prepare<T: RealField + Copy, const N: usize, const M: usize>(
    A: &SMatrix<T, N, N>,
    B: &SMatrix<T, N, M>,
    Q: &SMatrix<T, N, N>,
    R: &SMatrix<T, M, M>,
    settings: &RiccatiSettings<T>,
) -> Result<
    (
        SMatrix<T, N, N>,
        Cholesky<T, nalgebra::Const<M>>,
        SMatrix<T, N, N>,
    ),
    Error,
> {
    settings.validate()?;
    if !is_finite(A) {
        return Err(Error::invalid("a", "must be finite"));
    }
    if !is_finite(B) {
        return Err(Error::invalid("b", "must be finite"));
    }
    validate_weights(Q, R)?;
    let r_chol =
        Cholesky::new(symmetrize(R)).ok_or(Error::invalid("r", "must be positive definite"))?;
    let G = symmetrize(&(B * r_chol.solve(&B.transpose())));
    Ok((symmetrize(Q), r_chol, G))
}

/// How the doubling loop ended.
enum Doubling<T: RealField + Copy, const N: usize> {
    /// `H` after convergence or the iteration limit (`true` if converged).
    Done(SMatrix<T, N, N>, u32, bool),
    /// The iterates grew without bound or became non-finite.
    Diverged(u32),
}

/// The SDA iteration from `(A_0, G_0, H_0)` (see the module doc).
fn doubling<T: RealField + Copy, const N: usize>(
    mut a: SMatrix<T, N, N>,
    mut g: SMatrix<T, N, N>,
    mut h: SMatrix<T, N, N>,
    settings: &RiccatiSettings<T>,
) -> Doubling<T, N> {
    let identity = SMatrix::<T, N, N>::identity();
    // A_k ~ (closed loop)^(2^k) -> 0; growth beyond this means no stable closed loop.
    let blow_up = entry_norm(&a).max(T::one()) / T::default_epsilon();
    for k in 1..=settings.max_iterations {
        let Some(w_inv) = (identity + mul(&g, &h)).try_inverse() else {
            return Doubling::Diverged(k);
        };
        // A W^-1; H W^-1 = (I + H G)^-1 H and W^-1 G are symmetric, so the increments of H
        // and G are symmetric products (upper triangles only).
        let aw = mul(&a, &w_inv);
        let hwa = mul(&mul_sym(&h, &w_inv), &a);
        let dh = mul_tn_sym(&a, &hwa);
        let dg = mul_sym(&aw, &mul_nt(&g, &a));
        a = mul(&aw, &a);
        g += dg;
        h += dh;
        let growth = entry_norm(&a);
        let step = entry_norm(&dh);
        let size = entry_norm(&h);
        let finite = growth.is_finite()
            && step.is_finite()
            && size.is_finite()
            && entry_norm(&g).is_finite();
        if !finite || growth > blow_up {
            return Doubling::Diverged(k);
        }
        // Next increment ~ ||A_{k+1}||^2 ||H||: small once A_{k+1} has shrunk below 1.
        if step <= settings.tolerance * size && growth <= T::one() {
            return Doubling::Done(h, k, true);
        }
    }
    Doubling::Done(h, settings.max_iterations, false)
}

/// Solves the discrete algebraic Riccati equation (see the module doc) by structured
/// doubling.
///
/// `Err` only for malformed input (the error names `a`, `b`, `q`, `r` or a settings field);
/// the numerical outcome is the solution's [`RiccatiStatus`]. Never panics; at most
/// `settings.max_iterations` steps of a few `N x N` products and one `N x N` inverse.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, RiccatiStatus, solve_dare};
/// use nalgebra::{Matrix1, Matrix2, Vector2};
/// // Double integrator sampled at 0.1 s.
/// let a = Matrix2::new(1.0, 0.1, 0.0, 1.0);
/// let b = Vector2::new(0.005, 0.1);
/// let sol = solve_dare(
///     &a,
///     &b,
///     &Matrix2::identity(),
///     &Matrix1::new(1.0),
///     &RiccatiSettings::default(),
/// )?;
/// assert_eq!(sol.status, RiccatiStatus::Converged);
/// assert!(sol.residual < 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn solve_dare<T: RealField + Copy, const N: usize, const M: usize>(
    A: &SMatrix<T, N, N>,
    B: &SMatrix<T, N, M>,
    Q: &SMatrix<T, N, N>,
    R: &SMatrix<T, M, M>,
    settings: &RiccatiSettings<T>,
) -> Result<RiccatiSolution<T, N, M>, Error> {
    let (Q, _, G) = prepare(A, B, Q, R, settings)?;
    if !is_finite(&G) {
        return Ok(RiccatiSolution::failed(RiccatiStatus::NonFinite, 0));
    }
    let (X, iterations, converged) = match doubling(*A, G, Q, settings) {
        Doubling::Done(x, k, c) => (x, k, c),
        Doubling::Diverged(k) => {
            return Ok(RiccatiSolution::failed(RiccatiStatus::NotStabilizable, k));
        }
    };
    // K = (R + B^T X B)^-1 B^T X A.
    let btx = B.transpose() * X;
    let Some(s_chol) = Cholesky::new(symmetrize(&(R + btx * B))) else {
        return Ok(RiccatiSolution::failed(
            RiccatiStatus::NonFinite,
            iterations,
        ));
    };
    let btxa = btx * A;
    let K = s_chol.solve(&btxa);
    let residual_matrix = Q + A.transpose() * X * A - X - btxa.transpose() * K;
    Ok(finish(
        X,
        K,
        residual_matrix,
        &Q,
        iterations,
        converged,
        discrete_lyapunov_stable(&(A - B * K), &X),
    ))
}

/// `true` if `P` is positive definite with a margin of `1000 eps ||X||_1`.
fn positive_definite_with_margin<T: RealField + Copy, const N: usize>(
    p: &SMatrix<T, N, N>,
    scale: T,
) -> bool {
    let margin = scale * T::default_epsilon() * lit(1000.0);
    Cholesky::new(symmetrize(&(p - SMatrix::<T, N, N>::identity() * margin))).is_some()
}

/// Certifies that the discrete closed loop `a_cl` is asymptotically stable. Fast path, the
/// Lyapunov theorem: `X > 0` and `X - A_cl^T X A_cl > 0` (both with a round-off margin; the
/// DARE makes the latter `Q + K^T R K`). Otherwise (e.g. a singular `Q`) the eigenvalue-free
/// squaring certificate [`is_schur_stable`].
fn discrete_lyapunov_stable<T: RealField + Copy, const N: usize>(
    a_cl: &SMatrix<T, N, N>,
    x: &SMatrix<T, N, N>,
) -> bool {
    let scale = norm1(x);
    let lyapunov = x - a_cl.transpose() * x * a_cl;
    (positive_definite_with_margin(x, scale) && positive_definite_with_margin(&lyapunov, scale))
        || is_schur_stable(a_cl)
}

/// Certifies that the continuous closed loop `a_cl` is asymptotically stable: `X > 0` and
/// `-(A_cl^T X + X A_cl) > 0` (the CARE makes it `Q + K^T R K`), else [`is_hurwitz`].
fn continuous_lyapunov_stable<T: RealField + Copy, const N: usize>(
    a_cl: &SMatrix<T, N, N>,
    x: &SMatrix<T, N, N>,
) -> bool {
    let scale = norm1(x);
    let xa = x * a_cl;
    let lyapunov = -(xa + xa.transpose());
    (positive_definite_with_margin(x, scale) && positive_definite_with_margin(&lyapunov, scale))
        || is_hurwitz(a_cl)
}

/// Assembles the solution and its status from the pieces both solvers share.
fn finish<T: RealField + Copy, const N: usize, const M: usize>(
    X: SMatrix<T, N, N>,
    K: SMatrix<T, M, N>,
    residual_matrix: SMatrix<T, N, N>,
    Q: &SMatrix<T, N, N>,
    iterations: u32,
    converged: bool,
    stable: bool,
) -> RiccatiSolution<T, N, M> {
    let scale = norm1(&X).max(norm1(Q));
    let scale = if scale > T::zero() { scale } else { T::one() };
    let residual = norm1(&residual_matrix) / scale;
    let status = if !(is_finite(&K) && residual.is_finite()) {
        RiccatiStatus::NonFinite
    } else if !stable {
        RiccatiStatus::NotStabilizable
    } else if converged {
        RiccatiStatus::Converged
    } else {
        RiccatiStatus::MaxIterations
    };
    RiccatiSolution {
        x: X,
        gain: K,
        status,
        iterations,
        residual,
    }
}

/// Solves the continuous algebraic Riccati equation (see the module doc) by SDA-1: the
/// doubling iteration of [`solve_dare`] on a Cayley transform of the Hamiltonian.
///
/// `Err` only for malformed input (the error names `a`, `b`, `q`, `r` or a settings field);
/// the numerical outcome is the solution's [`RiccatiStatus`]. Never panics; bounded time.
///
/// ```
/// use ballbot_core::lqr::{RiccatiSettings, RiccatiStatus, solve_care};
/// use nalgebra::{Matrix1, Matrix2, Vector2};
/// // Double integrator, Q = I, R = 1: K = [1, sqrt(3)].
/// let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
/// let b = Vector2::new(0.0, 1.0);
/// let sol = solve_care(
///     &a,
///     &b,
///     &Matrix2::identity(),
///     &Matrix1::new(1.0),
///     &RiccatiSettings::default(),
/// )?;
/// assert_eq!(sol.status, RiccatiStatus::Converged);
/// approx::assert_relative_eq!(sol.gain[0], 1.0, epsilon = 1e-12);
/// approx::assert_relative_eq!(sol.gain[1], 3.0_f64.sqrt(), epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn solve_care<T: RealField + Copy, const N: usize, const M: usize>(
    A: &SMatrix<T, N, N>,
    B: &SMatrix<T, N, M>,
    Q: &SMatrix<T, N, N>,
    R: &SMatrix<T, M, M>,
    settings: &RiccatiSettings<T>,
) -> Result<RiccatiSolution<T, N, M>, Error> {
    let (Q, r_chol, G) = prepare(A, B, Q, R, settings)?;
    if !is_finite(&G) {
        return Ok(RiccatiSolution::failed(RiccatiStatus::NonFinite, 0));
    }
    let mut shift = A.norm().max((G.norm() * Q.norm()).sqrt());
    if !(shift.is_finite() && shift > T::zero()) {
        shift = T::one();
    }
    let mut start = None;
    for _ in 0..8 {
        start = cayley_start(A, &G, &Q, shift);
        if start.is_some() {
            break;
        }
        shift *= lit(1.5);
    }
    let Some((a0, g0, h0)) = start else {
        return Ok(RiccatiSolution::failed(RiccatiStatus::NonFinite, 0));
    };
    let (X, iterations, converged) = match doubling(a0, g0, h0, settings) {
        Doubling::Done(x, k, c) => (x, k, c),
        Doubling::Diverged(k) => {
            return Ok(RiccatiSolution::failed(RiccatiStatus::NotStabilizable, k));
        }
    };
    // K = R^-1 B^T X; X G X = X B K.
    let K = r_chol.solve(&(B.transpose() * X));
    let xa = X * A;
    let residual_matrix = xa.transpose() + xa - X * B * K + Q;
    Ok(finish(
        X,
        K,
        residual_matrix,
        &Q,
        iterations,
        converged,
        continuous_lyapunov_stable(&(A - B * K), &X),
    ))
}

/// The SDA-1 starting triple `(A_0, G_0, H_0)` for shift `g`; `None` if a matrix to invert is
/// singular or the result is not finite.
#[allow(clippy::type_complexity)]
fn cayley_start<T: RealField + Copy, const N: usize>(
    A: &SMatrix<T, N, N>,
    G: &SMatrix<T, N, N>,
    Q: &SMatrix<T, N, N>,
    g: T,
) -> Option<(SMatrix<T, N, N>, SMatrix<T, N, N>, SMatrix<T, N, N>)> {
    let identity = SMatrix::<T, N, N>::identity();
    let a_g = A - identity * g;
    let a_g_inv = a_g.try_inverse()?;
    let w_inv = (a_g.transpose() + Q * a_g_inv * G).try_inverse()?;
    let v_inv = (a_g + G * a_g_inv.transpose() * Q).try_inverse()?;
    let two_g = g * lit(2.0);
    let a0 = identity + v_inv * two_g;
    let g0 = symmetrize(&(a_g_inv * G * w_inv * two_g));
    let h0 = symmetrize(&(w_inv * Q * a_g_inv * two_g));
    (is_finite(&a0) && is_finite(&g0) && is_finite(&h0)).then_some((a0, g0, h0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix1, Matrix2, Vector2};

    fn settings() -> RiccatiSettings<f64> {
        RiccatiSettings::default()
    }

    #[test]
    fn settings_are_validated() {
        assert!(settings().validate().is_ok());
        for tolerance in [0.0, -1.0, f64::NAN] {
            let s = RiccatiSettings {
                tolerance,
                ..settings()
            };
            assert_eq!(
                s.validate(),
                Err(Error::invalid("tolerance", "must be finite and > 0"))
            );
        }
        let s = RiccatiSettings {
            max_iterations: 0,
            ..settings()
        };
        assert!(matches!(
            s.validate(),
            Err(Error::InvalidParameter {
                field: "max_iterations",
                ..
            })
        ));
    }

    #[test]
    fn malformed_input_names_the_argument() {
        let a = Matrix2::new(1.0, 0.1, 0.0, 1.0);
        let b = Vector2::new(0.0, 0.1);
        let q = Matrix2::identity();
        let r = Matrix1::new(1.0);
        let field = |res: Result<RiccatiSolution<f64, 2, 1>, Error>| match res {
            Err(Error::InvalidParameter { field, .. }) => field,
            other => panic!("expected an error, got {other:?}"),
        };
        let nan_a = Matrix2::new(f64::NAN, 0.0, 0.0, 1.0);
        assert_eq!(field(solve_dare(&nan_a, &b, &q, &r, &settings())), "a");
        assert_eq!(field(solve_care(&nan_a, &b, &q, &r, &settings())), "a");
        let inf_b = Vector2::new(f64::INFINITY, 0.0);
        assert_eq!(field(solve_dare(&a, &inf_b, &q, &r, &settings())), "b");
        let bad_q = Matrix2::new(1.0, 0.5, 0.0, 1.0);
        assert_eq!(field(solve_dare(&a, &b, &bad_q, &r, &settings())), "q");
        assert_eq!(
            field(solve_dare(&a, &b, &q, &Matrix1::new(0.0), &settings())),
            "r"
        );
        assert_eq!(
            field(solve_care(&a, &b, &q, &Matrix1::new(-1.0), &settings())),
            "r"
        );
    }

    #[test]
    fn weights_validation() {
        let r2 = Matrix2::new(1.0, 0.2, 0.2, 1.0);
        assert!(validate_weights(&Matrix2::<f64>::zeros(), &r2).is_ok());
        assert!(validate_weights(&Matrix2::new(1.0, 1.0, 1.0, 1.0), &r2).is_ok());
        assert_eq!(
            validate_weights(&Matrix2::new(1.0, 2.0, 2.0, 1.0), &r2),
            Err(Error::invalid("q", "must be positive semidefinite"))
        );
        assert_eq!(
            validate_weights(
                &Matrix2::<f64>::identity(),
                &Matrix2::new(1.0, 0.0, 0.5, 1.0)
            ),
            Err(Error::invalid("r", "must be symmetric"))
        );
        assert_eq!(
            validate_weights(
                &Matrix2::<f64>::identity(),
                &Matrix2::new(1.0, 0.0, 0.0, 0.0)
            ),
            Err(Error::invalid("r", "must be positive definite"))
        );
    }

    #[test]
    fn zero_weight_on_a_stable_plant_gives_zero_gain() {
        let a = Matrix2::new(0.5, 0.1, 0.0, -0.3);
        let b = Vector2::new(0.0, 1.0);
        let sol = solve_dare(&a, &b, &Matrix2::zeros(), &Matrix1::new(1.0), &settings()).unwrap();
        assert_eq!(sol.status, RiccatiStatus::Converged);
        assert_eq!(sol.x, Matrix2::zeros());
        assert_eq!(sol.gain, nalgebra::RowVector2::zeros());
    }

    #[test]
    fn singular_but_detectable_q_uses_the_fallback_certificate() {
        // Double integrator weighting position only: X is positive definite but
        // Q + K^T R K may be singular; either certificate must accept the stable loop.
        let a = Matrix2::new(1.0, 0.1, 0.0, 1.0);
        let b = Vector2::new(0.005, 0.1);
        let q = Matrix2::new(1.0, 0.0, 0.0, 0.0);
        let sol = solve_dare(&a, &b, &q, &Matrix1::new(1.0), &settings()).unwrap();
        assert_eq!(sol.status, RiccatiStatus::Converged);
        assert!(sol.residual < 1e-12);
        assert!(is_schur_stable(&(a - b * sol.gain)));
    }

    #[test]
    fn lyapunov_certificates_accept_stable_and_reject_unstable() {
        let x = Matrix2::new(2.0, 0.3, 0.3, 1.0);
        assert!(discrete_lyapunov_stable(
            &Matrix2::new(0.5, 0.1, 0.0, 0.4),
            &x
        ));
        assert!(!discrete_lyapunov_stable(
            &Matrix2::new(1.1, 0.0, 0.0, 0.4),
            &x
        ));
        assert!(continuous_lyapunov_stable(
            &Matrix2::new(-1.0, 0.5, 0.0, -2.0),
            &x
        ));
        assert!(!continuous_lyapunov_stable(
            &Matrix2::new(0.1, 0.0, 0.0, -2.0),
            &x
        ));
        // An indefinite X cannot certify, the fallback decides.
        let bad_x = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        assert!(discrete_lyapunov_stable(
            &Matrix2::new(0.5, 0.0, 0.0, 0.4),
            &bad_x
        ));
        assert!(!discrete_lyapunov_stable(
            &Matrix2::new(1.5, 0.0, 0.0, 0.4),
            &bad_x
        ));
    }

    #[test]
    fn two_input_dare_matches_textbook_gain() {
        let a = Matrix2::new(1.1, 0.2, -0.1, 0.9);
        let b = Matrix2::new(1.0, 0.0, 0.3, 0.5);
        let q = Matrix2::new(2.0, 0.5, 0.5, 1.0);
        let r = Matrix2::new(1.0, 0.1, 0.1, 0.5);
        let sol = solve_dare(&a, &b, &q, &r, &settings()).unwrap();
        assert_eq!(sol.status, RiccatiStatus::Converged);
        let x = sol.x;
        let k = (r + b.transpose() * x * b).try_inverse().unwrap() * b.transpose() * x * a;
        assert_relative_eq!(sol.gain, k, max_relative = 1e-12);
        let res = a.transpose() * x * a - x - a.transpose() * x * b * k + q;
        assert!(res.norm() < 1e-12 * x.norm());
    }

    #[test]
    fn status_display_and_predicates() {
        assert!(RiccatiStatus::Converged.is_converged());
        for s in [
            RiccatiStatus::MaxIterations,
            RiccatiStatus::NotStabilizable,
            RiccatiStatus::NonFinite,
        ] {
            assert!(!s.is_converged());
            let mut buf = [0u8; 96];
            let mut w = Buf(&mut buf, 0);
            core::fmt::Write::write_fmt(&mut w, format_args!("{s}")).unwrap();
            assert!(w.1 > 5);
        }
    }

    /// A fixed-size `fmt::Write` sink (no allocation in this crate's unit tests).
    struct Buf<'a>(&'a mut [u8], usize);

    impl core::fmt::Write for Buf<'_> {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            let end = self.1 + s.len();
            self.0
                .get_mut(self.1..end)
                .ok_or(core::fmt::Error)?
                .copy_from_slice(s.as_bytes());
            self.1 = end;
            Ok(())
        }
    }
}
