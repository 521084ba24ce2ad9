//! Foxglove well-known messages for the 3D panel: `foxglove.FrameTransform(s)` and
//! `foxglove.SceneUpdate`, as JSON with their JSON schemas.
//!
//! The types follow the field layout of the public Foxglove schemas (same field names, JSON
//! types and enum values, times as `{sec, nsec}`, byte fields as base64 strings); their JSON
//! schemas are generated from these definitions, with the doc comments as descriptions, under
//! the well-known schema names, so Foxglove's 3D panel recognises the channels. Log them with
//! [`McapLogger::channel`](super::McapLogger::channel) like any other message.
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

use std::borrow::Cow;

use ballbot_core::BallbotParams;
use nalgebra::{Isometry3, UnitQuaternion};
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::secs_to_ns;

/// A timestamp in seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Time {
    /// Seconds.
    pub sec: u32,
    /// Nanoseconds, 0 to 999,999,999.
    #[schemars(range(max = 999_999_999))]
    pub nsec: u32,
}

impl Time {
    /// The time stamp of a simulated time in seconds, rounded to the nanosecond; saturates to 0
    /// for negative or NaN times and to `u32::MAX` seconds beyond that.
    pub fn from_secs(time_secs: f64) -> Self {
        let time_ns =
            secs_to_ns(time_secs.max(0.0)).unwrap_or(if time_secs > 0.0 { u64::MAX } else { 0 });
        let sec = u32::try_from(time_ns / 1_000_000_000).unwrap_or(u32::MAX);
        // The remainder is below 1e9 and fits in u32.
        let nsec = u32::try_from(time_ns % 1_000_000_000).unwrap_or(0);
        Self { sec, nsec }
    }
}

/// A signed duration in seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Duration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0 to 999,999,999.
    #[schemars(range(max = 999_999_999))]
    pub nsec: u32,
}

/// A vector in 3D space that represents a direction only.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Vector3 {
    /// x coordinate length.
    pub x: f64,
    /// y coordinate length.
    pub y: f64,
    /// z coordinate length.
    pub z: f64,
}

impl Vector3 {
    /// A vector from its components.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

impl From<nalgebra::Vector3<f64>> for Vector3 {
    fn from(v: nalgebra::Vector3<f64>) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

/// A point representing a position in 3D space.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Point3 {
    /// x coordinate position.
    pub x: f64,
    /// y coordinate position.
    pub y: f64,
    /// z coordinate position.
    pub z: f64,
}

impl From<nalgebra::Point3<f64>> for Point3 {
    fn from(p: nalgebra::Point3<f64>) -> Self {
        Self {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }
}

/// A quaternion representing a rotation in 3D space (x, y, z vector part, w scalar part).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Quaternion {
    /// x value.
    pub x: f64,
    /// y value.
    pub y: f64,
    /// z value.
    pub z: f64,
    /// w value.
    pub w: f64,
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Self = Self {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };
}

impl Default for Quaternion {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl From<UnitQuaternion<f64>> for Quaternion {
    fn from(q: UnitQuaternion<f64>) -> Self {
        Self {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }
    }
}

/// A position and orientation for an object or reference frame in 3D space.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Pose {
    /// Point denoting position in 3D space.
    pub position: Vector3,
    /// Quaternion denoting orientation in 3D space.
    pub orientation: Quaternion,
}

impl From<&Isometry3<f64>> for Pose {
    fn from(iso: &Isometry3<f64>) -> Self {
        Self {
            position: iso.translation.vector.into(),
            orientation: iso.rotation.into(),
        }
    }
}

impl Pose {
    /// The pose at `position` with no rotation.
    pub const fn at(x: f64, y: f64, z: f64) -> Self {
        Self {
            position: Vector3::new(x, y, z),
            orientation: Quaternion::IDENTITY,
        }
    }
}

/// A color in RGBA format, each channel between 0 and 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Color {
    /// Red value between 0 and 1.
    pub r: f64,
    /// Green value between 0 and 1.
    pub g: f64,
    /// Blue value between 0 and 1.
    pub b: f64,
    /// Alpha value between 0 and 1.
    pub a: f64,
}

impl Color {
    /// A color from its channels, each between 0 and 1.
    pub const fn rgba(r: f64, g: f64, b: f64, a: f64) -> Self {
        Self { r, g, b, a }
    }
}

impl Default for Color {
    fn default() -> Self {
        Self::rgba(1.0, 1.0, 1.0, 1.0)
    }
}

/// A transform between two reference frames in 3D space.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.FrameTransform")]
pub struct FrameTransform {
    /// Timestamp of transform.
    pub timestamp: Time,
    /// Name of the parent frame.
    pub parent_frame_id: String,
    /// Name of the child frame.
    pub child_frame_id: String,
    /// Translation component of the transform.
    pub translation: Vector3,
    /// Rotation component of the transform.
    pub rotation: Quaternion,
}

impl FrameTransform {
    /// The transform `parent_from_child` (the child frame's pose in the parent frame) at a
    /// simulated time.
    pub fn new(
        time_secs: f64,
        parent_frame_id: &str,
        child_frame_id: &str,
        parent_from_child: &Isometry3<f64>,
    ) -> Self {
        Self {
            timestamp: Time::from_secs(time_secs),
            parent_frame_id: parent_frame_id.to_owned(),
            child_frame_id: child_frame_id.to_owned(),
            translation: parent_from_child.translation.vector.into(),
            rotation: parent_from_child.rotation.into(),
        }
    }
}

/// An array of FrameTransform messages.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.FrameTransforms")]
pub struct FrameTransforms {
    /// Array of transforms.
    pub transforms: Vec<FrameTransform>,
}

/// An enumeration indicating which entities should match a SceneEntityDeletion command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SceneEntityDeletionType {
    /// Delete the existing entity on the same topic that has the provided `id`.
    #[default]
    MatchingId = 0,
    /// Delete all existing entities on the same topic.
    All = 1,
}

/// Type of primitive to draw with a LinePrimitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineType {
    /// Connected line segments: 0-1, 1-2, ..., (n-1)-n.
    #[default]
    LineStrip = 0,
    /// Closed polygon: 0-1, 1-2, ..., (n-1)-n, n-0.
    LineLoop = 1,
    /// Individual line segments: 0-1, 2-3, 4-5, ...
    LineList = 2,
}

/// Foxglove enums travel as their integer values, with a `oneOf` of named constants as schema.
macro_rules! integer_enum {
    ($ty:ident, $name:literal, $description:literal, [$(($variant:ident, $value:literal, $label:literal)),+]) => {
        impl Serialize for $ty {
            fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_u8(*self as u8)
            }
        }

        impl<'de> Deserialize<'de> for $ty {
            fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                match u8::deserialize(deserializer)? {
                    $($value => Ok(Self::$variant),)+
                    other => Err(serde::de::Error::custom(format!(
                        "{other} is not a valid {}", $name
                    ))),
                }
            }
        }

        impl JsonSchema for $ty {
            fn schema_name() -> Cow<'static, str> {
                Cow::Borrowed($name)
            }

            fn inline_schema() -> bool {
                true
            }

            fn json_schema(_generator: &mut SchemaGenerator) -> Schema {
                json_schema!({
                    "title": $name,
                    "description": $description,
                    "type": "integer",
                    "oneOf": [$({"title": $label, "const": $value}),+]
                })
            }
        }
    };
}

integer_enum!(
    SceneEntityDeletionType,
    "foxglove.SceneEntityDeletionType",
    "An enumeration indicating which entities should match a SceneEntityDeletion command",
    [(MatchingId, 0, "MATCHING_ID"), (All, 1, "ALL")]
);

integer_enum!(
    LineType,
    "foxglove.LineType",
    "An enumeration indicating how input points should be interpreted to create lines",
    [
        (LineStrip, 0, "LINE_STRIP"),
        (LineLoop, 1, "LINE_LOOP"),
        (LineList, 2, "LINE_LIST")
    ]
);

/// Command to remove previously published entities.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct SceneEntityDeletion {
    /// Timestamp of the deletion. Only matching entities earlier than this timestamp will be
    /// deleted.
    pub timestamp: Time,
    /// Type of deletion action to perform.
    #[serde(rename = "type")]
    pub kind: SceneEntityDeletionType,
    /// Identifier which must match if `type` is `MATCHING_ID`.
    pub id: String,
}

/// A key with its associated value.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
pub struct KeyValuePair {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

/// A primitive representing an arrow, pointing along the +x axis of its pose.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct ArrowPrimitive {
    /// Position of the arrow's tail and orientation of the arrow. Identity orientation means
    /// the arrow points in the +x direction.
    pub pose: Pose,
    /// Length of the arrow shaft.
    pub shaft_length: f64,
    /// Diameter of the arrow shaft.
    pub shaft_diameter: f64,
    /// Length of the arrow head.
    pub head_length: f64,
    /// Diameter of the arrow head.
    pub head_diameter: f64,
    /// Color of the arrow.
    pub color: Color,
}

impl ArrowPrimitive {
    /// An arrow from `tail` along `vector` (in the entity's frame), its length scaled by
    /// `length_per_unit` (e.g. metres per newton for a force), with a head a fifth of its length.
    pub fn from_vector(
        tail: nalgebra::Point3<f64>,
        vector: nalgebra::Vector3<f64>,
        length_per_unit: f64,
        color: Color,
    ) -> Self {
        let length = vector.norm() * length_per_unit;
        let orientation = UnitQuaternion::rotation_between(&nalgebra::Vector3::x(), &vector)
            .unwrap_or_else(|| {
                // Antiparallel to x (or zero): turn half a turn about z.
                UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), std::f64::consts::PI)
            });
        let head_length = 0.2 * length;
        Self {
            pose: Pose {
                position: tail.coords.into(),
                orientation: orientation.into(),
            },
            shaft_length: length - head_length,
            shaft_diameter: 0.05 * length.max(0.2),
            head_length,
            head_diameter: 0.1 * length.max(0.2),
            color,
        }
    }
}

/// A primitive representing a cube or rectangular prism.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct CubePrimitive {
    /// Position of the center of the cube and orientation of the cube.
    pub pose: Pose,
    /// Size of the cube along each axis.
    pub size: Vector3,
    /// Color of the cube.
    pub color: Color,
}

/// A primitive representing a sphere or ellipsoid.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct SpherePrimitive {
    /// Position of the center of the sphere and orientation of the sphere.
    pub pose: Pose,
    /// Size (diameter) of the sphere along each axis.
    pub size: Vector3,
    /// Color of the sphere.
    pub color: Color,
}

/// A primitive representing a cylinder, elliptic cylinder, or truncated cone; its axis is the
/// z axis of its pose.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct CylinderPrimitive {
    /// Position of the center of the cylinder and orientation of the cylinder. The flat face(s)
    /// are perpendicular to the z-axis.
    pub pose: Pose,
    /// Size of the cylinder's bounding box.
    pub size: Vector3,
    /// 0-1, ratio of the diameter of the cylinder's bottom face (min z) to the bottom of the
    /// bounding box.
    pub bottom_scale: f64,
    /// 0-1, ratio of the diameter of the cylinder's top face (max z) to the top of the bounding
    /// box.
    pub top_scale: f64,
    /// Color of the cylinder.
    pub color: Color,
}

/// A primitive representing a series of points connected by lines.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct LinePrimitive {
    /// Drawing primitive to use for lines.
    #[serde(rename = "type")]
    pub kind: LineType,
    /// Origin of lines relative to reference frame.
    pub pose: Pose,
    /// Width of the line (metres, or pixels if `scale_invariant`).
    pub thickness: f64,
    /// Whether the line thickness is in pixels rather than metres.
    pub scale_invariant: bool,
    /// Points along the line.
    pub points: Vec<Point3>,
    /// Solid color to use for the whole line, used when `colors` is empty.
    pub color: Color,
    /// Per-point colors (if non-empty, one per point).
    pub colors: Vec<Color>,
    /// Indices into the `points` and `colors` arrays, to reuse points (empty: use all points
    /// in order).
    pub indices: Vec<u32>,
}

/// A primitive representing a set of triangles or a surface tiled by triangles.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct TriangleListPrimitive {
    /// Origin of triangles relative to reference frame.
    pub pose: Pose,
    /// Vertices to use for triangles, interpreted as a list of triples (0-1-2, 3-4-5, ...).
    pub points: Vec<Point3>,
    /// Solid color to use for the whole shape, used when `colors` is empty.
    pub color: Color,
    /// Per-vertex colors (if non-empty, one per point).
    pub colors: Vec<Color>,
    /// Indices into the `points` and `colors` arrays, to reuse vertices (empty: use all points
    /// in order).
    pub indices: Vec<u32>,
}

/// A primitive representing a text label.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct TextPrimitive {
    /// Position of the center of the text box and orientation of the text.
    pub pose: Pose,
    /// Whether the text should respect `pose.orientation` (false) or always face the camera
    /// (true).
    pub billboard: bool,
    /// Font size (height of one line of text).
    pub font_size: f64,
    /// Whether the font size is in pixels rather than metres.
    pub scale_invariant: bool,
    /// Color of the text.
    pub color: Color,
    /// Text.
    pub text: String,
}

/// A primitive representing a 3D model file loaded from an external URL or embedded data.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct ModelPrimitive {
    /// Origin of model relative to reference frame.
    pub pose: Pose,
    /// Scale factor to apply to the model along each axis.
    pub scale: Vector3,
    /// Solid color to use for the whole model if `override_color` is true.
    pub color: Color,
    /// Whether to use the color specified in `color` instead of any materials embedded in the
    /// original model.
    pub override_color: bool,
    /// URL pointing to model file. One of `url` or `data` should be provided.
    pub url: String,
    /// Media type of embedded model (e.g. `model/gltf-binary`). Required if `data` is provided
    /// instead of `url`.
    pub media_type: String,
    /// Embedded model, base64 encoded. One of `url` or `data` should be provided.
    #[schemars(extend("contentEncoding" = "base64"))]
    pub data: String,
}

/// A visual element in a 3D scene. An entity may be composed of multiple primitives which all
/// share the same frame of reference.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct SceneEntity {
    /// Timestamp of the entity.
    pub timestamp: Time,
    /// Frame of reference.
    pub frame_id: String,
    /// Identifier for the entity. An entity will replace any prior entity on the same topic with
    /// the same id.
    pub id: String,
    /// Length of time (relative to `timestamp`) after which the entity should be automatically
    /// removed. Zero value indicates the entity should remain visible until it is replaced or
    /// deleted.
    pub lifetime: Duration,
    /// Whether the entity should keep its location in the fixed frame (false) or follow the
    /// frame specified in `frame_id` as it moves relative to the fixed frame (true).
    pub frame_locked: bool,
    /// Additional user-provided metadata associated with the entity. Keys must be unique.
    pub metadata: Vec<KeyValuePair>,
    /// Arrow primitives.
    pub arrows: Vec<ArrowPrimitive>,
    /// Cube primitives.
    pub cubes: Vec<CubePrimitive>,
    /// Sphere primitives.
    pub spheres: Vec<SpherePrimitive>,
    /// Cylinder primitives.
    pub cylinders: Vec<CylinderPrimitive>,
    /// Line primitives.
    pub lines: Vec<LinePrimitive>,
    /// Triangle list primitives.
    pub triangles: Vec<TriangleListPrimitive>,
    /// Text primitives.
    pub texts: Vec<TextPrimitive>,
    /// Model primitives.
    pub models: Vec<ModelPrimitive>,
}

impl SceneEntity {
    /// An empty entity `id` in frame `frame_id` at a simulated time, locked to its frame (it
    /// moves with the frame's transforms) and without a lifetime.
    pub fn new(time_secs: f64, frame_id: &str, id: &str) -> Self {
        Self {
            timestamp: Time::from_secs(time_secs),
            frame_id: frame_id.to_owned(),
            id: id.to_owned(),
            frame_locked: true,
            ..Self::default()
        }
    }
}

/// An update to the entities displayed in a 3D scene.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[schemars(rename = "foxglove.SceneUpdate")]
pub struct SceneUpdate {
    /// Scene entities to delete.
    pub deletions: Vec<SceneEntityDeletion>,
    /// Scene entities to add or replace.
    pub entities: Vec<SceneEntity>,
}

/// Dimensions and frames for drawing a ballbot in Foxglove's 3D panel.
///
/// [`frames`](Self::frames) gives the transforms `world -> ball` and `world -> body` (log them
/// every step); [`scene`](Self::scene) draws, locked to those frames, the ball as a sphere with
/// a marker dot (so its rolling shows), the body as a cylinder whose axis is the body's z axis,
/// and the omniwheels as thin cylinders at the poses in `body_from_wheels` (each wheel's axle
/// along its z axis). Entities are frame-locked, so the scene only needs logging when it
/// changes, but logging it at a modest rate (e.g. 10 Hz) keeps it visible after seeking.
#[derive(Debug, Clone, PartialEq)]
pub struct BallbotScene {
    /// Ball radius (m).
    pub ball_radius_m: f64,
    /// Body cylinder radius (m).
    pub body_radius_m: f64,
    /// Height of the body cylinder's bottom face above the body frame origin (m).
    pub body_bottom_m: f64,
    /// Body cylinder height (m).
    pub body_height_m: f64,
    /// Omniwheel radius (m).
    pub wheel_radius_m: f64,
    /// Omniwheel width along its axle (m).
    pub wheel_width_m: f64,
    /// Each omniwheel's pose in the body frame, axle along the wheel's z axis.
    pub body_from_wheels: Vec<Isometry3<f64>>,
    /// Name of the fixed frame. Default `world`.
    pub world_frame: String,
    /// Name of the ball frame (origin at the ball centre). Default `ball`.
    pub ball_frame: String,
    /// Name of the body frame (origin at the ball centre, z up the body axis). Default `body`.
    pub body_frame: String,
}

impl BallbotScene {
    /// The MiaPURE with a 60 kg payload, from [`BallbotParams::miapure_60kg`].
    pub fn miapure_like() -> Self {
        Self::from_params(&BallbotParams::miapure_60kg())
    }

    /// The robot described by a parameter set: the ball radius of the sagittal plane, the
    /// omniwheels at their azimuths and contact angle with their radius (each wheel's centre on
    /// the line from the ball centre through its contact, axle `a_i = d_i x n_i` so that it
    /// rolls along the horizontal tangent `d_i`), and a body cylinder of 0.25 m radius from just above the wheels, centred on the
    /// COM height (at least 0.2 m tall). Change the public fields for another look.
    pub fn from_params(robot: &BallbotParams<f64>) -> Self {
        let ball_radius_m = robot.sagittal.ball_radius_m;
        let drivetrain = &robot.drivetrain;
        let wheel_radius_m = drivetrain.wheel_radius_m;
        let zenith_rad = drivetrain.contact_angle_rad;
        let body_from_wheels = drivetrain
            .wheel_azimuths_rad
            .iter()
            .map(|&azimuth_rad| {
                // Contact direction from the ball centre, then the wheel centre just outside it.
                let direction = nalgebra::Vector3::new(
                    zenith_rad.sin() * azimuth_rad.cos(),
                    zenith_rad.sin() * azimuth_rad.sin(),
                    zenith_rad.cos(),
                );
                let centre = direction * (ball_radius_m + wheel_radius_m);
                // The wheel drives the ball along the horizontal tangent d_i (MODEL.md section
                // 1): its axle is a_i = d_i x n_i, perpendicular to d_i and to the contact
                // normal, as in the world (`crate::world::contact`).
                let rolling = nalgebra::Vector3::new(-azimuth_rad.sin(), azimuth_rad.cos(), 0.0);
                let axle = rolling.cross(&direction);
                let rotation = UnitQuaternion::rotation_between(&nalgebra::Vector3::z(), &axle)
                    .unwrap_or_else(UnitQuaternion::identity);
                Isometry3::from_parts(centre.into(), rotation)
            })
            .collect();
        let body_bottom_m = (ball_radius_m + 2.0 * wheel_radius_m) * zenith_rad.cos() + 0.02;
        let body_height_m = (2.0 * (robot.sagittal.com_height_m - body_bottom_m)).max(0.2);
        Self {
            ball_radius_m,
            body_radius_m: 0.25,
            body_bottom_m,
            body_height_m,
            wheel_radius_m,
            wheel_width_m: 0.04,
            body_from_wheels,
            world_frame: "world".to_owned(),
            ball_frame: "ball".to_owned(),
            body_frame: "body".to_owned(),
        }
    }

    /// The transforms `world -> ball` and `world -> body` at a simulated time.
    pub fn frames(
        &self,
        time_secs: f64,
        world_from_ball: &Isometry3<f64>,
        world_from_body: &Isometry3<f64>,
    ) -> FrameTransforms {
        FrameTransforms {
            transforms: vec![
                FrameTransform::new(
                    time_secs,
                    &self.world_frame,
                    &self.ball_frame,
                    world_from_ball,
                ),
                FrameTransform::new(
                    time_secs,
                    &self.world_frame,
                    &self.body_frame,
                    world_from_body,
                ),
            ],
        }
    }

    /// The entities `ball`, `body` and `wheels` at a simulated time.
    pub fn scene(&self, time_secs: f64) -> SceneUpdate {
        let ball_diameter_m = 2.0 * self.ball_radius_m;
        let mut ball = SceneEntity::new(time_secs, &self.ball_frame, "ball");
        ball.spheres.push(SpherePrimitive {
            pose: Pose::default(),
            size: Vector3::new(ball_diameter_m, ball_diameter_m, ball_diameter_m),
            color: Color::rgba(0.85, 0.33, 0.10, 1.0),
        });
        let dot_m = 0.25 * self.ball_radius_m;
        ball.spheres.push(SpherePrimitive {
            pose: Pose::at(self.ball_radius_m, 0.0, 0.0),
            size: Vector3::new(dot_m, dot_m, dot_m),
            color: Color::rgba(1.0, 1.0, 1.0, 1.0),
        });

        let mut body = SceneEntity::new(time_secs, &self.body_frame, "body");
        let body_diameter_m = 2.0 * self.body_radius_m;
        body.cylinders.push(CylinderPrimitive {
            pose: Pose::at(0.0, 0.0, self.body_bottom_m + 0.5 * self.body_height_m),
            size: Vector3::new(body_diameter_m, body_diameter_m, self.body_height_m),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Color::rgba(0.0, 0.45, 0.74, 0.6),
        });

        let mut wheels = SceneEntity::new(time_secs, &self.body_frame, "wheels");
        let wheel_diameter_m = 2.0 * self.wheel_radius_m;
        for body_from_wheel in &self.body_from_wheels {
            wheels.cylinders.push(CylinderPrimitive {
                pose: body_from_wheel.into(),
                size: Vector3::new(wheel_diameter_m, wheel_diameter_m, self.wheel_width_m),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: Color::rgba(0.2, 0.2, 0.2, 1.0),
            });
        }
        SceneUpdate {
            deletions: Vec::new(),
            entities: vec![ball, body, wheels],
        }
    }

    /// The entity `contact_forces`: at each omniwheel's contact with the ball, an arrow of the
    /// normal force the wheel presses on the ball (towards the ball centre) and one of its
    /// traction (along `axle x normal`, the wheel's rolling direction, signed), scaled by
    /// `metres_per_newton`. Traction arrows are green while the contact sticks and red when
    /// `slipping`. `contacts` holds one entry per wheel, in the order of `body_from_wheels`.
    pub fn contact_forces(
        &self,
        time_secs: f64,
        contacts: &[WheelContact],
        metres_per_newton: f64,
    ) -> SceneEntity {
        let mut entity = SceneEntity::new(time_secs, &self.body_frame, "contact_forces");
        for (body_from_wheel, contact) in self.body_from_wheels.iter().zip(contacts) {
            let centre = body_from_wheel.translation.vector;
            let Some(inward) = (-centre).try_normalize(1e-12) else {
                continue;
            };
            let axle = body_from_wheel.rotation * nalgebra::Vector3::z();
            let rolling = axle.cross(&inward);
            let point = nalgebra::Point3::from(centre + inward * self.wheel_radius_m);
            entity.arrows.push(ArrowPrimitive::from_vector(
                point - inward * (contact.normal_force_n * metres_per_newton),
                inward * contact.normal_force_n,
                metres_per_newton,
                Color::rgba(0.0, 0.3, 0.9, 1.0),
            ));
            let traction_color = if contact.slipping {
                Color::rgba(0.9, 0.1, 0.1, 1.0)
            } else {
                Color::rgba(0.1, 0.7, 0.2, 1.0)
            };
            entity.arrows.push(ArrowPrimitive::from_vector(
                point,
                rolling * contact.traction_n,
                metres_per_newton,
                traction_color,
            ));
        }
        entity
    }
}

/// The contact state of one omniwheel, for [`BallbotScene::contact_forces`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelContact {
    /// Normal force the wheel presses on the ball (N), >= 0.
    pub normal_force_n: f64,
    /// Traction the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// Whether the contact slides (traction at the friction-cone limit).
    pub slipping: bool,
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::log::{check_message, check_schema, schema_for};

    #[test]
    fn time_from_secs_splits_and_saturates() {
        assert_eq!(
            Time::from_secs(12.25),
            Time {
                sec: 12,
                nsec: 250_000_000
            }
        );
        assert_eq!(Time::from_secs(-3.0), Time::default());
        assert_eq!(Time::from_secs(f64::NAN), Time::default());
        assert_eq!(Time::from_secs(1e30).sec, u32::MAX);
    }

    #[test]
    fn enums_serialise_as_integers_and_match_their_schema() {
        let deletion = SceneEntityDeletion {
            kind: SceneEntityDeletionType::All,
            ..SceneEntityDeletion::default()
        };
        let value = serde_json::to_value(&deletion).unwrap();
        assert_eq!(value["type"], 1);
        let schema = schema_for::<SceneEntityDeletion>();
        check_schema(&schema).unwrap();
        check_message(&schema, &value).unwrap();
        let bad = serde_json::json!({"timestamp": {"sec": 0, "nsec": 0}, "type": 7, "id": ""});
        assert!(check_message(&schema, &bad).is_err());
        let back: SceneEntityDeletion = serde_json::from_value(value).unwrap();
        assert_eq!(back, deletion);
    }

    #[test]
    fn arrow_points_along_its_vector() {
        let arrow = ArrowPrimitive::from_vector(
            nalgebra::Point3::origin(),
            nalgebra::Vector3::new(0.0, 0.0, 100.0),
            0.01,
            Color::default(),
        );
        let q = arrow.pose.orientation;
        let rotation =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z));
        let tip = rotation * nalgebra::Vector3::x();
        assert!((tip - nalgebra::Vector3::z()).norm() < 1e-12);
        assert!((arrow.shaft_length + arrow.head_length - 1.0).abs() < 1e-12);
    }

    #[test]
    fn contact_arrows_start_at_the_contacts_and_point_as_the_forces() {
        let robot = BallbotScene::miapure_like();
        let contacts = [
            WheelContact {
                normal_force_n: 200.0,
                traction_n: 50.0,
                slipping: false,
            },
            WheelContact {
                normal_force_n: 100.0,
                traction_n: -20.0,
                slipping: true,
            },
            WheelContact::default(),
        ];
        let entity = robot.contact_forces(1.0, &contacts, 0.001);
        assert_eq!(entity.frame_id, "body");
        assert_eq!(entity.arrows.len(), 6);
        let direction = |arrow: &ArrowPrimitive| {
            let q = arrow.pose.orientation;
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z))
                * nalgebra::Vector3::x()
        };
        let tip = |arrow: &ArrowPrimitive| {
            let p = arrow.pose.position;
            nalgebra::Vector3::new(p.x, p.y, p.z)
                + direction(arrow) * (arrow.shaft_length + arrow.head_length)
        };
        // The normal-force arrow of wheel 0 ends on the ball surface, pointing at the centre.
        let normal = &entity.arrows[0];
        assert!((tip(normal).norm() - robot.ball_radius_m).abs() < 1e-12);
        let inward = -tip(normal).normalize();
        assert!((direction(normal) - inward).norm() < 1e-12);
        assert!((normal.shaft_length + normal.head_length - 0.2).abs() < 1e-12);
        // Traction is tangent to the ball, starts at the contact, and red only when slipping.
        let traction = &entity.arrows[1];
        assert!(direction(traction).dot(&inward).abs() < 1e-12);
        let p = traction.pose.position;
        assert!((nalgebra::Vector3::new(p.x, p.y, p.z) - tip(normal)).norm() < 1e-12);
        assert!(traction.color.g > traction.color.r);
        assert!(entity.arrows[3].color.r > entity.arrows[3].color.g);
        // A negative traction points the other way.
        let axle = robot.body_from_wheels[1].rotation * nalgebra::Vector3::z();
        let inward_1 = -robot.body_from_wheels[1].translation.vector.normalize();
        assert!((direction(&entity.arrows[3]) + axle.cross(&inward_1)).norm() < 1e-9);
    }

    #[test]
    fn miapure_wheels_touch_the_ball_and_roll_along_the_horizontal_tangent() {
        let robot = BallbotScene::miapure_like();
        let params = BallbotParams::<f64>::miapure_60kg();
        assert_eq!(robot.ball_radius_m, params.sagittal.ball_radius_m);
        assert_eq!(robot.body_from_wheels.len(), 3);
        // The first wheel sits at azimuth 0: in the x-z plane, on the +x side, 45 deg up.
        let first = robot.body_from_wheels[0].translation.vector;
        assert!(first.y.abs() < 1e-12 && first.x > 0.0);
        assert!((first.z.atan2(first.x) - (90_f64 - 45.0).to_radians()).abs() < 1e-12);
        assert!(robot.body_bottom_m > first.z + robot.wheel_radius_m);
        for wheel in &robot.body_from_wheels {
            let centre_distance_m = wheel.translation.vector.norm();
            assert!((centre_distance_m - robot.ball_radius_m - robot.wheel_radius_m).abs() < 1e-12);
            let axle = wheel.rotation * nalgebra::Vector3::z();
            assert!(axle.dot(&wheel.translation.vector).abs() < 1e-12);
            // Rolling direction at the contact: axle x inward normal, horizontal (d_i).
            let inward = -wheel.translation.vector.normalize();
            let rolling = axle.cross(&inward);
            assert!(rolling.z.abs() < 1e-12, "{rolling}");
            assert!((rolling.norm() - 1.0).abs() < 1e-12);
        }
        // OW1 at azimuth 0 drives the ball along +y (d_1 = [0, 1, 0]).
        let axle = robot.body_from_wheels[0].rotation * nalgebra::Vector3::z();
        let inward = -robot.body_from_wheels[0].translation.vector.normalize();
        assert!((axle.cross(&inward) - nalgebra::Vector3::y()).norm() < 1e-12);
    }
}
