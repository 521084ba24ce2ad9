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

/// `x.round() as u64`, bit for bit, without a function call (`f64::round` calls the software
/// `round` of compiler-builtins, like [`floor`]): the robot loop's clock reads the simulated
/// time in microseconds every world step.
///
/// Below `2^52` the truncation and the fraction `x - trunc(x)` are exact, and a fraction of at
/// least one half rounds up (half away from zero, like `f64::round`); negative numbers and NaN
/// saturate to 0 and larger numbers are whole already, as with `as u64`.
#[inline]
pub(crate) fn round_to_u64(x: f64) -> u64 {
    if (0.0..WHOLE_FROM).contains(&x) {
        // In range: i64 holds it, and its conversion is one instruction (u64's is not).
        let t = x as i64;
        let up = i64::from(x - t as f64 >= 0.5);
        (t + up).unsigned_abs()
    } else {
        x.round() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_to_u64_is_round_as_u64() {
        let mut values = vec![
            0.0,
            -0.0,
            0.49999999999999994,
            0.5,
            1.5,
            2.5,
            -0.5,
            -0.7,
            -3.0,
            WHOLE_FROM - 0.5,
            WHOLE_FROM,
            1e19,
            2e19,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        // The simulated clock: 8 kHz steps accumulated as the world does, in microseconds.
        let mut t = 0.0_f64;
        for _ in 0..200_000 {
            t += 1.25e-4;
            values.push(t * 1e6);
        }
        let mut s: u64 = 0x2545_F491_4F6C_DD1D;
        for _ in 0..100_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let v = f64::from_bits(s >> 2);
            values.push(v);
            values.push(v.fract() * 1e6);
        }
        for x in values {
            assert_eq!(round_to_u64(x), x.round() as u64, "{x:e}");
        }
    }

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
