//! MCAP logs of the 3D world: per-step telemetry, the controller's outer loop, and a Foxglove
//! 3D scene in which the robot is seen moving, its wheels spinning and its contact forces.
//!
//! [`WorldLogger`] writes one run into one MCAP file through [`McapLogger`] (typed JSON
//! channels, simulated log time, chunked so that a killed run leaves a readable file):
//!
//! | topic | message | rate (defaults) |
//! | --- | --- | --- |
//! | [`topics::WORLD_TELEMETRY`] `/world/telemetry` | [`WorldTelemetryMsg`]: per wheel normal force, traction, cone utilisation, slip speed, wheel speed, motor torque, slipping; ball position/velocity/angular velocity; body pose, rates, tilt | every step (8 kHz), or every `telemetry_every_steps`-th |
//! | [`topics::WORLD_CONTROLLER`] `/world/controller` | [`WorldControllerMsg`]: the outer loop's references, estimates, shaped commands, safety mode and faults | once per outer step (400 Hz) |
//! | [`topics::WORLD_COMMAND`] `/world/command` | [`WorldCommandMsg`]: the velocity command given ([`WorldLogger::record_command`]) | at most 400 Hz |
//! | [`topics::TRANSFORMS`] `/tf` | `foxglove.FrameTransforms`: `world -> ball` (with the ball's rotation), `world -> body`, `body -> ow1..ow3` (with each wheel's spin angle) | 100 Hz |
//! | [`topics::SCENE`] `/scene` | `foxglove.SceneUpdate`: floor, ball, body, the three omniwheels, contact-force arrows coloured by cone utilisation (red when slipping), wheel labels | 50 Hz |
//! | [`topics::FAULTS`] `/faults` | [`WorldEventMsg`]: the world's failure (tilt, body on the floor, sustained slip, lift-off), safety-mode changes, user events such as a push | on events |
//!
//! `foxglove/world-layout.json` (in the repository) opens such a log with the 3D panel and plots
//! of the per-wheel forces. The bytes are a function of the messages only (no wall clock), so
//! the same seeded run gives a bit-identical file.
//!
//! ```
//! use ballbot_core::command::{Command, VelocityCommand};
//! use ballbot_sim::log::{McapLog, topics};
//! use ballbot_sim::world::{WorldRobot, WorldLogger, WorldParams};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("world.mcap");
//! let params = WorldParams::miapure_60kg();
//! let mut sim = WorldRobot::new(params)?;
//! let mut log = WorldLogger::create(&path, &params)?;
//! let command = VelocityCommand { vx_m_per_s: 0.3, vy_m_per_s: 0.0, yaw_rate_rad_per_s: 0.0 };
//! for _ in 0..800 {
//!     // 0.1 s at 8 kHz
//!     sim.step(Command::Velocity(command));
//!     log.record_core(&sim)?;
//! }
//! log.finish()?;
//!
//! let read = McapLog::open(&path)?;
//! assert_eq!(read.channel(topics::WORLD_TELEMETRY).map(|c| c.message_count), Some(800));
//! assert_eq!(read.channel(topics::WORLD_CONTROLLER).map(|c| c.message_count), Some(40));
//! // At the first step, then at 0.01, 0.02, ..., 0.1 s (100 Hz) and every 0.02 s (50 Hz).
//! assert_eq!(read.channel(topics::TRANSFORMS).map(|c| c.message_count), Some(11));
//! assert_eq!(read.channel(topics::SCENE).map(|c| c.message_count), Some(6));
//! # Ok(())
//! # }
//! ```

use std::path::Path;

use ballbot_core::ballbot::OuterOutput;
use ballbot_core::command::VelocityCommand;
use ballbot_core::safety::Mode;
use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::failure::{Failure, FailureKind, tilt_from_vertical_rad};
use super::params::WorldParams;
use super::sim::BallbotWorld;
use super::telemetry::{StepTelemetry, WheelTelemetry};
use crate::log::foxglove::{
    ArrowPrimitive, BallbotScene, Color, CubePrimitive, CylinderPrimitive, FrameTransform,
    FrameTransforms, LinePrimitive, LineType, Point3, Pose, Quaternion, SceneEntity, SceneUpdate,
    TextPrimitive, Vector3 as FoxVector3,
};
use crate::log::{Channel, ChannelInfo, LogError, LoggerOptions, McapLogger, topics};
use crate::rig::WorldRobot;

/// One omniwheel in one step (see [`WheelTelemetry`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WheelMsg {
    /// Normal force `N_i` of the wheel on the ball (N).
    pub normal_force_n: f64,
    /// Traction `F_i` the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// Traction the contact would need to keep sticking (N).
    pub traction_demand_n: f64,
    /// Friction-cone utilisation `|F_i| / (mu N_i)`, 0 when lifted off.
    pub cone_utilisation: f64,
    /// Slip speed along the rolling direction, ball surface minus wheel rim (m/s).
    pub slip_speed_m_per_s: f64,
    /// Whether the contact slides (traction demand beyond the friction cone).
    pub slipping: bool,
    /// Torque the actuator delivered at the wheel (N m).
    pub motor_torque_nm: f64,
    /// Wheel speed relative to the body (rad/s).
    pub speed_rad_per_s: f64,
    /// Wheel angle relative to the body (rad).
    pub angle_rad: f64,
}

impl From<&WheelTelemetry> for WheelMsg {
    fn from(w: &WheelTelemetry) -> Self {
        Self {
            normal_force_n: w.normal_force_n,
            traction_n: w.traction_n,
            traction_demand_n: w.traction_demand_n,
            cone_utilisation: w.cone_utilisation,
            slip_speed_m_per_s: w.slip_speed_m_per_s,
            slipping: w.slipping,
            motor_torque_nm: w.motor_torque_nm,
            speed_rad_per_s: w.speed_rad_per_s,
            angle_rad: w.angle_rad,
        }
    }
}

/// The world's state after one step, in world coordinates (z up); topic
/// [`topics::WORLD_TELEMETRY`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldTelemetryMsg {
    /// Simulated time at the end of the step (s); equal to the log time.
    pub time_s: f64,
    /// The omniwheels OW1, OW2, OW3.
    pub wheels: [WheelMsg; 3],
    /// Ball centre `[x, y, z]` (m).
    pub ball_position_m: [f64; 3],
    /// Ball orientation, world from ball (rolling shows as its rotation).
    pub ball_orientation: Quaternion,
    /// Ball velocity `[x, y, z]` (m/s).
    pub ball_velocity_m_per_s: [f64; 3],
    /// Horizontal ball speed `|(v_x, v_y)|` (m/s).
    pub ball_speed_m_per_s: f64,
    /// Ball angular velocity `[x, y, z]` (rad/s).
    pub ball_angular_velocity_rad_per_s: [f64; 3],
    /// Body frame origin (the nominal ball centre in the body) `[x, y, z]` (m).
    pub body_position_m: [f64; 3],
    /// Body orientation, world from body.
    pub body_orientation: Quaternion,
    /// Body angular velocity in the body frame `[x, y, z]` (rad/s).
    pub body_rate_rad_per_s: [f64; 3],
    /// Body tilt about the body-aligned horizontal axes `[theta_x, theta_y]` (rad).
    pub tilt_rad: [f64; 2],
    /// Angle between the body axis and the vertical (rad).
    pub tilt_from_vertical_rad: f64,
    /// Body yaw (ZYX Euler) (rad).
    pub yaw_rad: f64,
    /// Normal force of the floor on the ball (N).
    pub floor_force_n: f64,
    /// Largest cone utilisation of the three wheels.
    pub max_cone_utilisation: f64,
    /// Whether the world has detected a failure at or before this step.
    pub failed: bool,
}

impl WorldTelemetryMsg {
    /// The message of one step's telemetry; `failed` says whether a failure has been detected.
    pub fn new(t: &StepTelemetry, failed: bool) -> Self {
        let (_, _, yaw_rad) = t.body_orientation.euler_angles();
        let v = &t.ball_velocity_m_per_s;
        Self {
            time_s: t.time_s,
            wheels: t.wheels.each_ref().map(WheelMsg::from),
            ball_position_m: t.ball_position_m.into(),
            ball_orientation: t.ball_orientation.into(),
            ball_velocity_m_per_s: (*v).into(),
            ball_speed_m_per_s: v.x.hypot(v.y),
            ball_angular_velocity_rad_per_s: t.ball_angular_velocity_rad_per_s.into(),
            body_position_m: t.body_position_m.into(),
            body_orientation: t.body_orientation.into(),
            body_rate_rad_per_s: t.body_rate_rad_per_s.into(),
            tilt_rad: t.tilt_rad,
            tilt_from_vertical_rad: tilt_from_vertical_rad(t),
            yaw_rad,
            floor_force_n: t.floor_force_n,
            max_cone_utilisation: t
                .wheels
                .iter()
                .map(|w| w.cone_utilisation)
                .fold(0.0, f64::max),
            failed,
        }
    }
}

/// A wheeled-inverted-pendulum plane's state `[theta, phi, theta_dot, phi_dot]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlaneStateMsg {
    /// Tilt `theta` (rad).
    pub tilt_rad: f64,
    /// Ball angle `phi` (rad).
    pub ball_angle_rad: f64,
    /// Tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// Ball rate `phi_dot` (rad/s).
    pub ball_rate_rad_per_s: f64,
}

impl PlaneStateMsg {
    fn new(s: &ballbot_core::WipState<f64>) -> Self {
        Self {
            tilt_rad: s[TILT],
            ball_angle_rad: s[BALL_ANGLE],
            tilt_rate_rad_per_s: s[TILT_RATE],
            ball_rate_rad_per_s: s[BALL_RATE],
        }
    }
}

/// The three planar states of the controller: sagittal and frontal planes, spin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlanarStatesMsg {
    /// Sagittal plane (tilt about y, ball rolling along x).
    pub sagittal: PlaneStateMsg,
    /// Frontal plane (tilt about x, ball rolling along y).
    pub frontal: PlaneStateMsg,
    /// Heading `theta_z` (rad, unwrapped).
    pub yaw_rad: f64,
    /// Yaw rate `theta_dot_z` (rad/s).
    pub yaw_rate_rad_per_s: f64,
}

impl PlanarStatesMsg {
    fn new(
        sagittal: &ballbot_core::WipState<f64>,
        frontal: &ballbot_core::WipState<f64>,
        spin: &ballbot_core::spin::SpinState<f64>,
    ) -> Self {
        Self {
            sagittal: PlaneStateMsg::new(sagittal),
            frontal: PlaneStateMsg::new(frontal),
            yaw_rad: spin[0],
            yaw_rate_rad_per_s: spin[1],
        }
    }
}

/// One outer-loop step of the core's controller ([`OuterOutput`]); topic
/// [`topics::WORLD_CONTROLLER`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldControllerMsg {
    /// Safety mode: `idle`, `balancing`, `controlled_stop` or `fault`.
    pub mode: String,
    /// Whether the motors are driven.
    pub motors_enabled: bool,
    /// Faults raised this step, one bit per `ballbot_core::safety::Fault` code.
    pub fault_bits: u16,
    /// In a controlled stop, whether the shaped command has come to rest.
    pub stopped: bool,
    /// Reference omniwheel speeds `psi_dot_r` sent to the motor drivers (rad/s).
    pub wheel_speed_reference_rad_per_s: [f64; 3],
    /// Reference omniwheel accelerations over the period (rad/s^2).
    pub wheel_accel_reference_rad_per_s2: [f64; 3],
    /// Feedforward omniwheel torques `tau_r` (N m).
    pub feedforward_torque_nm: [f64; 3],
    /// Reference planar torques `[tau_rx, tau_ry, tau_rz]` (N m).
    pub reference_torque_nm: [f64; 3],
    /// Reference planar rates `[phi_dot_rx, phi_dot_ry, theta_dot_rz]` (rad/s).
    pub reference_rate_rad_per_s: [f64; 3],
    /// The estimated planar states.
    pub estimate: PlanarStatesMsg,
    /// The shaped planar command states.
    pub command: PlanarStatesMsg,
}

/// The name of a safety mode in logs.
pub fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Idle => "idle",
        Mode::Balancing => "balancing",
        Mode::ControlledStop => "controlled_stop",
        Mode::Fault => "fault",
    }
}

impl From<&OuterOutput<f64>> for WorldControllerMsg {
    fn from(out: &OuterOutput<f64>) -> Self {
        let m = &out.motors;
        Self {
            mode: mode_name(out.safety.mode).to_owned(),
            motors_enabled: m.enabled,
            fault_bits: out.safety.faults.bits(),
            stopped: out.stopped,
            wheel_speed_reference_rad_per_s: m.speed_rad_per_s.into(),
            wheel_accel_reference_rad_per_s2: m.accel_rad_per_s2.into(),
            feedforward_torque_nm: m.feedforward_torque_nm.into(),
            reference_torque_nm: out.reference_torque_nm.into(),
            reference_rate_rad_per_s: out.reference_rate_rad_per_s.into(),
            estimate: PlanarStatesMsg::new(
                &out.states.sagittal,
                &out.states.frontal,
                &out.states.spin,
            ),
            command: PlanarStatesMsg::new(
                &out.commands.sagittal,
                &out.commands.frontal,
                &out.commands.spin,
            ),
        }
    }
}

/// A velocity command given to the robot; topic [`topics::WORLD_COMMAND`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldCommandMsg {
    /// Commanded velocity along the body x axis (towards OW1) (m/s).
    pub vx_m_per_s: f64,
    /// Commanded velocity along the body y axis (m/s).
    pub vy_m_per_s: f64,
    /// Commanded yaw rate (rad/s).
    pub yaw_rate_rad_per_s: f64,
    /// Commanded speed `|(vx, vy)|` (m/s).
    pub speed_m_per_s: f64,
    /// Commanded heading in the body frame, `atan2(vy, vx)` (deg; 0 is towards OW1).
    pub heading_deg: f64,
}

impl From<&VelocityCommand<f64>> for WorldCommandMsg {
    fn from(c: &VelocityCommand<f64>) -> Self {
        Self {
            vx_m_per_s: c.vx_m_per_s,
            vy_m_per_s: c.vy_m_per_s,
            yaw_rate_rad_per_s: c.yaw_rate_rad_per_s,
            speed_m_per_s: c.vx_m_per_s.hypot(c.vy_m_per_s),
            heading_deg: c.vy_m_per_s.atan2(c.vx_m_per_s).to_degrees(),
        }
    }
}

/// A failure or another event of a world run; topic [`topics::FAULTS`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldEventMsg {
    /// What happened: a failure (`tilt`, `body_touched_floor`, `sustained_slip`, `lift_off`),
    /// a safety-mode change (`mode`), or a user event (e.g. `push`).
    pub kind: String,
    /// A human-readable description.
    pub description: String,
    /// The wheel concerned, 0-based (OW1 is 0), if any.
    pub wheel_index: Option<u8>,
    /// Angle between the body axis and the vertical at the event (rad).
    pub tilt_rad: f64,
}

impl WorldEventMsg {
    /// The event of a detected failure; `tilt_rad` is the tilt from the vertical at detection.
    pub fn failure(failure: &Failure, tilt_rad: f64) -> Self {
        let wheel = |i: usize| u8::try_from(i).ok();
        let (kind, wheel_index, description) = match failure.kind {
            FailureKind::Tilt { tilt_rad } => (
                "tilt",
                None,
                format!("tilt {:.1} deg beyond the limit", tilt_rad.to_degrees()),
            ),
            FailureKind::BodyTouchedFloor => {
                ("body_touched_floor", None, "body touched the floor".into())
            }
            FailureKind::SustainedSlip { wheel: i } => (
                "sustained_slip",
                wheel(i),
                format!("sustained slip of OW{}", i + 1),
            ),
            FailureKind::LiftOff { wheel: i } => {
                ("lift_off", wheel(i), format!("lift-off of OW{}", i + 1))
            }
        };
        Self {
            kind: kind.to_owned(),
            description: format!("{description} at {:.4} s", failure.time_s),
            wheel_index,
            tilt_rad,
        }
    }
}

/// What a [`WorldLogger`] writes and how often.
///
/// Rates are set on a grid of simulated time (a message at the first step at or after each
/// multiple of the interval), so they do not depend on how often `record` is called beyond
/// rounding to the next step. Sizes with the defaults, for the MiaPURE with the core's
/// controller (zstd chunks): see `docs/world.md`, section "Logs and Foxglove".
#[derive(Clone, Debug, PartialEq)]
pub struct WorldLogOptions {
    /// Write the telemetry at every n-th call of `record` (1: every physics step). Default 1.
    /// Must be >= 1.
    pub telemetry_every_steps: u32,
    /// Simulated time between `foxglove.FrameTransforms` messages (s). Default 0.01 (100 Hz).
    /// Must be finite and > 0.
    pub transform_interval_secs: f64,
    /// Simulated time between `foxglove.SceneUpdate` messages (s). Default 0.02 (50 Hz).
    /// Must be finite and > 0.
    pub scene_interval_secs: f64,
    /// The controller's outer-loop period (s): one [`WorldControllerMsg`] per outer step, and
    /// commands ([`WorldLogger::record_command`]) at most this often. Default 1/400 s, the
    /// core's outer-loop rate. Must be a whole multiple of the physics step.
    pub controller_interval_secs: f64,
    /// Length of a contact-force arrow per newton (m/N). Default 5e-4 (the 344 N static load
    /// draws 0.17 m). Must be finite and > 0.
    pub metres_per_newton: f64,
    /// Chunking, flushing and compression of the file.
    pub logger: LoggerOptions,
}

impl Default for WorldLogOptions {
    fn default() -> Self {
        Self {
            telemetry_every_steps: 1,
            transform_interval_secs: 0.01,
            scene_interval_secs: 0.02,
            controller_interval_secs: 1.0 / 400.0,
            metres_per_newton: 5e-4,
            logger: LoggerOptions::default(),
        }
    }
}

impl WorldLogOptions {
    /// The defaults with the telemetry at 1 kHz (every 8th step at 8 kHz): about a sixth of
    /// the file size (0.77 instead of 4.4 MB per simulated second), for experiments that write
    /// many logs.
    ///
    /// ```
    /// use ballbot_sim::world::WorldLogOptions;
    /// assert_eq!(WorldLogOptions::compact().telemetry_every_steps, 8);
    /// ```
    pub fn compact() -> Self {
        Self {
            telemetry_every_steps: 8,
            ..Self::default()
        }
    }

    /// Checks every field against the physics step `dt_secs`; `path` only names the file in
    /// the error.
    pub fn validate(&self, path: &Path, dt_secs: f64) -> Result<(), LogError> {
        let invalid = |field, requirement| LogError::InvalidOption {
            path: path.to_owned(),
            field,
            requirement,
        };
        if self.telemetry_every_steps == 0 {
            return Err(invalid("telemetry_every_steps", ">= 1"));
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.transform_interval_secs) {
            return Err(invalid("transform_interval_secs", "finite and > 0"));
        }
        if !positive(self.scene_interval_secs) {
            return Err(invalid("scene_interval_secs", "finite and > 0"));
        }
        if !positive(self.metres_per_newton) {
            return Err(invalid("metres_per_newton", "finite and > 0"));
        }
        let ratio = self.controller_interval_secs / dt_secs;
        if !(ratio.is_finite() && ratio >= 1.0 && (ratio - ratio.round()).abs() < 1e-9) {
            return Err(invalid(
                "controller_interval_secs",
                "a whole multiple of the physics step dt_secs",
            ));
        }
        self.logger.validate(path)
    }
}

/// A fixed grid of simulated times: due at the first call at or after each multiple of the
/// interval.
#[derive(Clone, Copy, Debug)]
struct Grid {
    interval_secs: f64,
    next_secs: f64,
}

impl Grid {
    /// A step landing on the grid up to rounding counts as on it.
    const TOLERANCE_SECS: f64 = 1e-9;

    fn new(interval_secs: f64) -> Self {
        Self {
            interval_secs,
            next_secs: f64::NEG_INFINITY,
        }
    }

    /// Whether a message is due at `time_secs`; if so, moves to the next grid time.
    fn due(&mut self, time_secs: f64) -> bool {
        if time_secs + Self::TOLERANCE_SECS < self.next_secs {
            return false;
        }
        self.next_secs = ((time_secs + Self::TOLERANCE_SECS) / self.interval_secs).floor()
            * self.interval_secs
            + self.interval_secs;
        true
    }
}

/// The 3D scene of a world run: the robot's dimensions and frames, and the entities drawn.
///
/// Frames: `world` (fixed, z up), `ball` (ball centre, rotating with the ball), `body` (the
/// body frame of [`BallbotWorld`]: origin at the nominal ball centre, x towards OW1), and
/// `ow1`, `ow2`, `ow3` (each omniwheel's centre, z along its axle `a_i = d_i x n_i`, rotated by
/// the wheel's angle, so the wheels turn in the 3D panel).
#[derive(Clone, Debug, PartialEq)]
pub struct WorldScene {
    /// Ball, body and wheel dimensions and poses in the body frame.
    pub robot: BallbotScene,
    /// Names of the wheel frames, `ow1`, `ow2`, `ow3`.
    pub wheel_frames: [String; 3],
    /// Length of a contact-force arrow per newton (m/N).
    pub metres_per_newton: f64,
    /// Side of the square floor drawn around the origin (m). Default 20.
    pub floor_size_m: f64,
}

impl WorldScene {
    /// The scene of the robot in `params`.
    pub fn new(params: &WorldParams, metres_per_newton: f64) -> Self {
        Self {
            robot: BallbotScene::from_params(&params.robot),
            wheel_frames: ["ow1".to_owned(), "ow2".to_owned(), "ow3".to_owned()],
            metres_per_newton,
            floor_size_m: 20.0,
        }
    }

    /// The transforms `world -> ball`, `world -> body` and `body -> ow_i` of one step.
    pub fn frames(&self, t: &StepTelemetry) -> FrameTransforms {
        let world_from_ball =
            Isometry3::from_parts(Translation3::from(t.ball_position_m), t.ball_orientation);
        let world_from_body =
            Isometry3::from_parts(Translation3::from(t.body_position_m), t.body_orientation);
        let mut frames = self
            .robot
            .frames(t.time_s, &world_from_ball, &world_from_body);
        for ((name, body_from_wheel), wheel) in self
            .wheel_frames
            .iter()
            .zip(&self.robot.body_from_wheels)
            .zip(&t.wheels)
        {
            let spin = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), wheel.angle_rad);
            let body_from_spinning_wheel = body_from_wheel * spin;
            frames.transforms.push(FrameTransform::new(
                t.time_s,
                &self.robot.body_frame,
                name,
                &body_from_spinning_wheel,
            ));
        }
        frames
    }

    /// The entities of one step: `floor`, `ball`, `body`, `ow1`..`ow3`, `contact_forces` and
    /// `labels` (the wheel names).
    pub fn scene(&self, t: &StepTelemetry) -> SceneUpdate {
        let time_secs = t.time_s;
        let mut update = self.robot.scene(time_secs);
        // The robot's own wheels are drawn in the spinning wheel frames instead.
        update.entities.retain(|e| e.id != "wheels");
        update.entities.insert(0, self.floor(time_secs));
        for name in &self.wheel_frames {
            update.entities.push(self.wheel(time_secs, name));
        }
        update
            .entities
            .push(self.contact_forces(time_secs, &t.wheels));
        update.entities.push(self.labels(time_secs));
        update
    }

    /// The wheel names `OW1`..`OW3` just outside each wheel, in the body frame, facing the
    /// camera.
    fn labels(&self, time_secs: f64) -> SceneEntity {
        let mut labels = SceneEntity::new(time_secs, &self.robot.body_frame, "labels");
        for (i, body_from_wheel) in self.robot.body_from_wheels.iter().enumerate() {
            let centre = body_from_wheel.translation.vector;
            let outward = Vector3::new(centre.x, centre.y, 0.0)
                .try_normalize(1e-12)
                .unwrap_or_else(Vector3::x);
            let at = centre + outward * (2.0 * self.robot.wheel_radius_m);
            labels.texts.push(TextPrimitive {
                pose: Pose::at(at.x, at.y, at.z),
                billboard: true,
                font_size: 14.0,
                scale_invariant: true,
                color: Color::rgba(1.0, 1.0, 1.0, 1.0),
                text: format!("OW{}", i + 1),
            });
        }
        labels
    }

    /// A grey floor slab just below z = 0 with lines every metre, in the world frame.
    fn floor(&self, time_secs: f64) -> SceneEntity {
        let mut floor = SceneEntity::new(time_secs, &self.robot.world_frame, "floor");
        let size_m = self.floor_size_m;
        floor.cubes.push(CubePrimitive {
            pose: Pose::at(0.0, 0.0, -0.006),
            size: FoxVector3::new(size_m, size_m, 0.01),
            color: Color::rgba(0.55, 0.55, 0.55, 1.0),
        });
        let half_m = 0.5 * size_m;
        let lines = size_m.floor() as i32;
        let mut points = Vec::with_capacity(4 * (lines as usize + 1));
        for k in 0..=lines {
            let at_m = -half_m + f64::from(k);
            let z_m = 0.0005;
            points.push(Point3::from(nalgebra::Point3::new(at_m, -half_m, z_m)));
            points.push(Point3::from(nalgebra::Point3::new(at_m, half_m, z_m)));
            points.push(Point3::from(nalgebra::Point3::new(-half_m, at_m, z_m)));
            points.push(Point3::from(nalgebra::Point3::new(half_m, at_m, z_m)));
        }
        floor.lines.push(LinePrimitive {
            kind: LineType::LineList,
            pose: Pose::default(),
            thickness: 0.01,
            scale_invariant: false,
            points,
            color: Color::rgba(0.25, 0.25, 0.25, 1.0),
            colors: Vec::new(),
            indices: Vec::new(),
        });
        floor
    }

    /// One omniwheel in its own (spinning) frame: a disc about the axle (z) with a light spoke
    /// along its x axis, so its rotation shows.
    fn wheel(&self, time_secs: f64, frame: &str) -> SceneEntity {
        let mut wheel = SceneEntity::new(time_secs, frame, frame);
        let r_m = self.robot.wheel_radius_m;
        let width_m = self.robot.wheel_width_m;
        wheel.cylinders.push(CylinderPrimitive {
            pose: Pose::default(),
            size: FoxVector3::new(2.0 * r_m, 2.0 * r_m, width_m),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Color::rgba(0.2, 0.2, 0.2, 1.0),
        });
        wheel.cubes.push(CubePrimitive {
            pose: Pose::at(0.5 * r_m, 0.0, 0.0),
            size: FoxVector3::new(r_m, 0.2 * r_m, 1.1 * width_m),
            color: Color::rgba(0.95, 0.85, 0.2, 1.0),
        });
        wheel
    }

    /// The contact force of each wheel on the ball, `N_i (-n_i) + F_i d_i`, as an arrow
    /// ending at the wheel's (nominal) contact point, in the body frame, coloured by
    /// [`cone_colour`].
    fn contact_forces(&self, time_secs: f64, wheels: &[WheelTelemetry; 3]) -> SceneEntity {
        let mut entity = SceneEntity::new(time_secs, &self.robot.body_frame, "contact_forces");
        for (body_from_wheel, w) in self.robot.body_from_wheels.iter().zip(wheels) {
            let centre = body_from_wheel.translation.vector;
            let Some(inward) = (-centre).try_normalize(1e-12) else {
                continue;
            };
            let axle = body_from_wheel.rotation * Vector3::z();
            let rolling = axle.cross(&inward);
            let contact = centre + inward * self.robot.wheel_radius_m;
            let force = inward * w.normal_force_n + rolling * w.traction_n;
            let tail = contact - force * self.metres_per_newton;
            entity.arrows.push(ArrowPrimitive::from_vector(
                nalgebra::Point3::from(tail),
                force,
                self.metres_per_newton,
                cone_colour(w.cone_utilisation, w.slipping),
            ));
        }
        entity
    }
}

/// The colour of a contact-force arrow: green at no traction through yellow (half the cone)
/// to orange at the cone's edge; red while the contact slips.
pub fn cone_colour(cone_utilisation: f64, slipping: bool) -> Color {
    if slipping {
        return Color::rgba(0.9, 0.05, 0.05, 1.0);
    }
    let u = if cone_utilisation.is_finite() {
        cone_utilisation.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let green = (0.1, 0.75, 0.2);
    let yellow = (0.95, 0.85, 0.1);
    let orange = (1.0, 0.45, 0.0);
    let mix = |a: (f64, f64, f64), b: (f64, f64, f64), s: f64| {
        Color::rgba(
            a.0 + (b.0 - a.0) * s,
            a.1 + (b.1 - a.1) * s,
            a.2 + (b.2 - a.2) * s,
            1.0,
        )
    };
    if u <= 0.5 {
        mix(green, yellow, 2.0 * u)
    } else {
        mix(yellow, orange, 2.0 * u - 1.0)
    }
}

/// Writes a world run into an MCAP file (see the module docs for the channels).
///
/// Create it with the run's parameters, call [`record_core`](Self::record_core) (with a
/// [`WorldRobot`]), [`record`](Self::record) (a [`BallbotWorld`] and any controller output) or
/// [`record_telemetry`](Self::record_telemetry) after every physics step, and
/// [`finish`](Self::finish) at the end. A run that is killed leaves a file that
/// [`McapLog::open`](crate::log::McapLog::open) reads up to the last closed chunk (at most
/// one second of simulated time is lost with the default [`LoggerOptions`]).
#[derive(Debug)]
pub struct WorldLogger {
    log: McapLogger,
    scene: WorldScene,
    options: WorldLogOptions,
    dt_secs: f64,
    steps_per_outer: u64,
    telemetry: Channel<WorldTelemetryMsg>,
    controller: Channel<WorldControllerMsg>,
    command: Channel<WorldCommandMsg>,
    transforms: Channel<FrameTransforms>,
    scene_channel: Channel<SceneUpdate>,
    events: Channel<WorldEventMsg>,
    records: u64,
    transform_grid: Grid,
    scene_grid: Grid,
    command_grid: Grid,
    last_outer_index: Option<u64>,
    last_mode: Option<Mode>,
    failure_logged: bool,
}

impl WorldLogger {
    /// Creates (or truncates) the log at `path` for a run of the world built from `params`,
    /// with the default [`WorldLogOptions`].
    pub fn create(path: impl AsRef<Path>, params: &WorldParams) -> Result<Self, LogError> {
        Self::with_options(path, params, WorldLogOptions::default())
    }

    /// Creates (or truncates) the log at `path` with the given options.
    pub fn with_options(
        path: impl AsRef<Path>,
        params: &WorldParams,
        options: WorldLogOptions,
    ) -> Result<Self, LogError> {
        let path = path.as_ref();
        options.validate(path, params.dt_secs)?;
        let mut log = McapLogger::create(path, options.logger.clone())?;
        let telemetry = log.channel::<WorldTelemetryMsg>(topics::WORLD_TELEMETRY)?;
        let controller = log.channel::<WorldControllerMsg>(topics::WORLD_CONTROLLER)?;
        let command = log.channel::<WorldCommandMsg>(topics::WORLD_COMMAND)?;
        let transforms = log.channel::<FrameTransforms>(topics::TRANSFORMS)?;
        let scene_channel = log.channel::<SceneUpdate>(topics::SCENE)?;
        let events = log.channel::<WorldEventMsg>(topics::FAULTS)?;
        // Validated above: a whole number >= 1.
        let steps_per_outer = (options.controller_interval_secs / params.dt_secs).round() as u64;
        Ok(Self {
            log,
            scene: WorldScene::new(params, options.metres_per_newton),
            dt_secs: params.dt_secs,
            steps_per_outer,
            telemetry,
            controller,
            command,
            transforms,
            scene_channel,
            events,
            records: 0,
            transform_grid: Grid::new(options.transform_interval_secs),
            scene_grid: Grid::new(options.scene_interval_secs),
            command_grid: Grid::new(options.controller_interval_secs),
            last_outer_index: None,
            last_mode: None,
            failure_logged: false,
            options,
        })
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        self.log.path()
    }

    /// The options in use.
    pub fn options(&self) -> &WorldLogOptions {
        &self.options
    }

    /// The scene drawn (dimensions, frame names).
    pub fn scene(&self) -> &WorldScene {
        &self.scene
    }

    /// The underlying logger, e.g. to add channels of one's own.
    pub fn logger_mut(&mut self) -> &mut McapLogger {
        &mut self.log
    }

    /// Records the step just taken by a [`WorldRobot`]: its world (telemetry, failure) and its
    /// controller's last outer-loop output.
    pub fn record_core(&mut self, sim: &WorldRobot) -> Result<(), LogError> {
        self.record(sim.world(), sim.last_outer())
    }

    /// Records the step just taken by `world`, with the output of the controller's outer loop
    /// that drove it, if any (e.g. [`WorldRobot::last_outer`]).
    pub fn record(
        &mut self,
        world: &BallbotWorld,
        outer: Option<&OuterOutput<f64>>,
    ) -> Result<(), LogError> {
        self.record_telemetry(world.telemetry(), world.failure(), outer)
    }

    /// Records one step from its parts: the step's telemetry, the first failure detected so
    /// far, and the controller's latest outer-loop output.
    ///
    /// The outer output is written once per outer step (every `controller_interval_secs`),
    /// stamped with the time at which the controller computed it: the start of the physics
    /// step at which an outer step falls due, as in [`WorldRobot::step`].
    pub fn record_telemetry(
        &mut self,
        t: &StepTelemetry,
        failure: Option<Failure>,
        outer: Option<&OuterOutput<f64>>,
    ) -> Result<(), LogError> {
        if let Some(out) = outer {
            self.record_outer(t, out)?;
        }
        let every = u64::from(self.options.telemetry_every_steps);
        if self.records.is_multiple_of(every) {
            let msg = WorldTelemetryMsg::new(t, failure.is_some());
            self.log.write(&self.telemetry, t.time_s, &msg)?;
        }
        self.records += 1;
        if self.transform_grid.due(t.time_s) {
            let frames = self.scene.frames(t);
            self.log.write(&self.transforms, t.time_s, &frames)?;
        }
        if self.scene_grid.due(t.time_s) {
            let update = self.scene.scene(t);
            self.log.write(&self.scene_channel, t.time_s, &update)?;
        }
        if let (Some(f), false) = (failure, self.failure_logged) {
            self.failure_logged = true;
            let msg = WorldEventMsg::failure(&f, tilt_from_vertical_rad(t));
            self.log.write(&self.events, f.time_s.max(0.0), &msg)?;
        }
        Ok(())
    }

    fn record_outer(&mut self, t: &StepTelemetry, out: &OuterOutput<f64>) -> Result<(), LogError> {
        // The physics step that has just ended started at `steps_done - 1`.
        let steps_done = (t.time_s / self.dt_secs).round();
        if steps_done.is_nan() || steps_done < 1.0 {
            return Ok(());
        }
        let outer_index = (steps_done as u64 - 1) / self.steps_per_outer;
        if self.last_outer_index == Some(outer_index) {
            return Ok(());
        }
        self.last_outer_index = Some(outer_index);
        let computed_s = (outer_index * self.steps_per_outer) as f64 * self.dt_secs;
        self.log
            .write(&self.controller, computed_s, &WorldControllerMsg::from(out))?;
        let mode = out.safety.mode;
        if self.last_mode != Some(mode) {
            self.last_mode = Some(mode);
            let msg = WorldEventMsg {
                kind: "mode".to_owned(),
                description: format!("controller mode {}", mode_name(mode)),
                wheel_index: None,
                tilt_rad: tilt_from_vertical_rad(t),
            };
            self.log.write(&self.events, computed_s, &msg)?;
        }
        Ok(())
    }

    /// Records the velocity command in force at `time_s`, at most once per
    /// `controller_interval_secs` (call it every step; repeated calls in between are skipped).
    pub fn record_command(
        &mut self,
        time_s: f64,
        command: &VelocityCommand<f64>,
    ) -> Result<(), LogError> {
        if self.command_grid.due(time_s) {
            self.log
                .write(&self.command, time_s, &WorldCommandMsg::from(command))?;
        }
        Ok(())
    }

    /// Records an event of the run on [`topics::FAULTS`], e.g. `kind = "push"` with a
    /// description of the impulse; `tilt_rad` is the tilt from the vertical at the event.
    pub fn record_event(
        &mut self,
        time_s: f64,
        kind: &str,
        description: &str,
        tilt_rad: f64,
    ) -> Result<(), LogError> {
        let msg = WorldEventMsg {
            kind: kind.to_owned(),
            description: description.to_owned(),
            wheel_index: None,
            tilt_rad,
        };
        self.log.write(&self.events, time_s, &msg)
    }

    /// The channels registered, with the number of messages written to each so far.
    pub fn channels(&self) -> Vec<ChannelInfo> {
        self.log.channels()
    }

    /// Writes the summary section and footer and returns the channels with their message
    /// counts.
    pub fn finish(self) -> Result<Vec<ChannelInfo>, LogError> {
        self.log.finish()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_due_once_per_interval() {
        let mut grid = Grid::new(0.02);
        let dt = 1.0 / 8000.0;
        let due = (0..1600)
            .filter(|k| grid.due(f64::from(k + 1) * dt))
            .count();
        // 0.2 s: the first call (at dt), then at 0.02, 0.04, ..., 0.2 s.
        assert_eq!(due, 11);
    }

    #[test]
    fn cone_colour_goes_from_green_to_orange_and_red_when_slipping() {
        let green = cone_colour(0.0, false);
        assert!(green.g > green.r);
        let orange = cone_colour(1.0, false);
        assert!(orange.r > orange.g && orange.b < 0.1);
        let red = cone_colour(0.3, true);
        assert!(red.r > 0.8 && red.g < 0.1);
        assert_eq!(cone_colour(f64::NAN, false), cone_colour(1.0, false));
        assert_eq!(cone_colour(2.0, false), cone_colour(1.0, false));
    }

    #[test]
    fn invalid_options_name_the_field() {
        let path = Path::new("x.mcap");
        let dt = 1.0 / 8000.0;
        let bad = WorldLogOptions {
            controller_interval_secs: 1.5 * dt,
            ..WorldLogOptions::default()
        };
        assert!(matches!(
            bad.validate(path, dt),
            Err(LogError::InvalidOption {
                field: "controller_interval_secs",
                ..
            })
        ));
        let bad = WorldLogOptions {
            telemetry_every_steps: 0,
            ..WorldLogOptions::default()
        };
        assert!(matches!(
            bad.validate(path, dt),
            Err(LogError::InvalidOption {
                field: "telemetry_every_steps",
                ..
            })
        ));
        WorldLogOptions::default().validate(path, dt).unwrap();
    }
}
