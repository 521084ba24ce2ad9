//! Omniwheel kinematics and statics (`ballbot_core::OmniKinematics`), vectorised over rows.
//!
//! Every map takes one 3-vector (shape `(3,)`, result `(3,)`) or a batch (shape `(n, 3)`,
//! result `(n, 3)`); WIP states are `(4,)` or `(n, 4)`; headings and torques are scalars or
//! `(n,)` arrays broadcast against the batch.

use crate::arrays::{Rows, array_out, broadcast, column_out, rows, rows_out};
use crate::errors::{Kind, core_error, error};
use crate::models::PyWip;
use crate::params::{PyBallbotParams, PyDrivetrainParams};
use ballbot_core::kinematics::{
    ContactForces, planar_torque_at_heading, relative_rate_at_heading, relative_rate_from_planar,
};
use ballbot_core::{OmniKinematics, WHEEL_COUNT};
use nalgebra::{Matrix3, Vector3, Vector4};
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;
type Out<'py> = PyResult<Bound<'py, PyArrayDyn<f64>>>;
type Arr3<'py> = Bound<'py, PyArrayDyn<f64>>;

fn matrix_out<'py>(py: Python<'py>, m: &Matrix3<f64>) -> Out<'py> {
    let mut v = Vec::with_capacity(9);
    for i in 0..3 {
        for j in 0..3 {
            v.push(m[(i, j)]);
        }
    }
    array_out(py, v, &[3, 3])
}

/// Applies a 3-vector map row by row.
fn map3<'py>(
    py: Python<'py>,
    input: &Arr<'py>,
    name: &str,
    f: impl Fn(&Vector3<f64>) -> Vector3<f64>,
) -> Out<'py> {
    let r: Rows<3> = rows(py, input, name)?;
    let out: Vec<[f64; 3]> = r
        .rows
        .iter()
        .map(|x| f(&Vector3::from(*x)).into())
        .collect();
    rows_out(py, out, r.single)
}

/// Contact forces at the three omniwheels, for one case (arrays of shape `(3,)`, scalars) or a
/// batch (`(n, 3)`, `(n,)`).
#[pyclass(name = "ContactForces", module = "ballbot", frozen)]
pub struct PyContactForces {
    forces: Vec<ContactForces<f64>>,
    single: bool,
}

impl PyContactForces {
    fn per_wheel<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&ballbot_core::WheelContact<f64>) -> f64,
    ) -> Out<'py> {
        let out: Vec<[f64; WHEEL_COUNT]> = self
            .forces
            .iter()
            .map(|c| core::array::from_fn(|i| f(&c.wheels[i])))
            .collect();
        rows_out(py, out, self.single)
    }

    fn per_case<'py>(&self, py: Python<'py>, f: impl Fn(&ContactForces<f64>) -> f64) -> Out<'py> {
        column_out(py, self.forces.iter().map(f).collect(), self.single)
    }
}

#[pymethods]
impl PyContactForces {
    /// Normal force at each contact (N, positive in compression).
    #[getter]
    fn normal_force_n<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_wheel(py, |w| w.normal_force_n)
    }

    /// Traction along each wheel's rolling direction (N).
    #[getter]
    fn traction_n<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_wheel(py, |w| w.traction_n)
    }

    /// `|traction| / (mu N)` at each contact; `inf` when lifted off. Above 1: slipping.
    #[getter]
    fn friction_utilisation<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_wheel(py, |w| w.friction_utilisation)
    }

    /// Whether each contact has lifted off (`N <= 0`), as 1.0 / 0.0.
    #[getter]
    fn lifted_off<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_wheel(py, |w| if w.lifted_off { 1.0 } else { 0.0 })
    }

    /// The largest friction utilisation over the three contacts.
    #[getter]
    fn max_friction_utilisation<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_case(py, |c| c.max_friction_utilisation())
    }

    /// Whether every contact holds (in its friction cone, not lifted off), as 1.0 / 0.0.
    #[getter]
    fn all_hold<'py>(&self, py: Python<'py>) -> Out<'py> {
        self.per_case(py, |c| if c.all_hold() { 1.0 } else { 0.0 })
    }

    fn __len__(&self) -> usize {
        self.forces.len()
    }
}

/// Validated omniwheel kinematics and statics of a three-wheel drivetrain
/// (`ballbot_core::OmniKinematics`).
#[pyclass(name = "OmniKinematics", module = "ballbot", frozen)]
pub struct PyOmniKinematics {
    inner: OmniKinematics<f64>,
}

#[pymethods]
impl PyOmniKinematics {
    #[new]
    fn py_new(
        py: Python<'_>,
        drivetrain: PyDrivetrainParams,
        ball_radius_m: f64,
    ) -> PyResult<Self> {
        let inner =
            OmniKinematics::new(drivetrain.inner, ball_radius_m).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The kinematics of a complete robot (its drivetrain and ball radius).
    #[staticmethod]
    fn from_ballbot(py: Python<'_>, params: PyBallbotParams) -> PyResult<Self> {
        let inner = OmniKinematics::from_ballbot(&params.inner).map_err(|e| core_error(py, e))?;
        Ok(Self { inner })
    }

    /// The drivetrain parameters.
    #[getter]
    fn drivetrain(&self) -> PyDrivetrainParams {
        PyDrivetrainParams {
            inner: *self.inner.drivetrain(),
        }
    }

    /// The ball radius (m).
    #[getter]
    fn ball_radius_m(&self) -> f64 {
        self.inner.ball_radius_m()
    }

    /// Unit contact normals `n_i` (rows), ball centre to contact: shape (3, 3).
    #[getter]
    fn contact_normals<'py>(&self, py: Python<'py>) -> Out<'py> {
        let w = self.inner.wheels();
        rows_out(
            py,
            w.iter().map(|w| w.contact_normal.into()).collect(),
            false,
        )
    }

    /// Unit rolling (traction) directions `d_i` (rows): shape (3, 3).
    #[getter]
    fn rolling_directions<'py>(&self, py: Python<'py>) -> Out<'py> {
        let w = self.inner.wheels();
        rows_out(
            py,
            w.iter().map(|w| w.rolling_direction.into()).collect(),
            false,
        )
    }

    /// Unit axle directions `u_i = n_i x d_i` (rows): shape (3, 3).
    #[getter]
    fn axle_directions<'py>(&self, py: Python<'py>) -> Out<'py> {
        let w = self.inner.wheels();
        rows_out(
            py,
            w.iter().map(|w| w.axle_direction.into()).collect(),
            false,
        )
    }

    /// Contact points relative to the ball centre (m, rows): shape (3, 3).
    #[getter]
    fn contact_points_m<'py>(&self, py: Python<'py>) -> Out<'py> {
        let w = self.inner.wheels();
        rows_out(
            py,
            w.iter().map(|w| w.contact_point_m.into()).collect(),
            false,
        )
    }

    /// Omniwheel speeds (rad/s) for relative ball-to-body rates `omega_rel` (rad/s, body
    /// coordinates), shape (3,) or (n, 3).
    fn wheel_speeds_rad_per_s<'py>(
        &self,
        py: Python<'py>,
        relative_rate_rad_per_s: Arr<'py>,
    ) -> Out<'py> {
        map3(
            py,
            &relative_rate_rad_per_s,
            "relative_rate_rad_per_s",
            |x| self.inner.wheel_speeds_rad_per_s(x),
        )
    }

    /// The inverse of `wheel_speeds_rad_per_s`: `omega_rel` (rad/s) from omniwheel speeds.
    fn relative_rate_rad_per_s<'py>(
        &self,
        py: Python<'py>,
        wheel_speeds_rad_per_s: Arr<'py>,
    ) -> Out<'py> {
        map3(py, &wheel_speeds_rad_per_s, "wheel_speeds_rad_per_s", |x| {
            self.inner.relative_rate_rad_per_s(x)
        })
    }

    /// Motor rotor speeds (rad/s): `gear_ratio` times the omniwheel speeds.
    fn motor_speeds_rad_per_s<'py>(
        &self,
        py: Python<'py>,
        relative_rate_rad_per_s: Arr<'py>,
    ) -> Out<'py> {
        map3(
            py,
            &relative_rate_rad_per_s,
            "relative_rate_rad_per_s",
            |x| self.inner.motor_speeds_rad_per_s(x),
        )
    }

    /// The inverse of `motor_speeds_rad_per_s`.
    fn relative_rate_from_motor_speeds_rad_per_s<'py>(
        &self,
        py: Python<'py>,
        motor_speeds_rad_per_s: Arr<'py>,
    ) -> Out<'py> {
        map3(py, &motor_speeds_rad_per_s, "motor_speeds_rad_per_s", |x| {
            self.inner.relative_rate_from_motor_speeds_rad_per_s(x)
        })
    }

    /// Omniwheel torques (N m) producing planar torques `[tau_x, tau_y, tau_z]` (N m).
    fn wheel_torques_nm<'py>(&self, py: Python<'py>, planar_torque_nm: Arr<'py>) -> Out<'py> {
        map3(py, &planar_torque_nm, "planar_torque_nm", |x| {
            self.inner.wheel_torques_nm(x)
        })
    }

    /// The inverse of `wheel_torques_nm`: planar torques (N m) from omniwheel torques.
    fn planar_torque_nm<'py>(&self, py: Python<'py>, wheel_torques_nm: Arr<'py>) -> Out<'py> {
        map3(py, &wheel_torques_nm, "wheel_torques_nm", |x| {
            self.inner.planar_torque_nm(x)
        })
    }

    /// Motor rotor torques (N m): omniwheel torques over `gear_ratio`.
    fn motor_torques_nm<'py>(&self, py: Python<'py>, planar_torque_nm: Arr<'py>) -> Out<'py> {
        map3(py, &planar_torque_nm, "planar_torque_nm", |x| {
            self.inner.motor_torques_nm(x)
        })
    }

    /// The inverse of `motor_torques_nm`.
    fn planar_torque_from_motor_torques_nm<'py>(
        &self,
        py: Python<'py>,
        motor_torques_nm: Arr<'py>,
    ) -> Out<'py> {
        map3(py, &motor_torques_nm, "motor_torques_nm", |x| {
            self.inner.planar_torque_from_motor_torques_nm(x)
        })
    }

    /// The matrix `J = (r_S / r_W) U` of `wheel_speeds_rad_per_s`, shape (3, 3).
    fn wheel_speed_matrix<'py>(&self, py: Python<'py>) -> Out<'py> {
        matrix_out(py, self.inner.wheel_speed_matrix())
    }

    /// The matrix `J^-T S` of `wheel_torques_nm`, shape (3, 3).
    fn wheel_torque_matrix<'py>(&self, py: Python<'py>) -> Out<'py> {
        matrix_out(py, self.inner.wheel_torque_matrix())
    }

    /// The drivetrain inertia reflected onto `omega_rel` (kg m^2), shape (3, 3).
    fn reflected_wheel_inertia_kg_m2<'py>(
        &self,
        py: Python<'py>,
        wheel_inertia_kg_m2: f64,
        rotor_inertia_kg_m2: f64,
    ) -> Out<'py> {
        matrix_out(
            py,
            &self
                .inner
                .reflected_wheel_inertia_kg_m2(wheel_inertia_kg_m2, rotor_inertia_kg_m2),
        )
    }

    /// The largest planar torque about each axis alone, `[x, y, z]` (N m).
    fn planar_torque_capacity_nm<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.planar_torque_capacity_nm().as_slice())
    }

    /// Scales each planar torque request uniformly so that no omniwheel exceeds its limit
    /// (the peak torque, or with `wheel_speeds_rad_per_s` the speed-dependent limits).
    /// Returns `(planar_torque_nm, wheel_torques_nm, scale)`.
    #[pyo3(signature = (planar_torque_nm, wheel_speeds_rad_per_s = None))]
    fn saturate_planar_torque<'py>(
        &self,
        py: Python<'py>,
        planar_torque_nm: Arr<'py>,
        wheel_speeds_rad_per_s: Option<Arr<'py>>,
    ) -> PyResult<(Arr3<'py>, Arr3<'py>, Arr3<'py>)> {
        let tau: Rows<3> = rows(py, &planar_torque_nm, "planar_torque_nm")?;
        let speeds: Option<Rows<3>> = match &wheel_speeds_rad_per_s {
            Some(s) => {
                let s = rows(py, s, "wheel_speeds_rad_per_s")?;
                if s.rows.len() != tau.rows.len() {
                    return Err(error(
                        py,
                        Kind::Shape,
                        format!(
                            "`wheel_speeds_rad_per_s` must have as many rows as \
                             `planar_torque_nm` ({}), got {}",
                            tau.rows.len(),
                            s.rows.len()
                        ),
                    ));
                }
                Some(s)
            }
            None => None,
        };
        let mut planar = Vec::with_capacity(tau.rows.len());
        let mut wheel = Vec::with_capacity(tau.rows.len());
        let mut scale = Vec::with_capacity(tau.rows.len());
        for (i, t) in tau.rows.iter().enumerate() {
            let t = Vector3::from(*t);
            let sat = match &speeds {
                Some(s) => self
                    .inner
                    .saturate_planar_torque_at_speed(&t, &Vector3::from(s.rows[i])),
                None => self.inner.saturate_planar_torque(&t),
            };
            planar.push(sat.planar_torque_nm.into());
            wheel.push(sat.wheel_torques_nm.into());
            scale.push(sat.scale);
        }
        Ok((
            rows_out::<3>(py, planar, tau.single)?,
            rows_out::<3>(py, wheel, tau.single)?,
            column_out(py, scale, tau.single)?,
        ))
    }

    /// Normal forces `[N_1, N_2, N_3]` (N) for support forces (N, body coordinates) and
    /// omniwheel torques (N m), both (3,) or (n, 3).
    fn normal_forces_n<'py>(
        &self,
        py: Python<'py>,
        support_force_n: Arr<'py>,
        wheel_torques_nm: Arr<'py>,
    ) -> Out<'py> {
        let (f, t) = paired(py, &support_force_n, &wheel_torques_nm)?;
        let out: Vec<[f64; 3]> = f
            .rows
            .iter()
            .zip(&t.rows)
            .map(|(f, t)| {
                self.inner
                    .normal_forces_n(&Vector3::from(*f), &Vector3::from(*t))
                    .into()
            })
            .collect();
        rows_out(py, out, f.single)
    }

    /// Normal force, traction, friction use and lift-off at each contact for support forces
    /// (N, body coordinates) and omniwheel torques (N m), both (3,) or (n, 3).
    fn contact_forces(
        &self,
        py: Python<'_>,
        support_force_n: Arr<'_>,
        wheel_torques_nm: Arr<'_>,
    ) -> PyResult<PyContactForces> {
        let (f, t) = paired(py, &support_force_n, &wheel_torques_nm)?;
        let forces = f
            .rows
            .iter()
            .zip(&t.rows)
            .map(|(f, t)| {
                self.inner
                    .contact_forces(&Vector3::from(*f), &Vector3::from(*t))
            })
            .collect();
        Ok(PyContactForces {
            forces,
            single: f.single,
        })
    }

    /// Contact forces of a planar WIP motion of `wip` at heading `heading_rad` (body frame,
    /// 0 = towards omniwheel 1) in state(s) `state` (4,) or (n, 4) under the WIP torque(s)
    /// `torque_nm`. Headings and torques are scalars or (n,) arrays.
    #[pyo3(signature = (wip, heading_rad, state, torque_nm))]
    fn wip_contact_forces(
        &self,
        py: Python<'_>,
        wip: PyRef<'_, PyWip>,
        heading_rad: Arr<'_>,
        state: Arr<'_>,
        torque_nm: Arr<'_>,
    ) -> PyResult<PyContactForces> {
        let s: Rows<4> = rows(py, &state, "state")?;
        let n = s.rows.len();
        let h = broadcast(py, &heading_rad, n, "heading_rad")?;
        let tau = broadcast(py, &torque_nm, n, "torque_nm")?;
        let forces = s
            .rows
            .iter()
            .zip(h.iter().zip(&tau))
            .map(|(s, (h, t))| {
                self.inner
                    .wip_contact_forces(&wip.inner, *h, &Vector4::from(*s), *t)
            })
            .collect();
        Ok(PyContactForces {
            forces,
            single: s.single,
        })
    }

    /// Contact forces of the decoupled 3D model: the sagittal WIP in `sagittal_state`, the
    /// frontal WIP in `frontal_state` (each (4,) or (n, 4)), driven by the planar torques
    /// `[tau_x, tau_y, tau_z]` (N m, (3,) or (n, 3)).
    #[pyo3(signature = (sagittal, sagittal_state, frontal, frontal_state, planar_torque_nm))]
    fn decoupled_contact_forces(
        &self,
        py: Python<'_>,
        sagittal: PyRef<'_, PyWip>,
        sagittal_state: Arr<'_>,
        frontal: PyRef<'_, PyWip>,
        frontal_state: Arr<'_>,
        planar_torque_nm: Arr<'_>,
    ) -> PyResult<PyContactForces> {
        let sy: Rows<4> = rows(py, &sagittal_state, "sagittal_state")?;
        let sx: Rows<4> = rows(py, &frontal_state, "frontal_state")?;
        let tau: Rows<3> = rows(py, &planar_torque_nm, "planar_torque_nm")?;
        let n = sy.rows.len();
        if sx.rows.len() != n || tau.rows.len() != n {
            return Err(error(
                py,
                Kind::Shape,
                format!(
                    "`sagittal_state`, `frontal_state` and `planar_torque_nm` must have the \
                     same number of rows, got {}, {} and {}",
                    n,
                    sx.rows.len(),
                    tau.rows.len()
                ),
            ));
        }
        let forces = (0..n)
            .map(|i| {
                self.inner.decoupled_contact_forces(
                    (&sagittal.inner, &Vector4::from(sy.rows[i])),
                    (&frontal.inner, &Vector4::from(sx.rows[i])),
                    &Vector3::from(tau.rows[i]),
                )
            })
            .collect();
        Ok(PyContactForces {
            forces,
            single: sy.single,
        })
    }

    /// The WIP torque range `[min, max]` (N m) that keeps every actuator within its limits,
    /// for a planar motion at `heading_rad` in state(s) `state`: shape (2,) or (n, 2).
    fn wip_actuator_torque_interval_nm<'py>(
        &self,
        py: Python<'py>,
        heading_rad: Arr<'py>,
        state: Arr<'py>,
    ) -> Out<'py> {
        let s: Rows<4> = rows(py, &state, "state")?;
        let h = broadcast(py, &heading_rad, s.rows.len(), "heading_rad")?;
        let out: Vec<[f64; 2]> = s
            .rows
            .iter()
            .zip(&h)
            .map(|(s, h)| {
                let r = self
                    .inner
                    .wip_actuator_torque_interval_nm(*h, &Vector4::from(*s));
                [r.min_nm, r.max_nm]
            })
            .collect();
        rows_out(py, out, s.single)
    }

    /// The WIP torque range `[min, max]` (N m) for which every contact holds, for `wip` at
    /// `heading_rad` in state(s) `state`: shape (2,) or (n, 2); NaN rows where no torque
    /// keeps all contacts.
    fn wip_contact_torque_interval_nm<'py>(
        &self,
        py: Python<'py>,
        wip: PyRef<'py, PyWip>,
        heading_rad: Arr<'py>,
        state: Arr<'py>,
    ) -> Out<'py> {
        let s: Rows<4> = rows(py, &state, "state")?;
        let h = broadcast(py, &heading_rad, s.rows.len(), "heading_rad")?;
        let out: Vec<[f64; 2]> = s
            .rows
            .iter()
            .zip(&h)
            .map(|(s, h)| {
                match self
                    .inner
                    .wip_contact_torque_interval_nm(&wip.inner, *h, &Vector4::from(*s))
                {
                    Some(r) => [r.min_nm, r.max_nm],
                    None => [f64::NAN, f64::NAN],
                }
            })
            .collect();
        rows_out(py, out, s.single)
    }
}

/// Two row batches that must have the same number of rows.
fn paired(py: Python<'_>, a: &Arr<'_>, b: &Arr<'_>) -> PyResult<(Rows<3>, Rows<3>)> {
    let ra: Rows<3> = rows(py, a, "support_force_n")?;
    let rb: Rows<3> = rows(py, b, "wheel_torques_nm")?;
    if ra.rows.len() != rb.rows.len() || ra.single != rb.single {
        return Err(error(
            py,
            Kind::Shape,
            format!(
                "`support_force_n` and `wheel_torques_nm` must have the same shape, got {:?} \
                 and {:?}",
                a.shape(),
                b.shape()
            ),
        ));
    }
    Ok((ra, rb))
}

/// `omega_rel = [phi_dot_x - theta_dot_x, phi_dot_y - theta_dot_y, -theta_z_dot]` (rad/s)
/// from ball rates `[phi_dot_x, phi_dot_y]` and tilt rates `[theta_dot_x, theta_dot_y]`
/// ((2,) or (n, 2)) and yaw rates (scalar or (n,)).
#[pyfunction]
#[pyo3(name = "relative_rate_from_planar", signature = (ball_rate_rad_per_s, tilt_rate_rad_per_s, yaw_rate_rad_per_s = None))]
fn py_relative_rate_from_planar<'py>(
    py: Python<'py>,
    ball_rate_rad_per_s: Arr<'py>,
    tilt_rate_rad_per_s: Arr<'py>,
    yaw_rate_rad_per_s: Option<Arr<'py>>,
) -> Out<'py> {
    let ball: Rows<2> = rows(py, &ball_rate_rad_per_s, "ball_rate_rad_per_s")?;
    let tilt: Rows<2> = rows(py, &tilt_rate_rad_per_s, "tilt_rate_rad_per_s")?;
    if ball.rows.len() != tilt.rows.len() {
        return Err(error(
            py,
            Kind::Shape,
            "`ball_rate_rad_per_s` and `tilt_rate_rad_per_s` must have the same shape",
        ));
    }
    let yaw = match yaw_rate_rad_per_s {
        Some(y) => broadcast(py, &y, ball.rows.len(), "yaw_rate_rad_per_s")?,
        None => vec![0.0; ball.rows.len()],
    };
    let out: Vec<[f64; 3]> = (0..ball.rows.len())
        .map(|i| relative_rate_from_planar(ball.rows[i], tilt.rows[i], yaw[i]).into())
        .collect();
    rows_out(py, out, ball.single)
}

/// `omega_rel` (rad/s) of planar WIP motions at headings `heading_rad` with ball and tilt
/// rates (all scalars or (n,)): shape (3,) for scalars, else (n, 3).
#[pyfunction]
#[pyo3(name = "relative_rate_at_heading")]
fn py_relative_rate_at_heading<'py>(
    py: Python<'py>,
    heading_rad: Arr<'py>,
    ball_rate_rad_per_s: Arr<'py>,
    tilt_rate_rad_per_s: Arr<'py>,
) -> Out<'py> {
    let n = batch_len(&[&heading_rad, &ball_rate_rad_per_s, &tilt_rate_rad_per_s]);
    let h = broadcast(py, &heading_rad, n.unwrap_or(1), "heading_rad")?;
    let b = broadcast(py, &ball_rate_rad_per_s, h.len(), "ball_rate_rad_per_s")?;
    let t = broadcast(py, &tilt_rate_rad_per_s, h.len(), "tilt_rate_rad_per_s")?;
    let out: Vec<[f64; 3]> = (0..h.len())
        .map(|i| relative_rate_at_heading(h[i], b[i], t[i]).into())
        .collect();
    rows_out(py, out, n.is_none())
}

/// Planar torque vectors `[tau_x, tau_y, 0]` (N m) of WIP torques `torque_nm` at headings
/// `heading_rad` (scalars or (n,)): shape (3,) for scalars, else (n, 3).
#[pyfunction]
#[pyo3(name = "planar_torque_at_heading")]
fn py_planar_torque_at_heading<'py>(
    py: Python<'py>,
    heading_rad: Arr<'py>,
    torque_nm: Arr<'py>,
) -> Out<'py> {
    let n = batch_len(&[&heading_rad, &torque_nm]);
    let h = broadcast(py, &heading_rad, n.unwrap_or(1), "heading_rad")?;
    let t = broadcast(py, &torque_nm, h.len(), "torque_nm")?;
    let out: Vec<[f64; 3]> = (0..h.len())
        .map(|i| planar_torque_at_heading(h[i], t[i]).into())
        .collect();
    rows_out(py, out, n.is_none())
}

/// The batch length of scalar-or-1-D arguments: the first 1-D length, `None` if all scalars.
fn batch_len(args: &[&Arr<'_>]) -> Option<usize> {
    args.iter().find_map(|a| match a.shape() {
        [n] => Some(*n),
        _ => None,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOmniKinematics>()?;
    m.add_class::<PyContactForces>()?;
    m.add_function(wrap_pyfunction!(py_relative_rate_from_planar, m)?)?;
    m.add_function(wrap_pyfunction!(py_relative_rate_at_heading, m)?)?;
    m.add_function(wrap_pyfunction!(py_planar_torque_at_heading, m)?)?;
    Ok(())
}
