//! Per-step records of the world: `WheelTelemetry`, `StepTelemetry`, `Measurement`,
//! `Failure`.

use ballbot_sim::world::failure::tilt_from_vertical_rad;
use ballbot_sim::world::{Failure, FailureKind, Measurement, StepTelemetry, WheelTelemetry};
use nalgebra::Vector3;
use numpy::PyArray1;
use pyo3::prelude::*;

/// One omniwheel in one step (`ballbot_sim::world::WheelTelemetry`).
#[pyclass(name = "WheelTelemetry", module = "ballbot", frozen, get_all)]
#[derive(Clone, Debug)]
pub struct PyWheelTelemetry {
    /// Normal force `N_i` (N), from the compliant contact.
    normal_force_n: f64,
    /// Traction `F_i` the wheel applies to the ball along its rolling direction (N).
    traction_n: f64,
    /// Traction the contact would need to keep sticking (N).
    traction_demand_n: f64,
    /// `|F_i| / (mu N_i)`, 0 when lifted off.
    cone_utilisation: f64,
    /// Slip speed along the rolling direction, ball surface minus wheel rim (m/s).
    slip_speed_m_per_s: f64,
    /// Whether the demand exceeded the friction cone (the contact slides).
    slipping: bool,
    /// Torque the actuator delivered at the wheel after its torque-speed limit (N m).
    motor_torque_nm: f64,
    /// Wheel speed relative to the body (rad/s).
    speed_rad_per_s: f64,
    /// Wheel angle relative to the body (rad).
    angle_rad: f64,
}

impl From<&WheelTelemetry> for PyWheelTelemetry {
    fn from(w: &WheelTelemetry) -> Self {
        Self {
            normal_force_n: w.normal_force_n,
            traction_n: w.traction_n,
            traction_demand_n: w.traction_demand_n,
            cone_utilisation: w.cone_utilisation,
            slip_speed_m_per_s: w.slip_speed_m_per_s,
            slipping: w.slipping,
            motor_torque_nm: w.motor_torque_nm,
            speed_rad_per_s: w.speed_rad_per_s,
            angle_rad: w.angle_rad,
        }
    }
}

#[pymethods]
impl PyWheelTelemetry {
    fn __repr__(&self) -> String {
        format!(
            "WheelTelemetry(normal_force_n={:.3}, traction_n={:.3}, cone_utilisation={:.3}, \
             slip_speed_m_per_s={:.4}, slipping={}, motor_torque_nm={:.3}, speed_rad_per_s={:.3})",
            self.normal_force_n,
            self.traction_n,
            self.cone_utilisation,
            self.slip_speed_m_per_s,
            if self.slipping { "True" } else { "False" },
            self.motor_torque_nm,
            self.speed_rad_per_s
        )
    }
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
    /// Simulated time at the end of the step (s).
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time_s
    }

    /// The three omniwheels (OW1, OW2, OW3).
    #[getter]
    fn wheels(&self) -> Vec<PyWheelTelemetry> {
        self.inner
            .wheels
            .iter()
            .map(PyWheelTelemetry::from)
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
            "StepTelemetry(time_s={:.6}, normal_force_n={:?}, ball_velocity_m_per_s={:?}, \
             tilt_rad={:?})",
            t.time_s,
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
    /// Time of the sample (s).
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time_s
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
            "Measurement(time_s={:.6}, tilt_rad={:?}, yaw_rad={:?}, body_rate_rad_per_s={:?}, \
             wheel_speed_rad_per_s={:?})",
            m.time_s, m.tilt_rad, m.yaw_rad, m.body_rate_rad_per_s, m.wheel_speed_rad_per_s
        )
    }
}

/// A detected failure of a world run (`ballbot_sim::world::Failure`): `kind` is `"tilt"`,
/// `"body_touched_floor"`, `"sustained_slip"` or `"lift_off"`; `wheel` (0-based, OW1 is 0)
/// for slip and lift-off, `tilt_rad` for a tilt failure.
#[pyclass(name = "Failure", module = "ballbot", frozen, eq, get_all)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyFailure {
    /// What failed: `"tilt"`, `"body_touched_floor"`, `"sustained_slip"`, `"lift_off"`.
    kind: &'static str,
    /// Simulated time of detection (s).
    time_s: f64,
    /// The wheel, 0-based, for `"sustained_slip"` and `"lift_off"`.
    wheel: Option<usize>,
    /// Tilt from the vertical when detected (rad), for `"tilt"`.
    tilt_rad: Option<f64>,
}

impl From<Failure> for PyFailure {
    fn from(f: Failure) -> Self {
        let (kind, wheel, tilt_rad) = match f.kind {
            FailureKind::Tilt { tilt_rad } => ("tilt", None, Some(tilt_rad)),
            FailureKind::BodyTouchedFloor => ("body_touched_floor", None, None),
            FailureKind::SustainedSlip { wheel } => ("sustained_slip", Some(wheel), None),
            FailureKind::LiftOff { wheel } => ("lift_off", Some(wheel), None),
        };
        Self {
            kind,
            time_s: f.time_s,
            wheel,
            tilt_rad,
        }
    }
}

#[pymethods]
impl PyFailure {
    fn __repr__(&self) -> String {
        let detail = match (self.wheel, self.tilt_rad) {
            (Some(w), _) => format!(", wheel={w}"),
            (_, Some(t)) => format!(", tilt_rad={t:.4}"),
            _ => String::new(),
        };
        format!(
            "Failure(kind={:?}, time_s={:.4}{detail})",
            self.kind, self.time_s
        )
    }
}
