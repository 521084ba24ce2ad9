//! Small fixed-size linear algebra that nalgebra's `no_std` build lacks: the matrix
//! exponential, the `phi1` function, zero-order-hold (ZOH) discretisation, eigenvalues with a
//! bounded iteration count, and stability certificates.
//!
//! Everything works on stack matrices (`SMatrix<T, N, N>`), allocates nothing, never panics
//! and runs in bounded time.
//!
//! # Matrix exponential
//!
//! [`expm`] uses scaling and squaring with the diagonal `[6/6]` Pade approximant: the matrix
//! is halved `s` times until its 1-norm is at most 1/2, where the Pade error is below
//! `4e-16` relative, then the approximant is squared `s` times.
//!
//! # Zero-order hold without an augmented matrix
//!
//! The usual trick (the exponential of the `(N + M) x (N + M)` block matrix `[[A, B], [0, 0]]`)
//! needs generic const arithmetic, which stable Rust lacks. [`zoh`] instead uses
//!
//! ```text
//! Ad = exp(A dt),   Bd = dt phi1(A dt) B,   phi1(X) = sum_k X^k / (k + 1)!
//! ```
//!
//! with `phi1` from its Taylor polynomial of degree 16 at the scaled matrix (1-norm <= 1/2,
//! truncation below `1e-19`) and the doubling identities `exp(2X) = exp(X)^2`,
//! `phi1(2X) = phi1(X) (exp(X) + I) / 2`, where `exp(X) = I + X phi1(X)`. Only `N x N`
//! products appear. The tests check `Ad` against [`expm`], both against a fine RK4
//! integration, and the semigroup property `Bd(2h) = Ad(h) Bd(h) + Bd(h)`.
//!
//! # Stability certificates
//!
//! [`is_schur_stable`] and [`is_hurwitz`] decide asymptotic stability without eigenvalues
//! (repeated squaring, Cayley transform); [`eigenvalues`] gives the poles themselves from
//! nalgebra's Schur decomposition with a bounded iteration count.

use crate::Error;
use crate::check::lit;
use nalgebra::allocator::Allocator;
use nalgebra::{
    Complex, Const, DefaultAllocator, DimDiff, DimSub, RealField, SMatrix, SVector, Schur, U1,
};

/// The scaled matrix's 1-norm bound in [`expm`] and [`zoh`].
const SCALED_NORM_BOUND: f64 = 0.5;
/// At most this many halvings (a 1-norm up to `2^127`, beyond `f32::MAX`).
const MAX_SQUARINGS: u32 = 128;
/// Taylor terms of `phi1` at the scaled matrix: `0.5^16 / 17! < 1e-19`.
const PHI1_TERMS: u32 = 16;

/// The 1-norm (largest absolute column sum) of a matrix.
///
/// ```
/// use ballbot_core::linalg::norm1;
/// use nalgebra::Matrix2;
/// assert_eq!(norm1(&Matrix2::new(1.0, -4.0, -2.0, 3.0)), 7.0);
/// ```
pub fn norm1<T: RealField + Copy, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> T {
    let mut best = T::zero();
    for j in 0..C {
        let mut sum = T::zero();
        for i in 0..R {
            sum += m[(i, j)].abs();
        }
        // `max` would drop a NaN; keep it visible to the caller's finiteness checks.
        if sum > best || !sum.is_finite() {
            best = sum;
        }
    }
    best
}

/// `true` when every entry is finite.
///
/// ```
/// use ballbot_core::linalg::is_finite;
/// use nalgebra::Matrix2;
/// assert!(is_finite(&Matrix2::new(1.0, -2.0, 0.0, 1e300)));
/// // One NaN or infinity anywhere (e.g. an overflowed product) is enough to fail.
/// assert!(!is_finite(&Matrix2::new(1.0, f64::NAN, 0.0, 1.0)));
/// assert!(!is_finite(&(Matrix2::new(1e300, 0.0, 0.0, 1.0) * 1e10)));
/// ```
pub fn is_finite<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// Solves `A X = B` by Gaussian elimination with partial pivoting. `None` if `A` is singular
/// (a zero pivot) or the result is not finite.
///
/// ```
/// use ballbot_core::linalg::solve;
/// use nalgebra::{Matrix2, Vector2};
/// let x = solve(&Matrix2::new(0.0, 2.0, 1.0, 1.0), &Vector2::new(4.0, 3.0)).unwrap();
/// approx::assert_relative_eq!(x, Vector2::new(1.0, 2.0), epsilon = 1e-15);
/// assert!(solve(&Matrix2::new(1.0, 2.0, 2.0, 4.0), &Vector2::new(1.0, 1.0)).is_none());
/// ```
#[allow(non_snake_case)]
pub fn solve<T: RealField + Copy, const N: usize, const K: usize>(
    A: &SMatrix<T, N, N>,
    B: &SMatrix<T, N, K>,
) -> Option<SMatrix<T, N, K>> {
    let mut a = *A;
    let mut x = *B;
    for col in 0..N {
        // Partial pivoting: the largest entry of the column at or below the diagonal.
        let mut pivot_row = col;
        let mut pivot_abs = a[(col, col)].abs();
        for row in col + 1..N {
            let v = a[(row, col)].abs();
            if v > pivot_abs {
                pivot_abs = v;
                pivot_row = row;
            }
        }
        if pivot_abs <= T::zero() || !pivot_abs.is_finite() {
            return None;
        }
        if pivot_row != col {
            a.swap_rows(col, pivot_row);
            x.swap_rows(col, pivot_row);
        }
        let inv_pivot = T::one() / a[(col, col)];
        for row in col + 1..N {
            let factor = a[(row, col)] * inv_pivot;
            if factor != T::zero() {
                for j in col + 1..N {
                    let v = a[(col, j)];
                    a[(row, j)] -= factor * v;
                }
                for j in 0..K {
                    let v = x[(col, j)];
                    x[(row, j)] -= factor * v;
                }
            }
        }
    }
    // Back substitution.
    for col in (0..N).rev() {
        let inv_pivot = T::one() / a[(col, col)];
        for j in 0..K {
            let mut v = x[(col, j)];
            for k in col + 1..N {
                v -= a[(col, k)] * x[(k, j)];
            }
            x[(col, j)] = v * inv_pivot;
        }
    }
    is_finite(&x).then_some(x)
}

/// `A B` with plain loops, inlined: faster than nalgebra's generic product for the small
/// fixed sizes of the Riccati iterations.
#[inline(always)]
pub(crate) fn mul<T: RealField + Copy, const R: usize, const K: usize, const C: usize>(
    a: &SMatrix<T, R, K>,
    b: &SMatrix<T, K, C>,
) -> SMatrix<T, R, C> {
    SMatrix::from_fn(|i, j| {
        let mut sum = T::zero();
        for k in 0..K {
            sum += a[(i, k)] * b[(k, j)];
        }
        sum
    })
}

/// `A B^T`.
#[inline(always)]
pub(crate) fn mul_nt<T: RealField + Copy, const R: usize, const K: usize, const C: usize>(
    a: &SMatrix<T, R, K>,
    b: &SMatrix<T, C, K>,
) -> SMatrix<T, R, C> {
    SMatrix::from_fn(|i, j| {
        let mut sum = T::zero();
        for k in 0..K {
            sum += a[(i, k)] * b[(j, k)];
        }
        sum
    })
}

/// `A B` for a product known to be symmetric: the upper triangle, mirrored.
#[inline(always)]
pub(crate) fn mul_sym<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, N, K>,
    b: &SMatrix<T, K, N>,
) -> SMatrix<T, N, N> {
    let mut out = SMatrix::<T, N, N>::zeros();
    for j in 0..N {
        for i in 0..=j {
            let mut sum = T::zero();
            for k in 0..K {
                sum += a[(i, k)] * b[(k, j)];
            }
            out[(i, j)] = sum;
            out[(j, i)] = sum;
        }
    }
    out
}

/// `A^T B` for a product known to be symmetric: the upper triangle, mirrored.
#[inline(always)]
pub(crate) fn mul_tn_sym<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SMatrix<T, K, N>,
) -> SMatrix<T, N, N> {
    let mut out = SMatrix::<T, N, N>::zeros();
    for j in 0..N {
        for i in 0..=j {
            let mut sum = T::zero();
            for k in 0..K {
                sum += a[(k, i)] * b[(k, j)];
            }
            out[(i, j)] = sum;
            out[(j, i)] = sum;
        }
    }
    out
}

/// The sum of the absolute values of all entries (an entrywise 1-norm; submultiplicative).
/// Cheap, and NaN or infinity in any entry makes it non-finite.
#[inline(always)]
pub(crate) fn entry_norm<T: RealField + Copy, const R: usize, const C: usize>(
    m: &SMatrix<T, R, C>,
) -> T {
    let mut sum = T::zero();
    for x in m.iter() {
        sum += x.abs();
    }
    sum
}

/// `(A + A^T) / 2`.
pub(crate) fn symmetrize<T: RealField + Copy, const N: usize>(
    m: &SMatrix<T, N, N>,
) -> SMatrix<T, N, N> {
    (m + m.transpose()) * lit::<T>(0.5)
}

/// The number of halvings `s` that bring `norm` to at most [`SCALED_NORM_BOUND`], and
/// `2^-s`. `None` if `norm` is not finite or needs more than [`MAX_SQUARINGS`].
fn scaling<T: RealField + Copy>(norm: T) -> Option<(u32, T)> {
    if !norm.is_finite() {
        return None;
    }
    let bound: T = lit(SCALED_NORM_BOUND);
    let half: T = lit(0.5);
    let mut factor = T::one();
    let mut scaled = norm;
    for s in 0..=MAX_SQUARINGS {
        if scaled <= bound {
            return Some((s, factor));
        }
        scaled *= half;
        factor *= half;
    }
    None
}

/// The matrix exponential `exp(A)` by scaling and squaring with the `[6/6]` Pade
/// approximant.
///
/// Returns `None` if `a` has a non-finite entry, its 1-norm exceeds `2^127`, or the result
/// overflows.
///
/// ```
/// use ballbot_core::linalg::expm;
/// use nalgebra::Matrix2;
/// // The generator of plane rotations: exp([[0, -t], [t, 0]]) = [[cos t, -sin t], [sin t, cos t]].
/// let t = 0.7_f64;
/// let e = expm(&Matrix2::new(0.0, -t, t, 0.0)).unwrap();
/// approx::assert_relative_eq!(
///     e,
///     Matrix2::new(t.cos(), -t.sin(), t.sin(), t.cos()),
///     epsilon = 1e-15
/// );
/// ```
pub fn expm<T: RealField + Copy, const N: usize>(a: &SMatrix<T, N, N>) -> Option<SMatrix<T, N, N>> {
    let (squarings, factor) = scaling(norm1(a))?;
    let x = a * factor;
    // c_k = (2q - k)! q! / ((2q)! k! (q - k)!) for q = 6.
    let c: [T; 7] = [
        T::one(),
        lit(0.5),
        lit(5.0 / 44.0),
        lit(1.0 / 66.0),
        lit(1.0 / 792.0),
        lit(1.0 / 15840.0),
        lit(1.0 / 665_280.0),
    ];
    let identity = SMatrix::<T, N, N>::identity();
    let x2 = x * x;
    let x4 = x2 * x2;
    let x6 = x4 * x2;
    // Even and odd parts: N = U + V, D = U - V.
    let even = identity * c[0] + x2 * c[2] + x4 * c[4] + x6 * c[6];
    let odd = x * (identity * c[1] + x2 * c[3] + x4 * c[5]);
    let numerator = even + odd;
    let denominator = even - odd;
    let mut e = solve(&denominator, &numerator)?;
    for _ in 0..squarings {
        e = e * e;
    }
    is_finite(&e).then_some(e)
}

/// `(exp(X), phi1(X))` by a Taylor series at the scaled matrix and the doubling identities.
fn exp_phi1<T: RealField + Copy, const N: usize>(
    x: &SMatrix<T, N, N>,
) -> Option<(SMatrix<T, N, N>, SMatrix<T, N, N>)> {
    let (squarings, factor) = scaling(norm1(x))?;
    let xs = x * factor;
    let identity = SMatrix::<T, N, N>::identity();
    // Horner: phi1 = I + X/2 (I + X/3 (I + ... (I + X/(m+1)))).
    let mut phi = identity;
    for j in (2..=PHI1_TERMS + 1).rev() {
        phi = identity + xs * phi * (T::one() / lit::<T>(f64::from(j)));
    }
    let mut e = identity + xs * phi;
    let half: T = lit(0.5);
    for _ in 0..squarings {
        phi = phi * (e + identity) * half;
        e = e * e;
    }
    (is_finite(&e) && is_finite(&phi)).then_some((e, phi))
}

/// A discrete-time linear system `x[k+1] = a x[k] + b u[k]`.
///
/// ```
/// use ballbot_core::linalg::zoh;
/// use nalgebra::{Matrix1, Vector1};
/// // x_dot = -x + u held for 0.1 s: a = exp(-0.1), b = 1 - exp(-0.1).
/// let d = zoh(&Matrix1::new(-1.0), &Vector1::new(1.0), 0.1)?;
/// approx::assert_relative_eq!(d.a[0], (-0.1f64).exp(), epsilon = 1e-14);
/// approx::assert_relative_eq!(d.b[0], 1.0 - (-0.1f64).exp(), epsilon = 1e-14);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteLti<T: RealField + Copy, const N: usize, const M: usize> {
    /// State transition `Ad = exp(A dt)`.
    pub a: SMatrix<T, N, N>,
    /// Input matrix `Bd = (integral_0^dt exp(A t) dt) B`.
    pub b: SMatrix<T, N, M>,
    /// The sample time (s).
    pub dt_secs: T,
}

/// Zero-order-hold discretisation of `x_dot = A x + B u` with the input held over
/// `dt_secs`: `Ad = exp(A dt)`, `Bd = dt phi1(A dt) B` (see the module doc).
///
/// Errors name the offending argument: `dt_secs` not finite and > 0, `a` or `b` with a
/// non-finite entry, or `exp(A dt)` overflowing.
///
/// ```
/// use ballbot_core::linalg::zoh;
/// use nalgebra::{Matrix2, Vector2};
/// // Double integrator: Ad = [[1, dt], [0, 1]], Bd = [dt^2 / 2, dt].
/// let d = zoh(
///     &Matrix2::new(0.0, 1.0, 0.0, 0.0),
///     &Vector2::new(0.0, 1.0),
///     0.1_f64,
/// )?;
/// approx::assert_relative_eq!(d.a, Matrix2::new(1.0, 0.1, 0.0, 1.0), epsilon = 1e-15);
/// approx::assert_relative_eq!(d.b, Vector2::new(0.005, 0.1), epsilon = 1e-15);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[allow(non_snake_case)]
pub fn zoh<T: RealField + Copy, const N: usize, const M: usize>(
    A: &SMatrix<T, N, N>,
    B: &SMatrix<T, N, M>,
    dt_secs: T,
) -> Result<DiscreteLti<T, N, M>, Error> {
    if !(dt_secs.is_finite() && dt_secs > T::zero()) {
        return Err(Error::invalid("dt_secs", "must be finite and > 0"));
    }
    if !is_finite(A) {
        return Err(Error::invalid("a", "must be finite"));
    }
    if !is_finite(B) {
        return Err(Error::invalid("b", "must be finite"));
    }
    let (e, phi) = exp_phi1(&(A * dt_secs)).ok_or(Error::invalid(
        "dt_secs",
        "makes exp(A dt) overflow: reduce it",
    ))?;
    let b = phi * B * dt_secs;
    if !is_finite(&b) {
        return Err(Error::invalid(
            "dt_secs",
            "makes exp(A dt) overflow: reduce it",
        ));
    }
    Ok(DiscreteLti { a: e, b, dt_secs })
}

/// The (complex) eigenvalues of a square matrix from nalgebra's real Schur decomposition,
/// limited to `64 N` QR sweeps. The `where` bounds hold for every concrete size (they only
/// spell out `N - 1` for the Hessenberg step). `None` if the matrix is not finite or the iteration did not
/// converge in that bound. Order: as they appear on the quasi-triangular Schur form.
///
/// ```
/// use ballbot_core::linalg::eigenvalues;
/// use nalgebra::Matrix2;
/// let ev = eigenvalues(&Matrix2::new(0.0, -2.0_f64, 2.0, 0.0)).unwrap();
/// approx::assert_relative_eq!(ev[0].im.abs(), 2.0, epsilon = 1e-12);
/// approx::assert_relative_eq!(ev[0].re, 0.0, epsilon = 1e-12);
/// ```
pub fn eigenvalues<T: RealField + Copy, const N: usize>(
    m: &SMatrix<T, N, N>,
) -> Option<SVector<Complex<T>, N>>
where
    Const<N>: DimSub<U1>,
    DefaultAllocator: Allocator<Const<N>, DimDiff<Const<N>, U1>> + Allocator<DimDiff<Const<N>, U1>>,
{
    if !is_finite(m) {
        return None;
    }
    let schur = Schur::<T, Const<N>>::try_new(*m, T::default_epsilon(), 64 * N.max(1))?;
    let ev = schur.complex_eigenvalues();
    ev.iter()
        .all(|z| z.re.is_finite() && z.im.is_finite())
        .then_some(ev)
}

/// Number of squarings in [`is_schur_stable`]: `log2(1/eps) - 8`, so a spectral radius
/// `1 - d` is certified for `d` above about `2^8 eps` (`M^(2^j)` shrinks like `exp(-2^j d)`).
fn certificate_squarings<T: RealField + Copy>() -> u32 {
    let mut eps = T::default_epsilon();
    let mut bits = 0_u32;
    while eps < T::one() && bits < 256 {
        eps *= lit(2.0);
        bits += 1;
    }
    bits.saturating_sub(8).max(8)
}

/// `true` when every eigenvalue of `m` lies strictly inside the unit circle (the discrete
/// closed loop is asymptotically stable), certified without eigenvalues: the spectral radius
/// satisfies `rho(M) <= ||M^p||^(1/p)`, so a power `M^(2^j)` with 1-norm below 1 proves
/// `rho(M) < 1`. Repeated squaring stops at that point, on overflow, or after
/// `log2(1/eps) - 8` squarings (44 in `f64`, 15 in `f32`), which resolves spectral radii up
/// to about `1 - 256 eps` (a little less for strongly non-normal matrices); closer to 1
/// counts as not stable, as it is within round-off of the boundary.
///
/// ```
/// use ballbot_core::linalg::is_schur_stable;
/// use nalgebra::Matrix2;
/// assert!(is_schur_stable(&Matrix2::new(0.9_f64, 100.0, 0.0, 0.9)));
/// assert!(!is_schur_stable(&Matrix2::new(1.0_f64, 0.0, 0.0, 0.5)));
/// ```
pub fn is_schur_stable<T: RealField + Copy, const N: usize>(m: &SMatrix<T, N, N>) -> bool {
    let mut p = *m;
    for _ in 0..=certificate_squarings::<T>() {
        let norm = norm1(&p);
        if !norm.is_finite() {
            return false;
        }
        if norm < T::one() {
            return true;
        }
        p = p * p;
    }
    false
}

/// `true` when every eigenvalue of `m` has a strictly negative real part (the continuous
/// closed loop is asymptotically stable). The Cayley transform
/// `C = (g I - M)^-1 (g I + M)`, `g = ||M||_1`, maps the open left half-plane onto the open
/// unit disc; [`is_schur_stable`] then certifies `C`.
///
/// ```
/// use ballbot_core::linalg::is_hurwitz;
/// use nalgebra::Matrix2;
/// assert!(is_hurwitz(&Matrix2::new(-1.0_f64, 50.0, 0.0, -2.0)));
/// assert!(!is_hurwitz(&Matrix2::new(0.0_f64, 1.0, 0.0, -2.0)));
/// ```
pub fn is_hurwitz<T: RealField + Copy, const N: usize>(m: &SMatrix<T, N, N>) -> bool {
    let g = norm1(m);
    if !g.is_finite() {
        return false;
    }
    if g == T::zero() {
        // The zero matrix: all eigenvalues are 0.
        return N == 0;
    }
    let identity = SMatrix::<T, N, N>::identity();
    match solve(&(identity * g - m), &(identity * g + m)) {
        Some(c) => is_schur_stable(&c),
        // g is an eigenvalue of m: unstable.
        None => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    #[test]
    fn norm1_is_largest_column_sum() {
        let m = Matrix2::new(1.0, -5.0, -2.0, 1.0);
        assert_eq!(norm1(&m), 6.0);
        assert!(!norm1(&Matrix2::new(f64::NAN, 0.0, 0.0, 0.0)).is_finite());
    }

    #[test]
    fn expm_of_zero_and_empty() {
        assert_eq!(expm(&Matrix3::<f64>::zeros()).unwrap(), Matrix3::identity());
        assert!(expm(&Matrix2::new(f64::NAN, 0.0, 0.0, 0.0)).is_none());
        assert!(expm(&Matrix2::new(1e300, 0.0, 0.0, 0.0)).is_none());
    }

    #[test]
    fn scaling_counts_halvings() {
        assert_eq!(scaling(0.5_f64), Some((0, 1.0)));
        assert_eq!(scaling(0.6_f64), Some((1, 0.5)));
        assert_eq!(scaling(4.0_f64), Some((3, 0.125)));
        assert_eq!(scaling(f64::INFINITY), None);
    }

    #[test]
    fn zoh_rejects_bad_arguments() {
        let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
        let b = Vector2::new(0.0, 1.0);
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(
                zoh(&a, &b, dt),
                Err(Error::invalid("dt_secs", "must be finite and > 0"))
            );
        }
        let bad_a = Matrix2::new(f64::NAN, 1.0, 0.0, 0.0);
        assert!(matches!(
            zoh(&bad_a, &b, 0.1),
            Err(Error::InvalidParameter { field: "a", .. })
        ));
        let bad_b = Vector2::new(0.0, f64::INFINITY);
        assert!(matches!(
            zoh(&a, &bad_b, 0.1),
            Err(Error::InvalidParameter { field: "b", .. })
        ));
        let fast = Matrix2::new(1e3, 0.0, 0.0, 0.0);
        assert!(matches!(
            zoh(&fast, &b, 10.0),
            Err(Error::InvalidParameter {
                field: "dt_secs",
                ..
            })
        ));
    }

    #[test]
    fn zoh_of_scalar_decay_is_closed_form() {
        // x_dot = -a x + u: Ad = e^{-a dt}, Bd = (1 - e^{-a dt}) / a.
        let a = 3.0_f64;
        for dt in [1e-4, 0.0025, 0.3, 2.0, 20.0] {
            let d = zoh(
                &nalgebra::Matrix1::new(-a),
                &nalgebra::Matrix1::new(1.0),
                dt,
            )
            .unwrap();
            let e = (-a * dt).exp();
            assert_relative_eq!(d.a[0], e, max_relative = 1e-14);
            assert_relative_eq!(d.b[0], -(-a * dt).exp_m1() / a, max_relative = 1e-14);
        }
    }

    #[test]
    fn eigenvalues_of_triangular() {
        let m = Matrix3::new(1.0, 2.0, 3.0, 0.0, -4.0, 5.0, 0.0, 0.0, 0.5);
        let ev = eigenvalues(&m).unwrap();
        let mut re = [ev[0].re, ev[1].re, ev[2].re];
        re.sort_by(f64::total_cmp);
        assert_relative_eq!(
            Vector3::from(re),
            Vector3::new(-4.0, 0.5, 1.0),
            epsilon = 1e-12
        );
        assert!(eigenvalues(&Matrix2::new(f64::NAN, 0.0, 0.0, 0.0)).is_none());
    }

    #[test]
    fn stability_certificates() {
        // Strongly non-normal but stable.
        assert!(is_schur_stable(&Matrix2::new(0.99, 1e4, 0.0, 0.99)));
        assert!(!is_schur_stable(&Matrix2::new(1.01, 0.0, 0.0, 0.1)));
        // Complex pair of modulus 1: marginal, not asymptotically stable.
        let (s, c) = 0.3_f64.sin_cos();
        assert!(!is_schur_stable(&Matrix2::new(c, -s, s, c)));
        assert!(is_schur_stable(&(Matrix2::new(c, -s, s, c) * 0.999)));
        assert!(!is_schur_stable(&Matrix2::new(f64::NAN, 0.0, 0.0, 0.0)));
        assert!(is_hurwitz(&Matrix2::new(-1e-3, 1.0, -1.0, -1e-3)));
        assert!(!is_hurwitz(&Matrix2::new(1e-3, 1.0, -1.0, 1e-3)));
        assert!(!is_hurwitz(&Matrix2::new(0.0, 1.0, -1.0, 0.0)));
        assert!(!is_hurwitz(&Matrix2::<f64>::zeros()));
        // f32 too.
        assert!(is_schur_stable(&Matrix2::new(0.99_f32, 10.0, 0.0, 0.5)));
        assert!(!is_hurwitz(&Matrix2::new(0.5_f32, 0.0, 0.0, -1.0)));
    }
}
