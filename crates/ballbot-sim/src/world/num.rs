//! Scalar helpers of the 8 kHz path.

/// `2^52`: from here on every `f64` is a whole number.
const WHOLE_FROM: f64 = 4_503_599_627_370_496.0;

/// `x.floor()`, bit for bit, without a function call: on x86_64 without SSE4.1, `f64::floor`
/// calls the software `floor` of compiler-builtins (about 25 instructions), which the roller
/// gaps and the encoders' quantisation used six times a world step.
///
/// Below `2^52` in magnitude the truncation to an integer and back is exact; a whole number is
/// returned as it is (so `-0.0` stays `-0.0`), anything else (NaN, infinities, larger
/// numbers, all whole already) goes to `f64::floor`.
///
/// ```text
/// floor(2.5) = 2, floor(-2.5) = -3, floor(-0.5) = -1, floor(-0.0) = -0.0
/// ```
#[inline]
pub(crate) fn floor(x: f64) -> f64 {
    if x.abs() < WHOLE_FROM {
        // In range: the conversions are exact.
        let t = x as i64 as f64;
        if t == x {
            x
        } else if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_is_f64_floor_bit_for_bit() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.5,
            -2.5,
            1e-300,
            -1e-300,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            WHOLE_FROM - 0.5,
            -(WHOLE_FROM - 0.5),
            WHOLE_FROM,
            -WHOLE_FROM,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        // A deterministic spread over many magnitudes.
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..100_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let v = f64::from_bits(s);
            if v.is_finite() {
                values.push(v);
                values.push(v.fract() * 1e3);
                values.push(-(v.fract() * 1e9));
            }
        }
        for x in values {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "{x:e}");
        }
    }
}
