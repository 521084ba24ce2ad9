//! Foxglove's well-known messages for the 3D panel, from the official Foxglove SDK
//! (`foxglove::schemas`: `FrameTransforms`, `SceneUpdate`, `JointStates`, `Log`, ...), with
//! helpers that build them from nalgebra types and simulated time.
//!
//! The SDK's types are protobuf messages that carry their own schema; log them with
//! [`McapLogger::foxglove_channel`](crate::McapLogger::foxglove_channel) and read them back
//! with [`McapLog::decode_protobuf`](crate::McapLog::decode_protobuf) (or as JSON with
//! [`McapLog::json_series`](crate::McapLog::json_series)).
//!
//! [`BallbotScene`] draws a ballbot (ball, body, omniwheels) from poses, and the contact forces
//! of the omniwheels as arrows ([`BallbotScene::contact_forces`]):
//!
//! ```
//! use ballbot_log::foxglove::{BallbotScene, FrameTransforms, SceneUpdate};
//! use ballbot_log::{LoggerOptions, McapLog, McapLogger};
//! use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("3d.mcap");
//! let mut log = McapLogger::create(&path, LoggerOptions::default())?;
//! let tf = log.foxglove_channel::<FrameTransforms>("/tf")?;
//! let scene = log.foxglove_channel::<SceneUpdate>("/scene")?;
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
//!
//! let read = McapLog::open(&path)?;
//! let frames = read.decode_protobuf::<FrameTransforms>("/tf")?;
//! assert_eq!(frames[99].1.transforms[1].child_frame_id, "body");
//! # Ok(())
//! # }
//! ```

mod ballbot_scene;
mod convert;

pub use ::foxglove::schemas::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, FrameTransform, FrameTransforms,
    JointState, JointStates, KeyValuePair, LinePrimitive, Log, Point3, Pose, Quaternion,
    SceneEntity, SceneEntityDeletion, SceneUpdate, SpherePrimitive, TextPrimitive, Timestamp,
    Vector3, line_primitive::Type as LineType, log::Level as LogLevel,
};
pub use ballbot_scene::{BallbotScene, WheelContact};
pub use convert::{
    arrow, entity, frame_transform, point3, pose, pose_at, position_of, quaternion, rgba,
    rotation_of, size, timestamp, vector3,
};
