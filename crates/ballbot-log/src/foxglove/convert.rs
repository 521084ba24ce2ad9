//! Building the SDK's messages from nalgebra types and simulated time.

use nalgebra::{Isometry3, UnitQuaternion};

use ::foxglove::schemas::{
    ArrowPrimitive, Color, FrameTransform, Point3, Pose, Quaternion, SceneEntity, Timestamp,
    Vector3,
};

use crate::secs_to_ns;

/// The time stamp of a simulated time in seconds, rounded to the nanosecond; saturates to 0
/// for negative or NaN times and to `u32::MAX` seconds beyond that.
///
/// ```
/// let t = ballbot_log::foxglove::timestamp(12.25);
/// assert_eq!((t.sec(), t.nsec()), (12, 250_000_000));
/// assert_eq!(ballbot_log::foxglove::timestamp(-3.0).sec(), 0);
/// ```
pub fn timestamp(time_secs: f64) -> Timestamp {
    let time_ns =
        secs_to_ns(time_secs.max(0.0)).unwrap_or(if time_secs > 0.0 { u64::MAX } else { 0 });
    let sec = u32::try_from(time_ns / 1_000_000_000).unwrap_or(u32::MAX);
    // The remainder is below 1e9 and fits in u32.
    let nsec = u32::try_from(time_ns % 1_000_000_000).unwrap_or(0);
    Timestamp::new(sec, nsec)
}

/// A vector.
pub fn vector3(v: &nalgebra::Vector3<f64>) -> Vector3 {
    Vector3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

/// A point.
pub fn point3(p: &nalgebra::Point3<f64>) -> Point3 {
    Point3 {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// A rotation as a quaternion.
pub fn quaternion(q: &UnitQuaternion<f64>) -> Quaternion {
    Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    }
}

/// The pose of a frame: its position and orientation.
pub fn pose(iso: &Isometry3<f64>) -> Pose {
    Pose {
        position: Some(vector3(&iso.translation.vector)),
        orientation: Some(quaternion(&iso.rotation)),
    }
}

/// The pose at a position with no rotation.
pub fn pose_at(x: f64, y: f64, z: f64) -> Pose {
    pose(&Isometry3::translation(x, y, z))
}

/// A size or extent along x, y, z.
pub fn size(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

/// A colour from its channels, each between 0 and 1.
pub fn rgba(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

/// The transform `parent_from_child` (the child frame's pose in the parent frame) at a
/// simulated time.
pub fn frame_transform(
    time_secs: f64,
    parent_frame_id: &str,
    child_frame_id: &str,
    parent_from_child: &Isometry3<f64>,
) -> FrameTransform {
    FrameTransform {
        timestamp: Some(timestamp(time_secs)),
        parent_frame_id: parent_frame_id.to_owned(),
        child_frame_id: child_frame_id.to_owned(),
        translation: Some(vector3(&parent_from_child.translation.vector)),
        rotation: Some(quaternion(&parent_from_child.rotation)),
    }
}

/// An empty entity `id` in frame `frame_id` at a simulated time, locked to its frame (it moves
/// with the frame's transforms) and without a lifetime.
pub fn entity(time_secs: f64, frame_id: &str, id: &str) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp(time_secs)),
        frame_id: frame_id.to_owned(),
        id: id.to_owned(),
        frame_locked: true,
        ..SceneEntity::default()
    }
}

/// An arrow from `tail` along `vector` (in the entity's frame), its length scaled by
/// `length_per_unit` (e.g. metres per newton for a force), with a head a fifth of its length.
///
/// ```
/// use ballbot_log::foxglove::{arrow, rgba};
/// let a = arrow(nalgebra::Point3::origin(), nalgebra::Vector3::new(0.0, 0.0, 100.0), 0.01, rgba(1.0, 0.0, 0.0, 1.0));
/// assert!((a.shaft_length + a.head_length - 1.0).abs() < 1e-12);
/// ```
pub fn arrow(
    tail: nalgebra::Point3<f64>,
    vector: nalgebra::Vector3<f64>,
    length_per_unit: f64,
    color: Color,
) -> ArrowPrimitive {
    let length = vector.norm() * length_per_unit;
    let orientation = UnitQuaternion::rotation_between(&nalgebra::Vector3::x(), &vector)
        .unwrap_or_else(|| {
            // Antiparallel to x (or zero): turn half a turn about z.
            UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), std::f64::consts::PI)
        });
    let head_length = 0.2 * length;
    ArrowPrimitive {
        pose: Some(Pose {
            position: Some(vector3(&tail.coords)),
            orientation: Some(quaternion(&orientation)),
        }),
        shaft_length: length - head_length,
        shaft_diameter: 0.05 * length.max(0.2),
        head_length,
        head_diameter: 0.1 * length.max(0.2),
        color: Some(color),
    }
}

/// The rotation of a pose (identity if it has none), for tests and readers.
pub fn rotation_of(pose: Option<&Pose>) -> UnitQuaternion<f64> {
    pose.and_then(|p| p.orientation.as_ref())
        .map_or_else(UnitQuaternion::identity, |q| {
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z))
        })
}

/// The position of a pose (the origin if it has none), for tests and readers.
pub fn position_of(pose: Option<&Pose>) -> nalgebra::Vector3<f64> {
    pose.and_then(|p| p.position.as_ref())
        .map_or_else(nalgebra::Vector3::zeros, |v| {
            nalgebra::Vector3::new(v.x, v.y, v.z)
        })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn timestamp_splits_and_saturates() {
        let t = timestamp(12.25);
        assert_eq!((t.sec(), t.nsec()), (12, 250_000_000));
        assert_eq!(timestamp(f64::NAN), Timestamp::new(0, 0));
        assert_eq!(timestamp(1e30).sec(), u32::MAX);
    }

    #[test]
    fn arrow_points_along_its_vector() {
        let a = arrow(
            nalgebra::Point3::new(1.0, 2.0, 3.0),
            nalgebra::Vector3::new(0.0, 0.0, 100.0),
            0.01,
            rgba(1.0, 1.0, 1.0, 1.0),
        );
        let tip = rotation_of(a.pose.as_ref()) * nalgebra::Vector3::x();
        assert!((tip - nalgebra::Vector3::z()).norm() < 1e-12);
        assert_eq!(
            position_of(a.pose.as_ref()),
            nalgebra::Vector3::new(1.0, 2.0, 3.0)
        );
        assert!((a.shaft_length + a.head_length - 1.0).abs() < 1e-12);
    }

    #[test]
    fn frame_transform_carries_the_pose() {
        let iso = Isometry3::from_parts(
            nalgebra::Translation3::new(1.0, -2.0, 0.5),
            UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), 0.3),
        );
        let tf = frame_transform(0.5, "world", "body", &iso);
        let back = rotation_of(Some(&Pose {
            position: tf.translation,
            orientation: tf.rotation,
        }));
        assert!(back.angle_to(&iso.rotation) < 1e-12);
        assert_eq!(tf.translation.unwrap().y, -2.0);
    }
}
