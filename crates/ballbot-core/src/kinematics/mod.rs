//! Omniwheel kinematics and statics: planar rates and torques <-> omniwheel and motor speeds
//! and torques (the paper's V3D and T3D), torque capacity and saturation, and the normal and
//! traction forces at the three omniwheel contacts.
//!
//! # Frames and sign conventions
//!
//! Everything is in the body frame B (MODEL.md section 1): z up along the body axis, x towards
//! omniwheel 1. Wheel `i` touches the ball (radius `r_S`) at azimuth `beta_i`
//! (counter-clockwise from x, seen from above) and contact angle `alpha` from the vertical:
//!
//! * contact normal `n_i = [sin a cos b_i, sin a sin b_i, cos a]` (ball centre to contact),
//! * rolling (traction) direction `d_i = [-sin b_i, cos b_i, 0]`,
//! * `u_i = n_i x d_i = [-cos a cos b_i, -cos a sin b_i, sin a]`, the direction of the wheel's
//!   axle; the rollers leave the contact free along it.
//!
//! **Rates.** The relative angular velocity of the ball with respect to the body, in body
//! coordinates, is `omega_rel = omega_ball - omega_body`. In the paper's planar variables
//! (small tilt, the ball does not spin about the vertical) it is
//! `omega_rel = [phi_dot_x - theta_dot_x, phi_dot_y - theta_dot_y, -theta_z_dot]`
//! ([`relative_rate_from_planar`]). The omniwheel speed is
//!
//! ```text
//! psi_dot_i = (r_S / r_W) u_i . omega_rel
//! ```
//!
//! Positive `psi_dot_i` means the wheel rim at the contact moves along `+d_i` relative to the
//! body, together with the ball surface: the wheel turns positively about its axle direction
//! `d_i x n_i = -u_i`. The motor rotor turns `gear_ratio` times faster, in the same sense.
//!
//! **Torques.** The planar torque vector is `tau = [tau_x, tau_y, tau_z]`: `tau_x`, `tau_y` are
//! the torques the body applies to the ball in the frontal and sagittal planes (the WIP input;
//! the body feels `-tau`), `tau_z` is the yaw torque on the body (the ball feels `-tau_z`), as
//! in MODEL.md sections 2 and 3. Omniwheel torque `tau_i` is the torque of actuator `i` on its
//! wheel, positive in the sense of positive `psi_dot_i`; the rotor torque is `tau_i /
//! gear_ratio` (lossless gearbox). Wheel `i` then pushes the ball at its contact with the
//! traction force `F_i d_i`, `F_i = tau_i / r_W` (massless wheel), and the total torque of the
//! tractions on the ball about its centre is `r_S sum_i F_i u_i = [tau_x, tau_y, -tau_z]`.
//! Hence the power balance, which holds exactly for every layout:
//!
//! ```text
//! sum_i tau_i psi_dot_i = tau_x omega_rel_x + tau_y omega_rel_y - tau_z omega_rel_z
//! ```
//!
//! With `J = (r_S / r_W) U` (rows `u_i`) and `S = diag(1, 1, -1)` the maps are
//! `psi_dot = J omega_rel`, `omega_rel = J^-1 psi_dot`, `tau_wheel = J^-T S tau`,
//! `tau = S J^T tau_wheel`. All four matrices are computed once, at construction.
//!
//! For the symmetric layout (0, 120, 240 deg) they reduce to MODEL.md's closed forms, e.g.
//! `tau_i = (r_W / (3 r_S)) [(2 / cos a)(-cos b_i tau_x - sin b_i tau_y) - tau_z / sin a]`.
//!
//! **Forces.** [`contact`] gives the normal force, traction and friction-cone use at each
//! contact for a given support force and wheel torques ([`OmniKinematics::contact_forces`]).
//!
//! [`limits`] gives the exact range of WIP torques that the actuators and the contacts allow
//! for a planar motion at any heading.
//!
//! ```
//! use ballbot_core::{BallbotParams, OmniKinematics};
//! use nalgebra::Vector3;
//! let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
//! // Pure sagittal travel (ball rolling about y) leaves omniwheel 1 idle.
//! let psi_dot = kin.wheel_speeds_rad_per_s(&Vector3::new(0.0, 5.0, 0.0));
//! approx::assert_abs_diff_eq!(psi_dot[0], 0.0, epsilon = 1e-12);
//! approx::assert_relative_eq!(psi_dot[1], -psi_dot[2], epsilon = 1e-12);
//! // The torque capacity of 43.2 N m per actuator, in planar terms.
//! let cap = kin.planar_torque_capacity_nm();
//! approx::assert_relative_eq!(cap[2], 167.9, epsilon = 0.05);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

pub mod contact;
pub mod limits;

pub use contact::{
    ContactForces, WheelContact, decoupled_support_force_n, planar_support_force_n,
    support_force_in_body_n,
};
pub use limits::TorqueInterval;

mod maps;
mod planar;
mod saturation;

pub use planar::{
    ball_rate_from_relative_rate, planar_torque_at_heading, plane_axis_at_heading,
    relative_rate_at_heading, relative_rate_from_planar,
};
pub use saturation::TorqueSaturation;

use crate::check::positive;
use crate::{BallbotParams, DrivetrainParams, Error, WHEEL_COUNT};
use nalgebra::{Matrix3, RealField, Vector3};

/// The geometry of one omniwheel contact, in body coordinates.
///
/// ```
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// for w in kin.wheels() {
///     // n, d, u form a right-handed orthonormal frame at each contact.
///     approx::assert_relative_eq!(
///         w.contact_normal.cross(&w.rolling_direction),
///         w.axle_direction
///     );
///     assert!(w.contact_normal.dot(&w.rolling_direction).abs() < 1e-15);
///     // Contacts 45 deg from the vertical, on the ball's surface.
///     approx::assert_relative_eq!(w.contact_normal.z, 0.5f64.sqrt(), epsilon = 1e-15);
///     approx::assert_relative_eq!(w.contact_point_m.norm(), 0.1145, epsilon = 1e-15);
/// }
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelGeometry<T> {
    /// Azimuth `beta_i` of the contact, counter-clockwise from body x seen from above (rad).
    pub azimuth_rad: T,
    /// Unit contact normal `n_i`, from the ball centre to the contact.
    pub contact_normal: Vector3<T>,
    /// Unit rolling direction `d_i`: traction acts along it; positive wheel speed moves the rim
    /// at the contact along `+d_i` relative to the body.
    pub rolling_direction: Vector3<T>,
    /// Unit `u_i = n_i x d_i`, along the wheel's axle (the rollers' free direction). Positive
    /// wheel speed is a rotation about `-u_i`.
    pub axle_direction: Vector3<T>,
    /// Contact point relative to the ball centre, `r_S n_i` (m).
    pub contact_point_m: Vector3<T>,
}

/// Validated omniwheel kinematics and statics of a three-wheel ballbot drivetrain, for any
/// valid contact angle and wheel azimuths. See the [module docs](self) for conventions.
///
/// ```
/// use ballbot_core::kinematics::relative_rate_from_planar;
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// use nalgebra::Vector3;
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// // Rolling forward at 1 m/s (phi_dot_y = 1 / r_S) upright: wheel 1 idles, wheels 2 and 3
/// // turn at -+9.80 rad/s (73.5 rad/s at the rotors).
/// let omega_rel = relative_rate_from_planar([0.0, 1.0 / 0.1145], [0.0, 0.0], 0.0);
/// let psi_dot = kin.wheel_speeds_rad_per_s(&omega_rel);
/// approx::assert_relative_eq!(psi_dot, Vector3::new(0.0, -9.798, 9.798), epsilon = 1e-3);
/// // Power balance: omniwheel power equals planar power for any torque and rate.
/// let tau = Vector3::new(5.0, 30.0, -2.0);
/// let wheel_power_w = kin.wheel_torques_nm(&tau).dot(&psi_dot);
/// approx::assert_relative_eq!(wheel_power_w, tau[1] * omega_rel[1], epsilon = 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OmniKinematics<T> {
    drivetrain: DrivetrainParams<T>,
    ball_radius_m: T,
    wheels: [WheelGeometry<T>; WHEEL_COUNT],
    /// `J = (r_S / r_W) U`: relative rate -> omniwheel speeds.
    wheel_speed_from_rel: Matrix3<T>,
    /// `J^-1`.
    rel_from_wheel_speed: Matrix3<T>,
    /// `J^-T S`: planar torque -> omniwheel torques.
    wheel_torque_from_planar: Matrix3<T>,
    /// `S J^T`.
    planar_from_wheel_torque: Matrix3<T>,
    /// Columns `n_i`, inverted: support force -> normal forces.
    normal_from_force: Matrix3<T>,
    /// `normal_from_force [d_1 d_2 d_3] / r_W`: omniwheel torques -> normal forces.
    normal_from_wheel_torque: Matrix3<T>,
    planar_torque_capacity_nm: Vector3<T>,
}

impl<T: RealField + Copy> OmniKinematics<T> {
    /// Builds the kinematics from a drivetrain and the ball radius `ball_radius_m` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field: any field rejected by
    /// [`DrivetrainParams::validate`] (contact angle outside (0, 90) deg, singular wheel layout,
    /// non-positive radii...), `ball_radius_m` not finite and positive, or
    /// `wheel_azimuths_rad` when the layout's matrices cannot be inverted.
    ///
    /// ```
    /// use ballbot_core::{DrivetrainParams, Error, OmniKinematics};
    /// let kin = OmniKinematics::new(DrivetrainParams::<f64>::miapure(), 0.1145)?;
    /// assert_eq!(kin.ball_radius_m(), 0.1145);
    /// // The ball radius is checked here; the drivetrain by its own validation.
    /// assert_eq!(
    ///     OmniKinematics::new(DrivetrainParams::<f64>::miapure(), -0.1),
    ///     Err(Error::invalid("ball_radius_m", "must be finite and > 0"))
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(drivetrain: DrivetrainParams<T>, ball_radius_m: T) -> Result<Self, Error> {
        drivetrain.validate()?;
        positive(ball_radius_m, "ball_radius_m")?;

        let (sin_a, cos_a) = drivetrain.contact_angle_rad.sin_cos();
        let wheels = drivetrain.wheel_azimuths_rad.map(|beta| {
            let (sin_b, cos_b) = beta.sin_cos();
            let contact_normal = Vector3::new(sin_a * cos_b, sin_a * sin_b, cos_a);
            let rolling_direction = Vector3::new(-sin_b, cos_b, T::zero());
            WheelGeometry {
                azimuth_rad: beta,
                contact_normal,
                rolling_direction,
                axle_direction: contact_normal.cross(&rolling_direction),
                contact_point_m: contact_normal * ball_radius_m,
            }
        });

        let singular = Error::invalid(
            "wheel_azimuths_rad",
            "wheel layout is singular: the wheel axles must span 3D",
        );
        let ratio = ball_radius_m / drivetrain.wheel_radius_m;
        let u = Matrix3::from_rows(&[
            wheels[0].axle_direction.transpose(),
            wheels[1].axle_direction.transpose(),
            wheels[2].axle_direction.transpose(),
        ]);
        let wheel_speed_from_rel = u * ratio;
        let rel_from_wheel_speed = wheel_speed_from_rel.try_inverse().ok_or(singular)?;
        let flip_z = Matrix3::from_diagonal(&Vector3::new(T::one(), T::one(), -T::one()));
        let wheel_torque_from_planar = rel_from_wheel_speed.transpose() * flip_z;
        let planar_from_wheel_torque = flip_z * wheel_speed_from_rel.transpose();

        let normals = Matrix3::from_columns(&wheels.map(|w| w.contact_normal));
        let directions = Matrix3::from_columns(&wheels.map(|w| w.rolling_direction));
        let normal_from_force = normals.try_inverse().ok_or(singular)?;
        let normal_from_wheel_torque = normal_from_force * directions / drivetrain.wheel_radius_m;

        let mut capacity = Vector3::zeros();
        let peak = drivetrain.actuator.peak_torque_nm;
        for (j, cap) in capacity.iter_mut().enumerate() {
            let worst = wheel_torque_from_planar.column(j).amax();
            if !(worst.is_finite() && worst > T::zero()) {
                return Err(singular);
            }
            *cap = peak / worst;
        }

        let all_finite = [
            &rel_from_wheel_speed,
            &wheel_torque_from_planar,
            &normal_from_force,
            &normal_from_wheel_torque,
        ]
        .iter()
        .all(|m| m.iter().all(|x| x.is_finite()));
        if !all_finite {
            return Err(singular);
        }

        Ok(Self {
            drivetrain,
            ball_radius_m,
            wheels,
            wheel_speed_from_rel,
            rel_from_wheel_speed,
            wheel_torque_from_planar,
            planar_from_wheel_torque,
            normal_from_force,
            normal_from_wheel_torque,
            planar_torque_capacity_nm: capacity,
        })
    }

    /// Builds the kinematics of a complete robot (its drivetrain and ball radius).
    ///
    /// # Errors
    /// As [`Self::new`], and whatever [`BallbotParams::validate`] rejects.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, DrivetrainParams, OmniKinematics};
    /// let params = BallbotParams::<f64>::miapure_unloaded();
    /// let kin = OmniKinematics::from_ballbot(&params)?;
    /// assert_eq!(
    ///     kin,
    ///     OmniKinematics::new(DrivetrainParams::miapure(), params.ball_radius_m())?
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn from_ballbot(params: &BallbotParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Self::new(params.drivetrain, params.ball_radius_m())
    }

    /// The drivetrain this was built from.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, DrivetrainParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert_eq!(*kin.drivetrain(), DrivetrainParams::miapure());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn drivetrain(&self) -> &DrivetrainParams<T> {
        &self.drivetrain
    }

    /// The ball radius `r_S` (m).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // 1 m/s of travel is 1 / r_S = 8.73 rad/s of ball rate.
    /// approx::assert_relative_eq!(1.0 / kin.ball_radius_m(), 8.734, epsilon = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn ball_radius_m(&self) -> T {
        self.ball_radius_m
    }

    /// The geometry of each wheel's contact, in body coordinates.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let azimuths_deg = kin.wheels().map(|w| w.azimuth_rad.to_degrees().round());
    /// assert_eq!(azimuths_deg, [0.0, 120.0, 240.0]);
    /// // The three contacts are symmetric: their normals sum to a vertical vector.
    /// let sum = kin
    ///     .wheels()
    ///     .iter()
    ///     .fold(nalgebra::Vector3::zeros(), |acc, w| acc + w.contact_normal);
    /// approx::assert_abs_diff_eq!(sum.x, 0.0, epsilon = 1e-15);
    /// approx::assert_abs_diff_eq!(sum.y, 0.0, epsilon = 1e-15);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wheels(&self) -> &[WheelGeometry<T>; WHEEL_COUNT] {
        &self.wheels
    }

    // ---- speeds -------------------------------------------------------------------------
}

#[cfg(test)]
mod tests;
