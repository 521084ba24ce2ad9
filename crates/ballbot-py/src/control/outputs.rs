//! One controller step's result, with each term (`LqrOutput`, `PiPdOutput`, ...).

use crate::enums::{step_status, step_status_name};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Defines a frozen output class: float fields plus a `status` (`ballbot.StepStatus`).
macro_rules! py_output {
    (
        $(#[$meta:meta])*
        $py_ty:ident($core:ty, $name:literal) { $($field:ident),* $(,)? }
    ) => {
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
                let d = PyDict::new(py);
                $(d.set_item(stringify!($field), self.inner.$field)?;)*
                d.set_item("status", step_status(py, self.inner.status)?)?;
                Ok(d)
            }

            fn __repr__(&self) -> String {
                let fields: Vec<String> =
                    vec![$(format!("{}={:?}", stringify!($field), self.inner.$field)),*];
                format!(
                    "{}({}, status=StepStatus.{})",
                    $name,
                    fields.join(", "),
                    step_status_name(self.inner.status).to_uppercase()
                )
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
        tilt_term_nm, tilt_rate_term_nm, ball_rate_term_nm, saturation_nm,
        anchor_correction_rad_per_s,
    }
}

py_output! {
    /// One speed-PI step's result, with each term.
    PySpeedPiOutput(ballbot_core::control::SpeedPiOutput<f64>, "SpeedPiOutput") {
        torque_nm, feedforward_nm, proportional_nm, integral_nm, saturation_nm,
        speed_error_rad_per_s,
    }
}
