//! Validation helpers shared by the parameter structs.

use crate::Error;
use nalgebra::RealField;

/// `value` must be finite and strictly positive.
pub(crate) fn positive<T: RealField + Copy>(value: T, field: &'static str) -> Result<(), Error> {
    if value.is_finite() && value > T::zero() {
        Ok(())
    } else {
        Err(Error::invalid(field, "must be finite and > 0"))
    }
}

/// `value` must be finite and not negative.
pub(crate) fn non_negative<T: RealField + Copy>(
    value: T,
    field: &'static str,
) -> Result<(), Error> {
    if value.is_finite() && value >= T::zero() {
        Ok(())
    } else {
        Err(Error::invalid(field, "must be finite and >= 0"))
    }
}

/// `value` must be finite.
pub(crate) fn finite<T: RealField + Copy>(value: T, field: &'static str) -> Result<(), Error> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(field, "must be finite"))
    }
}

/// Converts an `f64` literal into `T` (exact for `f64`, rounded for `f32`).
#[inline]
pub(crate) fn lit<T: RealField + Copy>(value: f64) -> T {
    nalgebra::convert(value)
}
