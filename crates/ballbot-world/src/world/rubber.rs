//! Normal stiffness and damping of the omniwheel contact from the ball's rubber coating.
//!
//! # Model
//!
//! MiaPURE's ball is a bowling ball covered with 6.35 mm of 60A SBR (paper, lines 85-91); the
//! rollers are TPU, far stiffer than 60A rubber and taken as rigid, like the bowling ball under
//! the layer. So the contact compliance is that of a thin, bonded, incompressible layer
//! indented by a rigid roller:
//!
//! 1. **Modulus from hardness** (A. N. Gent, Trans. Inst. Rubber Ind. 34:46, 1958):
//!    `E = 0.0981 (56 + 7.62336 S) / (0.137505 (254 - 2.54 S))` MPa for Shore A hardness `S`;
//!    60A gives `E` = 3.61 MPa, and the shear modulus of the incompressible rubber is
//!    `G = E / 3` = 1.20 MPa.
//! 2. **Contact curvature**: in the wheel plane the roller profile follows the rim (radius
//!    `r_W`), across it the roller's own radius `r_roller`; against the ball (radius `R`) the
//!    relative radii are `R_x = 1 / (1/r_W + 1/R)` and `R_y = 1 / (1/r_roller + 1/R)`, combined
//!    as the equivalent radius `R_e = sqrt(R_x R_y)` (40.4 mm, 10.0 mm, 20.1 mm).
//! 3. **Thin bonded layer** (K. L. Johnson, *Contact Mechanics*, CUP 1985, section 5.9): for a
//!    layer of thickness `t` much thinner than the contact, bonded to a rigid base and pressed
//!    by a frictionless rigid body, the pressure obeys `lap p = -3 G w / t^3` with the
//!    indentation `w = delta - r^2 / (2 R_e)`. With `p = dp/dr = 0` at the contact radius
//!    `a`: `delta = a^2 / (4 R_e)`, `p = 3 G (a^2 - r^2)^2 / (32 R_e t^3)` and
//!    `F = 2 pi G R_e^2 delta^3 / t^3`.
//! 4. **Linearised at the static load** (the named variant
//!    [`ContactParams::rubber_coated`](crate::world::ContactParams::rubber_coated), the default
//!    world's contact before the whole-range law of item 6): `F_0 = m_U g / (3 cos alpha)`
//!    (343.6 N), `delta_0 = (F_0 t^3 / (2 pi G R_e^2))^(1/3)` = 3.1 mm and
//!    `k = dF/d delta = 3 F_0 / delta_0` = 3.4e5 N/m. The contact radius
//!    `a = 2 sqrt(R_e delta_0)` = 15.7 mm is 2.5 layer thicknesses, where the thin-layer limit
//!    is fair; Hertz's half-space value (`a << t`), `(6 F_0 E*^2 R_e)^(1/3)` with `E* = 4E/3`,
//!    is 1.0e5 N/m, a lower bound. A roller that grips the rubber (no slip at the top face)
//!    would be 4^(1/3) = 1.59 times stiffer. The linear spring keeps the static force but not
//!    the static deflection (1.0 mm instead of 3.1 mm): it lifts off early.
//! 5. **Damping from the loss factor** `eta`: a hysteretic spring `k (1 + i eta)` dissipates
//!    per cycle what a viscous `c = eta k / omega` does at the frequency `omega` of the mode it
//!    carries. That mode is the ball against the body (effective mass `m_b m_U / (m_b + m_U)`,
//!    3.4 kg) on the three contacts' vertical stiffness `3 k cos^2 alpha`: `omega` = 383 rad/s
//!    (61 Hz) for the linearised law, `c` = 88 N s/m, damping ratio `eta / 2` = 0.05. With the
//!    whole-range law `c = (eta / omega_0) k(delta)` follows the tangent, `omega_0` taken on
//!    the tangent at the static load.
//! 6. **The whole range** ([`CoatingLaw`], the default world's wheel contacts and the ball
//!    on the floor): the thin-layer law holds once the patch is several layer thicknesses
//!    wide, Hertz's half-space law `F = (4/3) E* sqrt(R_e) delta^1.5` (`E* = 4 G` for the
//!    incompressible rubber on a rigid body; Johnson, section 4.2) while it is much narrower.
//!    Their sum keeps each limit and is our interpolation between them.
//!    - Under a roller (`R_e` 20.1 mm) the static 343.6 N compresses the layer by 2.64 mm
//!      (the thin layer alone: 3.06 mm), the Hertz term carrying 36 %; the tangent there is
//!      3.2e5 N/m, so `omega_0` = 374 rad/s. The wheel lifts off only after the whole 2.64 mm
//!      of travel. That is 42 % of the layer's thickness, beyond the about 30 % where the
//!      linear theory holds (below): the real layer is stiffer there and its deflection
//!      smaller, so this law errs towards late lift-off and a soft contact. No law for a
//!      thin bonded layer at finite strain under a curved indenter is in the sources we have.
//!    - On the floor (`R_e` = the ball's 114.5 mm) the loaded robot's 764 N compresses the
//!      layer by 1.20 mm (19 % of its thickness), with a patch `2 a = 4 sqrt(R_e delta)` =
//!      47 mm wide, 7.4 layer thicknesses; the Hertz term carries 12 % of it.
//!
//!    The linear theory under-predicts the stiffness of rubber compressed beyond about 30 %.
//!    The patch's shear stiffness is the same kind of sum: the thin layer's `G pi a^2 / t`
//!    plus Mindlin's `8 G a / (2 - nu)` (used on the floor; the wheel contact's traction keeps
//!    its own stick stiffness, [`crate::world::ContactParams::traction_stiffness_n_per_m`]).
//!    Damping from the loss factor as in 5 ([`crate::world::floor`]).
//!
//! At 8 kHz the wheel mode's `omega dt` is 0.05, well inside the explicit step's bound; the
//! tangent grows with the load (twice the static load: 1.6 times the stiffness).

use super::rollers::MIAPURE_ROLLER_RADIUS_M;

/// The ball's rubber layer and the roller that presses it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RubberLayer {
    /// Shore A hardness of the layer. MiaPURE: 60 (paper).
    pub shore_a_hardness: f64,
    /// Layer thickness `t` (m). MiaPURE: 6.35e-3 (paper).
    pub thickness_m: f64,
    /// Loss factor `eta` (tan delta) of the rubber. MiaPURE: 0.1, the low end of 0.10-0.25
    /// compiled for SBR at 10-100 Hz and room temperature
    /// (<https://materialmap.github.io/rubber_damping_reference.html>); the lower end is the
    /// less damped, the conservative side for vibration.
    pub loss_factor: f64,
    /// Roller radius across the wheel plane at the contact (m). MiaPURE: 0.011 (estimate,
    /// [`MIAPURE_ROLLER_RADIUS_M`]).
    pub roller_radius_m: f64,
}

impl RubberLayer {
    /// MiaPURE's coating: 6.35 mm of 60A SBR, pressed by 11 mm TPU rollers.
    pub fn miapure() -> Self {
        Self {
            shore_a_hardness: 60.0,
            thickness_m: 6.35e-3,
            loss_factor: 0.1,
            roller_radius_m: MIAPURE_ROLLER_RADIUS_M,
        }
    }

    /// Young's modulus from the Shore A hardness by Gent's relation (Pa).
    pub fn youngs_modulus_pa(&self) -> f64 {
        let s = self.shore_a_hardness;
        0.0981 * (56.0 + 7.62336 * s) / (0.137505 * (254.0 - 2.54 * s)) * 1.0e6
    }

    /// Equivalent contact radius `R_e = sqrt(R_x R_y)` against a wheel of radius
    /// `wheel_radius_m` and a ball of radius `ball_radius_m` (m).
    pub fn equivalent_radius_m(&self, wheel_radius_m: f64, ball_radius_m: f64) -> f64 {
        let r_x = 1.0 / (1.0 / wheel_radius_m + 1.0 / ball_radius_m);
        let r_y = 1.0 / (1.0 / self.roller_radius_m + 1.0 / ball_radius_m);
        (r_x * r_y).sqrt()
    }

    /// Static deflection `delta_0` of the thin-layer law under `load_n` (m).
    pub fn deflection_m(&self, load_n: f64, wheel_radius_m: f64, ball_radius_m: f64) -> f64 {
        let g = self.youngs_modulus_pa() / 3.0;
        let r_e = self.equivalent_radius_m(wheel_radius_m, ball_radius_m);
        let t3 = self.thickness_m.powi(3);
        (load_n * t3 / (std::f64::consts::TAU * g * r_e * r_e)).cbrt()
    }

    /// Normal stiffness linearised at `load_n`, `3 F_0 / delta_0` (N/m).
    pub fn stiffness_n_per_m(&self, load_n: f64, wheel_radius_m: f64, ball_radius_m: f64) -> f64 {
        3.0 * load_n / self.deflection_m(load_n, wheel_radius_m, ball_radius_m)
    }

    /// Equivalent viscous damping `eta k / omega` at the mode frequency `omega_rad_per_s`
    /// (N s/m).
    pub fn damping_n_s_per_m(&self, stiffness_n_per_m: f64, omega_rad_per_s: f64) -> f64 {
        self.loss_factor * stiffness_n_per_m / omega_rad_per_s
    }
}

/// The coating's force-deflection law against a rigid body, over the whole range from first
/// touch to a patch many layer thicknesses wide (module documentation, items 3 and 6):
/// `F(delta) = K_H delta^1.5 + K_T delta^3`, the sum of Hertz's half-space law (exact while the
/// patch is much narrower than the layer) and the thin bonded layer's (exact once it is much
/// wider). Between the two limits the sum is an interpolation, an assumption of ours: it is at
/// most twice either limit where they cross. Used for the ball on the floor
/// ([`crate::world::floor`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoatingLaw {
    /// `K_H = (4/3) E* sqrt(R_e)` with `E* = 4 G` for the incompressible layer on a rigid
    /// body (N / m^1.5).
    pub hertz_n_per_m1_5: f64,
    /// `K_T = 2 pi G R_e^2 / t^3` (N / m^3).
    pub thin_layer_n_per_m3: f64,
    /// The patch's shear stiffness is the same kind of sum; its thin-layer term per metre of
    /// deflection, `4 pi G R_e / t` (the layer's `G pi a^2 / t` with `a^2 = 4 R_e delta`)
    /// (N/m^2).
    pub shear_thin_n_per_m2: f64,
    /// Its Hertz-range term per square root of deflection: Mindlin's `8 G a / (2 - nu)` with
    /// `nu = 1/2` and Hertz's `a = sqrt(R_e delta)`, `(16/3) G sqrt(R_e)` (N / m^1.5).
    pub shear_hertz_n_per_m1_5: f64,
}

/// One evaluation of [`CoatingLaw`] at a deflection.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CoatingForce {
    /// The elastic force `F(delta)` (N), >= 0.
    pub force_n: f64,
    /// Its tangent `dF/d delta` (N/m).
    pub stiffness_n_per_m: f64,
    /// The patch's tangential (shear) stiffness (N/m).
    pub shear_stiffness_n_per_m: f64,
}

impl CoatingForce {
    /// The normal force with the loss factor's damping at the penetration rate
    /// `rate_m_per_s`: `F(delta) + c delta_dot` with `c = damping_secs k(delta)`
    /// (`damping_secs = eta / omega_0`, module documentation, item 5), never pulling (N).
    #[inline]
    pub fn damped_normal_n(&self, rate_m_per_s: f64, damping_secs: f64) -> f64 {
        (self.force_n + damping_secs * self.stiffness_n_per_m * rate_m_per_s).max(0.0)
    }
}

impl CoatingLaw {
    /// The law of `layer` pressed by a rigid body; `equivalent_radius_m` is `R_e` of the two
    /// surfaces (the ball's radius on a flat floor).
    ///
    /// ```
    /// use ballbot_world::world::rubber::{CoatingLaw, RubberLayer};
    /// let law = CoatingLaw::new(&RubberLayer::miapure(), 0.1145);
    /// // The loaded robot (77.9 kg) on the floor: 1.20 mm.
    /// let d = law.deflection_m(77.9 * 9.81);
    /// assert!((d - 1.20e-3).abs() < 0.01e-3, "{d}");
    /// assert!((law.evaluate(d).force_n - 77.9 * 9.81).abs() < 1e-6);
    /// ```
    pub fn new(layer: &RubberLayer, equivalent_radius_m: f64) -> Self {
        let g = layer.youngs_modulus_pa() / 3.0;
        let r_e = equivalent_radius_m;
        let t = layer.thickness_m;
        Self {
            hertz_n_per_m1_5: 16.0 / 3.0 * g * r_e.sqrt(),
            thin_layer_n_per_m3: std::f64::consts::TAU * g * r_e * r_e / (t * t * t),
            shear_thin_n_per_m2: 2.0 * std::f64::consts::TAU * g * r_e / t,
            shear_hertz_n_per_m1_5: 16.0 / 3.0 * g * r_e.sqrt(),
        }
    }

    /// Force, stiffness and shear stiffness at `deflection_m` (all 0 for `deflection_m <= 0`).
    #[inline]
    pub fn evaluate(&self, deflection_m: f64) -> CoatingForce {
        if deflection_m.is_nan() || deflection_m <= 0.0 {
            return CoatingForce::default();
        }
        let d = deflection_m;
        let sqrt_d = d.sqrt();
        let d2 = d * d;
        CoatingForce {
            force_n: self.hertz_n_per_m1_5 * d * sqrt_d + self.thin_layer_n_per_m3 * d2 * d,
            stiffness_n_per_m: 1.5 * self.hertz_n_per_m1_5 * sqrt_d
                + 3.0 * self.thin_layer_n_per_m3 * d2,
            shear_stiffness_n_per_m: self.shear_thin_n_per_m2 * d
                + self.shear_hertz_n_per_m1_5 * sqrt_d,
        }
    }

    /// The elastic energy stored at `deflection_m`, the law's integral
    /// `K_H delta^2.5 / 2.5 + K_T delta^4 / 4` (J; 0 for `deflection_m <= 0`).
    pub fn energy_j(&self, deflection_m: f64) -> f64 {
        if deflection_m.is_nan() || deflection_m <= 0.0 {
            return 0.0;
        }
        let d = deflection_m;
        self.hertz_n_per_m1_5 * d * d * d.sqrt() / 2.5 + self.thin_layer_n_per_m3 * d.powi(4) / 4.0
    }

    /// The deflection that carries `load_n` (m): Newton's method on the monotone law from the
    /// thin layer's value (0 for `load_n <= 0`).
    pub fn deflection_m(&self, load_n: f64) -> f64 {
        if load_n.is_nan() || load_n <= 0.0 {
            return 0.0;
        }
        let mut d = (load_n / self.thin_layer_n_per_m3).cbrt();
        for _ in 0..50 {
            let f = self.evaluate(d);
            let step = (f.force_n - load_n) / f.stiffness_n_per_m;
            d = (d - step).max(0.5 * d);
            if step.abs() < 1e-15 {
                break;
            }
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coating_energy_is_the_integral_of_its_force() {
        // dE/d delta = F by central differences, and E by the trapezoid rule over F.
        let law = CoatingLaw::new(&RubberLayer::miapure(), 0.0201);
        for d in [0.2e-3, 1.0e-3, 2.64e-3, 4.0e-3] {
            let h = 1e-4 * d;
            let de = (law.energy_j(d + h) - law.energy_j(d - h)) / (2.0 * h);
            let f = law.evaluate(d).force_n;
            assert!((de - f).abs() < 1e-6 * f, "{d}: {de} vs {f}");
            let n = 20_000;
            let trapezoid: f64 = (0..n)
                .map(|i| {
                    let (a, b) = (d * i as f64 / n as f64, d * (i + 1) as f64 / n as f64);
                    0.5 * (law.evaluate(a).force_n + law.evaluate(b).force_n) * (b - a)
                })
                .sum();
            let e = law.energy_j(d);
            assert!((trapezoid - e).abs() < 1e-6 * e, "{d}: {trapezoid} vs {e}");
        }
        assert_eq!(law.energy_j(-1e-3), 0.0);
        assert_eq!(law.energy_j(f64::NAN), 0.0);
    }

    #[test]
    fn gent_gives_3_6_mpa_for_60a() {
        let e = RubberLayer::miapure().youngs_modulus_pa();
        assert!((e - 3.605e6).abs() < 1e3, "{e}");
    }

    #[test]
    fn thin_layer_law_is_cubic_and_its_tangent_is_three_f_over_delta() {
        let l = RubberLayer::miapure();
        let d1 = l.deflection_m(100.0, 0.0625, 0.1145);
        let d8 = l.deflection_m(800.0, 0.0625, 0.1145);
        assert!((d8 / d1 - 2.0).abs() < 1e-12, "F ~ delta^3");
        // Numerical tangent of F(delta) at 343.6 N.
        let f0 = 343.6;
        let d0 = l.deflection_m(f0, 0.0625, 0.1145);
        let h = 1e-3 * f0;
        let dd = l.deflection_m(f0 + h, 0.0625, 0.1145) - l.deflection_m(f0 - h, 0.0625, 0.1145);
        let k_num = 2.0 * h / dd;
        let k = l.stiffness_n_per_m(f0, 0.0625, 0.1145);
        assert!((k - k_num).abs() < 1e-4 * k, "{k} {k_num}");
        assert!((d0 - 3.06e-3).abs() < 0.01e-3, "{d0}");
    }
}
