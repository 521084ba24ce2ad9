//! Range checks of parameter fields: the error names the field and the bound.

use super::WorldError;

/// `Ok` if `value` is finite and > 0, else the error naming `field`.
pub(super) fn positive(value: f64, field: &'static str) -> Result<(), WorldError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(WorldError::InvalidParameter {
            field,
            requirement: "must be finite and > 0",
        })
    }
}

/// `Ok` if `value` is finite and >= 0, else the error naming `field`.
pub(super) fn non_negative(value: f64, field: &'static str) -> Result<(), WorldError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(WorldError::InvalidParameter {
            field,
            requirement: "must be finite and >= 0",
        })
    }
}
