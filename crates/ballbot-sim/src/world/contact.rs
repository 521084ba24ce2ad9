//! The omniwheel-ball contact: compliant normal force, traction only along the rolling
//! direction, bounded by the friction cone, with stick and kinetic slip.
//!
//! # Model
//!
//! Each omniwheel is a rim of radius `r_W` whose centre `w` is fixed in the body at
//! `(r + r_W) n_i` from the nominal ball centre (MODEL.md section 1: `n_i` is the nominal
//! contact normal). With ball centre `c` and radius `r`, the contact normal is
//! `n = (w - c) / |w - c|`, the penetration `delta = r + r_W - |w - c|` and the contact point
//! `p = c + r n`. The wheel's axle `a_i = d_i x n_i` is body-fixed; the rolling direction is
//! `d = n x a` (normalised), the direction a positive wheel speed moves the rim at `p`.
//!
//! * Normal force (Kelvin-Voigt, unilateral): `N = max(0, k delta + c_n delta_dot)` while
//!   `delta > 0`, else 0 (lift-off). The normal forces are therefore outputs of the dynamics:
//!   they follow acceleration and lean and can reach zero.
//! * Traction along `d` only: the rollers leave the axle direction free, so no force acts
//!   along `a`. The slip velocity `s = d . (v_ball(p) - v_rim(p))` (ball surface minus wheel
//!   rim, the rim moving with the body plus `r_W psi_dot d`) feeds an elasto-plastic
//!   (bristle) friction law with deflection state `z` (`z_dot = s` while sticking):
//!   `F_stick = -(k_t z + c_t s)`. If `|F_stick| <= mu N` the contact sticks and
//!   `F = F_stick`; otherwise it slips, `F = mu_k N sign(F_stick)` and the bristle is reset to
//!   the slide limit `z = -F / k_t`. `F` is the force the wheel applies to the ball along `d`;
//!   the body receives `-(N n + F d)` at `p`.
//!
//! # Step size
//!
//! The forces are explicit in the state, integrated by a semi-implicit Euler step. With the
//! defaults (`k = 2e6 N/m`, `k_t = 5e5 N/m`) and the smallest effective masses in the loop
//! (ball against body about 3.4 kg for the normal mode, ball surface against wheel rim about
//! 1 kg for the tangential mode) the highest frequencies are about 950 and 710 rad/s, so the
//! step must satisfy `omega dt << 2`; at the default 8 kHz `omega dt` is about 0.12. Halving
//! the step is needed for stiffnesses four times higher. The stick damping adds the bound
//! `c_t dt / m_eff < 1` (0.15 at the defaults).

use rapier3d_f64::glamx::DVec3;

/// Per-wheel contact parameters resolved for fast evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// Normal stiffness (N/m).
    pub normal_stiffness_n_per_m: f64,
    /// Normal damping (N s/m).
    pub normal_damping_n_s_per_m: f64,
    /// Stick stiffness (N/m).
    pub traction_stiffness_n_per_m: f64,
    /// Stick damping (N s/m).
    pub traction_damping_n_s_per_m: f64,
    /// Static friction coefficient `mu` (roller on ball).
    pub static_friction: f64,
    /// Kinetic friction coefficient `mu_k`.
    pub kinetic_friction: f64,
}

/// The kinematic inputs of one contact, all in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactKinematics {
    /// Unit normal from the ball centre to the contact.
    pub normal: DVec3,
    /// Unit rolling direction of the wheel at the contact.
    pub rolling_dir: DVec3,
    /// Penetration `delta` (m), positive when pressed.
    pub penetration_m: f64,
    /// Penetration rate `delta_dot` (m/s).
    pub penetration_rate_m_per_s: f64,
    /// Slip velocity along the rolling direction, ball surface minus wheel rim (m/s).
    pub slip_speed_m_per_s: f64,
}

/// What the contact law produced for one wheel in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOutput {
    /// Normal force `N` (N), >= 0.
    pub normal_force_n: f64,
    /// Traction `F` the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// The traction the contact would need to keep sticking, `F_stick` (N).
    pub traction_demand_n: f64,
    /// `|F| / (mu N)`: how much of the friction cone is used (0 when `N = 0`).
    pub cone_utilisation: f64,
    /// Whether the contact slips (demand beyond `mu N`, or lifted off with slip).
    pub slipping: bool,
}

impl ContactLaw {
    /// Evaluates the law for one contact and advances its bristle deflection `z` (m) by
    /// `dt_secs`.
    pub fn evaluate(
        &self,
        kin: &ContactKinematics,
        bristle_m: &mut f64,
        dt_secs: f64,
    ) -> ContactOutput {
        if kin.penetration_m <= 0.0 {
            *bristle_m = 0.0;
            return ContactOutput {
                slipping: kin.slip_speed_m_per_s.abs() > 0.0,
                ..ContactOutput::default()
            };
        }
        let normal_force_n = (self.normal_stiffness_n_per_m * kin.penetration_m
            + self.normal_damping_n_s_per_m * kin.penetration_rate_m_per_s)
            .max(0.0);
        let demand = -(self.traction_stiffness_n_per_m * *bristle_m
            + self.traction_damping_n_s_per_m * kin.slip_speed_m_per_s);
        let limit = self.static_friction * normal_force_n;
        let (traction_n, slipping) = if demand.abs() <= limit {
            *bristle_m += kin.slip_speed_m_per_s * dt_secs;
            (demand, false)
        } else {
            let f = (self.kinetic_friction * normal_force_n).copysign(demand);
            *bristle_m = -f / self.traction_stiffness_n_per_m;
            (f, true)
        };
        let cone_utilisation = if limit > 0.0 {
            traction_n.abs() / limit
        } else {
            0.0
        };
        ContactOutput {
            normal_force_n,
            traction_n,
            traction_demand_n: demand,
            cone_utilisation,
            slipping,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> ContactLaw {
        ContactLaw {
            normal_stiffness_n_per_m: 1e6,
            normal_damping_n_s_per_m: 0.0,
            traction_stiffness_n_per_m: 1e5,
            traction_damping_n_s_per_m: 0.0,
            static_friction: 0.5,
            kinetic_friction: 0.4,
        }
    }

    fn kin(pen: f64, slip: f64) -> ContactKinematics {
        ContactKinematics {
            normal: DVec3::Z,
            rolling_dir: DVec3::X,
            penetration_m: pen,
            penetration_rate_m_per_s: 0.0,
            slip_speed_m_per_s: slip,
        }
    }

    #[test]
    fn sticks_inside_the_cone_and_slips_beyond() {
        // N = 100 N, mu N = 50 N: bristle at 4e-4 m demands 40 N (stick), 6e-4 m 60 N (slip).
        let l = law();
        let mut z = 4e-4;
        let out = l.evaluate(&kin(1e-4, 0.0), &mut z, 1e-3);
        assert!((out.normal_force_n - 100.0).abs() < 1e-9);
        assert!(!out.slipping);
        assert!((out.traction_n + 40.0).abs() < 1e-9);
        let mut z = 6e-4;
        let out = l.evaluate(&kin(1e-4, 0.0), &mut z, 1e-3);
        assert!(out.slipping);
        assert!((out.traction_n + 40.0).abs() < 1e-9, "kinetic 0.4 * 100");
        assert!((z - 4e-4).abs() < 1e-12, "bristle reset to the slide limit");
    }

    #[test]
    fn lift_off_gives_no_force() {
        let mut z = 1e-3;
        let out = law().evaluate(&kin(-1e-5, 0.3), &mut z, 1e-3);
        assert_eq!(out.normal_force_n, 0.0);
        assert_eq!(out.traction_n, 0.0);
        assert_eq!(z, 0.0);
    }
}
