//! Planar torque and rate mapped to the actuators, and the omniwheel contact forces.
//!
//! For travel at heading `h` the planar torque vector is `tau e_perp`, `e_perp = [-sin h,
//! cos h, 0]`, and the relative rate is `(phi_dot - theta_dot) e_perp`. MODEL.md section 4 then
//! gives each omniwheel's torque and speed:
//!
//! ```text
//! tau_i = kappa_i tau,        kappa_i = 2 r_W sin(h - beta_i) / (3 r_S cos a)
//! psi_dot_i = rho_i (phi_dot - theta_dot),   rho_i = (r_S / r_W) cos a sin(h - beta_i)
//! ```
//!
//! (so `sum tau_i psi_dot_i = tau (phi_dot - theta_dot)`). Traction on the body at wheel `i` is
//! `F_i = -tau_i / r_W` along `d_i`, so that its moment about the ball centre,
//! `sum r_S F_i u_i`, is the `-tau e_perp` the body feels. The normal forces follow from the
//! body's force balance (MODEL.md section 5), written in body coordinates:
//! `sum_i N_i n_i + sum_i F_i d_i = m_U (a_COM + g e_z)`, with the body COM acceleration of the
//! WIP, `a_e = r phi_ddot + l (cos th th_ddot - sin th th_dot^2)`,
//! `a_z = -l (sin th th_ddot + cos th th_dot^2)`, rotated by the tilt into the body frame.

use super::problem::Drive;
use ballbot_core::{Wip, WipState};
use nalgebra::{Matrix3, Vector3};

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
    /// Traction force on the body per planar torque (N per N m), omniwheels only.
    pub traction_per_planar: f64,
}

/// Omniwheel contact geometry for the normal forces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Contacts {
    /// Inverse of the matrix whose columns are the contact normals `n_i` (body frame).
    normals_inv: Matrix3<f64>,
    /// `sum_i (F_i / tau) d_i`: the traction force on the body per planar torque.
    traction_per_planar: Vector3<f64>,
    /// Travel direction in the body frame.
    travel: Vector3<f64>,
    /// Roller-ball friction coefficient.
    pub friction: f64,
}

/// All actuators of a drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DriveMap {
    motors: [Motor; 3],
    count: usize,
    pub contacts: Option<Contacts>,
}

impl DriveMap {
    pub fn new(drive: &Drive, ball_radius_m: f64) -> Self {
        match *drive {
            Drive::Direct(a) => {
                let m = Motor {
                    torque_per_planar: 1.0,
                    speed_per_relative_rate: 1.0,
                    peak_torque_nm: a.peak_torque_nm,
                    no_load_speed_rad_per_s: a.no_load_speed_rad_per_s,
                    traction_per_planar: 0.0,
                };
                Self {
                    motors: [m; 3],
                    count: 1,
                    contacts: None,
                }
            }
            Drive::Omniwheels {
                params,
                heading_rad,
            } => {
                let (sa, ca) = params.contact_angle_rad.sin_cos();
                let rs = ball_radius_m;
                let rw = params.wheel_radius_m;
                let mut normals = Matrix3::zeros();
                let mut traction = Vector3::zeros();
                let motors = core::array::from_fn(|i| {
                    let beta = params.wheel_azimuths_rad[i];
                    let (sb, cb) = beta.sin_cos();
                    let s = (heading_rad - beta).sin();
                    let kappa = 2.0 * rw * s / (3.0 * rs * ca);
                    normals.set_column(i, &Vector3::new(sa * cb, sa * sb, ca));
                    let f = -kappa / rw;
                    traction += Vector3::new(-sb, cb, 0.0) * f;
                    Motor {
                        torque_per_planar: kappa,
                        speed_per_relative_rate: rs / rw * ca * s,
                        peak_torque_nm: params.actuator.peak_torque_nm,
                        no_load_speed_rad_per_s: params.actuator.no_load_speed_rad_per_s,
                        traction_per_planar: f,
                    }
                });
                // The layout was validated non-singular (DrivetrainParams::validate); a
                // failure here leaves the normal forces at the static share.
                let normals_inv = normals.try_inverse().unwrap_or_else(Matrix3::zeros);
                let (sh, ch) = heading_rad.sin_cos();
                Self {
                    motors,
                    count: 3,
                    contacts: Some(Contacts {
                        normals_inv,
                        traction_per_planar: traction,
                        travel: Vector3::new(ch, sh, 0.0),
                        friction: params.wheel_ball_friction,
                    }),
                }
            }
        }
    }

    /// The actuators that carry load in this plane (a wheel whose axle is along the travel,
    /// like omniwheel 1 in the sagittal plane, is skipped for torque limits).
    pub fn motors(&self) -> &[Motor] {
        &self.motors[..self.count]
    }
}

impl Contacts {
    /// Normal forces `N_i` (N) and their gradients with respect to the knot variables.
    pub fn normal_forces(
        &self,
        wip: &Wip<f64>,
        s: &WipState<f64>,
        torque_nm: f64,
    ) -> ([f64; 3], [KnotGradient; 3]) {
        let p = wip.params();
        let (m, l, r, g) = (
            p.body_mass_kg,
            p.com_height_m,
            p.ball_radius_m,
            p.gravity_m_per_s2,
        );
        let (st, ct) = s[0].sin_cos();
        let thd = s[2];
        let qdd = wip.accelerations(s, torque_nm);
        let lin = wip.linearize(s, torque_nm);
        let grad_row = |row: usize| -> KnotGradient {
            [
                lin.A[(row, 0)],
                lin.A[(row, 1)],
                lin.A[(row, 2)],
                lin.A[(row, 3)],
                lin.B[row],
            ]
        };
        let g_th = grad_row(2);
        let g_ph = grad_row(3);
        // COM acceleration in the world (travel, vertical).
        let a_e = r * qdd[1] + l * (ct * qdd[0] - st * thd * thd);
        let a_z = -l * (st * qdd[0] + ct * thd * thd);
        let mut da_e = [0.0; 5];
        let mut da_z = [0.0; 5];
        for k in 0..5 {
            da_e[k] = r * g_ph[k] + l * ct * g_th[k];
            da_z[k] = -l * st * g_th[k];
        }
        da_e[0] += l * (-st * qdd[0] - ct * thd * thd);
        da_e[2] += -2.0 * l * st * thd;
        da_z[0] += -l * (ct * qdd[0] - st * thd * thd);
        da_z[2] += -2.0 * l * ct * thd;
        let pe = m * a_e;
        let pz = m * (a_z + g);
        // Into the tilted body frame.
        let pb_e = pe * ct - pz * st;
        let pb_z = pe * st + pz * ct;
        let mut dpb_e = [0.0; 5];
        let mut dpb_z = [0.0; 5];
        for k in 0..5 {
            dpb_e[k] = m * (ct * da_e[k] - st * da_z[k]);
            dpb_z[k] = m * (st * da_e[k] + ct * da_z[k]);
        }
        dpb_e[0] += -pe * st - pz * ct;
        dpb_z[0] += pe * ct - pz * st;
        let rhs = self.travel * pb_e + Vector3::z() * pb_z - self.traction_per_planar * torque_nm;
        let n = self.normals_inv * rhs;
        let mut grads = [[0.0; 5]; 3];
        for k in 0..5 {
            let mut d = self.travel * dpb_e[k] + Vector3::z() * dpb_z[k];
            if k == 4 {
                d -= self.traction_per_planar;
            }
            let dn = self.normals_inv * d;
            for (i, gr) in grads.iter_mut().enumerate() {
                gr[k] = dn[i];
            }
        }
        ([n[0], n[1], n[2]], grads)
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
        );
        (wip, map)
    }

    #[test]
    fn static_load_is_shared_equally() {
        let (wip, map) = miapure(0.0);
        let (n, _) = map
            .contacts
            .unwrap()
            .normal_forces(&wip, &Vector4::zeros(), 0.0);
        for ni in n {
            // MODEL.md section 5: m_U g / (3 cos a) = 344 N.
            approx::assert_relative_eq!(ni, 74.3 * 9.81 / (3.0 * 0.5f64.sqrt()), epsilon = 1e-9);
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
            let (n, _) = c.normal_forces(&wip, &s, torque_nm);
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
        let (wip, map) = miapure(0.4);
        let c = map.contacts.unwrap();
        let s = Vector4::new(0.1, 0.3, -0.4, 7.0);
        let tau = 12.0;
        let (_, grads) = c.normal_forces(&wip, &s, tau);
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
            let (np, _) = c.normal_forces(&wip, &sp, tp);
            let (nm, _) = c.normal_forces(&wip, &sm, tm);
            for i in 0..3 {
                let fd = (np[i] - nm[i]) / (2.0 * h);
                approx::assert_relative_eq!(grads[i][k], fd, epsilon = 1e-5, max_relative = 1e-6);
            }
        }
    }
}
