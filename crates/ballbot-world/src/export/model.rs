//! [`RobotModel`]: the world's robot as a tree of rigid bodies (ball; body = chassis, three
//! omniwheel hubs and their rollers), computed from [`WorldParams`] once, written by both the
//! MJCF and the URDF writer.
//!
//! # From the world to rigid bodies
//!
//! The world ([`crate::world::BallbotWorld`]) has two rigid bodies: the ball (mass `m_B`,
//! inertia `I_B` about its centre) and the body (mass `m_U`, centre of mass `(0, 0, l)` in the
//! body frame, principal inertias `frontal.body_inertia_kg_m2`, `sagittal.body_inertia_kg_m2`,
//! `spin.inertia_kg_m2`), the omniwheels' mass being part of the body's. Each omniwheel only
//! adds a spin state relative to the body, with the inertia `wheel_inertia_kg_m2` about its
//! axle plus the rotor's `rotor_inertia_kg_m2` reflected through the gear ratio squared.
//!
//! A simulator with jointed bodies needs the wheels and rollers as bodies of their own, so the
//! export splits the world's body into a chassis and three wheels such that the **composite**
//! (chassis, hubs and rollers, at any wheel or roller angle) has exactly the world body's mass,
//! centre of mass and inertia tensor:
//!
//! * each omniwheel is a uniform disc of the wheel radius `r_W` with the world's axle inertia
//!   `I_W`: mass `m_W = 2 I_W / r_W^2` (0.61 kg for MiaPURE, whose 1.2e-3 kg m^2 is itself the
//!   estimate of a 0.6 kg disc);
//! * its `N_r` rollers (the world's [`crate::world::RollerParams::count`], or
//!   [`CONTINUOUS_RIM_ROLLERS`] for the ideal world's continuous rim) are TPU barrels
//!   ([`ROLLER_DENSITY_KG_PER_M3`]) whose outer profile lies on the rim circle, with mid radius
//!   [`crate::world::rollers::MIAPURE_ROLLER_RADIUS_M`] and the world's gap between roller ends;
//!   their mass and inertia are those of the solid cylinder of mid radius and roller length;
//! * the hub carries the rest of the wheel's mass and axle inertia (a disc as thick as a
//!   roller);
//! * the chassis carries the rest of the body: mass `m_U - 3 m_W`, its centre of mass and
//!   inertia tensor (generally not diagonal) solved from the composite with the parallel-axis
//!   theorem.
//!
//! The rotor's reflected inertia is the hub joint's armature (MJCF) and the motor drives the
//! hub through the gear ratio.
//!
//! # Frames
//!
//! World z up, the floor at z = 0, the robot at rest at the origin. The body frame's origin is
//! the nominal ball centre (as in the world), x towards OW1. Wheel `i` (azimuth `beta_i`,
//! contact angle `alpha`) has its centre at `(r + r_W) n_i`, with `n_i = (sin alpha cos beta_i,
//! sin alpha sin beta_i, cos alpha)`, and its hub frame has x towards the ball (`-n_i`), y along
//! the rolling direction `d_i = (-sin beta_i, cos beta_i, 0)` and z along the axle
//! `a_i = d_i x n_i`, the hub joint's axis (MODEL.md section 1). Roller `j` sits at the angle
//! `2 pi j / N_r` from the hub's x axis, so at zero wheel angle the ball touches mid-roller, as
//! in the world ([`crate::world::rollers`]); its frame has z along the roller's axis (the rim's
//! tangent) and x pointing away from the hub's centre.

use super::ExportError;
use crate::world::WorldParams;
use crate::world::rollers::MIAPURE_ROLLER_RADIUS_M;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Rollers per omniwheel when the world's rim is continuous (`contact.rollers.count` 0, the
/// ideal world): the count of [`crate::world::RollerParams::miapure`].
pub const CONTINUOUS_RIM_ROLLERS: u32 = 10;

/// Density of the rollers (kg/m^3): thermoplastic polyurethane (TPU), 1.1 to 1.25 g/cm^3 on
/// datasheets; MiaPURE's rollers are TPU (module [`crate::world::rollers`]).
pub const ROLLER_DENSITY_KG_PER_M3: f64 = 1200.0;

/// Mass, centre of mass and inertia of one rigid body, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of mass in the body's frame (m).
    pub com_m: Vector3<f64>,
    /// Inertia tensor about the centre of mass, in the body's frame's axes (kg m^2).
    pub inertia_kg_m2: Matrix3<f64>,
}

impl Inertial {
    /// A body whose centre of mass is its frame's origin, with principal inertias along its
    /// axes.
    fn principal(mass_kg: f64, diagonal_kg_m2: Vector3<f64>) -> Self {
        Self {
            mass_kg,
            com_m: Vector3::zeros(),
            inertia_kg_m2: Matrix3::from_diagonal(&diagonal_kg_m2),
        }
    }

    /// This body seen from a parent frame in which its frame is `pose`.
    pub fn in_parent(&self, pose: &Pose) -> Self {
        let r = pose.rotation.matrix();
        Self {
            mass_kg: self.mass_kg,
            com_m: pose.position_m + r * self.com_m,
            inertia_kg_m2: r * self.inertia_kg_m2 * r.transpose(),
        }
    }

    /// The composite of rigidly joined bodies (all in one frame): total mass, centre of mass,
    /// inertia about it (parallel-axis theorem). `None` if the total mass is not positive.
    pub fn composite(parts: &[Inertial]) -> Option<Self> {
        let mass_kg: f64 = parts.iter().map(|p| p.mass_kg).sum();
        if !positive(mass_kg) {
            return None;
        }
        let com_m = parts
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.com_m * p.mass_kg)
            / mass_kg;
        let inertia_kg_m2 = parts.iter().fold(Matrix3::zeros(), |acc, p| {
            acc + p.inertia_kg_m2 + parallel_axis(p.mass_kg, &(p.com_m - com_m))
        });
        Some(Self {
            mass_kg,
            com_m,
            inertia_kg_m2,
        })
    }
}

/// `m (|d|^2 E - d d^T)`: the inertia a point mass `m` at offset `d` adds (kg m^2).
pub fn parallel_axis(mass_kg: f64, offset_m: &Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * offset_m.norm_squared() - offset_m * offset_m.transpose()) * mass_kg
}

/// Where a child frame sits in its parent: `parent_from_child`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The child's origin in the parent frame (m).
    pub position_m: Vector3<f64>,
    /// The child's axes in the parent frame (columns).
    pub rotation: Rotation3<f64>,
}

/// The shape of every roller: a barrel whose outer profile is the rim circle of radius `r_W`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollerShape {
    /// Radius at mid-roller (m).
    pub mid_radius_m: f64,
    /// Half the roller's length along its axis (m).
    pub half_length_m: f64,
    /// Distance from the hub's centre to the roller's axis, `r_W - mid_radius_m` (m).
    pub axis_offset_m: f64,
    /// The wheel radius `r_W` (m), the radius of the rollers' outer profile about the hub.
    pub rim_radius_m: f64,
}

impl RollerShape {
    /// The roller's radius at `s` along its axis from its middle (m):
    /// `sqrt(r_W^2 - s^2) - (r_W - mid_radius_m)`.
    pub fn radius_at_m(&self, s_m: f64) -> f64 {
        (self.rim_radius_m * self.rim_radius_m - s_m * s_m).sqrt() - self.axis_offset_m
    }
}

/// One roller of an omniwheel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roller {
    /// The roller's frame in its hub's frame (z along the roller's axis, its joint's axis).
    pub pose: Pose,
    /// Mass and inertia in the roller's frame.
    pub inertial: Inertial,
}

/// One omniwheel: a hub on a motor-driven joint, carrying its rollers.
#[derive(Clone, Debug, PartialEq)]
pub struct Wheel {
    /// `ow1`, `ow2`, `ow3`.
    pub name: String,
    /// The hub's frame in the body frame (z along the axle, the joint's axis).
    pub pose: Pose,
    /// The hub's mass and inertia in its frame.
    pub hub: Inertial,
    /// The rollers.
    pub rollers: Vec<Roller>,
}

/// The world's robot as rigid bodies and the data the writers need (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotModel {
    /// Ball radius `r` (m).
    pub ball_radius_m: f64,
    /// The ball, in its own frame (centred).
    pub ball: Inertial,
    /// The chassis: the world body without the omniwheels, in the body frame.
    pub chassis: Inertial,
    /// The three omniwheels (OW1..OW3).
    pub wheels: Vec<Wheel>,
    /// The rollers' shape.
    pub roller: RollerShape,
    /// Reflected rotor inertia on each hub joint, `I_rotor N^2` (kg m^2).
    pub armature_kg_m2: f64,
    /// Viscous friction of each hub joint (N m s/rad).
    pub wheel_damping_nm_s_per_rad: f64,
    /// Gear ratio between motor rotor and wheel.
    pub gear_ratio: f64,
    /// Peak torque at the wheel (N m).
    pub peak_wheel_torque_nm: f64,
    /// No-load speed at the wheel (rad/s).
    pub no_load_speed_rad_per_s: f64,
    /// Wheel-ball (roller-ball) friction coefficient.
    pub wheel_ball_friction: f64,
    /// Ball-floor friction coefficient.
    pub ball_floor_friction: f64,
    /// Ball-floor torsional friction, the world's `spin_friction_m` (m).
    pub spin_friction_m: f64,
    /// Ball-floor rolling friction as a length, the world's `rolling_resistance` times `r` (m).
    pub rolling_friction_m: f64,
    /// Chassis half-width (m), for its drawn box.
    pub chassis_half_width_m: f64,
    /// Chassis height above the ball centre (m), for its drawn box.
    pub chassis_height_m: f64,
    /// Gravity (m/s^2, along -z).
    pub gravity_m_per_s2: f64,
    /// The world's rigid step (s), the exported simulator's time step.
    pub timestep_secs: f64,
    /// Time constant of the roller-ball contact (s, MuJoCo's `solref`, critically damped): the
    /// inverse of the world's ball contact frequency
    /// ([`WorldParams::ball_contact_frequency_rad_per_s`], 2.7 ms in the default world), at
    /// least two time steps (MuJoCo's stability bound). The body then rests 1.6 mm lower on the
    /// ball; the default world's whole-range coating law, which this linear contact matches in
    /// its tangent at rest and not in its deflection, sinks it 3.8 mm.
    pub roller_contact_timeconst_secs: f64,
    /// Time constant of the ball-floor contact (s): two time steps, MuJoCo's stiffest stable
    /// setting (the ball settles 1.3 mm into the floor; 1.20 mm into the world's coating).
    pub floor_contact_timeconst_secs: f64,
}

impl RobotModel {
    /// The robot of the world `params` (validated first).
    ///
    /// Errors: [`ExportError::World`] for parameters the world rejects;
    /// [`ExportError::Split`] when the chassis cannot carry what is left of the body (e.g. wheels
    /// heavier than the body).
    ///
    /// ```
    /// use ballbot_world::export::RobotModel;
    /// use ballbot_world::world::WorldParams;
    /// let model = RobotModel::new(&WorldParams::miapure_60kg())?;
    /// assert_eq!((model.wheels.len(), model.wheels[0].rollers.len()), (3, 10));
    /// # Ok::<(), ballbot_world::export::ExportError>(())
    /// ```
    pub fn new(params: &WorldParams) -> Result<Self, ExportError> {
        params.validate()?;
        let robot = &params.robot;
        let dt = &robot.drivetrain;
        let roller = roller_shape(params)?;
        let wheels = (0..3)
            .map(|i| wheel(params, &roller, i))
            .collect::<Result<Vec<_>, _>>()?;
        let chassis = chassis(params, &wheels)?;
        let r = robot.ball_radius_m();
        let n = dt.actuator.gear_ratio;
        Ok(Self {
            ball_radius_m: r,
            ball: Inertial::principal(
                robot.sagittal.ball_mass_kg,
                Vector3::repeat(robot.sagittal.ball_inertia_kg_m2),
            ),
            chassis,
            wheels,
            roller,
            armature_kg_m2: params.rotor_inertia_kg_m2 * n * n,
            wheel_damping_nm_s_per_rad: params.wheel_damping_nm_s_per_rad,
            gear_ratio: n,
            peak_wheel_torque_nm: dt.actuator.peak_torque_nm,
            no_load_speed_rad_per_s: dt.actuator.no_load_speed_rad_per_s,
            wheel_ball_friction: dt.wheel_ball_friction,
            ball_floor_friction: dt.ball_floor_friction,
            spin_friction_m: params.spin_friction_m,
            rolling_friction_m: params.rolling_resistance * r,
            chassis_half_width_m: params.chassis_half_width_m,
            chassis_height_m: params.chassis_height_m,
            gravity_m_per_s2: robot.sagittal.gravity_m_per_s2,
            timestep_secs: params.rigid_step_secs(),
            roller_contact_timeconst_secs: (1.0 / params.ball_contact_frequency_rad_per_s())
                .max(2.0 * params.rigid_step_secs()),
            floor_contact_timeconst_secs: 2.0 * params.rigid_step_secs(),
        })
    }

    /// The body as the world sees it: chassis, hubs and rollers joined, in the body frame.
    pub fn body_composite(&self) -> Inertial {
        let mut parts = vec![self.chassis];
        for w in &self.wheels {
            parts.push(w.hub.in_parent(&w.pose));
            for r in &w.rollers {
                parts.push(r.inertial.in_parent(&r.pose).in_parent(&w.pose));
            }
        }
        // The chassis alone has a positive mass (RobotModel::new).
        Inertial::composite(&parts).unwrap_or(self.chassis)
    }

    /// Mass of the whole robot, ball and body (kg).
    pub fn total_mass_kg(&self) -> f64 {
        self.ball.mass_kg + self.body_composite().mass_kg
    }
}

/// `x > 0` (false for NaN).
fn positive(x: f64) -> bool {
    x > 0.0
}

fn split_error(field: &'static str, requirement: &'static str) -> ExportError {
    ExportError::Split { field, requirement }
}

/// The rollers' shape from the world's roller count and gap (module documentation).
fn roller_shape(params: &WorldParams) -> Result<RollerShape, ExportError> {
    let r_w = params.robot.drivetrain.wheel_radius_m;
    let count = roller_count(params);
    let mid_radius_m = MIAPURE_ROLLER_RADIUS_M.min(0.25 * r_w);
    // The roller spans its pitch on the rim minus the gap (a chord, as in world::rollers).
    let half_gap_rad = if params.contact.rollers.count > 0 {
        params.contact.rollers.gap_width_m / (2.0 * r_w)
    } else {
        0.0
    };
    let half_span_rad = std::f64::consts::PI / f64::from(count) - half_gap_rad;
    let shape = RollerShape {
        mid_radius_m,
        half_length_m: r_w * half_span_rad.sin(),
        axis_offset_m: r_w - mid_radius_m,
        rim_radius_m: r_w,
    };
    if !(positive(half_span_rad) && positive(shape.radius_at_m(shape.half_length_m))) {
        return Err(split_error(
            "contact.rollers.count",
            "the rollers must be at least 3 and leave each roller a barrel of positive length \
             and end radius",
        ));
    }
    Ok(shape)
}

fn roller_count(params: &WorldParams) -> u32 {
    match params.contact.rollers.count {
        0 => CONTINUOUS_RIM_ROLLERS,
        n => n,
    }
}

/// Omniwheel `i`: its hub frame, hub and rollers (module documentation).
fn wheel(params: &WorldParams, shape: &RollerShape, i: usize) -> Result<Wheel, ExportError> {
    let dt = &params.robot.drivetrain;
    let (a, b) = (dt.contact_angle_rad, dt.wheel_azimuths_rad[i]);
    let n = Vector3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos());
    let d = Vector3::new(-b.sin(), b.cos(), 0.0);
    let axle = d.cross(&n);
    let pose = Pose {
        position_m: n * (params.robot.ball_radius_m() + dt.wheel_radius_m),
        rotation: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[-n, d, axle])),
    };
    let count = roller_count(params);
    if count < 3 {
        return Err(split_error(
            "contact.rollers.count",
            "must be 0 (a continuous rim) or at least 3",
        ));
    }
    let rollers: Vec<Roller> = (0..count).map(|j| roller(shape, j, count)).collect();
    let r_w = dt.wheel_radius_m;
    let wheel_mass_kg = 2.0 * params.wheel_inertia_kg_m2 / (r_w * r_w);
    let rollers_mass_kg: f64 = rollers.iter().map(|r| r.inertial.mass_kg).sum();
    // The rollers' inertia about the axle (the hub's z), through the hub's centre.
    let rollers_axle_kg_m2: f64 = rollers
        .iter()
        .map(|r| {
            let p = r.inertial.in_parent(&r.pose);
            (p.inertia_kg_m2 + parallel_axis(p.mass_kg, &p.com_m))[(2, 2)]
        })
        .sum();
    let hub_mass_kg = wheel_mass_kg - rollers_mass_kg;
    let hub_axle_kg_m2 = params.wheel_inertia_kg_m2 - rollers_axle_kg_m2;
    if !(positive(hub_mass_kg) && positive(hub_axle_kg_m2)) {
        return Err(split_error(
            "wheel_inertia_kg_m2",
            "must exceed the rollers' inertia about the axle (the hub keeps the rest)",
        ));
    }
    // A disc as thick as a roller: I_axle = m R^2 / 2, I_transverse = I_axle / 2 + m w^2 / 12.
    let width_m = 2.0 * shape.mid_radius_m;
    let transverse = 0.5 * hub_axle_kg_m2 + hub_mass_kg * width_m * width_m / 12.0;
    Ok(Wheel {
        name: format!("ow{}", i + 1),
        pose,
        hub: Inertial::principal(
            hub_mass_kg,
            Vector3::new(transverse, transverse, hub_axle_kg_m2),
        ),
        rollers,
    })
}

/// Roller `j` of `count`: at the angle `2 pi j / count` from the hub's x axis.
fn roller(shape: &RollerShape, j: u32, count: u32) -> Roller {
    let g = std::f64::consts::TAU * f64::from(j) / f64::from(count);
    let radial = Vector3::new(g.cos(), g.sin(), 0.0);
    let tangent = Vector3::new(-g.sin(), g.cos(), 0.0);
    let pose = Pose {
        position_m: radial * shape.axis_offset_m,
        rotation: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
            radial,
            tangent.cross(&radial),
            tangent,
        ])),
    };
    // The solid cylinder of mid radius and roller length.
    let (rho, len) = (shape.mid_radius_m, 2.0 * shape.half_length_m);
    let mass_kg = ROLLER_DENSITY_KG_PER_M3 * std::f64::consts::PI * rho * rho * len;
    let transverse = mass_kg * (3.0 * rho * rho + len * len) / 12.0;
    Roller {
        pose,
        inertial: Inertial::principal(
            mass_kg,
            Vector3::new(transverse, transverse, 0.5 * mass_kg * rho * rho),
        ),
    }
}

/// The chassis: what is left of the world's body once the wheels are taken out.
fn chassis(params: &WorldParams, wheels: &[Wheel]) -> Result<Inertial, ExportError> {
    let robot = &params.robot;
    let body = Inertial {
        mass_kg: robot.sagittal.body_mass_kg,
        com_m: Vector3::new(0.0, 0.0, robot.sagittal.com_height_m),
        inertia_kg_m2: Matrix3::from_diagonal(&Vector3::new(
            robot.frontal.body_inertia_kg_m2,
            robot.sagittal.body_inertia_kg_m2,
            robot.spin.inertia_kg_m2,
        )),
    };
    let parts: Vec<Inertial> = wheels
        .iter()
        .flat_map(|w| {
            std::iter::once(w.hub.in_parent(&w.pose)).chain(
                w.rollers
                    .iter()
                    .map(|r| r.inertial.in_parent(&r.pose).in_parent(&w.pose)),
            )
        })
        .collect();
    let mass_kg = body.mass_kg - parts.iter().map(|p| p.mass_kg).sum::<f64>();
    if !positive(mass_kg) {
        return Err(split_error(
            "robot.sagittal.body_mass_kg",
            "must exceed the three omniwheels' mass (2 wheel_inertia_kg_m2 / r_W^2 each)",
        ));
    }
    let com_m = (body.com_m * body.mass_kg
        - parts
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.com_m * p.mass_kg))
        / mass_kg;
    // The body's inertia about its COM, less each part's own and parallel-axis terms about it,
    // less the chassis' own parallel-axis term.
    let inertia_kg_m2 = parts.iter().fold(body.inertia_kg_m2, |acc, p| {
        acc - p.inertia_kg_m2 - parallel_axis(p.mass_kg, &(p.com_m - body.com_m))
    }) - parallel_axis(mass_kg, &(com_m - body.com_m));
    let inertia_kg_m2 = 0.5 * (inertia_kg_m2 + inertia_kg_m2.transpose());
    if !is_physical_inertia(&inertia_kg_m2) {
        return Err(split_error(
            "robot",
            "the body's inertia must exceed the omniwheels' about its centre of mass (the \
             chassis' inertia must be positive definite)",
        ));
    }
    Ok(Inertial {
        mass_kg,
        com_m,
        inertia_kg_m2,
    })
}

/// Positive definite, with principal moments obeying the triangle inequality.
fn is_physical_inertia(inertia: &Matrix3<f64>) -> bool {
    let e = inertia.symmetric_eigenvalues();
    let (a, b, c) = (e[0], e[1], e[2]);
    e.iter().all(|&x| x > 0.0) && a + b >= c && b + c >= a && a + c >= b
}
