//! Time, vectors, points, quaternions, poses and colours of the Foxglove schemas.

use nalgebra::{Isometry3, UnitQuaternion};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::log::secs_to_ns;

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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

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
}
