//! The rapier3d world: floor, ball, body, three omniwheels with their own spin states.

use super::WorldError;
use super::check::non_negative;
use super::contact::{ContactKinematics, ContactLaw, ContactOutput, NormalLaw};
use super::driver::{DriverFault, MotorDriver};
use super::failure::{Failure, FailureMonitor, StopRules};
use super::floor::{BallState, Floor};
use super::imu::ImuTruth;
use super::params::WorldParams;
use super::rigid::{RigidState, RigidStepper, Wrench};
use super::rollers::{RimContact, RollerProfile};
use super::sensors::{Measurement, Sensors};
use super::telemetry::{StepTelemetry, WheelTelemetry};
use super::transmission::{Drivetrain, DrivetrainLoads, DrivetrainState};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rapier3d_f64::glamx::{DQuat, DVec3};
use rapier3d_f64::prelude::{
    MassProperties, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, RigidBodyType,
};

mod energy;

/// How far the body sits below its rigid-contact position on the ball at rest (m): the sink
/// `s` at which the three contacts, their wheel centres at `l_m = r + r_W` along normals at
/// `contact_angle_rad` from the vertical, carry `weight_n` together. Sinking turns the
/// contact normals: the penetration is `l - sqrt(l^2 sin^2 a + (l cos a - s)^2)` and each
/// contact carries `weight / (3 cos a')` with `cos a' = (l cos a - s) / (l - delta)`; a
/// fixed point from `s = delta(weight / (3 cos a)) / cos a` (a few iterations: the angle
/// moves by a few thousandths of a radian).
fn static_sink_m(law: &NormalLaw, weight_n: f64, l_m: f64, contact_angle_rad: f64) -> f64 {
    let (sin_a, cos_a) = contact_angle_rad.sin_cos();
    let (horizontal, vertical) = (l_m * sin_a, l_m * cos_a);
    let mut sink_m = law.deflection_m(weight_n / (3.0 * cos_a)) / cos_a;
    for _ in 0..8 {
        let reach = (horizontal * horizontal + (vertical - sink_m).powi(2)).sqrt();
        let cos_now = (vertical - sink_m) / reach;
        let delta = law.deflection_m(weight_n / (3.0 * cos_now));
        let along = ((l_m - delta).powi(2) - horizontal * horizontal).max(0.0);
        sink_m = vertical - along.sqrt();
    }
    sink_m
}

/// Solver iterations (substeps) of rapier's step. Rapier has no contact to solve: the floor is
/// the world's own compliant contact ([`crate::world::floor`]), evaluated every world step
/// like the omniwheels'; rapier integrates the two bodies under the forces applied to them.
/// One substep does that, without the passes over constraints (there are none), and CCD is off.
pub const RAPIER_SOLVER_ITERATIONS: usize = 1;

/// Body-fixed geometry of one omniwheel.
#[derive(Clone, Copy, Debug)]
struct WheelGeometry {
    /// Wheel centre in the body frame, `(r + r_W) n_i` (m).
    centre_local: DVec3,
    /// Axle direction in the body frame, `a_i = d_i x n_i`.
    axle_local: DVec3,
}

/// Spin state of one omniwheel's drivetrain (motor side and wheel, relative to the body) and
/// its contact's tangential bristle.
#[derive(Clone, Copy, Debug, Default)]
struct WheelState {
    drive: DrivetrainState,
    bristle_m: f64,
}

/// The simulated ballbot: rapier3d integrates ball and body; the omniwheel contacts, the
/// wheel spin states, the ball's compliant contact on the floor and its rolling and spin
/// friction are computed here (see [`crate::world::contact`], [`crate::world::floor`]).
///
/// Frames: world z up, a level floor at z = 0 (an inclined one through the origin). The body
/// frame's origin is the nominal ball centre (where the ball centre sits when all three
/// contacts touch with zero penetration), x towards OW1; the body's centre of mass is at
/// `(0, 0, l)` in it.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_world::world::{BallbotWorld, WorldParams};
/// let mut world = BallbotWorld::new(WorldParams::ideal(BallbotParams::miapure_60kg()))?;
/// // Motors off for 1 s: the perfectly upright body has not started to fall, and each
/// // omniwheel carries m_U g / (3 cos alpha) = 343.6 N.
/// for _ in 0..8000 {
///     world.step([0.0; 3]);
/// }
/// let n = world.telemetry().wheels[0].normal_force_n;
/// assert!((n - 343.6).abs() < 1.0, "{n}");
/// // In the default world the rubber coating's whole-range law lets the body sink 3.8 mm
/// // (2.7 mm into each contact), which turns the contact normals: 349.0 N.
/// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
/// for _ in 0..8000 {
///     world.step([0.0; 3]);
/// }
/// let n = world.telemetry().wheels[0].normal_force_n;
/// assert!((n - 349.0).abs() < 1.0, "{n}");
/// # Ok::<(), ballbot_world::world::WorldError>(())
/// ```
pub struct BallbotWorld {
    params: WorldParams,
    pub(super) physics: PhysicsWorld,
    ball: RigidBodyHandle,
    pub(super) body: RigidBodyHandle,
    /// The floor and the ball's contact on it ([`crate::world::floor`]).
    pub(super) floor: Floor,
    law: ContactLaw,
    rollers: RollerProfile,
    geometry: [WheelGeometry; 3],
    wheels: [WheelState; 3],
    motor_cmd_nm: [f64; 3],
    drivers: [MotorDriver; 3],
    /// The drivetrain between each motor and its wheel ([`crate::world::transmission`]).
    drivetrain: Drivetrain,
    telemetry: StepTelemetry,
    monitor: FailureMonitor,
    sensors: Sensors,
    spin_friction_gain_nm_s: f64,
    /// The chassis' clearance above the floor at the body's current pose (m), which the
    /// failure monitor reads every world step: recomputed where the pose or the floor changes
    /// (`refresh_poses`, floor bumps and steps), at most once per rigid step.
    clearance_m: f64,
    /// Multi-rate bookkeeping between rapier steps ([`crate::world::rigid`]).
    rigid: RigidStepper,
}

fn to_glam(v: Vector3<f64>) -> DVec3 {
    DVec3::new(v.x, v.y, v.z)
}

fn to_na(v: DVec3) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

fn quat_to_na(q: DQuat) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.x, q.y, q.z))
}

impl BallbotWorld {
    /// Builds the world with the robot at rest, upright, ball on the floor at the origin and
    /// the contacts pre-loaded to their static normal forces.
    pub fn new(params: WorldParams) -> Result<Self, WorldError> {
        params.validate()?;
        let robot = &params.robot;
        let r = robot.ball_radius_m();
        let dt = &robot.drivetrain;
        let g = robot.sagittal.gravity_m_per_s2;
        let mut physics = PhysicsWorld::new();
        physics.gravity = DVec3::new(0.0, 0.0, -g);
        physics.integration_parameters.dt = params.rigid_step_secs();
        // No contact for rapier to solve: see RAPIER_SOLVER_ITERATIONS.
        physics.integration_parameters.num_solver_iterations = RAPIER_SOLVER_ITERATIONS;
        physics.integration_parameters.max_ccd_substeps = 0;
        // Nor any constraint or joint: the solver's passes over constraints (warm start, the
        // biased and the relaxation pass) have nothing to change, so they are skipped (the
        // velocities and poses rapier integrates are the same bit for bit).
        physics.integration_parameters.num_internal_pgs_iterations = 0;
        physics
            .integration_parameters
            .num_internal_stabilization_iterations = 0;
        physics.integration_parameters.warmstart_coefficient = 0.0;

        let m_u = robot.sagittal.body_mass_kg;
        let m_b = robot.sagittal.ball_mass_kg;
        // The ball starts pressed into the floor by the robot's weight, along the plane's
        // normal.
        let load_n = (m_b + m_u) * g * params.floor.plane_normal().z;
        let floor = Floor::new(&params.floor, r, m_b, load_n, dt.ball_floor_friction);
        let floor_sink = floor.static_deflection_m(load_n);
        let ball_centre = floor.plane_normal() * (r - floor_sink);

        let ball_props = MassProperties::new(
            DVec3::ZERO,
            robot.sagittal.ball_mass_kg,
            DVec3::splat(robot.sagittal.ball_inertia_kg_m2),
        );
        // No collider: nothing touches the ball in rapier (see RAPIER_SOLVER_ITERATIONS), so
        // its mass properties are given directly, like the body's.
        let ball = physics.insert_body(
            RigidBodyBuilder::dynamic()
                .translation(ball_centre)
                .additional_mass_properties(ball_props)
                .can_sleep(false),
        );

        let body_props = MassProperties::new(
            DVec3::new(0.0, 0.0, robot.sagittal.com_height_m),
            m_u,
            DVec3::new(
                robot.frontal.body_inertia_kg_m2,
                robot.sagittal.body_inertia_kg_m2,
                robot.spin.inertia_kg_m2,
            ),
        );
        // Start with the static penetration so the contacts carry the body's weight.
        let a = dt.contact_angle_rad;
        let normal_law = params.wheel_normal_law();
        let sink_m = static_sink_m(&normal_law, m_u * g, r + dt.wheel_radius_m, a);
        let body = physics.insert_body(
            RigidBodyBuilder::dynamic()
                .translation(ball_centre - DVec3::new(0.0, 0.0, sink_m))
                .additional_mass_properties(body_props)
                .can_sleep(false),
        );

        let r_w = dt.wheel_radius_m;
        let geometry = dt.wheel_azimuths_rad.map(|b| {
            let n = DVec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos());
            let d = DVec3::new(-b.sin(), b.cos(), 0.0);
            WheelGeometry {
                centre_local: n * (r + r_w),
                axle_local: d.cross(n),
            }
        });
        let c = &params.contact;
        let law = ContactLaw {
            normal: normal_law,
            traction_stiffness_n_per_m: c.traction_stiffness_n_per_m,
            traction_damping_n_s_per_m: c.traction_damping_n_s_per_m,
            static_friction: dt.wheel_ball_friction,
            kinetic_friction: dt.wheel_ball_friction * c.kinetic_friction_ratio,
            axle_loss_coefficient: c.axle_loss.coefficient(),
            axle_regularisation_speed_m_per_s: c.axle_loss.regularisation_speed_m_per_s,
        };
        let rollers = RollerProfile::new(&c.rollers, r_w, r);
        let state = RigidState::read(
            &physics,
            ball,
            body,
            geometry.map(|g| g.centre_local),
            geometry.map(|g| g.axle_local),
        );
        let rigid = RigidStepper::new(params.rigid_step_ratio, &physics, ball, body, state);
        let mut world = Self {
            physics,
            ball,
            body,
            floor,
            law,
            rollers,
            geometry,
            wheels: [WheelState::default(); 3],
            motor_cmd_nm: [0.0; 3],
            drivers: [MotorDriver::new(params.driver, dt.actuator); 3],
            drivetrain: params.drivetrain(),
            telemetry: StepTelemetry {
                time_secs: 0.0,
                wheels: [WheelTelemetry::default(); 3],
                ball_position_m: Vector3::zeros(),
                ball_orientation: UnitQuaternion::identity(),
                ball_velocity_m_per_s: Vector3::zeros(),
                ball_angular_velocity_rad_per_s: Vector3::zeros(),
                body_position_m: Vector3::zeros(),
                body_orientation: UnitQuaternion::identity(),
                body_rate_rad_per_s: Vector3::zeros(),
                tilt_rad: [0.0; 2],
                floor_force_n: 0.0,
            },
            monitor: FailureMonitor::new(params.failure),
            sensors: Sensors::new(params.sensors, dt.actuator.gear_ratio, params.dt_secs),
            // Half the gain that would stop the ball's spin in one step: a stiff, stable
            // regularisation of the Coulomb spin friction.
            spin_friction_gain_nm_s: 0.5 * robot.sagittal.ball_inertia_kg_m2 / params.dt_secs,
            // Set by refresh_poses below.
            clearance_m: f64::INFINITY,
            rigid,
            params,
        };
        for h in [world.ball, world.body] {
            let colliders = &world.physics.colliders;
            world.physics.bodies[h].recompute_mass_properties_from_colliders(colliders);
        }
        world.restart_rigid();
        world.refresh_poses();
        Ok(world)
    }

    /// The parameters the world was built with.
    pub fn params(&self) -> &WorldParams {
        &self.params
    }

    /// Simulated time (s).
    pub fn time_secs(&self) -> f64 {
        self.telemetry.time_secs
    }

    /// The telemetry of the last step (at construction: the initial poses).
    pub fn telemetry(&self) -> &StepTelemetry {
        &self.telemetry
    }

    /// The first failure detected, if any (the simulation keeps running after it).
    pub fn failure(&self) -> Option<Failure> {
        self.monitor.failure()
    }

    /// Which failures count ([`StopRules`]; all by default). Set before stepping: it clears
    /// any failure already latched.
    ///
    /// ```
    /// use ballbot_world::world::{BallbotWorld, StopRules, WorldParams};
    /// let mut world = BallbotWorld::new(WorldParams::miapure_60kg())?;
    /// world.set_stop_rules(StopRules::none());
    /// assert_eq!(world.stop_rules(), StopRules::none());
    /// # Ok::<(), ballbot_world::world::WorldError>(())
    /// ```
    pub fn set_stop_rules(&mut self, rules: StopRules) {
        self.monitor = FailureMonitor::with_rules(self.params.failure, rules);
    }

    /// The stop rules in force.
    pub fn stop_rules(&self) -> StopRules {
        self.monitor.rules()
    }

    /// Per wheel (OW1..OW3), why its motor driver disarmed, if it has (only the ODrive model
    /// trips; see [`crate::world::driver`]).
    pub fn driver_faults(&self) -> [Option<DriverFault>; 3] {
        self.drivers.each_ref().map(MotorDriver::fault)
    }

    /// Samples the sensors (IMU, encoders) at the current state.
    pub fn measure(&mut self) -> Measurement {
        self.sensors.sample(&self.telemetry)
    }

    /// The encoders' wheel speed estimate (rad/s), as the motor drivers read it every step.
    pub fn encoder_speeds_rad_per_s(&self) -> [f64; 3] {
        self.sensors.wheel_speeds()
    }

    /// Applies a horizontal (or any) impulse (N s) at the body's centre of mass, e.g. a push.
    pub fn push_body(&mut self, impulse_ns: Vector3<f64>) {
        self.sync_rigid();
        let body = &mut self.physics.bodies[self.body];
        body.apply_impulse(to_glam(impulse_ns), true);
        self.restart_rigid();
    }

    /// Sets the body's linear velocity of its centre of mass (m/s) and angular velocity
    /// (rad/s, world frame), e.g. to start a test from a moving state. The IMU's attitude
    /// filter starts again from the new state (a jump no accelerometer could sense).
    pub fn set_body_velocity(
        &mut self,
        linear_m_per_s: Vector3<f64>,
        angular_rad_per_s: Vector3<f64>,
    ) {
        self.sync_rigid();
        let body = &mut self.physics.bodies[self.body];
        body.set_linvel(to_glam(linear_m_per_s), true);
        body.set_angvel(to_glam(angular_rad_per_s), true);
        self.restart_rigid();
        self.sensors.restart_imu();
    }

    /// Sets the ball's linear (m/s) and angular (rad/s) velocity.
    pub fn set_ball_velocity(
        &mut self,
        linear_m_per_s: Vector3<f64>,
        angular_rad_per_s: Vector3<f64>,
    ) {
        self.sync_rigid();
        let ball = &mut self.physics.bodies[self.ball];
        ball.set_linvel(to_glam(linear_m_per_s), true);
        ball.set_angvel(to_glam(angular_rad_per_s), true);
        self.restart_rigid();
    }

    /// Rotates the body about the ball centre by `tilt_rad = [theta_x, theta_y]` (rotation
    /// about world x, then y), keeping the contacts' penetration: a starting pose, so the
    /// IMU's attitude filter starts again from it, as if it had converged there.
    pub fn tilt_body(&mut self, tilt_rad: [f64; 2]) {
        self.sync_rigid();
        let c = self.physics.bodies[self.ball].translation();
        let body = &mut self.physics.bodies[self.body];
        let rot = DQuat::from_rotation_y(tilt_rad[1]) * DQuat::from_rotation_x(tilt_rad[0]);
        let pose = *body.position();
        let offset = pose.translation - c;
        body.set_translation(c + rot * offset, true);
        body.set_rotation(rot * pose.rotation, true);
        self.restart_rigid();
        self.refresh_poses();
        self.sensors.restart_imu();
    }

    /// Moves the whole robot (ball and body) by `offset_m`, e.g. into the air.
    pub fn translate_robot(&mut self, offset_m: Vector3<f64>) {
        self.sync_rigid();
        let off = to_glam(offset_m);
        for h in [self.ball, self.body] {
            let rb = &mut self.physics.bodies[h];
            let t = rb.translation();
            rb.set_translation(t + off, true);
        }
        self.restart_rigid();
        self.floor.release();
        self.refresh_poses();
    }

    /// Sets gravity along -z (m/s^2); 0 gives free flight. `params().robot` follows (both
    /// planes' `gravity_m_per_s2`), so logs and reports see the value in force.
    ///
    /// Unlike [`WorldParams::validate`], which asks for a robot the core can balance (`g > 0`),
    /// 0 is accepted here: the free-flight test rig. Errors (the world unchanged):
    /// [`WorldError::InvalidParameter`] naming `robot.sagittal.gravity_m_per_s2` unless the
    /// value is finite and >= 0.
    pub fn set_gravity_m_per_s2(&mut self, gravity_m_per_s2: f64) -> Result<(), WorldError> {
        non_negative(gravity_m_per_s2, "robot.sagittal.gravity_m_per_s2")?;
        self.params.robot.sagittal.gravity_m_per_s2 = gravity_m_per_s2;
        self.params.robot.frontal.gravity_m_per_s2 = gravity_m_per_s2;
        self.sync_rigid();
        self.physics.gravity = DVec3::new(0.0, 0.0, -gravity_m_per_s2);
        self.restart_rigid();
        Ok(())
    }

    /// Sets the ball-floor friction coefficient (0: a frictionless floor);
    /// `params().robot.drivetrain.ball_floor_friction` follows.
    ///
    /// Errors (the world unchanged): [`WorldError::InvalidParameter`] naming
    /// `robot.drivetrain.ball_floor_friction` unless the value is finite and >= 0 (0 is the
    /// frictionless test rig; construction asks for > 0).
    pub fn set_floor_friction(&mut self, friction: f64) -> Result<(), WorldError> {
        non_negative(friction, "robot.drivetrain.ball_floor_friction")?;
        self.params.robot.drivetrain.ball_floor_friction = friction;
        self.floor.set_friction(friction);
        Ok(())
    }

    /// Sets the omniwheel-ball static friction coefficient `mu` (0: frictionless wheels);
    /// the kinetic one follows with the configured ratio, and so does
    /// `params().robot.drivetrain.wheel_ball_friction`.
    ///
    /// Errors (the world unchanged): [`WorldError::InvalidParameter`] naming
    /// `robot.drivetrain.wheel_ball_friction` unless the value is finite and >= 0 (0 is the
    /// frictionless test rig; construction asks for > 0).
    pub fn set_wheel_ball_friction(&mut self, friction: f64) -> Result<(), WorldError> {
        non_negative(friction, "robot.drivetrain.wheel_ball_friction")?;
        self.params.robot.drivetrain.wheel_ball_friction = friction;
        self.law.static_friction = friction;
        self.law.kinetic_friction = friction * self.params.contact.kinetic_friction_ratio;
        Ok(())
    }

    /// Test rig: clamps the ball (`true`) in place, or releases it.
    pub fn set_ball_fixed(&mut self, fixed: bool) {
        self.sync_rigid();
        let kind = if fixed {
            RigidBodyType::Fixed
        } else {
            RigidBodyType::Dynamic
        };
        self.physics.bodies[self.ball].set_body_type(kind, true);
        self.restart_rigid();
    }

    /// Test rig: clamps the body (`true`) in place, or releases it.
    pub fn set_body_fixed(&mut self, fixed: bool) {
        self.sync_rigid();
        let kind = if fixed {
            RigidBodyType::Fixed
        } else {
            RigidBodyType::Dynamic
        };
        self.physics.bodies[self.body].set_body_type(kind, true);
        self.restart_rigid();
    }

    /// Height of the chassis' lowest corner above the floor below it (m).
    pub fn chassis_clearance_m(&self) -> f64 {
        self.clearance_m
    }

    /// Recomputes [`Self::chassis_clearance_m`] (after the floor changed).
    pub(super) fn refresh_clearance(&mut self) {
        self.clearance_m = self.clearance_at_pose();
    }

    /// The chassis' clearance at the body's pose in rapier.
    fn clearance_at_pose(&self) -> f64 {
        // The corners (+-h, +-h, 0) of the body frame.
        let pose = self.physics.bodies[self.body].position();
        let h = self.params.chassis_half_width_m;
        let ex = pose.rotation * DVec3::X * h;
        let ey = pose.rotation * DVec3::Y * h;
        let mut clearance = f64::INFINITY;
        for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let p = pose.translation + ex * sx + ey * sy;
            clearance = clearance.min(p.z - self.floor.height_m(p.x, p.y));
        }
        clearance
    }

    fn contact_geometry(&self) -> [ContactKinematics; 3] {
        core::array::from_fn(|i| self.contact(i).0)
    }

    /// Wheel `i`'s contact kinematics, the contact point (world) and where on the rim it lies
    /// (roller gaps: [`crate::world::rollers`]), at the state the contacts see now.
    #[inline(always)]
    fn contact(&self, i: usize) -> (ContactKinematics, DVec3, RimContact) {
        let s = self.rigid.now();
        let c = s.ball_centre;
        let v_c = s.ball_velocity;
        let w_ball = s.ball_angvel;
        let com = s.body_com;
        let v_com = s.body_velocity;
        let w_body = s.body_angvel;
        let r = self.params.robot.ball_radius_m();
        let r_w = self.params.robot.drivetrain.wheel_radius_m;
        let centre = s.wheel_centres[i];
        let axle = s.axles[i];
        let diff = centre - c;
        let dist = diff.length();
        let n = diff / dist;
        let p = c + n * r;
        let d = n.cross(axle).normalize();
        let v_centre = v_com + w_body.cross(centre - com);
        let v_body_p = v_com + w_body.cross(p - com);
        let v_ball_p = v_c + w_ball.cross(p - c);
        // The effective radius r_W - dip(psi) and its rate, the rim speed's lever arm.
        let w = &self.wheels[i].drive;
        let rim = self.rollers.at(w.wheel_angle_rad);
        let v_rim = v_body_p + d * (rim.rim_radius_m * w.wheel_speed_rad_per_s);
        let slip = v_ball_p - v_rim;
        let axle_dir = d.cross(n);
        (
            ContactKinematics {
                normal: n,
                rolling_dir: d,
                axle_dir,
                penetration_m: r + (r_w - rim.dip_m) - dist,
                penetration_rate_m_per_s: -n.dot(v_centre - v_c)
                    - rim.dip_slope_m_per_rad * w.wheel_speed_rad_per_s,
                slip_speed_m_per_s: d.dot(slip),
                axle_slip_speed_m_per_s: axle_dir.dot(slip),
            },
            p,
            rim,
        )
    }

    /// Advances the world by one step of `params.dt_secs` with the motor torque commands
    /// `motor_torque_nm` (N m at the wheel; each passes through its motor driver at the
    /// wheel's current speed: [`WorldParams::driver`], the ODrive model in the default world, the
    /// actuator's straight torque-speed line in the ideal one). Returns the step's telemetry.
    pub fn step(&mut self, motor_torque_nm: [f64; 3]) -> &StepTelemetry {
        self.motor_cmd_nm = motor_torque_nm;
        let dt = self.params.dt_secs;
        let mut ball_force = DVec3::ZERO;
        let mut ball_torque = DVec3::ZERO;
        let mut body_force = DVec3::ZERO;
        let mut body_torque = DVec3::ZERO;
        let c = self.rigid.now().ball_centre;
        let body_com = self.rigid.now().body_com;
        for (i, &command_nm) in motor_torque_nm.iter().enumerate() {
            // Each wheel's contact reads only its own wheel's state, updated below.
            let (kin, p, rim) = self.contact(i);
            let wheel = &mut self.wheels[i];
            let out: ContactOutput = self.law.evaluate(&kin, &mut wheel.bristle_m, dt);
            let drive = self.drivers[i].step(command_nm, wheel.drive.motor_speed_rad_per_s);
            let tau = drive.torque_nm;
            // At a roller gap the normal force turns the wheel by N d(dip)/d(psi), the
            // generalised force of the normal spring (crate::world::rollers). The force itself
            // stays on the line of centres, so the hub passes the reaction to the body, like the
            // motor's: angular momentum and energy are both kept.
            let loads = DrivetrainLoads {
                motor_nm: tau,
                traction_nm: rim.rim_radius_m * out.traction_n,
                gap_nm: out.normal_force_n * rim.dip_slope_m_per_rad,
            };
            let spin = self.drivetrain.step(&mut wheel.drive, &loads, dt);
            // The wheel presses the ball away from itself (-n) and drives it along d.
            let f = kin.rolling_dir * out.traction_n + kin.axle_dir * out.axle_force_n
                - kin.normal * out.normal_force_n;
            ball_force += f;
            ball_torque += (p - c).cross(f);
            body_force -= f;
            body_torque -= (p - body_com).cross(f);
            // The body takes the change of the spins' angular momentum, n I_r dw_m/dt +
            // I_w dw_w/dt, not the torque that accelerates the reflected inertia.
            body_torque -= self.rigid.now().axles[i] * spin.spin_momentum_rate_nm;
            self.telemetry.wheels[i] = WheelTelemetry {
                normal_force_n: out.normal_force_n,
                traction_n: out.traction_n,
                traction_demand_n: out.traction_demand_n,
                axle_force_n: out.axle_force_n,
                cone_utilisation: out.cone_utilisation,
                slip_speed_m_per_s: kin.slip_speed_m_per_s,
                slipping: out.slipping,
                motor_torque_nm: tau,
                driver_current_a: drive.current_a,
                driver_limit: drive.limit,
                speed_rad_per_s: wheel.drive.wheel_speed_rad_per_s,
                angle_rad: wheel.drive.wheel_angle_rad,
                motor_speed_rad_per_s: wheel.drive.motor_speed_rad_per_s,
                motor_angle_rad: wheel.drive.motor_angle_rad,
                coupling_torque_nm: spin.coupling_torque_nm,
                gearbox_friction_nm: spin.friction_torque_nm,
            };
        }
        // The floor's compliant contact, then the ball's rolling resistance and spin
        // (torsional) friction, both bounded by its load.
        let state = self.rigid.now();
        let floor = self.floor.step(
            &BallState {
                centre: c,
                velocity: state.ball_velocity,
                angvel: state.ball_angvel,
            },
            dt,
        );
        ball_force += floor.wrench.force;
        ball_torque += floor.wrench.torque;
        let floor_n = floor.normal_n;
        let w_ball = state.ball_angvel;
        let w_h = DVec3::new(w_ball.x, w_ball.y, 0.0);
        let r = self.params.robot.ball_radius_m();
        let roll_max = self.params.rolling_resistance * floor_n * r;
        let w_h_len = w_h.length();
        const ROLL_EPS_RAD_PER_S: f64 = 0.05;
        if w_h_len > 0.0 {
            ball_torque -= w_h * (roll_max / w_h_len.max(ROLL_EPS_RAD_PER_S));
        }
        let spin_max = self.params.spin_friction_m * floor_n;
        let spin = (self.spin_friction_gain_nm_s * w_ball.z).clamp(-spin_max, spin_max);
        ball_torque.z -= spin;

        let ball = Wrench {
            force: ball_force,
            torque: ball_torque,
        };
        let body = Wrench {
            force: body_force,
            torque: body_torque,
        };
        self.telemetry.time_secs += dt;
        self.telemetry.floor_force_n = floor.wrench.force.z;
        self.sensors
            .record_encoders(self.telemetry.wheels.map(|w| w.motor_angle_rad));
        if self.rigid.add(ball, body, dt) {
            self.step_rigid();
        }
        let (telemetry, rigid, gravity) = (&self.telemetry, &self.rigid, self.physics.gravity);
        self.sensors.record_imu(|| ImuTruth {
            time_secs: telemetry.time_secs,
            orientation: telemetry.body_orientation,
            body_rate_rad_per_s: telemetry.body_rate_rad_per_s,
            velocity_m_per_s: to_na(rigid.now().body_velocity),
            gravity_m_per_s2: to_na(gravity),
        });
        self.monitor.update(&self.telemetry, self.clearance_m, dt);
        &self.telemetry
    }

    /// Steps rapier over the world steps since its last step, with the average of their
    /// wrenches, and starts the next interval ([`crate::world::rigid`]).
    fn step_rigid(&mut self) {
        let substeps = self.rigid.substeps();
        if substeps == 0 {
            return;
        }
        let interval = self.params.dt_secs * f64::from(substeps);
        let full = substeps == self.rigid.ratio();
        if !full {
            self.physics.integration_parameters.dt = interval;
        }
        let (ball_avg, body_avg) = self.rigid.averages();
        {
            let ball = &mut self.physics.bodies[self.ball];
            ball.reset_forces(false);
            ball.reset_torques(false);
            ball.add_force(ball_avg.force, false);
            ball.add_torque(ball_avg.torque, false);
        }
        {
            let body = &mut self.physics.bodies[self.body];
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_force(body_avg.force, false);
            body.add_torque(body_avg.torque, false);
        }
        self.physics.step();
        if !full {
            self.physics.integration_parameters.dt = self.params.rigid_step_secs();
        }
        let wheels = self.wheels_local();
        self.rigid
            .finish(&mut self.physics, (self.ball, self.body), wheels, interval);
        self.refresh_poses();
    }

    /// Completes the rigid step in progress (if any), so that rapier holds the current state:
    /// before a change made to the bodies from outside.
    pub(super) fn sync_rigid(&mut self) {
        self.step_rigid();
    }

    /// Starts a new rigid interval at rapier's state (after a change made from outside).
    pub(super) fn restart_rigid(&mut self) {
        let (centres, axles) = self.wheels_local();
        let state = RigidState::read(&self.physics, self.ball, self.body, centres, axles);
        self.rigid
            .restart(&self.physics, self.ball, self.body, state);
    }

    /// The wheels' centres and axles in the body frame.
    fn wheels_local(&self) -> ([DVec3; 3], [DVec3; 3]) {
        (
            self.geometry.map(|g| g.centre_local),
            self.geometry.map(|g| g.axle_local),
        )
    }

    /// Reads the poses and velocities into the telemetry and the chassis' clearance: after
    /// every change of the bodies' poses.
    fn refresh_poses(&mut self) {
        let ball = &self.physics.bodies[self.ball];
        let body = &self.physics.bodies[self.body];
        let t = &mut self.telemetry;
        t.ball_position_m = to_na(ball.translation());
        t.ball_orientation = quat_to_na(ball.position().rotation);
        t.ball_velocity_m_per_s = to_na(ball.linvel());
        t.ball_angular_velocity_rad_per_s = to_na(ball.angvel());
        let rot = body.position().rotation;
        t.body_position_m = to_na(body.translation());
        t.body_orientation = quat_to_na(rot);
        t.body_rate_rad_per_s = to_na(rot.inverse() * body.angvel());
        // Tilt about the body-aligned horizontal axes: the body's z axis seen in the
        // yaw-only frame.
        let z = rot * DVec3::Z;
        let x = rot * DVec3::X;
        // cos and sin of the yaw angle atan2(x_y, x_x), without the trigonometry.
        let x_h = (x.x * x.x + x.y * x.y).sqrt();
        let (c, s) = if x_h > 0.0 {
            (x.x / x_h, x.y / x_h)
        } else {
            (1.0, 0.0)
        };
        let zx = c * z.x + s * z.y;
        let zy = -s * z.x + c * z.y;
        t.tilt_rad = [(-zy).atan2(z.z), zx.atan2(z.z)];
        self.refresh_clearance();
    }
}
