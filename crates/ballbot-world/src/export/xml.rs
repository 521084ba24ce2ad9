//! Number formatting shared by the writers: every value in Rust's shortest round-trip form,
//! so a parser reads back the very `f64` the model holds.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// A vector as `x y z`.
pub(super) fn vec3(v: &Vector3<f64>) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

/// A rotation as MJCF's `quat`: `w x y z`.
pub(super) fn quat(r: &Rotation3<f64>) -> String {
    let q = UnitQuaternion::from_rotation_matrix(r);
    format!("{} {} {} {}", q.w, q.i, q.j, q.k)
}

/// A rotation as URDF's `rpy`: roll, pitch, yaw about the fixed x, y, z axes
/// (`R = Rz(yaw) Ry(pitch) Rx(roll)`).
pub(super) fn rpy(r: &Rotation3<f64>) -> String {
    let (roll, pitch, yaw) = r.euler_angles();
    format!("{roll} {pitch} {yaw}")
}

/// The upper triangle of a symmetric tensor in MJCF's `fullinertia` order:
/// `ixx iyy izz ixy ixz iyz`.
pub(super) fn full_inertia(i: &Matrix3<f64>) -> String {
    format!(
        "{} {} {} {} {} {}",
        i[(0, 0)],
        i[(1, 1)],
        i[(2, 2)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 2)]
    )
}
