//! Disturbances of a running world that its parameters do not describe: a payload that shifts
//! on the body, and a bump on the floor (the fault-injection matrix,
//! `crate::studies::robustness`, uses both).

use super::WorldError;
use super::check::positive;
use super::sim::BallbotWorld;
use nalgebra::Vector3;
use rapier3d_f64::glamx::DVec3;
use rapier3d_f64::prelude::{ColliderBuilder, MassProperties};

/// A rigid bump across the robot's path with a circular-arc profile of chord `width_m` and
/// rise `height_m`: a rounded door threshold or a cable protector. The ball rolls over it; the
/// wheels above may lose contact. (A sharp-edged bar would be a worse model: the rigid ball
/// would roll over a knife edge that a rubber-coated ball wraps around.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorBump {
    /// Where the bar's centre line crosses the path, on the floor (m).
    pub centre_m: [f64; 2],
    /// The path's direction (deg from world x); the bar lies across it.
    pub heading_deg: f64,
    /// Height: the arc's rise above the floor (m).
    pub height_m: f64,
    /// Width along the path: the chord of the arc at the floor (m).
    pub width_m: f64,
    /// Length across the path (m).
    pub length_m: f64,
}

impl FloorBump {
    /// Checks every field (finite; height, width and length > 0).
    ///
    /// ```
    /// use ballbot_sim::world::FloorBump;
    /// let bump = FloorBump { centre_m: [1.0, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        width_m: 0.04, length_m: 2.0 };
    /// assert!(bump.validate().is_ok());
    /// let err = FloorBump { height_m: -0.01, ..bump }.validate().unwrap_err();
    /// assert!(err.to_string().contains("height_m"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let finite = |v: f64, field| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(WorldError::InvalidParameter {
                    field,
                    requirement: "must be finite",
                })
            }
        };
        finite(self.centre_m[0], "centre_m")?;
        finite(self.centre_m[1], "centre_m")?;
        finite(self.heading_deg, "heading_deg")?;
        positive(self.height_m, "height_m")?;
        positive(self.width_m, "width_m")?;
        positive(self.length_m, "length_m")
    }
}

impl BallbotWorld {
    /// Moves the body's centre of mass by `offset_m` (body frame) from where the parameters
    /// put it, `(0, 0, l)`: a payload that slides or a rider who shifts. Mass and inertia about
    /// the centre of mass are unchanged, and so is the body's pose; a repeated call replaces
    /// the offset. The controller's model is not told.
    ///
    /// Errors (the world unchanged): [`WorldError::InvalidParameter`] naming `offset_m` unless
    /// every component is finite.
    ///
    /// ```
    /// use ballbot_sim::world::{BallbotWorld, WorldParams};
    /// use nalgebra::Vector3;
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// let before = world.body_com_m();
    /// world.shift_payload_m(Vector3::new(0.05, 0.0, 0.0))?;
    /// assert!((world.body_com_m().x - before.x - 0.05).abs() < 1e-9);
    /// assert!(world.shift_payload_m(Vector3::new(f64::NAN, 0.0, 0.0)).is_err());
    /// # Ok::<(), ballbot_sim::world::WorldError>(())
    /// ```
    pub fn shift_payload_m(&mut self, offset_m: Vector3<f64>) -> Result<(), WorldError> {
        if !offset_m.iter().all(|v| v.is_finite()) {
            return Err(WorldError::InvalidParameter {
                field: "offset_m",
                requirement: "must be finite",
            });
        }
        let robot = &self.params().robot;
        let props = MassProperties::new(
            DVec3::new(
                offset_m.x,
                offset_m.y,
                robot.sagittal.com_height_m + offset_m.z,
            ),
            robot.sagittal.body_mass_kg,
            DVec3::new(
                robot.frontal.body_inertia_kg_m2,
                robot.sagittal.body_inertia_kg_m2,
                robot.spin.inertia_kg_m2,
            ),
        );
        self.sync_rigid();
        let body = &mut self.physics.bodies[self.body];
        body.set_additional_mass_properties(props, true);
        body.recompute_mass_properties_from_colliders(&self.physics.colliders);
        self.restart_rigid();
        Ok(())
    }

    /// The body's centre of mass in the world (m).
    pub fn body_com_m(&self) -> Vector3<f64> {
        let c = self.physics.bodies[self.body].center_of_mass();
        Vector3::new(c.x, c.y, c.z)
    }

    /// Puts `bump` on the floor, with the floor's friction.
    ///
    /// Errors (the world unchanged): [`FloorBump::validate`].
    ///
    /// ```
    /// use ballbot_sim::world::{BallbotWorld, FloorBump, WorldParams};
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// // A 1 cm bar 0.5 m ahead, across the x direction.
    /// let bump = FloorBump { centre_m: [0.5, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        width_m: 0.04, length_m: 2.0 };
    /// world.add_floor_bump(bump)?;
    /// assert!(world.add_floor_bump(FloorBump { width_m: 0.0, ..bump }).is_err());
    /// # Ok::<(), ballbot_sim::world::WorldError>(())
    /// ```
    pub fn add_floor_bump(&mut self, bump: FloorBump) -> Result<(), WorldError> {
        bump.validate()?;
        let heading = bump.heading_deg.to_radians();
        let friction = self.params().robot.drivetrain.ball_floor_friction;
        // The arc's circle: radius rho = (w^2 / 4 + h^2) / (2 h), its centre h - rho above
        // the floor (below it for a flat bump), a capsule lying across the path.
        let (w, h) = (bump.width_m, bump.height_m);
        let rho = (0.25 * w * w + h * h) / (2.0 * h);
        let collider = ColliderBuilder::capsule_y(0.5 * bump.length_m, rho)
            .translation(DVec3::new(bump.centre_m[0], bump.centre_m[1], h - rho))
            .rotation(DVec3::new(0.0, 0.0, heading))
            .friction(friction)
            .restitution(0.0);
        let handle = self.physics.colliders.insert(collider);
        self.obstacles.push(handle);
        Ok(())
    }
}
