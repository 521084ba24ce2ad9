//! Planar rates and torques along a heading, and the conversions between absolute ball rates
//! and rates relative to the body.

use nalgebra::{RealField, Vector3};

/// The relative ball-to-body angular velocity `omega_rel` (rad/s, body coordinates) in the
/// paper's planar variables: `[phi_dot_x - theta_dot_x, phi_dot_y - theta_dot_y,
/// -theta_z_dot]`.
///
/// `ball_rate_rad_per_s = [phi_dot_x, phi_dot_y]` (frontal, sagittal ball rates),
/// `tilt_rate_rad_per_s = [theta_dot_x, theta_dot_y]`, `yaw_rate_rad_per_s = theta_z_dot`.
/// This is the small-tilt form of MODEL.md section 4 (the ball is assumed not to spin about
/// the vertical); a 3D simulator should pass its exact `omega_ball - omega_body` in body
/// coordinates to [`OmniKinematics::wheel_speeds_rad_per_s`](super::OmniKinematics::wheel_speeds_rad_per_s) instead.
///
/// ```
/// use ballbot_core::kinematics::relative_rate_from_planar;
/// // Ball rolling at 2 rad/s in the sagittal plane under a body leaning forward at 0.5 rad/s,
/// // turning at 0.1 rad/s.
/// let w = relative_rate_from_planar([0.0, 2.0], [0.0, 0.5], 0.1);
/// assert_eq!([w[0], w[1], w[2]], [0.0, 1.5, -0.1]);
/// ```
pub fn relative_rate_from_planar<T: RealField + Copy>(
    ball_rate_rad_per_s: [T; 2],
    tilt_rate_rad_per_s: [T; 2],
    yaw_rate_rad_per_s: T,
) -> Vector3<T> {
    Vector3::new(
        ball_rate_rad_per_s[0] - tilt_rate_rad_per_s[0],
        ball_rate_rad_per_s[1] - tilt_rate_rad_per_s[1],
        -yaw_rate_rad_per_s,
    )
}

/// The inverse of [`relative_rate_from_planar`] for the ball: `[phi_dot_x, phi_dot_y]`
/// (rad/s) from the relative rate `omega_rel` and the tilt rates
/// `tilt_rate_rad_per_s = [theta_dot_x, theta_dot_y]`. The yaw rate is `-omega_rel[2]` (the
/// ball assumed not to spin about the vertical).
///
/// ```
/// use ballbot_core::kinematics::{ball_rate_from_relative_rate, relative_rate_from_planar};
/// // Round trip through the relative rate.
/// let (ball, tilt) = ([1.5, -2.0], [0.25, 0.5]);
/// let w = relative_rate_from_planar(ball, tilt, 0.3);
/// assert_eq!(ball_rate_from_relative_rate(&w, tilt), ball);
/// ```
pub fn ball_rate_from_relative_rate<T: RealField + Copy>(
    relative_rate_rad_per_s: &Vector3<T>,
    tilt_rate_rad_per_s: [T; 2],
) -> [T; 2] {
    [
        relative_rate_rad_per_s[0] + tilt_rate_rad_per_s[0],
        relative_rate_rad_per_s[1] + tilt_rate_rad_per_s[1],
    ]
}

/// The horizontal rotation axis `a = z x e = [-sin h, cos h, 0]` of a vertical plane of travel
/// at heading `h` (`heading_rad`, body frame, 0 = towards omniwheel 1, counter-clockwise from
/// above). A planar WIP travelling at heading `h` tilts and rolls about `a`: positive rates roll
/// the ball and lean the body towards `e = [cos h, sin h, 0]`. Heading 0 is the sagittal plane
/// (`a = y`), heading 90 deg the frontal plane with `a = -x`.
///
/// ```
/// use ballbot_core::kinematics::plane_axis_at_heading;
/// use nalgebra::Vector3;
/// // Heading 0: the sagittal plane, rotation about y; 90 deg: the frontal plane, about -x.
/// approx::assert_relative_eq!(plane_axis_at_heading(0.0), Vector3::y());
/// approx::assert_relative_eq!(
///     plane_axis_at_heading(std::f64::consts::FRAC_PI_2),
///     -Vector3::x()
/// );
/// // The axis is horizontal and perpendicular to the direction of travel [cos h, sin h, 0].
/// let h = 2.0f64;
/// let a = plane_axis_at_heading(h);
/// approx::assert_abs_diff_eq!(a.dot(&Vector3::new(h.cos(), h.sin(), 0.0)), 0.0);
/// ```
pub fn plane_axis_at_heading<T: RealField + Copy>(heading_rad: T) -> Vector3<T> {
    let (sin_h, cos_h) = heading_rad.sin_cos();
    Vector3::new(-sin_h, cos_h, T::zero())
}

/// `omega_rel` (rad/s, body coordinates) of a planar WIP motion at heading `heading_rad`:
/// `(phi_dot - theta_dot) a` ([`plane_axis_at_heading`]), no yaw.
///
/// ```
/// use ballbot_core::kinematics::{relative_rate_at_heading, relative_rate_from_planar};
/// // Heading 0 is the sagittal plane of the planar variables: phi_dot_y - theta_dot_y on y.
/// let w = relative_rate_at_heading(0.0, 8.0, 0.5);
/// approx::assert_relative_eq!(w, relative_rate_from_planar([0.0, 8.0], [0.0, 0.5], 0.0));
/// // At 180 deg the same rates point the other way.
/// approx::assert_relative_eq!(
///     relative_rate_at_heading(std::f64::consts::PI, 8.0, 0.5),
///     -w,
///     epsilon = 1e-12
/// );
/// ```
pub fn relative_rate_at_heading<T: RealField + Copy>(
    heading_rad: T,
    ball_rate_rad_per_s: T,
    tilt_rate_rad_per_s: T,
) -> Vector3<T> {
    plane_axis_at_heading(heading_rad) * (ball_rate_rad_per_s - tilt_rate_rad_per_s)
}

/// The planar torque vector `[tau_x, tau_y, 0]` (N m) of a planar WIP torque `torque_nm` (the
/// torque the body applies to the ball in that plane) at heading `heading_rad`: `torque_nm a`.
///
/// ```
/// use ballbot_core::kinematics::planar_torque_at_heading;
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// // Driving towards omniwheel 1 (heading 0) takes no torque from omniwheel 1.
/// let wheels = kin.wheel_torques_nm(&planar_torque_at_heading(0.0, 20.0));
/// approx::assert_abs_diff_eq!(wheels[0], 0.0, epsilon = 1e-12);
/// // Driving away from omniwheel 2 (heading 120 + 180 deg) loads omniwheel 2 least.
/// let wheels = kin.wheel_torques_nm(&planar_torque_at_heading(300f64.to_radians(), 20.0));
/// approx::assert_abs_diff_eq!(wheels[1], 0.0, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn planar_torque_at_heading<T: RealField + Copy>(heading_rad: T, torque_nm: T) -> Vector3<T> {
    plane_axis_at_heading(heading_rad) * torque_nm
}
