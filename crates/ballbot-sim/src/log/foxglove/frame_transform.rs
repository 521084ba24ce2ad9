//! `foxglove.FrameTransform(s)`: poses of frames relative to their parents.

use nalgebra::Isometry3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::geometry::{Quaternion, Time, Vector3};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::schema_name_for;

    #[test]
    fn well_known_schema_names() {
        assert_eq!(
            schema_name_for::<FrameTransform>(),
            "foxglove.FrameTransform"
        );
        assert_eq!(
            schema_name_for::<FrameTransforms>(),
            "foxglove.FrameTransforms"
        );
    }
}
