//! Energies and momenta of the world, for the conservation tests and the studies. They read
//! rapier's state, i.e. the last rigid step's ([`crate::world::rigid`]), and the wheels' current
//! spins: read them right after a rigid step (every `rigid_step_ratio` world steps) for a
//! consistent total.

use super::{BallbotWorld, to_glam, to_na};
use nalgebra::Vector3;
use rapier3d_f64::glamx::DVec3;

impl BallbotWorld {
    /// Total kinetic energy of ball, body and the drivetrains' spins (J).
    pub fn kinetic_energy_j(&self) -> f64 {
        let wheels: f64 = self
            .wheels
            .iter()
            .map(|w| self.drivetrain.kinetic_energy_j(&w.drive))
            .sum();
        self.physics.bodies[self.ball].kinetic_energy()
            + self.physics.bodies[self.body].kinetic_energy()
            + wheels
    }

    /// Gravitational potential energy of ball and body above the floor (J).
    pub fn potential_energy_j(&self) -> f64 {
        let g = -self.physics.gravity.z;
        let ball = &self.physics.bodies[self.ball];
        let body = &self.physics.bodies[self.body];
        g * (ball.mass() * ball.center_of_mass().z + body.mass() * body.center_of_mass().z)
    }

    /// Elastic energy stored in the contacts' normal compliance (J): the three omniwheel
    /// contacts' and the ball coating's on the floor (the tangential bristles' is not counted).
    pub fn contact_energy_j(&self) -> f64 {
        let wheels: f64 = self
            .contact_geometry()
            .iter()
            .map(|g| self.law.normal.energy_j(g.penetration_m))
            .sum();
        wheels + self.floor.elastic_energy_j(self.rigid.now().ball_centre)
    }

    /// Elastic energy stored in the three drivetrains' couplings (J; 0 when rigid).
    pub fn coupling_energy_j(&self) -> f64 {
        self.wheels
            .iter()
            .map(|w| self.drivetrain.coupling_energy_j(&w.drive))
            .sum()
    }

    /// Total linear momentum of ball and body (N s).
    pub fn linear_momentum_ns(&self) -> Vector3<f64> {
        let ball = &self.physics.bodies[self.ball];
        let body = &self.physics.bodies[self.body];
        to_na(ball.linvel() * ball.mass() + body.linvel() * body.mass())
    }

    /// Total angular momentum of ball, body and the wheels' and rotors' spins about the world
    /// origin (N m s): [`Self::rigid_angular_momentum_nms`] plus each drivetrain's
    /// `n I_r w_m + I_w w_w` along its axle (`(I_w + n I_r) w` when rigid,
    /// [`crate::world::WorldParams::wheel_spin_momentum_inertia_kg_m2`]).
    pub fn angular_momentum_nms(&self) -> Vector3<f64> {
        let mut total = to_glam(self.rigid_angular_momentum_nms());
        let rot = self.physics.bodies[self.body].position().rotation;
        for (g, w) in self.geometry.iter().zip(&self.wheels) {
            total += rot * g.axle_local * self.drivetrain.spin_momentum_nms(&w.drive);
        }
        to_na(total)
    }

    /// Angular momentum of the two rigid bodies, ball and body, about the world origin
    /// (N m s), without the wheels' and rotors' spins.
    pub fn rigid_angular_momentum_nms(&self) -> Vector3<f64> {
        let mut total = DVec3::ZERO;
        for h in [self.ball, self.body] {
            let rb = &self.physics.bodies[h];
            let com = rb.center_of_mass();
            let rot = rb.position().rotation;
            let inertia = rb.mass_properties().local_mprops.principal_inertia();
            let frame = rot
                * rb.mass_properties()
                    .local_mprops
                    .principal_inertia_local_frame;
            let w_local = frame.inverse() * rb.angvel();
            total += frame * (inertia * w_local) + com.cross(rb.linvel() * rb.mass());
        }
        to_na(total)
    }
}
