//! Foxglove well-known messages for the 3D panel: `foxglove.FrameTransform(s)` and
//! `foxglove.SceneUpdate`, as JSON with their JSON schemas.
//!
//! The types follow the field layout of the public Foxglove schemas (same field names, JSON
//! types and enum values, times as `{sec, nsec}`, byte fields as base64 strings); their JSON
//! schemas are generated from these definitions, with the doc comments as descriptions, under
//! the well-known schema names, so Foxglove's 3D panel recognises the channels. Log them with
//! [`McapLogger::channel`](crate::log::McapLogger::channel) like any other message.
//!
//! [`BallbotScene`] draws a ballbot (ball, body, omniwheels) from poses, and the contact forces
//! of the omniwheels as arrows ([`BallbotScene::contact_forces`]):
//!
//! ```
//! use ballbot_sim::log::foxglove::{BallbotScene, FrameTransforms, SceneUpdate};
//! use ballbot_sim::log::{LoggerOptions, McapLogger};
//! use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let mut log = McapLogger::create(dir.path().join("3d.mcap"), LoggerOptions::default())?;
//! let tf = log.channel::<FrameTransforms>("/tf")?;
//! let scene = log.channel::<SceneUpdate>("/scene")?;
//! let robot = BallbotScene::miapure_like();
//! for step in 0..100 {
//!     let time_secs = f64::from(step) * 0.01;
//!     let x_m = 0.5 * time_secs;
//!     let world_from_ball = Isometry3::from_parts(
//!         Translation3::new(x_m, 0.0, robot.ball_radius_m),
//!         UnitQuaternion::from_axis_angle(&Vector3::y_axis(), x_m / robot.ball_radius_m),
//!     );
//!     let world_from_body = Isometry3::translation(x_m, 0.0, robot.ball_radius_m);
//!     log.write(&tf, time_secs, &robot.frames(time_secs, &world_from_ball, &world_from_body))?;
//!     log.write(&scene, time_secs, &robot.scene(time_secs))?;
//! }
//! log.finish()?;
//! # Ok(())
//! # }
//! ```

mod ballbot_scene;
mod frame_transform;
mod geometry;
mod scene;

pub use ballbot_scene::{BallbotScene, WheelContact};
pub use frame_transform::{FrameTransform, FrameTransforms};
pub use geometry::{Color, Duration, Point3, Pose, Quaternion, Time, Vector3};
pub use scene::{
    ArrowPrimitive, CubePrimitive, CylinderPrimitive, KeyValuePair, LinePrimitive, LineType,
    ModelPrimitive, SceneEntity, SceneEntityDeletion, SceneEntityDeletionType, SceneUpdate,
    SpherePrimitive, TextPrimitive, TriangleListPrimitive,
};
