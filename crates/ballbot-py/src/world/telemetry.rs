//! Per-step records of the world: `WheelTelemetry`, `StepTelemetry`, `Measurement`,
//! `Failure`.

use ballbot_sim::world::failure::tilt_from_vertical_rad;
use ballbot_sim::world::{Failure, FailureKind, Measurement, StepTelemetry, WheelTelemetry};
use nalgebra::Vector3;
use numpy::PyArray1;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};

/// One omniwheel in one step (`ballbot_sim::world::WheelTelemetry`, wrapped).
#[pyclass(name = "WheelTelemetry", module = "ballbot", frozen)]
#[derive(Clone, Debug)]
pub struct PyWheelTelemetry {
    pub(crate) inner: WheelTelemetry,
}

/// Getters delegating to the wrapped record's fields (documented there).
macro_rules! wheel_getters {
    ($($field:ident: $ty:ty),* $(,)?) => {
        #[pymethods]
        impl PyWheelTelemetry {
    /// Pickling: through the record's JSON (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle::by_json(slf.as_any(), &slf.get().inner)
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner = crate::pickle::from_json(py, text)?;

        Ok(Self { inner })
    }

            $(
                #[getter]
                fn $field(&self) -> $ty {
                    self.inner.$field
                }
            )*

            /// Which driver limit shaped the torque: `"none"`, `"current"`, `"voltage"`,
            /// `"velocity_limiter"` or `"disarmed"` (`DriverLimit::as_str`).
            #[getter]
            fn driver_limit(&self) -> &'static str {
                self.inner.driver_limit.as_str()
            }

            /// The fields as a dict.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                [
                    $((stringify!($field), self.inner.$field.into_bound_py_any(py)?),)*
                    ("driver_limit", self.inner.driver_limit.as_str().into_bound_py_any(py)?),
                ]
                .into_py_dict(py)
            }

            fn __repr__(&self) -> String {
                let w = &self.inner;
                format!(
                    "WheelTelemetry(normal_force_n={:.3}, traction_n={:.3}, cone_utilisation={:.3}, \
                     slip_speed_m_per_s={:.4}, slipping={}, motor_torque_nm={:.3}, \
                     speed_rad_per_s={:.3})",
                    w.normal_force_n,
                    w.traction_n,
                    w.cone_utilisation,
                    w.slip_speed_m_per_s,
                    if w.slipping { "True" } else { "False" },
                    w.motor_torque_nm,
                    w.speed_rad_per_s
                )
            }
        }
    };
}

wheel_getters! {
    normal_force_n: f64,
    traction_n: f64,
    traction_demand_n: f64,
    axle_force_n: f64,
    cone_utilisation: f64,
    slip_speed_m_per_s: f64,
    slipping: bool,
    motor_torque_nm: f64,
    driver_current_a: f64,
    speed_rad_per_s: f64,
    angle_rad: f64,
    motor_speed_rad_per_s: f64,
    motor_angle_rad: f64,
    coupling_torque_nm: f64,
    gearbox_friction_nm: f64,
}

pub(crate) fn vec_out<'py>(py: Python<'py>, v: &Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

/// Everything the world reports after one step, in world coordinates, z up
/// (`ballbot_sim::world::StepTelemetry`). Vectors are numpy arrays of shape (3,);
/// orientations are unit quaternions `(x, y, z, w)` (scalar last, as scipy's `Rotation`).
#[pyclass(name = "StepTelemetry", module = "ballbot", frozen)]
pub struct PyStepTelemetry {
    pub(crate) inner: StepTelemetry,
}

#[pymethods]
impl PyStepTelemetry {
    /// Pickling: through the record's JSON (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle::by_json(slf.as_any(), &slf.get().inner)
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner = crate::pickle::from_json(py, text)?;

        Ok(Self { inner })
    }

    /// Simulated time at the end of the step (s).
    #[getter]
    fn time_secs(&self) -> f64 {
        self.inner.time_secs
    }

    /// The three omniwheels (OW1, OW2, OW3).
    #[getter]
    fn wheels(&self) -> Vec<PyWheelTelemetry> {
        self.inner
            .wheels
            .iter()
            .map(|w| PyWheelTelemetry { inner: *w })
            .collect()
    }

    /// Ball centre (m).
    #[getter]
    fn ball_position_m<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_position_m)
    }

    /// Ball orientation, world from ball, `(x, y, z, w)`.
    #[getter]
    fn ball_orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.ball_orientation.coords.as_slice())
    }

    /// Ball velocity (m/s).
    #[getter]
    fn ball_velocity_m_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_velocity_m_per_s)
    }

    /// Ball angular velocity (rad/s).
    #[getter]
    fn ball_angular_velocity_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.ball_angular_velocity_rad_per_s)
    }

    /// Body frame origin, the nominal ball centre in the body (m).
    #[getter]
    fn body_position_m<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.body_position_m)
    }

    /// Body orientation, world from body, `(x, y, z, w)`.
    #[getter]
    fn body_orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.body_orientation.coords.as_slice())
    }

    /// Body angular velocity in the body frame (rad/s).
    #[getter]
    fn body_rate_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_out(py, &self.inner.body_rate_rad_per_s)
    }

    /// Body tilt about the body-aligned horizontal axes, `(theta_x, theta_y)` (rad).
    #[getter]
    fn tilt_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.tilt_rad)
    }

    /// Angle between the body axis and the vertical (rad).
    #[getter]
    fn tilt_from_vertical_rad(&self) -> f64 {
        tilt_from_vertical_rad(&self.inner)
    }

    /// Normal force of the floor on the ball (N).
    #[getter]
    fn floor_force_n(&self) -> f64 {
        self.inner.floor_force_n
    }

    fn __repr__(&self) -> String {
        let t = &self.inner;
        format!(
            "StepTelemetry(time_secs={:.6}, normal_force_n={:?}, ball_velocity_m_per_s={:?}, \
             tilt_rad={:?})",
            t.time_secs,
            t.wheels.map(|w| w.normal_force_n),
            [
                t.ball_velocity_m_per_s.x,
                t.ball_velocity_m_per_s.y,
                t.ball_velocity_m_per_s.z
            ],
            t.tilt_rad
        )
    }
}

/// One sample of every sensor (`ballbot_sim::world::Measurement`): IMU tilt as ZYX Euler
/// angles (as the core's `ImuSample`), gyro, quantised encoders and their windowed speeds.
#[pyclass(name = "Measurement", module = "ballbot", frozen)]
pub struct PyMeasurement {
    pub(crate) inner: Measurement,
}

#[pymethods]
impl PyMeasurement {
    /// Pickling: through the record's JSON (exact).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle::by_json(slf.as_any(), &slf.get().inner)
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let inner = crate::pickle::from_json(py, text)?;

        Ok(Self { inner })
    }

    /// Time of the sample (s).
    #[getter]
    fn time_secs(&self) -> f64 {
        self.inner.time_secs
    }

    /// IMU `(roll, pitch)` (rad); pitch > 0 leans towards +x (OW1).
    #[getter]
    fn tilt_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.tilt_rad)
    }

    /// IMU yaw (rad).
    #[getter]
    fn yaw_rad(&self) -> f64 {
        self.inner.yaw_rad
    }

    /// Gyro: body angular velocity in the body frame (rad/s).
    #[getter]
    fn body_rate_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.body_rate_rad_per_s)
    }

    /// Encoder angles of the three wheels relative to the body, quantised (rad).
    #[getter]
    fn wheel_angle_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.wheel_angle_rad)
    }

    /// Wheel speeds as a motor driver measures them, over the encoder window (rad/s).
    #[getter]
    fn wheel_speed_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.wheel_speed_rad_per_s)
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "Measurement(time_secs={:.6}, tilt_rad={:?}, yaw_rad={:?}, body_rate_rad_per_s={:?}, \
             wheel_speed_rad_per_s={:?})",
            m.time_secs, m.tilt_rad, m.yaw_rad, m.body_rate_rad_per_s, m.wheel_speed_rad_per_s
        )
    }
}

/// A detected failure of a world run (`ballbot_sim::world::Failure`, wrapped): `kind` is a
/// `FailureKind`; `wheel` (`"OW1"`..`"OW3"`) for slip, lift-off and a driver trip,
/// `tilt_rad` for a tilt failure.
#[pyclass(name = "Failure", module = "ballbot", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyFailure {
    pub(crate) inner: Failure,
}

impl From<Failure> for PyFailure {
    fn from(inner: Failure) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyFailure {
    /// Pickling: by its parts (kind name, wheel index, tilt, time).
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (String, Option<usize>, Option<f64>, f64))> {
        let f = &slf.get().inner;
        let rebuild = slf.get_type().getattr("_from_parts")?;
        Ok((
            rebuild,
            (
                f.kind.as_str().to_owned(),
                f.kind.wheel(),
                f.kind.tilt_rad(),
                f.time_secs,
            ),
        ))
    }

    /// Unpickling (see `__reduce__`).
    #[staticmethod]
    fn _from_parts(
        py: Python<'_>,
        kind: &str,
        wheel: Option<usize>,
        tilt_rad: Option<f64>,
        time_secs: f64,
    ) -> PyResult<Self> {
        let kind = match (kind, wheel, tilt_rad) {
            ("tilt", _, Some(tilt_rad)) => FailureKind::Tilt { tilt_rad },
            ("body_touched_floor", _, _) => FailureKind::BodyTouchedFloor,
            ("sustained_slip", Some(wheel), _) => FailureKind::SustainedSlip { wheel },
            ("lift_off", Some(wheel), _) => FailureKind::LiftOff { wheel },
            ("driver_trip", Some(wheel), _) => FailureKind::DriverTrip { wheel },
            _ => {
                return Err(crate::errors::error(
                    py,
                    crate::errors::Kind::Parameter,
                    format!("unpickling Failure: bad parts {kind:?} {wheel:?} {tilt_rad:?}"),
                ));
            }
        };
        Ok(Self {
            inner: Failure { kind, time_secs },
        })
    }

    /// What failed: `FailureKind.TILT`, `BODY_TOUCHED_FLOOR`, `SUSTAINED_SLIP`, `LIFT_OFF` or
    /// `DRIVER_TRIP`.
    #[getter]
    fn kind<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::enums::failure_kind(py, &self.inner.kind)
    }

    /// Simulated time of detection (s).
    #[getter]
    fn time_secs(&self) -> f64 {
        self.inner.time_secs
    }

    /// The wheel, `"OW1"`, `"OW2"` or `"OW3"`, for slip and lift-off.
    #[getter]
    fn wheel(&self) -> Option<&'static str> {
        self.inner.kind.wheel_name()
    }

    /// The wheel's 0-based index (OW1 is 0), for slip and lift-off.
    #[getter]
    fn wheel_index(&self) -> Option<usize> {
        self.inner.kind.wheel()
    }

    /// Tilt from the vertical when detected (rad), for a tilt failure.
    #[getter]
    fn tilt_rad(&self) -> Option<f64> {
        self.inner.kind.tilt_rad()
    }

    fn __repr__(&self) -> String {
        let kind = &self.inner.kind;
        let detail = match (kind.wheel_name(), kind.tilt_rad()) {
            (Some(w), _) => format!(", wheel={w:?}"),
            (_, Some(t)) => format!(", tilt_rad={t:.4}"),
            _ => String::new(),
        };
        format!(
            "Failure(kind=FailureKind.{}, time_secs={:.4}{detail})",
            kind.as_str().to_uppercase(),
            self.inner.time_secs
        )
    }
}
