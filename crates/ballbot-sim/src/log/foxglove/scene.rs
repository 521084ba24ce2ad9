//! `foxglove.SceneUpdate`: entities made of primitives (arrows, cubes, spheres, cylinders,
//! lines, triangles, texts, models), and their deletions.

use std::borrow::Cow;

use nalgebra::UnitQuaternion;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::geometry::{Color, Duration, Point3, Pose, Time, Vector3};

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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::log::{check_message, check_schema, schema_for};

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
}
