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
use nalgebra::{RealField, SMatrix};

mod solve;
mod status;
#[cfg(test)]
mod tests;

pub use solve::{solve_care, solve_dare, validate_weights};
pub use status::RiccatiStatus;

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
