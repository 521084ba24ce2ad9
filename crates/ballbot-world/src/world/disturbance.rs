//! Disturbances of a running world that its parameters do not describe: a payload that shifts
//! on the body, and a bump or a step on the floor (the fault-injection matrix,
//! `ballbot_studies::studies::robustness`, uses the first two; the floor's model:
//! [`crate::world::floor`]).

use super::WorldError;
pub use super::floor::{FloorBump, FloorStep};
use super::sim::BallbotWorld;
use nalgebra::Vector3;
use rapier3d_f64::glamx::DVec3;
use rapier3d_f64::prelude::MassProperties;

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
    /// use ballbot_world::world::{BallbotWorld, WorldParams};
    /// use nalgebra::Vector3;
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// let before = world.body_com_m();
    /// world.shift_payload_m(Vector3::new(0.05, 0.0, 0.0))?;
    /// assert!((world.body_com_m().x - before.x - 0.05).abs() < 1e-9);
    /// assert!(world.shift_payload_m(Vector3::new(f64::NAN, 0.0, 0.0)).is_err());
    /// # Ok::<(), ballbot_world::world::WorldError>(())
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

    /// Puts `bump` on the floor, with the floor's friction and coating law.
    ///
    /// Errors (the world unchanged): [`FloorBump::validate`].
    ///
    /// ```
    /// use ballbot_world::world::{BallbotWorld, FloorBump, WorldParams};
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// // A 1 cm bar 0.5 m ahead, across the x direction.
    /// let bump = FloorBump { centre_m: [0.5, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        width_m: 0.04, length_m: 2.0 };
    /// world.add_floor_bump(bump)?;
    /// assert!(world.add_floor_bump(FloorBump { width_m: 0.0, ..bump }).is_err());
    /// # Ok::<(), ballbot_world::world::WorldError>(())
    /// ```
    pub fn add_floor_bump(&mut self, bump: FloorBump) -> Result<(), WorldError> {
        bump.validate()?;
        self.floor.add_bump(&bump);
        self.refresh_clearance();
        Ok(())
    }

    /// Puts `step` on the floor.
    ///
    /// Errors (the world unchanged): [`FloorStep::validate`].
    ///
    /// ```
    /// use ballbot_world::world::{BallbotWorld, FloorStep, WorldParams};
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// let step = FloorStep { edge_m: [0.5, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        edge_radius_m: 0.003 };
    /// world.add_floor_step(step)?;
    /// assert!((world.floor_height_m(0.6, 0.0) - 0.01).abs() < 1e-12);
    /// assert!(world.add_floor_step(FloorStep { height_m: f64::NAN, ..step }).is_err());
    /// # Ok::<(), ballbot_world::world::WorldError>(())
    /// ```
    pub fn add_floor_step(&mut self, step: FloorStep) -> Result<(), WorldError> {
        step.validate()?;
        self.floor.add_step(&step);
        self.refresh_clearance();
        Ok(())
    }

    /// The floor's height at `(x_m, y_m)` (m): the plane, bumps and steps.
    pub fn floor_height_m(&self, x_m: f64, y_m: f64) -> f64 {
        self.floor.height_m(x_m, y_m)
    }
}
