//! One controller step's result, with each term (`LqrOutput`, `PiPdOutput`, ...).
//!
//! The terms are the core's [`Terms`]: `to_dict` and `__repr__` visit them with
//! [`Terms::for_each_term`], and each class's getter list is checked against
//! [`Terms::TERM_NAMES`] at compile time (Python attributes have to be declared one by one).

use crate::enums::step_status;
use ballbot_core::control::Terms;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};
use std::fmt::Write;

/// `true` when `a` and `b` hold the same names in the same order (for a const assertion).
const fn same_names(a: &[&str], b: &[&str]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        let (x, y) = (a[i].as_bytes(), b[i].as_bytes());
        if x.len() != y.len() {
            return false;
        }
        let mut j = 0;
        while j < x.len() {
            if x[j] != y[j] {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// Defines a frozen output class: a getter per term (checked against the core's
/// `TERM_NAMES`) plus a `status` (`ballbot.StepStatus`).
macro_rules! py_output {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ty, $name:literal) { $($field:ident),* $(,)? }
    ) => {
        const _: () = assert!(
            same_names(&[$(stringify!($field)),*], <$core as Terms<f64>>::TERM_NAMES),
            concat!($name, "'s getters are not the core's terms"),
        );

        $(#[$meta])*
        // A free list: `step` creates one output per call, so reusing the allocations
        // shortens the call from Python.
        #[pyclass(name = $name, module = "ballbot", frozen, freelist = 32)]
        pub struct $py_ty {
            pub(crate) inner: $core,
        }

        #[pymethods]
        impl $py_ty {
            $(
                #[getter]
                fn $field(&self) -> f64 {
                    self.inner.$field
                }
            )*

            /// `StepStatus.NOMINAL`, `SATURATED` or `INVALID_INPUT`.
            #[getter]
            fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                step_status(py, self.inner.status)
            }

            /// The fields as a dict.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let mut fields: Vec<(&str, Bound<'py, PyAny>)> = Vec::new();
                let mut converted = Ok(());
                self.inner.for_each_term(|name, value| {
                    match value.into_bound_py_any(py) {
                        Ok(v) => fields.push((name, v)),
                        Err(e) => converted = Err(e),
                    }
                });
                converted?;
                fields.push(("status", step_status(py, self.inner.status)?));
                fields.into_py_dict(py)
            }

            fn __repr__(&self) -> String {
                let mut out = format!("{}(", $name);
                self.inner.for_each_term(|name, value| {
                    let _ = write!(out, "{name}={value:?}, ");
                });
                let _ = write!(
                    out,
                    "status=StepStatus.{})",
                    self.inner.status.as_str().to_uppercase()
                );
                out
            }
        }
    };
}

py_output! {
    /// One LQR step's result, with each term.
    PyLqrOutput(ballbot_core::control::LqrOutput<f64>, "LqrOutput") {
        torque_nm, tilt_term_nm, tilt_rate_term_nm, ball_rate_term_nm, saturation_nm,
    }
}

py_output! {
    /// One PI-PD step's result, with each term.
    PyPiPdOutput(ballbot_core::control::PiPdOutput<f64>, "PiPdOutput") {
        torque_nm, reference_tilt_rad, tilt_feedforward_rad, speed_p_term_rad, speed_i_term_rad,
        tilt_limit_rad, tilt_p_term_nm, tilt_d_term_nm, saturation_nm,
    }
}

py_output! {
    /// One LQR-PI outer step's result: what goes to the inner speed PI, and each term.
    PyLqrPiOuterOutput(ballbot_core::control::LqrPiOuterOutput<f64>, "LqrPiOuterOutput") {
        reference_torque_nm, reference_ball_rate_rad_per_s, reference_ball_accel_rad_per_s2,
        reference_tilt_accel_rad_per_s2, tilt_term_nm, tilt_rate_term_nm, ball_rate_term_nm,
        saturation_nm, anchor_correction_rad_per_s,
    }
}

py_output! {
    /// One speed-PI step's result, with each term.
    PySpeedPiOutput(ballbot_core::control::SpeedPiOutput<f64>, "SpeedPiOutput") {
        torque_nm, feedforward_nm, proportional_nm, integral_nm, saturation_nm,
        speed_error_rad_per_s,
    }
}
