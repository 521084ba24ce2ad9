//! MCAP logs of the 3D world: per-step telemetry, the controller's outer loop, and a Foxglove
//! 3D scene in which the robot is seen moving, its wheels spinning and its contact forces.
//!
//! [`WorldLogger`] writes one run into one MCAP file through
//! [`McapLogger`](crate::McapLogger) (typed JSON channels and the Foxglove SDK's protobuf
//! messages, simulated log time, chunked so that a killed run leaves a readable file), and with
//! the `live` feature to a live Foxglove view as well ([`LogSink`](crate::LogSink)):
//!
//! | topic | message | rate (defaults) |
//! | --- | --- | --- |
//! | [`topics::WORLD_TELEMETRY`](crate::topics::WORLD_TELEMETRY) `/world/telemetry` | [`WorldTelemetryMsg`]: per wheel normal force, traction, cone utilisation, slip speed, wheel speed, motor torque, slipping; ball position/velocity/angular velocity; body pose, rates, tilt | every step (8 kHz), or every `telemetry_every_steps`-th |
//! | [`topics::WORLD_CONTROLLER`](crate::topics::WORLD_CONTROLLER) `/world/controller` | [`WorldControllerMsg`]: the outer loop's references, estimates, shaped commands, safety mode and faults | once per outer step (400 Hz), or every `controller_every_outer_steps`-th |
//! | [`topics::WORLD_COMMAND`](crate::topics::WORLD_COMMAND) `/world/command` | [`WorldCommandMsg`]: the velocity command given ([`WorldLogger::record_command`]) | at most 400 Hz |
//! | [`topics::TRANSFORMS`](crate::topics::TRANSFORMS) `/tf` | `foxglove.FrameTransforms` (protobuf): `world -> ball` (with the ball's rotation), `world -> body`, `body -> ow1..ow3` (with each wheel's spin angle) | 100 Hz |
//! | [`topics::JOINT_STATES`](crate::topics::JOINT_STATES) `/joint_states` | `foxglove.JointStates` (protobuf): `ow1..ow3` angle (rad), speed (rad/s), motor torque as effort (N m) | 100 Hz |
//! | [`topics::SCENE`](crate::topics::SCENE) `/scene` | `foxglove.SceneUpdate` (protobuf): floor, ball, body, the three omniwheels, contact-force arrows coloured by cone utilisation (red when slipping), wheel labels | 50 Hz |
//! | [`topics::FAULTS`](crate::topics::FAULTS) `/faults` | [`WorldEventMsg`]: the world's failure (tilt, body on the floor, sustained slip, lift-off), safety-mode changes, user events such as a push | on events |
//! | [`topics::LOG`](crate::topics::LOG) `/log` | `foxglove.Log` (protobuf): the same events as text, for Foxglove's Log panel (failure: error; controlled stop: warning) | on events |
//!
//! [`WorldLogOptions::capped_at_telemetry_rate`] slows every periodic channel to the telemetry's
//! rate, so that a log decimated to 1 Hz costs little between the steps it writes.
//!
//! `foxglove/world-layout.json` (in the repository) opens such a log with the 3D panel and plots
//! of the per-wheel forces. The bytes are a function of the messages only (no wall clock), so
//! the same seeded run gives a bit-identical file.
//!
//! ```
//! use ballbot_core::command::{Command, VelocityCommand};
//! use ballbot_log::{McapLog, WorldLogger, topics};
//! use ballbot_world::rig::WorldRobot;
//! use ballbot_world::world::WorldParams;
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
//!     log.record_robot(&sim)?;
//! }
//! log.finish()?;
//!
//! let read = McapLog::open(&path)?;
//! assert_eq!(read.channel(topics::WORLD_TELEMETRY).map(|c| c.message_count), Some(800));
//! assert_eq!(read.channel(topics::WORLD_CONTROLLER).map(|c| c.message_count), Some(40));
//! // At the first step, then at 0.01, 0.02, ..., 0.1 s (100 Hz) and every 0.02 s (50 Hz).
//! assert_eq!(read.channel(topics::TRANSFORMS).map(|c| c.message_count), Some(11));
//! assert_eq!(read.channel(topics::JOINT_STATES).map(|c| c.message_count), Some(11));
//! assert_eq!(read.channel(topics::SCENE).map(|c| c.message_count), Some(6));
//! # Ok(())
//! # }
//! ```

mod grid;
mod logger;
mod messages;
mod options;
mod scene;

pub use logger::WorldLogger;
pub use messages::{
    PlanarStatesMsg, PlaneStateMsg, WorldCommandMsg, WorldControllerMsg, WorldEventMsg,
    WorldTelemetryMsg,
};
pub use options::WorldLogOptions;
pub use scene::{WorldScene, cone_colour};
