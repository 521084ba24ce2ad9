//! Planar torque and rate mapped to the actuators, and the omniwheel contact forces, from the
//! core's omniwheel kinematics ([`ballbot_core::kinematics`], MODEL.md sections 4 and 5).
//!
//! For travel at heading `h` the planar torque `tau` and the relative rate
//! `phi_dot - theta_dot` act about the plane's axis; each omniwheel then sees
//! `tau_i = kappa_i tau` and `psi_dot_i = rho_i (phi_dot - theta_dot)` (constants of the
//! layout and heading, taken from [`OmniKinematics`]).
//!
//! Contact forces: the wheels transmit the contact torque
//! `tau_c = tau - I_W (phi_ddot - theta_ddot) - b_m (phi_dot - theta_dot)`, so traction
//! `F_i = kappa_i tau_c / r_W`, and the normal forces are `N = P F_s + Q kappa tau_c` with
//! the body's support force `F_s` ([`kinematics::planar_support_force_n`]):
//!
//! ```text
//! F_s . e_b = m (r phi_ddot cos(theta) + l theta_ddot - g sin(theta))
//! F_s . z   = m (r phi_ddot sin(theta) - l theta_dot^2 + g cos(theta))
//! ```
//!
//! The values come from the core; this module adds their exact gradients with respect to the
//! knot variables `[theta, phi, theta_dot, phi_dot, tau]`, through the analytic Jacobian of the
//! accelerations ([`Wip::linearize`]), for the SQP's linearised traction cones.

use super::error::TrajoptError;
use ballbot_core::kinematics::{
    self, planar_support_force_n, planar_torque_at_heading, relative_rate_at_heading,
};
use ballbot_core::{ActuatorParams, DrivetrainParams, OmniKinematics, Wip, WipState};
use nalgebra::{Matrix3, Vector3};

/// How the actuators drive the plane, for the motor-side and traction limits.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Drive {
    /// One actuator drives the wheel directly (the PIPTB): motor torque = planar torque,
    /// motor speed = relative rate `phi_dot - theta_dot`.
    Direct(ActuatorParams<f64>),
    /// Three omniwheels on a ball (MiaPURE). The plane is the vertical plane of travel at
    /// `heading_rad` in the body frame (0 = towards omniwheel 1, MODEL.md section 1). Planar
    /// torque and relative rate map to each wheel with MODEL.md section 4.
    Omniwheels {
        /// The drivetrain: geometry, actuator, roller-ball friction.
        params: DrivetrainParams<f64>,
        /// Direction of travel in the body frame (rad), counter-clockwise from +x.
        heading_rad: f64,
    },
}

/// Gradient with respect to the knot variables `[theta, phi, theta_dot, phi_dot, tau]`.
pub(crate) type KnotGradient = [f64; 5];

/// One actuator as seen from the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Motor {
    /// Motor (omniwheel) torque per planar torque.
    pub torque_per_planar: f64,
    /// Motor speed per relative rate `phi_dot - theta_dot`.
    pub speed_per_relative_rate: f64,
    /// Peak torque (N m).
    pub peak_torque_nm: f64,
    /// No-load speed (rad/s).
    pub no_load_speed_rad_per_s: f64,
}

/// Normal forces and tractions at one knot with their gradients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct KnotForces {
    /// Normal force `N_i` (N).
    pub normal_n: [f64; 3],
    /// `d N_i / d v`.
    pub normal_grad: [KnotGradient; 3],
    /// Traction `F_i` of wheel `i` on the ball (N), signed.
    pub traction_n: [f64; 3],
    /// `d F_i / d v`.
    pub traction_grad: [KnotGradient; 3],
}

/// Omniwheel contact geometry for the normal forces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Contacts {
    kin: OmniKinematics<f64>,
    heading_rad: f64,
    /// `kappa`: omniwheel torque per planar torque.
    kappa: Vector3<f64>,
    /// Roller-ball friction coefficient.
    pub wheel_ball_friction: f64,
}

/// All actuators of a drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DriveMap {
    motors: [Motor; 3],
    count: usize,
    pub contacts: Option<Contacts>,
}

impl DriveMap {
    pub fn new(drive: &Drive, ball_radius_m: f64) -> Result<Self, TrajoptError> {
        match *drive {
            Drive::Direct(a) => {
                let m = Motor {
                    torque_per_planar: 1.0,
                    speed_per_relative_rate: 1.0,
                    peak_torque_nm: a.peak_torque_nm,
                    no_load_speed_rad_per_s: a.no_load_speed_rad_per_s,
                };
                Ok(Self {
                    motors: [m; 3],
                    count: 1,
                    contacts: None,
                })
            }
            Drive::Omniwheels {
                params,
                heading_rad,
            } => {
                let kin = OmniKinematics::new(params, ball_radius_m)?;
                let kappa = kin.wheel_torques_nm(&planar_torque_at_heading(heading_rad, 1.0));
                let rho =
                    kin.wheel_speeds_rad_per_s(&relative_rate_at_heading(heading_rad, 1.0, 0.0));
                let motors = core::array::from_fn(|i| Motor {
                    torque_per_planar: kappa[i],
                    speed_per_relative_rate: rho[i],
                    peak_torque_nm: params.actuator.peak_torque_nm,
                    no_load_speed_rad_per_s: params.actuator.no_load_speed_rad_per_s,
                });
                Ok(Self {
                    motors,
                    count: 3,
                    contacts: Some(Contacts {
                        kin,
                        heading_rad,
                        kappa,
                        wheel_ball_friction: params.wheel_ball_friction,
                    }),
                })
            }
        }
    }

    /// Every actuator of the drive (a wheel the plane does not load, like omniwheel 1 in the
    /// sagittal plane, has zero coefficients).
    pub fn motors(&self) -> &[Motor] {
        &self.motors[..self.count]
    }
}

impl Contacts {
    /// Normal forces and tractions at a knot, with their gradients.
    pub fn forces(&self, wip: &Wip<f64>, s: &WipState<f64>, torque_nm: f64) -> KnotForces {
        let p = wip.params();
        let (m, l, r, g) = (
            p.body_mass_kg,
            p.com_height_m,
            p.ball_radius_m,
            p.gravity_m_per_s2,
        );
        let (iw, bm) = (p.wheel_inertia_kg_m2, p.drive_damping_nm_s_per_rad);
        let (st, ct) = s[0].sin_cos();
        let thd = s[2];
        let acc = wip.accelerations(s, torque_nm);
        let lin = wip.linearize(s, torque_nm);
        let row = |k: usize| -> KnotGradient {
            [
                lin.A[(k, 0)],
                lin.A[(k, 1)],
                lin.A[(k, 2)],
                lin.A[(k, 3)],
                lin.B[k],
            ]
        };
        let (g_th, g_ph) = (row(2), row(3));
        let support = planar_support_force_n(p, self.heading_rad, s, &acc);
        // Gradients of the support force's components along travel and up (body frame).
        let mut d_along = [0.0; 5];
        let mut d_up = [0.0; 5];
        let mut d_contact = [0.0; 5];
        for k in 0..5 {
            d_along[k] = m * (r * ct * g_ph[k] + l * g_th[k]);
            d_up[k] = m * r * st * g_ph[k];
            d_contact[k] = -iw * (g_ph[k] - g_th[k]);
        }
        d_along[0] += m * (-r * acc[1] * st - g * ct);
        d_up[0] += m * (r * acc[1] * ct - g * st);
        d_up[2] += -2.0 * m * l * thd;
        d_contact[4] += 1.0;
        d_contact[3] -= bm;
        d_contact[2] += bm;
        let contact_torque = torque_nm - iw * (acc[1] - acc[0]) - bm * (s[3] - s[2]);
        let wheel = self.kappa * contact_torque;
        let normal = self.kin.normal_forces_n(&support, &wheel);
        let (pm, qm): (&Matrix3<f64>, &Matrix3<f64>) = self.kin.normal_force_matrices();
        let travel = kinematics::plane_axis_at_heading(self.heading_rad);
        // e = z x a rotated back: the travel direction is a rotated by -90 deg about z.
        let e = Vector3::new(travel[1], -travel[0], 0.0);
        let q_kappa = qm * self.kappa;
        let rw = self.kin.drivetrain().wheel_radius_m;
        let mut out = KnotForces {
            normal_n: [normal[0], normal[1], normal[2]],
            normal_grad: [[0.0; 5]; 3],
            traction_n: core::array::from_fn(|i| wheel[i] / rw),
            traction_grad: [[0.0; 5]; 3],
        };
        for k in 0..5 {
            let dn = pm * (e * d_along[k] + Vector3::z() * d_up[k]) + q_kappa * d_contact[k];
            for i in 0..3 {
                out.normal_grad[i][k] = dn[i];
                out.traction_grad[i][k] = self.kappa[i] / rw * d_contact[k];
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use ballbot_core::{DrivetrainParams, WipParams};
    use nalgebra::Vector4;

    fn miapure(heading_rad: f64) -> (Wip<f64>, DriveMap) {
        let wip = Wip::new(WipParams::miapure_60kg()).unwrap();
        let map = DriveMap::new(
            &Drive::Omniwheels {
                params: DrivetrainParams::miapure(),
                heading_rad,
            },
            wip.params().ball_radius_m,
        )
        .unwrap();
        (wip, map)
    }

    /// MiaPURE with wheel inertia and drivetrain friction, so every term is exercised.
    fn lossy(heading_rad: f64) -> (Wip<f64>, DriveMap) {
        let params = WipParams {
            wheel_inertia_kg_m2: 0.05,
            drive_damping_nm_s_per_rad: 0.3,
            ball_damping_nm_s_per_rad: 0.2,
            ..WipParams::miapure_60kg()
        };
        let wip = Wip::new(params).unwrap();
        let map = DriveMap::new(
            &Drive::Omniwheels {
                params: DrivetrainParams::miapure(),
                heading_rad,
            },
            params.ball_radius_m,
        )
        .unwrap();
        (wip, map)
    }

    #[test]
    fn static_load_is_shared_equally() {
        let (wip, map) = miapure(0.0);
        let f = map.contacts.unwrap().forces(&wip, &Vector4::zeros(), 0.0);
        for ni in f.normal_n {
            // MODEL.md section 5: m_U g / (3 cos a) = 344 N.
            approx::assert_relative_eq!(ni, 74.3 * 9.81 / (3.0 * 0.5f64.sqrt()), epsilon = 1e-9);
        }
    }

    #[test]
    fn forces_are_the_core_kinematics_contact_forces() {
        let (wip, map) = lossy(0.7);
        let c = map.contacts.unwrap();
        let kin = OmniKinematics::new(DrivetrainParams::miapure(), 0.1145).unwrap();
        for (s, tau) in [
            (Vector4::new(0.1, 0.3, -0.4, 7.0), 12.0),
            (Vector4::new(-0.2, 1.0, 0.8, -3.0), -30.0),
        ] {
            let mine = c.forces(&wip, &s, tau);
            let core = kin.wip_contact_forces(&wip, 0.7, &s, tau);
            for i in 0..3 {
                approx::assert_relative_eq!(
                    mine.normal_n[i],
                    core.wheels[i].normal_force_n,
                    max_relative = 1e-12
                );
                approx::assert_relative_eq!(
                    mine.traction_n[i],
                    core.wheels[i].traction_n,
                    epsilon = 1e-9
                );
            }
        }
    }

    #[test]
    fn sagittal_torque_capacity_is_96_9_nm() {
        let (_, map) = miapure(0.0);
        let cap = map
            .motors()
            .iter()
            .map(|m| m.peak_torque_nm / m.torque_per_planar.abs().max(1e-300))
            .fold(f64::INFINITY, f64::min);
        approx::assert_relative_eq!(cap, 96.9, epsilon = 0.05);
    }

    #[test]
    fn motor_power_equals_planar_power() {
        let (_, map) = miapure(0.7);
        let (tau, rate) = (3.0, -2.0);
        let p: f64 = map
            .motors()
            .iter()
            .map(|m| m.torque_per_planar * tau * m.speed_per_relative_rate * rate)
            .sum();
        approx::assert_relative_eq!(p, tau * rate, epsilon = 1e-12);
    }

    #[test]
    fn accelerating_towards_wheel_one_unloads_the_other_two() {
        let (wip, map) = miapure(0.0);
        let c = map.contacts.unwrap();
        for torque_nm in [-20.0, 20.0] {
            // Upright at rest: the COM accelerates along travel by r phi_ddot + l theta_ddot.
            let s = Vector4::zeros();
            let qdd = wip.accelerations(&s, torque_nm);
            let a_e = 0.1145 * qdd[1] + 0.5 * qdd[0];
            let n = c.forces(&wip, &s, torque_nm).normal_n;
            // Towards OW1 (+x) loads OW1 and unloads OW2 and OW3 (MODEL.md section 5).
            assert!((n[0] - n[1]) * a_e > 0.0, "{n:?} {a_e}");
            approx::assert_relative_eq!(n[1], n[2], epsilon = 1e-9);
            // Upright with no tilt rate: the vertical load is the weight.
            let vertical: f64 = n.iter().map(|ni| ni * 0.5f64.sqrt()).sum();
            approx::assert_relative_eq!(vertical, 74.3 * 9.81, epsilon = 1e-9);
        }
    }

    #[test]
    fn gradients_match_finite_differences() {
        let (wip, map) = lossy(0.4);
        let c = map.contacts.unwrap();
        let s = Vector4::new(0.1, 0.3, -0.4, 7.0);
        let tau = 12.0;
        let f = c.forces(&wip, &s, tau);
        for k in 0..5 {
            let h = 1e-6;
            let (mut sp, mut sm) = (s, s);
            let (mut tp, mut tm) = (tau, tau);
            if k < 4 {
                sp[k] += h;
                sm[k] -= h;
            } else {
                tp += h;
                tm -= h;
            }
            let (fp, fm) = (c.forces(&wip, &sp, tp), c.forces(&wip, &sm, tm));
            for i in 0..3 {
                let fd = (fp.normal_n[i] - fm.normal_n[i]) / (2.0 * h);
                approx::assert_relative_eq!(
                    f.normal_grad[i][k],
                    fd,
                    epsilon = 1e-5,
                    max_relative = 1e-6
                );
                let fd = (fp.traction_n[i] - fm.traction_n[i]) / (2.0 * h);
                approx::assert_relative_eq!(
                    f.traction_grad[i][k],
                    fd,
                    epsilon = 1e-5,
                    max_relative = 1e-6
                );
            }
        }
    }
}
