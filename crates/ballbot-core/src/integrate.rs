//! Fixed-step explicit integration.

use nalgebra::{RealField, SVector};

/// One classical fourth-order Runge-Kutta step of `x_dot = f(x)` over `dt_secs`, the input
/// held constant over the step (zero-order hold; capture it in `f`).
///
/// ```
/// use ballbot_core::rk4_step;
/// use nalgebra::Vector1;
/// // x_dot = -x from 1 over 0.1 s: exp(-0.1) to fifth order.
/// let x = rk4_step(|x: &Vector1<f64>| -x, &Vector1::new(1.0), 0.1);
/// approx::assert_relative_eq!(x[0], (-0.1f64).exp(), epsilon = 1e-7);
/// ```
pub fn rk4_step<T, const N: usize, F>(mut f: F, x: &SVector<T, N>, dt_secs: T) -> SVector<T, N>
where
    T: RealField + Copy,
    F: FnMut(&SVector<T, N>) -> SVector<T, N>,
{
    let two: T = nalgebra::convert(2.0);
    let half = dt_secs / two;
    let k1 = f(x);
    let k2 = f(&(x + k1 * half));
    let k3 = f(&(x + k2 * half));
    let k4 = f(&(x + k3 * dt_secs));
    x + (k1 + (k2 + k3) * two + k4) * (dt_secs / nalgebra::convert(6.0))
}
