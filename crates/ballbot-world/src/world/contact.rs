//! The omniwheel-ball contact: compliant normal force, traction along the rolling direction,
//! optional roller losses along the axle, both bounded by one friction cone, with stick and
//! kinetic slip.
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
//! * Normal force (unilateral, [`NormalLaw`]): while `delta > 0` either the linear
//!   Kelvin-Voigt `N = max(0, k delta + c_n delta_dot)` (the ideal world's stiff contact) or
//!   the ball coating's law over its whole range, `N = max(0, F(delta) + c(delta) delta_dot)`
//!   with `F` the Hertz plus thin-layer law of [`CoatingLaw`] and `c = eta k(delta) / omega_0`
//!   (the default world's); else 0 (lift-off). The normal forces are therefore outputs of the
//!   dynamics: they follow acceleration and lean and can reach zero.
//! * Traction along `d`: the slip velocity `s = d . (v_ball(p) - v_rim(p))` (ball surface minus wheel
//!   rim, the rim moving with the body plus `r_W psi_dot d`) feeds an elasto-plastic
//!   (bristle) friction law with deflection state `z` (`z_dot = s` while sticking):
//!   `F_stick = -(k_t z + c_t s)`.
//! * Along the axle `a` the rollers turn freely; the only force there is their rolling and
//!   pin loss `F_a = -C_a N s_a / max(|s_a|, s_eps)` with the axle slip
//!   `s_a = a . (v_ball(p) - v_rim(p))` ([`crate::world::axle_loss`]; `C_a = 0` in the ideal
//!   world, where no force acts along `a`).
//! * One friction cone for both: if `|(F_stick, F_a)| <= mu N` the contact sticks and
//!   `F = F_stick`. Otherwise the whole contact slides (isotropic Coulomb friction): the
//!   force keeps the direction of the demand `(F_stick, F_a)` and takes the kinetic magnitude
//!   `mu_k N`, so both components shrink by the same factor, and the bristle is reset to the
//!   slide limit `z = -F / k_t`. Without axle losses this is `F = mu_k N sign(F_stick)`.
//!
//! `F` and `F_a` are the forces the wheel applies to the ball along `d` and `a`; the body
//! receives `-(N n + F d + F_a a)` at `p`.
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
//!
//! The realistic mechanisms stay inside these bounds at 8 kHz: the rubber-coated contact
//! ([`crate::world::rubber`], 3.4e5 N/m) is six times softer (`omega dt` = 0.05); the axle
//! losses' linear zone is a damper `C_a N / s_eps` with `C_a N dt / (s_eps m_eff)` = 0.5 at
//! 1000 N ([`crate::world::axle_loss`]); the roller gaps ([`crate::world::rollers`]) move the
//! effective radius by 50 um over 25 steps at 10 rad/s and leave the stiffness as it is. At a
//! gap's centre the contact jumps between roller ends within one step, an energy error of at
//! most `N d(dip)/d(psi) psi_dot dt` per passage (0.4 mJ at 3 rad/s).

use super::rubber::CoatingLaw;
use rapier3d_f64::glamx::DVec3;

/// How the normal force follows the penetration `delta` and its rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalLaw {
    /// The linear spring-damper `N = max(0, k delta + c delta_dot)`.
    Linear {
        /// `k` (N/m).
        stiffness_n_per_m: f64,
        /// `c` (N s/m).
        damping_n_s_per_m: f64,
    },
    /// The rubber coating's law ([`CoatingLaw`]) with the loss factor's damping:
    /// `N = max(0, F(delta) + damping_secs k(delta) delta_dot)`, `k = dF/d delta`.
    Coating {
        /// The force-deflection law.
        law: CoatingLaw,
        /// `eta / omega_0` (s): damping per unit of tangent stiffness.
        damping_secs: f64,
    },
}

impl NormalLaw {
    /// The normal force at penetration `penetration_m` > 0 and its rate (N, >= 0).
    #[inline]
    pub fn force_n(&self, penetration_m: f64, rate_m_per_s: f64) -> f64 {
        match *self {
            Self::Linear {
                stiffness_n_per_m,
                damping_n_s_per_m,
            } => (stiffness_n_per_m * penetration_m + damping_n_s_per_m * rate_m_per_s).max(0.0),
            Self::Coating { law, damping_secs } => law
                .evaluate(penetration_m)
                .damped_normal_n(rate_m_per_s, damping_secs),
        }
    }

    /// The elastic energy stored at `penetration_m` (J; 0 when not pressed).
    pub fn energy_j(&self, penetration_m: f64) -> f64 {
        match *self {
            Self::Linear {
                stiffness_n_per_m, ..
            } => 0.5 * stiffness_n_per_m * penetration_m.max(0.0).powi(2),
            Self::Coating { law, .. } => law.energy_j(penetration_m),
        }
    }

    /// The penetration that carries `load_n` at rest (m).
    pub fn deflection_m(&self, load_n: f64) -> f64 {
        match *self {
            Self::Linear {
                stiffness_n_per_m, ..
            } => load_n.max(0.0) / stiffness_n_per_m,
            Self::Coating { law, .. } => law.deflection_m(load_n),
        }
    }

    /// The tangent stiffness `dN/d delta` at rest under `load_n` (N/m).
    pub fn stiffness_n_per_m(&self, load_n: f64) -> f64 {
        match *self {
            Self::Linear {
                stiffness_n_per_m, ..
            } => stiffness_n_per_m,
            Self::Coating { law, .. } => law.evaluate(law.deflection_m(load_n)).stiffness_n_per_m,
        }
    }
}

/// Per-wheel contact parameters resolved for fast evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// The normal force's law.
    pub normal: NormalLaw,
    /// Stick stiffness (N/m).
    pub traction_stiffness_n_per_m: f64,
    /// Stick damping (N s/m).
    pub traction_damping_n_s_per_m: f64,
    /// Static friction coefficient `mu` (roller on ball).
    pub static_friction: f64,
    /// Kinetic friction coefficient `mu_k`.
    pub kinetic_friction: f64,
    /// Axle loss per unit normal force `C_a` (0: the rollers turn freely).
    pub axle_loss_coefficient: f64,
    /// Axle slip speed below which the axle loss is linear in the slip `s_eps` (m/s), > 0.
    pub axle_regularisation_speed_m_per_s: f64,
}

/// The kinematic inputs of one contact, all in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactKinematics {
    /// Unit normal from the ball centre to the contact.
    pub normal: DVec3,
    /// Unit rolling direction of the wheel at the contact.
    pub rolling_dir: DVec3,
    /// Unit axle direction in the contact plane, `d x n` (the body's axle `a` projected
    /// normal to `n`).
    pub axle_dir: DVec3,
    /// Penetration `delta` (m), positive when pressed.
    pub penetration_m: f64,
    /// Penetration rate `delta_dot` (m/s).
    pub penetration_rate_m_per_s: f64,
    /// Slip velocity along the rolling direction, ball surface minus wheel rim (m/s).
    pub slip_speed_m_per_s: f64,
    /// Slip velocity along the axle, ball surface minus wheel rim (m/s).
    pub axle_slip_speed_m_per_s: f64,
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
    /// Force `F_a` the wheel applies to the ball along its axle (N): the rollers' losses.
    pub axle_force_n: f64,
    /// `|(F, F_a)| / (mu N)`: how much of the friction cone is used (0 when `N = 0`).
    pub cone_utilisation: f64,
    /// Whether the contact slips (demand beyond `mu N`, or lifted off with slip).
    pub slipping: bool,
}

impl ContactLaw {
    /// Evaluates the law for one contact and advances its bristle deflection `z` (m) by
    /// `dt_secs`.
    #[inline]
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
        let normal_force_n = self
            .normal
            .force_n(kin.penetration_m, kin.penetration_rate_m_per_s);
        let demand = -(self.traction_stiffness_n_per_m * *bristle_m
            + self.traction_damping_n_s_per_m * kin.slip_speed_m_per_s);
        let axle_demand =
            -self.axle_loss_coefficient * normal_force_n * kin.axle_slip_speed_m_per_s
                / kin
                    .axle_slip_speed_m_per_s
                    .abs()
                    .max(self.axle_regularisation_speed_m_per_s);
        let limit = self.static_friction * normal_force_n;
        // |(F_stick, F_a)|; a norm only when there is an axle force (the ideal world's rollers
        // are free, and abs is exact and cheaper there). The forces are far from overflow, so
        // the plain square root does (libm's hypot cost a twentieth of the world step).
        let demand_norm = if axle_demand == 0.0 {
            demand.abs()
        } else {
            (demand * demand + axle_demand * axle_demand).sqrt()
        };
        let (traction_n, axle_force_n, slipping) = if demand_norm <= limit {
            *bristle_m += kin.slip_speed_m_per_s * dt_secs;
            (demand, axle_demand, false)
        } else {
            // Slide along the demand's direction with the kinetic magnitude. Without axle
            // losses demand / |demand| is exactly +-1, so F = mu_k N sign(F_stick) bit for bit.
            let kinetic = self.kinetic_friction * normal_force_n;
            let f = kinetic * (demand / demand_norm);
            *bristle_m = -f / self.traction_stiffness_n_per_m;
            (f, kinetic * (axle_demand / demand_norm), true)
        };
        let cone_utilisation = if limit > 0.0 {
            if axle_force_n == 0.0 {
                traction_n.abs() / limit
            } else {
                (traction_n * traction_n + axle_force_n * axle_force_n).sqrt() / limit
            }
        } else {
            0.0
        };
        ContactOutput {
            normal_force_n,
            traction_n,
            traction_demand_n: demand,
            axle_force_n,
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
            normal: NormalLaw::Linear {
                stiffness_n_per_m: 1e6,
                damping_n_s_per_m: 0.0,
            },
            traction_stiffness_n_per_m: 1e5,
            traction_damping_n_s_per_m: 0.0,
            static_friction: 0.5,
            kinetic_friction: 0.4,
            axle_loss_coefficient: 0.0,
            axle_regularisation_speed_m_per_s: 0.01,
        }
    }

    /// The same law with axle losses `C_a` = 0.1.
    fn lossy() -> ContactLaw {
        ContactLaw {
            axle_loss_coefficient: 0.1,
            ..law()
        }
    }

    fn kin(pen: f64, slip: f64) -> ContactKinematics {
        ContactKinematics {
            normal: DVec3::Z,
            rolling_dir: DVec3::X,
            axle_dir: DVec3::NEG_Y,
            penetration_m: pen,
            penetration_rate_m_per_s: 0.0,
            slip_speed_m_per_s: slip,
            axle_slip_speed_m_per_s: 0.0,
        }
    }

    fn kin_axle(pen: f64, slip: f64, axle_slip: f64) -> ContactKinematics {
        ContactKinematics {
            axle_slip_speed_m_per_s: axle_slip,
            ..kin(pen, slip)
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

    #[test]
    fn axle_force_opposes_the_axle_slip_and_saturates() {
        // N = 100 N, C_a = 0.1: 10 N beyond s_eps = 0.01 m/s, linear below.
        for (axle_slip, expected) in [(0.5, -10.0), (-0.02, 10.0), (0.005, -5.0), (0.0, 0.0)] {
            let mut z = 0.0;
            let out = lossy().evaluate(&kin_axle(1e-4, 0.0, axle_slip), &mut z, 1e-3);
            assert!(
                (out.axle_force_n - expected).abs() < 1e-9,
                "{axle_slip}: {out:?}"
            );
            assert!(out.axle_force_n * axle_slip <= 0.0, "never positive work");
        }
        let mut z = 0.0;
        let ideal = law().evaluate(&kin_axle(1e-4, 0.0, 0.5), &mut z, 1e-3);
        assert_eq!(ideal.axle_force_n, 0.0, "free rollers");
    }

    #[test]
    fn the_cone_bounds_the_vector_sum() {
        // N = 100 N, mu N = 50 N, axle force 10 N. Traction demand 45 N alone sticks; with the
        // axle force |(45, 10)| = 46.1 N still sticks and the cone use is 46.1 / 50.
        let mut z = -4.5e-4;
        let out = lossy().evaluate(&kin_axle(1e-4, 0.0, 1.0), &mut z, 1e-3);
        assert!(!out.slipping);
        let expected = 45.0_f64.hypot(10.0) / 50.0;
        assert!((out.cone_utilisation - expected).abs() < 1e-12, "{out:?}");
        // Demand 49 N: alone it sticks, with the axle force |(49, 10)| = 50.01 N > 50 N it
        // slides: both components scaled to the kinetic 40 N along the demand.
        let mut z = -4.9e-4;
        let alone = law().evaluate(&kin_axle(1e-4, 0.0, 1.0), &mut z, 1e-3);
        assert!(!alone.slipping);
        let mut z = -4.9e-4;
        let out = lossy().evaluate(&kin_axle(1e-4, 0.0, 1.0), &mut z, 1e-3);
        assert!(out.slipping, "{out:?}");
        let norm = 49.0_f64.hypot(10.0);
        assert!(
            (out.traction_n - 40.0 * 49.0 / norm).abs() < 1e-9,
            "{out:?}"
        );
        assert!(
            (out.axle_force_n + 40.0 * 10.0 / norm).abs() < 1e-9,
            "{out:?}"
        );
        assert!(
            (out.cone_utilisation - 0.8).abs() < 1e-12,
            "kinetic over static"
        );
        assert!(
            (z + out.traction_n / 1e5).abs() < 1e-15,
            "bristle at the slide limit"
        );
    }

    #[test]
    fn contact_forces_never_feed_energy_into_the_slip() {
        // Power of the tangential forces on the relative motion, F s + F_a s_a, is <= 0 for
        // a contact at zero bristle deflection (only damping and losses act), sticking or not.
        let mut l = lossy();
        l.traction_damping_n_s_per_m = 200.0;
        for slip in [-1.0, -0.1, 0.0, 0.05, 2.0] {
            for axle_slip in [-3.0, -0.004, 0.0, 0.3] {
                let mut z = 0.0;
                let out = l.evaluate(&kin_axle(1e-4, slip, axle_slip), &mut z, 1e-3);
                let power = out.traction_n * slip + out.axle_force_n * axle_slip;
                assert!(power <= 0.0, "{slip} {axle_slip}: {power}");
            }
        }
    }

    #[test]
    fn lift_off_gives_no_axle_force() {
        let mut z = 0.0;
        let out = lossy().evaluate(&kin_axle(-1e-5, 0.0, 0.3), &mut z, 1e-3);
        assert_eq!(out.axle_force_n, 0.0);
        assert_eq!(out.cone_utilisation, 0.0);
    }
}
