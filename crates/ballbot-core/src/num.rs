//! Scalar helpers shared by the command shapers and the controllers: plain-comparison
//! `min`/`max`/symmetric clamp that compile to one instruction each on x86_64.

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
