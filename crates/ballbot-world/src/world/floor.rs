//! The floor and the ball's compliant contact on it, evaluated every world step (8 kHz).
//!
//! # Model
//!
//! The floor is a height map of rigid primitives ([`terrain`]): a plane through the origin
//! that may be inclined ([`FloorParams::slope_rad`]), with bumps ([`crate::world::FloorBump`],
//! a circular-arc bar) and steps ([`crate::world::FloorStep`], a raised plateau with a rounded
//! edge) added to a running world. The ball's rubber coating is what gives:
//!
//! * **Normal force** per primitive the ball touches, penetration `delta` along the primitive's
//!   normal `n` at the ball: `N = max(0, F(delta) + c(delta) delta_dot)` with the coating's law
//!   `F` ([`CoatingLaw`]: Hertz's half-space law plus the thin bonded layer's) for the
//!   equivalent radius of ball and primitive, and the loss factor's damping
//!   `c = eta k(delta) / omega_0` (`k = dF/d delta`): a hysteretic spring `k (1 + i eta)`
//!   dissipates per cycle what this viscous one does at `omega_0`, the ball's own frequency on
//!   the plane under the robot's static load, `sqrt(k(delta_0) / m_B)` (706 rad/s for the
//!   loaded MiaPURE). It vanishes at first touch, grows with the load like the stiffness,
//!   and never pulls.
//! * **Friction inside a cone**: a two-dimensional bristle `z` in the contact's tangent plane
//!   (the patch's shear), `F_stick = -(k_s z + c_s s)` with the slip velocity `s` of the ball's
//!   surface at the contact, the patch's shear stiffness `k_s(delta)` ([`CoatingLaw`]) and
//!   `c_s = eta k_s / omega_s` with `omega_s` the ball's frequency on the shear stiffness
//!   under the static load. While `|F_stick| <= mu N` the patch sticks (`z_dot = s`);
//!   beyond, it slides with `mu_k N` along `F_stick` and the bristle sits at the slide limit.
//!   The cone is isotropic (`mu` = [`ballbot_core::DrivetrainParams::ball_floor_friction`]).
//! * Rolling resistance and the spin friction ([`crate::world::WorldParams::rolling_resistance`],
//!   [`crate::world::WorldParams::spin_friction_m`]) read the sum of the normal forces.
//!
//! The force acts at the contact point `p = c - R n` on the ball's surface. Bumps and steps
//! stand on the plane: their heights are measured vertically from the plane below the ball,
//! exact on a level floor and an approximation on an incline (the plane's normal is not
//! vertical there).
//!
//! # Step size
//!
//! At the loaded robot's 1.20 mm the floor's tangent stiffness is 1.8e6 N/m, the ball's own
//! frequency on it 706 rad/s: `omega dt` = 0.09 at 8 kHz. The 5 mm drop of `tests/world_floor.rs`
//! peaks at 2,539 N (1.83 mm), where the stiffness is 2.2 times higher: still far inside the
//! semi-implicit Euler step's bound of 2.

pub mod obstacle;
pub mod terrain;
#[cfg(test)]
mod tests;

pub use obstacle::{FloorBump, FloorStep};

use super::WorldError;
use super::check::positive;
use super::rigid::Wrench;
use super::rubber::{CoatingLaw, RubberLayer};
use rapier3d_f64::glamx::DVec3;
use terrain::{Patch, Terrain};

/// The floor under the ball: the ball coating's contact law and the floor's inclination.
/// Bumps and steps are added to a running world ([`crate::world::BallbotWorld::add_floor_bump`],
/// [`crate::world::BallbotWorld::add_floor_step`]).
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct FloorParams {
    /// Shore A hardness of the ball's coating. MiaPURE: 60 (paper, lines 85-91).
    #[schemars(range(min = 10, max = 90))]
    pub coating_shore_a_hardness: f64,
    /// Thickness of the coating (m). MiaPURE: 6.35e-3 (paper).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub coating_thickness_m: f64,
    /// Loss factor `eta` (tan delta) of the coating (dimensionless). MiaPURE: 0.1, the low end
    /// of 0.10-0.25 for SBR at 10-100 Hz ([`RubberLayer::loss_factor`]).
    #[schemars(range(min = 0, max = 2))]
    pub coating_loss_factor: f64,
    /// Kinetic over static friction coefficient while the ball slides on the floor
    /// (dimensionless, in (0, 1]). Default 1: one Coulomb coefficient, as in the earlier
    /// worlds (an estimate; a rubber ball on a hard floor).
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub kinetic_friction_ratio: f64,
    /// The floor's inclination (rad, in [0, 0.5]). Default 0: level.
    #[schemars(range(min = 0, max = 0.5))]
    pub slope_rad: f64,
    /// The direction the floor rises towards (deg from world x). Default 0.
    pub slope_heading_deg: f64,
}

impl Default for FloorParams {
    fn default() -> Self {
        Self::miapure()
    }
}

impl FloorParams {
    /// MiaPURE's ball ([`RubberLayer::miapure`]'s coating) on a level floor.
    pub fn miapure() -> Self {
        let layer = RubberLayer::miapure();
        Self {
            coating_shore_a_hardness: layer.shore_a_hardness,
            coating_thickness_m: layer.thickness_m,
            coating_loss_factor: layer.loss_factor,
            kinetic_friction_ratio: 1.0,
            slope_rad: 0.0,
            slope_heading_deg: 0.0,
        }
    }

    /// The coating as a [`RubberLayer`] (the roller radius is the wheel contact's, unused here).
    pub fn coating(&self) -> RubberLayer {
        RubberLayer {
            shore_a_hardness: self.coating_shore_a_hardness,
            thickness_m: self.coating_thickness_m,
            loss_factor: self.coating_loss_factor,
            ..RubberLayer::miapure()
        }
    }

    /// The unit normal of the plane (pointing up).
    pub fn plane_normal(&self) -> DVec3 {
        let (s, c) = self.slope_rad.sin_cos();
        let h = self.slope_heading_deg.to_radians();
        // 0 - x, not -x: a level floor's normal is (+0, +0, 1).
        DVec3::new(0.0 - s * h.cos(), 0.0 - s * h.sin(), c)
    }

    /// Checks every field; the error names the first one out of range.
    ///
    /// ```
    /// use ballbot_world::world::FloorParams;
    /// assert!(FloorParams::miapure().validate().is_ok());
    /// let err = FloorParams { slope_rad: 0.7, ..FloorParams::miapure() }.validate();
    /// assert!(err.unwrap_err().to_string().contains("floor.slope_rad"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let range = |v: f64, lo: f64, hi: f64, field, requirement| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(WorldError::InvalidParameter { field, requirement })
            }
        };
        range(
            self.coating_shore_a_hardness,
            10.0,
            90.0,
            "floor.coating_shore_a_hardness",
            "must be in [10, 90] (Gent's relation)",
        )?;
        positive(self.coating_thickness_m, "floor.coating_thickness_m")?;
        range(
            self.coating_loss_factor,
            0.0,
            2.0,
            "floor.coating_loss_factor",
            "must be in [0, 2]",
        )?;
        if !(self.kinetic_friction_ratio > 0.0 && self.kinetic_friction_ratio <= 1.0) {
            return Err(WorldError::InvalidParameter {
                field: "floor.kinetic_friction_ratio",
                requirement: "must be in (0, 1]",
            });
        }
        range(
            self.slope_rad,
            0.0,
            0.5,
            "floor.slope_rad",
            "must be in [0, 0.5]",
        )?;
        if self.slope_heading_deg.is_finite() {
            Ok(())
        } else {
            Err(WorldError::InvalidParameter {
                field: "floor.slope_heading_deg",
                requirement: "must be finite",
            })
        }
    }
}

/// What the floor did to the ball in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct FloorOutput {
    /// Force at the ball's centre and torque about it (N, N m).
    pub wrench: Wrench,
    /// Sum of the normal forces (N): the load rolling resistance and spin friction read.
    pub normal_n: f64,
}

/// The ball's state as the floor contact reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct BallState {
    pub centre: DVec3,
    pub velocity: DVec3,
    pub angvel: DVec3,
}

/// The floor in a running world: the terrain, the contact law and one bristle per primitive.
pub(super) struct Floor {
    terrain: Terrain,
    layer: RubberLayer,
    ball_radius_m: f64,
    /// `eta / omega_0` and `eta / omega_s` (s): damping per unit of normal and shear
    /// stiffness.
    normal_damping_secs: f64,
    shear_damping_secs: f64,
    static_friction: f64,
    kinetic_ratio: f64,
    /// Bristle deflection per primitive (m, world frame; 0 while out of contact).
    bristles: Vec<DVec3>,
}

impl Floor {
    /// The floor under a ball of `ball_radius_m` and `ball_mass_kg` whose static load on the
    /// plane is `static_load_n` (the damping's reference frequencies), with friction
    /// coefficient `friction`.
    pub(super) fn new(
        params: &FloorParams,
        ball_radius_m: f64,
        ball_mass_kg: f64,
        static_load_n: f64,
        friction: f64,
    ) -> Self {
        let layer = params.coating();
        let terrain = Terrain::new(params.plane_normal(), &layer, ball_radius_m);
        let law = terrain.plane_law();
        let at_rest = law.evaluate(law.deflection_m(static_load_n));
        let per_stiffness = |k: f64| {
            if k > 0.0 {
                layer.loss_factor / (k / ball_mass_kg).sqrt()
            } else {
                0.0
            }
        };
        Self {
            normal_damping_secs: per_stiffness(at_rest.stiffness_n_per_m),
            shear_damping_secs: per_stiffness(at_rest.shear_stiffness_n_per_m),
            bristles: vec![DVec3::ZERO; terrain.len()],
            terrain,
            layer,
            ball_radius_m,
            static_friction: friction,
            kinetic_ratio: params.kinetic_friction_ratio,
        }
    }

    /// The deflection of the coating on the plane under `load_n` (m).
    pub(super) fn static_deflection_m(&self, load_n: f64) -> f64 {
        self.terrain.plane_law().deflection_m(load_n)
    }

    /// The plane's unit normal.
    pub(super) fn plane_normal(&self) -> DVec3 {
        self.terrain.plane_normal()
    }

    pub(super) fn set_friction(&mut self, friction: f64) {
        self.static_friction = friction;
    }

    pub(super) fn add_bump(&mut self, bump: &FloorBump) {
        self.terrain.add_bump(bump, &self.layer, self.ball_radius_m);
        self.bristles.push(DVec3::ZERO);
    }

    pub(super) fn add_step(&mut self, step: &FloorStep) {
        self.terrain.add_step(step);
        self.bristles.push(DVec3::ZERO);
    }

    /// Forgets the bristles (after the robot was moved from outside).
    pub(super) fn release(&mut self) {
        self.bristles.iter_mut().for_each(|z| *z = DVec3::ZERO);
    }

    /// The floor's height at `(x, y)` (m): the chassis' clearance is measured from it.
    pub(super) fn height_m(&self, x: f64, y: f64) -> f64 {
        self.terrain.height_m(x, y)
    }

    /// The elastic energy the coating stores against every primitive under a ball centred at
    /// `centre` (J): each patch's [`CoatingLaw::energy_j`] at its penetration (the tangential
    /// bristles' energy is not counted).
    pub(super) fn elastic_energy_j(&self, centre: DVec3) -> f64 {
        (0..self.terrain.len())
            .filter_map(|i| self.terrain.patch(i, centre, self.ball_radius_m))
            .map(|p| p.law.energy_j(p.penetration_m))
            .sum()
    }

    /// Evaluates every primitive's contact with the ball and advances the bristles by
    /// `dt_secs`.
    pub(super) fn step(&mut self, ball: &BallState, dt_secs: f64) -> FloorOutput {
        let mut out = FloorOutput::default();
        let r = self.ball_radius_m;
        let (mu, mu_k) = (
            self.static_friction,
            self.static_friction * self.kinetic_ratio,
        );
        for (i, z) in self.bristles.iter_mut().enumerate() {
            let Some(patch) = self.terrain.patch(i, ball.centre, r) else {
                *z = DVec3::ZERO;
                continue;
            };
            let Patch { normal: n, .. } = patch;
            let law = patch.law.evaluate(patch.penetration_m);
            let rate = -n.dot(ball.velocity);
            let normal_n = law.damped_normal_n(rate, self.normal_damping_secs);
            // The surface's slip at the contact point, in the tangent plane.
            let lever = -n * r;
            let slip = ball.velocity + ball.angvel.cross(lever);
            let slip_t = slip - n * n.dot(slip);
            *z -= n * n.dot(*z);
            let k_s = law.shear_stiffness_n_per_m;
            let c_s = self.shear_damping_secs * k_s;
            let demand = -(*z * k_s + slip_t * c_s);
            let limit = mu * normal_n;
            let demand_len = demand.length();
            let friction = if demand_len <= limit {
                *z += slip_t * dt_secs;
                demand
            } else {
                let f = demand * (mu_k * normal_n / demand_len);
                *z = if k_s > 0.0 { -f / k_s } else { DVec3::ZERO };
                f
            };
            let force = n * normal_n + friction;
            out.wrench.force += force;
            out.wrench.torque += lever.cross(force);
            out.normal_n += normal_n;
        }
        out
    }
}

/// The law of `layer` on a primitive of curvature radius `radius_m` across it (infinite along
/// it) under a ball of radius `ball_radius_m`: `R_e = sqrt(R_x R_y)`, `R_x` the relative radius
/// across, `R_y = R` along.
pub(super) fn law_on_cylinder(
    layer: &RubberLayer,
    radius_m: f64,
    ball_radius_m: f64,
) -> CoatingLaw {
    let r_x = radius_m * ball_radius_m / (radius_m + ball_radius_m);
    CoatingLaw::new(layer, (r_x * ball_radius_m).sqrt())
}
