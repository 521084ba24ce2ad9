//! The solvers: weight validation, the structure-preserving doubling of the discrete equation
//! ([`solve_dare`]) and the Cayley-transformed continuous one ([`solve_care`]), and the checks
//! of their solutions (see the [module](super) doc).
#![allow(non_snake_case)]

use super::{RiccatiSettings, RiccatiSolution, RiccatiStatus};
use crate::Error;
use crate::check::lit;
use crate::linalg::{
    entry_norm, is_finite, is_hurwitz, is_schur_stable, mul, mul_nt, mul_sym, mul_tn_sym, norm1,
    symmetrize,
};
use nalgebra::{Cholesky, RealField, SMatrix};

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
pub(super) fn discrete_lyapunov_stable<T: RealField + Copy, const N: usize>(
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
pub(super) fn continuous_lyapunov_stable<T: RealField + Copy, const N: usize>(
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
