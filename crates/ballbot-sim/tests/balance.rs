//! A minimal balancing loop built from the core's planar model: per plane, state feedback on
//! `[theta, theta_dot, phi_dot]` placed by Ackermann's formula on the core's reduced upright
//! linearisation, a PD yaw hold, and the omniwheel torque map (MODEL.md section 4). It runs at
//! the outer rate and holds its torques in between (no inner motor PI).
//!
//! A test fixture: it exercises the world's physics independently of the shipped controller
//! and loop (`ballbot_sim::rig`), so a physics test cannot pass or fail because of the
//! controller. It is deliberately simple and reads only the sensors.

use ballbot_core::{BallbotParams, Wip, WipParams};
use ballbot_sim::world::{Measurement, WorldError};
use nalgebra::{Matrix3, Vector3};

/// Design of the [`PlanarBalancer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarBalancerParams {
    /// Closed-loop poles of each plane's reduced model (rad/s, real, negative). Default
    /// -19.5, -4.78, -2.06: those of the LQR in MODEL.md section 6.
    pub poles_rad_per_s: [f64; 3],
    /// Natural frequency of the yaw hold (rad/s). Default 8.
    pub yaw_bandwidth_rad_per_s: f64,
    /// Outer-loop rate (Hz). Default 400.
    pub rate_hz: f64,
}

impl Default for PlanarBalancerParams {
    fn default() -> Self {
        Self {
            poles_rad_per_s: [-19.5, -4.78, -2.06],
            yaw_bandwidth_rad_per_s: 8.0,
            rate_hz: 400.0,
        }
    }
}

/// Per-plane state feedback plus yaw hold, mapped to the three motors.
#[derive(Clone, Debug)]
pub struct PlanarBalancer {
    params: PlanarBalancerParams,
    gain_sagittal: Vector3<f64>,
    gain_frontal: Vector3<f64>,
    yaw_kp: f64,
    yaw_kd: f64,
    /// `(r_W / r) U^-1`: wheel speeds to the relative rate `omega_rel`.
    speeds_to_rel: Matrix3<f64>,
    /// `(r_W / r) U^-T`: planar torques `[tau_x, tau_y, -tau_z]` to motor torques.
    planar_to_motor: Matrix3<f64>,
    ball_radius_m: f64,
    last: Option<Measurement>,
    torque_nm: [f64; 3],
}

/// Gains `k` with `u = -k . x` placing the poles of `(A, B)` (Ackermann).
fn place(a: &Matrix3<f64>, b: &Vector3<f64>, poles: [f64; 3]) -> Result<Vector3<f64>, WorldError> {
    let c = Matrix3::from_columns(&[*b, a * b, a * a * b]);
    let c_inv = c.try_inverse().ok_or(WorldError::InvalidParameter {
        field: "robot",
        requirement: "the planar model must be controllable",
    })?;
    let [p1, p2, p3] = poles;
    // (s - p1)(s - p2)(s - p3) = s^3 + c2 s^2 + c1 s + c0
    let c2 = -(p1 + p2 + p3);
    let c1 = p1 * p2 + p1 * p3 + p2 * p3;
    let c0 = -p1 * p2 * p3;
    let phi = a * a * a + a * a * c2 + a * c1 + Matrix3::identity() * c0;
    let k = c_inv.row(2) * phi;
    Ok(k.transpose())
}

fn plane_gain(plane: &WipParams<f64>, poles: [f64; 3]) -> Result<Vector3<f64>, WorldError> {
    let wip = Wip::new(*plane)?;
    let (a, b) = wip.linearize_upright().reduced();
    place(&a, &b, poles)
}

impl PlanarBalancer {
    /// Designs the loop for `robot`.
    pub fn new(
        robot: &BallbotParams<f64>,
        params: PlanarBalancerParams,
    ) -> Result<Self, WorldError> {
        robot.validate()?;
        if params
            .poles_rad_per_s
            .iter()
            .any(|p| !(p.is_finite() && *p < 0.0))
        {
            return Err(WorldError::InvalidParameter {
                field: "poles_rad_per_s",
                requirement: "must be finite and < 0",
            });
        }
        if !(params.rate_hz.is_finite() && params.rate_hz > 0.0) {
            return Err(WorldError::InvalidParameter {
                field: "rate_hz",
                requirement: "must be finite and > 0",
            });
        }
        let dt = &robot.drivetrain;
        let a = dt.contact_angle_rad;
        let u =
            Matrix3::from_rows(&dt.wheel_azimuths_rad.map(|b| {
                nalgebra::RowVector3::new(-a.cos() * b.cos(), -a.cos() * b.sin(), a.sin())
            }));
        let singular = WorldError::InvalidParameter {
            field: "drivetrain.wheel_azimuths_rad",
            requirement: "wheel layout must be invertible",
        };
        let u_inv = u.try_inverse().ok_or(singular)?;
        let ratio = dt.wheel_radius_m / robot.ball_radius_m();
        let w = params.yaw_bandwidth_rad_per_s;
        Ok(Self {
            gain_sagittal: plane_gain(&robot.sagittal, params.poles_rad_per_s)?,
            gain_frontal: plane_gain(&robot.frontal, params.poles_rad_per_s)?,
            yaw_kp: robot.spin.inertia_kg_m2 * w * w,
            yaw_kd: (2.0 * w * robot.spin.inertia_kg_m2 - robot.spin.damping_nm_s_per_rad).max(0.0),
            speeds_to_rel: u_inv * ratio,
            planar_to_motor: u_inv.transpose() * ratio,
            ball_radius_m: robot.ball_radius_m(),
            params,
            last: None,
            torque_nm: [0.0; 3],
        })
    }

    /// Outer-loop period (s).
    pub fn period_secs(&self) -> f64 {
        1.0 / self.params.rate_hz
    }

    /// One outer-loop update from a sensor sample and a body-frame velocity command
    /// `[v_x, v_y]` (m/s). Wheel speeds come from differencing the encoder angles between
    /// updates (zero on the first).
    pub fn update(&mut self, m: &Measurement, velocity_m_per_s: [f64; 2]) -> [f64; 3] {
        let speeds = match &self.last {
            Some(prev) if m.time_secs > prev.time_secs => {
                let dt = m.time_secs - prev.time_secs;
                Vector3::from_fn(|i, _| (m.wheel_angle_rad[i] - prev.wheel_angle_rad[i]) / dt)
            }
            _ => Vector3::zeros(),
        };
        self.last = Some(*m);
        let rel = self.speeds_to_rel * speeds;
        let rate = m.body_rate_rad_per_s;
        let r = self.ball_radius_m;
        // Sagittal: rotation about y, travel along x = r phi_y.
        let s_y = Vector3::new(
            m.tilt_rad[1],
            rate[1],
            rel.y + rate[1] - velocity_m_per_s[0] / r,
        );
        // Frontal: rotation about x, travel along y = -r phi_x.
        let s_x = Vector3::new(
            m.tilt_rad[0],
            rate[0],
            rel.x + rate[0] + velocity_m_per_s[1] / r,
        );
        let tau_y = -self.gain_sagittal.dot(&s_y);
        let tau_x = -self.gain_frontal.dot(&s_x);
        let tau_z = -(self.yaw_kp * m.yaw_rad + self.yaw_kd * rate[2]);
        let motors = self.planar_to_motor * Vector3::new(tau_x, tau_y, -tau_z);
        self.torque_nm = [motors.x, motors.y, motors.z];
        self.torque_nm
    }
}
