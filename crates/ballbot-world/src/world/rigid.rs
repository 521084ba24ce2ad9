//! Multi-rate stepping: the rigid bodies (rapier: ball, body, floor) step once every
//! `rigid_step_ratio` world steps, while the omniwheel contacts, the wheel spin states and the
//! motor drivers step every world step.
//!
//! # Scheme
//!
//! Between two rapier steps, [`RigidStepper`] predicts the ball's and the body's motion at the
//! world step `dt` with the forces of the omniwheel contacts computed at that step (semi-implicit
//! Euler, the same integrator as rapier's):
//!
//! * ball: `m_B v_dot = sum F_i + m_B g + F_floor`, `I_B w_dot = sum (p_i - c) x F_i + T_floor`
//!   plus its rolling and spin friction, with the floor's compliant contact
//!   ([`crate::world::floor`]) evaluated at that step too;
//! * body: `m_U v_dot = -sum F_i + m_U g`, `I_U w_dot = -sum (p_i - c_U) x F_i - sum a_i tau_i`
//!   (`I_U` in world axes at the last rapier step);
//! * the wheel centres move with the body's predicted velocity field; the body's orientation and
//!   its wheel axles stay at the last rapier step's (over 1 ms the body turns by about 1 mrad at
//!   1 rad/s).
//!
//! At the end of the interval rapier steps the two bodies by `ratio dt` with the average of the
//! predicted forces and torques. Rapier has no contact of its own, so for the linear velocities
//! its step and the prediction agree up to rounding. Positions keep the finely integrated path:
//! the new ball centre and body centre of mass are the predicted ones plus `ratio dt` times
//! `v_rapier - v_predicted`. So everything that is stiff (the ball against the body on the
//! three contacts, the ball's surface against the wheel rims, the ball on the floor) is
//! integrated at `dt`; only the bodies' orientations step at `ratio dt`.
//!
//! Momentum: the contact forces act on ball and body in equal and opposite pairs every world
//! step, and rapier applies their sums, so the total linear momentum changes only by gravity and
//! the floor, as at `ratio = 1`. The torques use the lever arms at the predicted positions; rapier
//! applies them about the centres of mass of the interval's start, which moves the total angular
//! momentum about the origin by the relative displacement of ball and body within one interval
//! times the contact forces (micrometres times hundreds of newtons).
//!
//! With `ratio = 1` nothing is predicted: the world is the single-rate world bit for bit.

use rapier3d_f64::glamx::{DQuat, DVec3};
use rapier3d_f64::prelude::{PhysicsWorld, RigidBodyHandle};

/// A force and a torque (N, N m), world frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Wrench {
    pub force: DVec3,
    pub torque: DVec3,
}

impl Wrench {
    pub(super) const ZERO: Self = Self {
        force: DVec3::ZERO,
        torque: DVec3::ZERO,
    };
}

/// Ball and body as the omniwheel contacts see them at one world step: read from rapier after
/// each rapier step, predicted in between.
#[derive(Clone, Copy, Debug)]
pub(super) struct RigidState {
    /// Ball centre (m).
    pub ball_centre: DVec3,
    /// Ball velocity (m/s).
    pub ball_velocity: DVec3,
    /// Ball angular velocity (rad/s).
    pub ball_angvel: DVec3,
    /// Body centre of mass (m).
    pub body_com: DVec3,
    /// Body centre-of-mass velocity (m/s).
    pub body_velocity: DVec3,
    /// Body angular velocity (rad/s).
    pub body_angvel: DVec3,
    /// Wheel centres (m).
    pub wheel_centres: [DVec3; 3],
    /// Wheel axles (unit vectors).
    pub axles: [DVec3; 3],
}

impl RigidState {
    /// Reads the state from rapier; `centres_local` and `axles_local` are the wheels' centres and
    /// axles in the body frame.
    pub(super) fn read(
        physics: &PhysicsWorld,
        ball: RigidBodyHandle,
        body: RigidBodyHandle,
        centres_local: [DVec3; 3],
        axles_local: [DVec3; 3],
    ) -> Self {
        let b = &physics.bodies[ball];
        let u = &physics.bodies[body];
        let pose = u.position();
        Self {
            ball_centre: b.translation(),
            ball_velocity: b.linvel(),
            ball_angvel: b.angvel(),
            body_com: u.center_of_mass(),
            body_velocity: u.linvel(),
            body_angvel: u.angvel(),
            wheel_centres: centres_local.map(|c| pose.transform_point(c)),
            axles: axles_local.map(|a| pose.rotation * a),
        }
    }
}

/// Inverse mass and inverse inertia of one body, inertia in world axes.
#[derive(Clone, Copy, Debug)]
struct InverseMass {
    /// Whether rapier moves the body (a test rig can clamp it).
    dynamic: bool,
    inv_mass: f64,
    /// Principal axes in the world frame.
    frame: DQuat,
    /// Inverse principal moments (1 / kg m^2; 0 where a moment is 0).
    inv_principal: DVec3,
}

impl InverseMass {
    fn read(physics: &PhysicsWorld, handle: RigidBodyHandle) -> Self {
        let rb = &physics.bodies[handle];
        let local = &rb.mass_properties().local_mprops;
        let inv = |i: f64| if i > 0.0 { 1.0 / i } else { 0.0 };
        let principal = local.principal_inertia();
        Self {
            dynamic: rb.is_dynamic(),
            inv_mass: inv(rb.mass()),
            frame: rb.position().rotation * local.principal_inertia_local_frame,
            inv_principal: DVec3::new(inv(principal.x), inv(principal.y), inv(principal.z)),
        }
    }

    fn inv_inertia_times(&self, torque: DVec3) -> DVec3 {
        self.frame * (self.inv_principal * (self.frame.inverse() * torque))
    }
}

/// One rigid step's bookkeeping: the state at its start, the predicted state now and the sums
/// of the wrenches applied so far.
pub(super) struct RigidStepper {
    ratio: u32,
    substeps: u32,
    start: RigidState,
    now: RigidState,
    ball_sum: Wrench,
    body_sum: Wrench,
    /// The body's rotation over the interval so far, `sum w_k dt` (rad, world axes).
    body_turn: DVec3,
    ball_mass: InverseMass,
    body_mass: InverseMass,
    gravity: DVec3,
}

impl RigidStepper {
    /// A stepper that starts an interval at `state`; `ratio >= 1` world steps per rapier step.
    pub(super) fn new(
        ratio: u32,
        physics: &PhysicsWorld,
        ball: RigidBodyHandle,
        body: RigidBodyHandle,
        state: RigidState,
    ) -> Self {
        Self {
            ratio: ratio.max(1),
            substeps: 0,
            start: state,
            now: state,
            ball_sum: Wrench::ZERO,
            body_sum: Wrench::ZERO,
            body_turn: DVec3::ZERO,
            ball_mass: InverseMass::read(physics, ball),
            body_mass: InverseMass::read(physics, body),
            gravity: physics.gravity,
        }
    }

    /// World steps per rapier step.
    pub(super) fn ratio(&self) -> u32 {
        self.ratio
    }

    /// World steps since the last rapier step.
    pub(super) fn substeps(&self) -> u32 {
        self.substeps
    }

    /// The state the contacts see now.
    pub(super) fn now(&self) -> &RigidState {
        &self.now
    }

    /// Starts a new interval at `state` (after a rapier step or a change made to rapier from
    /// outside, such as a push), reading the masses and inertias again.
    pub(super) fn restart(
        &mut self,
        physics: &PhysicsWorld,
        ball: RigidBodyHandle,
        body: RigidBodyHandle,
        state: RigidState,
    ) {
        self.substeps = 0;
        self.start = state;
        self.now = state;
        self.ball_sum = Wrench::ZERO;
        self.body_sum = Wrench::ZERO;
        self.body_turn = DVec3::ZERO;
        // Only the prediction reads masses and gravity (nothing is predicted at ratio 1).
        if self.ratio > 1 {
            self.ball_mass = InverseMass::read(physics, ball);
            self.body_mass = InverseMass::read(physics, body);
            self.gravity = physics.gravity;
        }
    }

    /// Adds one world step's wrenches on ball and body (torques about their current centres)
    /// and, between rapier steps, advances the predicted state by `dt_secs`. Returns whether
    /// the interval is complete (rapier steps now).
    pub(super) fn add(&mut self, ball: Wrench, body: Wrench, dt_secs: f64) -> bool {
        self.ball_sum.force += ball.force;
        self.ball_sum.torque += ball.torque;
        self.body_sum.force += body.force;
        self.body_sum.torque += body.torque;
        self.substeps += 1;
        if self.ratio > 1 {
            self.predict(ball, body, dt_secs);
        }
        self.substeps >= self.ratio
    }

    fn predict(&mut self, ball: Wrench, body: Wrench, dt: f64) {
        let s = &mut self.now;
        let b = &self.ball_mass;
        let u = &self.body_mass;
        if b.dynamic {
            s.ball_velocity += (self.gravity + ball.force * b.inv_mass) * dt;
            s.ball_angvel += b.inv_inertia_times(ball.torque) * dt;
        }
        if u.dynamic {
            s.body_velocity += (self.gravity + body.force * u.inv_mass) * dt;
            s.body_angvel += u.inv_inertia_times(body.torque) * dt;
        }
        s.ball_centre += s.ball_velocity * dt;
        let com = s.body_com;
        for c in &mut s.wheel_centres {
            *c += (s.body_velocity + s.body_angvel.cross(*c - com)) * dt;
        }
        s.body_com += s.body_velocity * dt;
        self.body_turn += s.body_angvel * dt;
    }

    /// The average wrenches on ball and body over the substeps taken (the forces rapier
    /// applies for the interval).
    pub(super) fn averages(&self) -> (Wrench, Wrench) {
        let n = f64::from(self.substeps.max(1));
        let avg = |w: &Wrench| Wrench {
            force: w.force / n,
            torque: w.torque / n,
        };
        (avg(&self.ball_sum), avg(&self.body_sum))
    }

    /// After rapier stepped the interval (`interval_secs`, with [`Self::averages`] applied):
    /// moves ball and body to the finely integrated positions and starts the next interval. At
    /// `ratio = 1` this only reads the state.
    pub(super) fn finish(
        &mut self,
        physics: &mut PhysicsWorld,
        handles: (RigidBodyHandle, RigidBodyHandle),
        wheels_local: ([DVec3; 3], [DVec3; 3]),
        interval_secs: f64,
    ) {
        let (ball, body) = handles;
        if self.ratio > 1 {
            let (p, s0) = (&self.now, &self.start);
            // Rapier moved each body by `interval * v_end`; the fine path differs from that by
            // what the velocities did within the interval, which is added back.
            if self.ball_mass.dynamic {
                let rb = &mut physics.bodies[ball];
                let fine = p.ball_centre - (s0.ball_centre + p.ball_velocity * interval_secs);
                rb.set_translation(rb.translation() + fine, false);
            }
            if self.body_mass.dynamic {
                let rb = &mut physics.bodies[body];
                let fine = p.body_com - (s0.body_com + p.body_velocity * interval_secs);
                let turn = self.body_turn - p.body_angvel * interval_secs;
                let rotation = (DQuat::from_scaled_axis(turn) * rb.rotation()).normalize();
                let com = rb.center_of_mass() + fine;
                let local_com = rb.mass_properties().local_mprops.local_com;
                rb.set_rotation(rotation, false);
                rb.set_translation(com - rotation * local_com, false);
            }
        }
        let state = RigidState::read(physics, ball, body, wheels_local.0, wheels_local.1);
        self.restart(physics, ball, body, state);
    }
}
