//! Scalar helpers shared by the command shapers and the controllers: plain-comparison
//! `min`/`max`/symmetric clamp that compile to one instruction each on x86_64, and planar
//! norms that never overflow or underflow for finite input ([`hypot`], [`direction`]).

use crate::check::lit;
use nalgebra::RealField;

/// `x` limited to `[-limit, limit]` (`limit >= 0`) with plain comparisons: a NaN passes
/// through (callers check finiteness where it matters). `max`/`min` of `RealField` are
/// NaN-aware and cost several instructions each; these run every outer step.
///
/// Written as `min(limit, max(-limit, x))` with the plain [`min`] and [`max`] (one `maxsd` and
/// one `minsd` on x86_64, no branch): their NaN operand comes second, so a NaN `x` passes
/// through both, and ties keep `x`.
#[inline]
pub(crate) fn clamp_sym<T: RealField + Copy>(x: T, limit: T) -> T {
    min(limit, max(-limit, x))
}

/// The smaller of `a` and `b` (plain comparison; `b` if either is NaN or they are equal): one
/// `minsd` on x86_64, where `RealField::min` is NaN-aware and several instructions.
#[inline]
pub(crate) fn min<T: RealField + Copy>(a: T, b: T) -> T {
    if a < b { a } else { b }
}

/// The larger of `a` and `b` (plain comparison; `b` if either is NaN or they are equal): one
/// `maxsd` on x86_64.
#[inline]
pub(crate) fn max<T: RealField + Copy>(a: T, b: T) -> T {
    if a > b { a } else { b }
}

/// Whether `x` is NaN (it compares with nothing; `RealField` has no `is_nan`).
#[inline]
pub(crate) fn is_nan<T: RealField + Copy>(x: T) -> bool {
    x.partial_cmp(&T::zero()).is_none()
}

/// The smallest positive normal number of `T` (up to a factor below 2): `4 / T::MAX`, i.e.
/// `2^-1022` for `f64` and `2^-126` for `f32`. A square at or above it kept every bit.
#[inline]
pub(crate) fn smallest_normal<T: RealField + Copy>() -> T {
    let largest = T::max_value().unwrap_or_else(|| lit(f64::MAX));
    lit::<T>(4.0) / largest
}

/// `sqrt(x^2 + y^2)` without overflow or underflow in the squares: for any finite `x`, `y`
/// the result is finite unless the norm itself exceeds `T::MAX` (then `+inf`), and exact to
/// a few ulps, subnormal inputs included. A non-finite input gives `|x| + |y|` (`+inf` or
/// NaN).
///
/// The plain form `(x*x + y*y).sqrt()` overflows to `+inf` once a component passes
/// `sqrt(T::MAX)` (`1.3e154` for `f64`, `1.8e19` for `f32`) and loses every bit below
/// `sqrt(min normal)`; this takes that form only where the sum of squares is a finite normal
/// number (one comparison more on the usual path), and otherwise scales by the larger
/// magnitude `m` first: `m sqrt((x/m)^2 + (y/m)^2)`, the squares then within `[0, 2]`.
#[inline]
pub(crate) fn hypot<T: RealField + Copy>(x: T, y: T) -> T {
    let squares = x * x + y * y;
    if squares.is_finite() && squares >= smallest_normal() {
        return squares.sqrt();
    }
    if !(x.is_finite() && y.is_finite()) {
        return x.abs() + y.abs();
    }
    let m = max(x.abs(), y.abs());
    if m == T::zero() {
        return m;
    }
    let (a, b) = (x / m, y / m);
    m * (a * a + b * b).sqrt()
}

/// The unit vector along `(x, y)` and the vector's length, `((x / n, y / n), n)`; `None` for a
/// zero or non-finite vector. The unit vector is exact to a few ulps for every finite nonzero
/// input, also where the length overflows to `+inf` (components near `T::MAX`) or the squares
/// underflow (subnormal components): it is computed from the scaled components (see
/// [`hypot`]), never from the length.
#[inline]
pub(crate) fn direction<T: RealField + Copy>(x: T, y: T) -> Option<((T, T), T)> {
    let squares = x * x + y * y;
    if squares.is_finite() && squares >= smallest_normal() {
        let n = squares.sqrt();
        return Some(((x / n, y / n), n));
    }
    if !(x.is_finite() && y.is_finite()) {
        return None;
    }
    let m = max(x.abs(), y.abs());
    if m == T::zero() {
        return None;
    }
    let (a, b) = (x / m, y / m);
    // In [1, sqrt(2)]: the larger scaled component is +-1.
    let s = (a * a + b * b).sqrt();
    Some(((a / s, b / s), m * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn branch_free_clamp_matches_the_branchy_one_bit_for_bit() {
        // clamp_sym and min/max replaced comparisons chains: NaN passes, ties keep x, and the
        // sign of zero survives.
        let reference = |x: f64, limit: f64| {
            if x > limit {
                limit
            } else if x < -limit {
                -limit
            } else {
                x
            }
        };
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            2.0,
            -2.0,
            2.5,
            -2.5,
            1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for limit in [0.0, 2.0, 1e300, f64::INFINITY] {
            for x in specials {
                let (got, want) = (clamp_sym(x, limit), reference(x, limit));
                assert!(
                    got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                    "clamp_sym({x}, {limit}) = {got}, want {want}"
                );
            }
        }
        // The documented choices: the second argument wins ties and NaN comparisons (the
        // branch-free select the hot paths rely on), so -0.0 and a NaN in `b` pass through.
        let bits = |x: f64| x.to_bits();
        assert_eq!((min(1.0, 2.0), min(2.0, 1.0)), (1.0, 1.0));
        assert_eq!((max(1.0, 2.0), max(2.0, 1.0)), (2.0, 2.0));
        assert_eq!((min(f64::NAN, 1.0), max(f64::NAN, 1.0)), (1.0, 1.0));
        assert!(min(1.0, f64::NAN).is_nan() && max(1.0, f64::NAN).is_nan());
        assert_eq!(bits(min(0.0, -0.0)), bits(-0.0));
        assert_eq!(bits(max(0.0, -0.0)), bits(-0.0));
    }
}

#[cfg(test)]
mod norm_tests {
    //! [`hypot`] and [`direction`] against a wider reference over the whole finite range of
    //! `f32` and `f64`, magnitudes log-uniform (subnormals included), signs random.

    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::RngSeed;

    /// The seed of these properties (proptest prints the failing case).
    const SEED: u64 = 0x6e6f_726d;

    fn config() -> ProptestConfig {
        ProptestConfig {
            rng_seed: RngSeed::Fixed(SEED),
            ..ProptestConfig::with_cases(4096)
        }
    }

    /// `+-10^e`, `e` uniform in `[lo, hi]`, or an exact zero now and then.
    fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
        prop_oneof![
            20 => (any::<bool>(), lo..hi).prop_map(|(negative, e)| {
                let m = 10f64.powf(e);
                if negative { -m } else { m }
            }),
            1 => Just(0.0),
        ]
    }

    /// `|got - want| <= ulps` ulps of `want` (a few roundings) or of the smallest subnormal
    /// `tiny` (a subnormal result is rounded absolutely), or both infinite.
    fn close(got: f64, want: f64, eps: f64, ulps: f64) -> bool {
        let tiny = if eps < 1e-10 { 4.9e-324 } else { 1.4e-45 };
        got == want || (got - want).abs() <= ulps * (eps * want.abs() + tiny)
    }

    proptest! {
        #![proptest_config(config())]

        #[test]
        fn f64_norms_never_overflow_and_keep_the_direction(
            x in log_uniform(-323.0, 308.2),
            y in log_uniform(-323.0, 308.2),
        ) {
            let want = x.hypot(y);
            let got = hypot(x, y);
            prop_assert!(close(got, want, f64::EPSILON, 4.0), "hypot({x:e}, {y:e}) = {got:e}, want {want:e}");
            prop_assert!(got.is_finite() || want > f64::MAX);
            match direction(x, y) {
                None => prop_assert!(x == 0.0 && y == 0.0),
                Some(((ux, uy), n)) => {
                    prop_assert!(close(n, want, f64::EPSILON, 4.0), "{n:e} vs {want:e}");
                    prop_assert!((ux.hypot(uy) - 1.0).abs() <= 4.0 * f64::EPSILON, "({ux}, {uy})");
                    // Same direction: the cross product vanishes (relative to the inputs).
                    let m = x.abs().max(y.abs());
                    let cross = ux * (y / m) - uy * (x / m);
                    prop_assert!(cross.abs() <= 8.0 * f64::EPSILON, "({ux}, {uy}) vs ({x:e}, {y:e})");
                    prop_assert!(ux * x >= 0.0 && uy * y >= 0.0);
                }
            }
        }

        #[test]
        fn f32_norms_never_overflow_and_keep_the_direction(
            x in log_uniform(-44.8, 38.5).prop_map(|v| v as f32),
            y in log_uniform(-44.8, 38.5).prop_map(|v| v as f32),
        ) {
            let want = f64::from(x).hypot(f64::from(y));
            let got = f64::from(hypot(x, y));
            let eps = f64::from(f32::EPSILON);
            prop_assert!(close(got, want, eps, 4.0) || (got.is_infinite() && want > f64::from(f32::MAX)),
                "hypot({x:e}, {y:e}) = {got:e}, want {want:e}");
            match direction(x, y) {
                None => prop_assert!(x == 0.0 && y == 0.0),
                Some(((ux, uy), n)) => {
                    let n = f64::from(n);
                    prop_assert!(close(n, want, eps, 4.0) || (n.is_infinite() && want > f64::from(f32::MAX)));
                    let (ux, uy) = (f64::from(ux), f64::from(uy));
                    prop_assert!((ux.hypot(uy) - 1.0).abs() <= 4.0 * eps, "({ux}, {uy})");
                    let m = f64::from(x.abs().max(y.abs()));
                    let cross = ux * (f64::from(y) / m) - uy * (f64::from(x) / m);
                    prop_assert!(cross.abs() <= 8.0 * eps, "({ux}, {uy}) vs ({x:e}, {y:e})");
                }
            }
        }
    }
}
