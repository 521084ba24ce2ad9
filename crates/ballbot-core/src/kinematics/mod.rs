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

/// A planar torque request scaled so that no omniwheel exceeds its torque limit.
///
/// ```
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// use nalgebra::Vector3;
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// // 120 N m about x exceeds the 83.9 N m capacity: scaled to it, wheel 1 at its 43.2 N m peak.
/// let s = kin.saturate_planar_torque(&Vector3::new(120.0, 0.0, 0.0));
/// approx::assert_relative_eq!(s.scale, 83.94 / 120.0, epsilon = 1e-4);
/// approx::assert_relative_eq!(s.wheel_torques_nm.amax(), 43.2, epsilon = 1e-9);
/// approx::assert_relative_eq!(
///     kin.wheel_torques_nm(&s.planar_torque_nm),
///     s.wheel_torques_nm,
///     epsilon = 1e-9
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueSaturation<T> {
    /// The planar torque actually applied, `scale` times the request,
    /// `[tau_x, tau_y, tau_z]` (N m).
    pub planar_torque_nm: Vector3<T>,
    /// The omniwheel torques that produce it (N m, at the omniwheel).
    pub wheel_torques_nm: Vector3<T>,
    /// The uniform factor in `[0, 1]` applied to the request: 1 when it was feasible, 0 for a
    /// non-finite request.
    pub scale: T,
}

impl<T: RealField + Copy> TorqueSaturation<T> {
    /// Whether the request had to be scaled down (`scale < 1`).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert!(
    ///     !kin.saturate_planar_torque(&Vector3::new(0.0, 50.0, 0.0))
    ///         .is_saturated()
    /// );
    /// assert!(
    ///     kin.saturate_planar_torque(&Vector3::new(0.0, 100.0, 0.0))
    ///         .is_saturated()
    /// );
    /// // A non-finite request gives no torque at all.
    /// let nan = kin.saturate_planar_torque(&Vector3::new(f64::NAN, 0.0, 0.0));
    /// assert!(nan.is_saturated() && nan.scale == 0.0 && nan.wheel_torques_nm == Vector3::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn is_saturated(&self) -> bool {
        self.scale < T::one()
    }

    /// No torque at all (`scale = 0`): the answer to a non-finite input.
    fn zero() -> Self {
        Self {
            planar_torque_nm: Vector3::zeros(),
            wheel_torques_nm: Vector3::zeros(),
            scale: T::zero(),
        }
    }
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

/// The relative ball-to-body angular velocity `omega_rel` (rad/s, body coordinates) in the
/// paper's planar variables: `[phi_dot_x - theta_dot_x, phi_dot_y - theta_dot_y,
/// -theta_z_dot]`.
///
/// `ball_rate_rad_per_s = [phi_dot_x, phi_dot_y]` (frontal, sagittal ball rates),
/// `tilt_rate_rad_per_s = [theta_dot_x, theta_dot_y]`, `yaw_rate_rad_per_s = theta_z_dot`.
/// This is the small-tilt form of MODEL.md section 4 (the ball is assumed not to spin about
/// the vertical); a 3D simulator should pass its exact `omega_ball - omega_body` in body
/// coordinates to [`OmniKinematics::wheel_speeds_rad_per_s`] instead.
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

    /// Omniwheel speeds `psi_dot_i = (r_S / r_W) u_i . omega_rel` (rad/s, at the omniwheel)
    /// for the relative ball-to-body angular velocity `relative_rate_rad_per_s` (body
    /// coordinates; see [`relative_rate_from_planar`]).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // Turning in place at 1 rad/s (omega_rel = [0, 0, -1]) spins all three wheels alike, at
    /// // (r_S / r_W) sin(45 deg) = 1.295 rad/s backwards.
    /// let psi_dot = kin.wheel_speeds_rad_per_s(&Vector3::new(0.0, 0.0, -1.0));
    /// approx::assert_relative_eq!(psi_dot, Vector3::repeat(-1.2954), epsilon = 1e-4);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wheel_speeds_rad_per_s(&self, relative_rate_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.wheel_speed_from_rel * relative_rate_rad_per_s
    }

    /// The exact inverse of [`Self::wheel_speeds_rad_per_s`]: `omega_rel` (rad/s) from the
    /// omniwheel speeds.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // Odometry: encoder speeds back to the ball's rate relative to the body.
    /// let omega_rel = Vector3::new(0.4, -3.0, 0.7);
    /// let measured = kin.wheel_speeds_rad_per_s(&omega_rel);
    /// approx::assert_relative_eq!(
    ///     kin.relative_rate_rad_per_s(&measured),
    ///     omega_rel,
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn relative_rate_rad_per_s(&self, wheel_speeds_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.rel_from_wheel_speed * wheel_speeds_rad_per_s
    }

    /// Motor rotor speeds (rad/s): `gear_ratio` times [`Self::wheel_speeds_rad_per_s`].
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // 1 m/s forward: wheels 2 and 3 at -+9.80 rad/s, their rotors 7.5 times faster.
    /// let motors = kin.motor_speeds_rad_per_s(&Vector3::new(0.0, 1.0 / 0.1145, 0.0));
    /// approx::assert_relative_eq!(motors, Vector3::new(0.0, -73.48, 73.48), epsilon = 0.01);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn motor_speeds_rad_per_s(&self, relative_rate_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.wheel_speeds_rad_per_s(relative_rate_rad_per_s) * self.drivetrain.actuator.gear_ratio
    }

    /// The exact inverse of [`Self::motor_speeds_rad_per_s`]: `omega_rel` (rad/s) from the
    /// motor rotor speeds.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let omega_rel = Vector3::new(-1.0, 2.0, 0.5);
    /// let rotors = kin.motor_speeds_rad_per_s(&omega_rel);
    /// approx::assert_relative_eq!(
    ///     kin.relative_rate_from_motor_speeds_rad_per_s(&rotors),
    ///     omega_rel,
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn relative_rate_from_motor_speeds_rad_per_s(
        &self,
        motor_speeds_rad_per_s: &Vector3<T>,
    ) -> Vector3<T> {
        self.relative_rate_rad_per_s(
            &(motor_speeds_rad_per_s / self.drivetrain.actuator.gear_ratio),
        )
    }

    // ---- torques ------------------------------------------------------------------------

    /// Omniwheel torques (N m, at the omniwheel) producing the planar torque
    /// `planar_torque_nm = [tau_x, tau_y, tau_z]`: `tau_wheel = J^-T S tau`, so that the power
    /// balance holds exactly.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let tau = Vector3::new(10.0, -20.0, 5.0);
    /// let wheels = kin.wheel_torques_nm(&tau);
    /// // Round trip, and the power balance sum_i tau_i psi_dot_i = tau . S omega_rel.
    /// approx::assert_relative_eq!(kin.planar_torque_nm(&wheels), tau, epsilon = 1e-12);
    /// let omega_rel = Vector3::new(0.3, -1.0, 0.2);
    /// let wheel_power = wheels.dot(&kin.wheel_speeds_rad_per_s(&omega_rel));
    /// approx::assert_relative_eq!(wheel_power, 10.0 * 0.3 + 20.0 - 5.0 * 0.2, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wheel_torques_nm(&self, planar_torque_nm: &Vector3<T>) -> Vector3<T> {
        self.wheel_torque_from_planar * planar_torque_nm
    }

    /// The exact inverse of [`Self::wheel_torques_nm`]: the planar torque
    /// `[tau_x, tau_y, tau_z]` (N m) the omniwheel torques produce, `S J^T tau_wheel`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // 1 N m on every wheel is pure yaw: tau_z = -3 (r_S / r_W) sin(45 deg) = -3.886 N m on
    /// // the body (it turns against the wheels' positive sense).
    /// let tau = kin.planar_torque_nm(&Vector3::repeat(1.0));
    /// approx::assert_relative_eq!(tau, Vector3::new(0.0, 0.0, -3.886), epsilon = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn planar_torque_nm(&self, wheel_torques_nm: &Vector3<T>) -> Vector3<T> {
        self.planar_from_wheel_torque * wheel_torques_nm
    }

    /// Motor rotor torques (N m): [`Self::wheel_torques_nm`] divided by `gear_ratio`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // The sagittal torque capacity (96.9 N m) takes a rotor to its 43.2 / 7.5 = 5.76 N m peak.
    /// let capacity_y = kin.planar_torque_capacity_nm()[1];
    /// let rotor = kin.motor_torques_nm(&Vector3::new(0.0, capacity_y, 0.0));
    /// approx::assert_relative_eq!(rotor.amax(), 5.76, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn motor_torques_nm(&self, planar_torque_nm: &Vector3<T>) -> Vector3<T> {
        self.wheel_torques_nm(planar_torque_nm) / self.drivetrain.actuator.gear_ratio
    }

    /// The exact inverse of [`Self::motor_torques_nm`]: the planar torque (N m) from the motor
    /// rotor torques.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let tau = Vector3::new(12.0, -30.0, 4.0);
    /// approx::assert_relative_eq!(
    ///     kin.planar_torque_from_motor_torques_nm(&kin.motor_torques_nm(&tau)),
    ///     tau,
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn planar_torque_from_motor_torques_nm(&self, motor_torques_nm: &Vector3<T>) -> Vector3<T> {
        self.planar_torque_nm(&(motor_torques_nm * self.drivetrain.actuator.gear_ratio))
    }

    /// The matrix `J = (r_S / r_W) U` of [`Self::wheel_speeds_rad_per_s`] (for building linear
    /// constraints, e.g. in a trajectory optimiser).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let j = kin.wheel_speed_matrix();
    /// // Row i is (r_S / r_W) u_i; wheel 1's is 1.832 [-cos 45, 0, sin 45].
    /// approx::assert_relative_eq!(
    ///     j.row(0).transpose(),
    ///     Vector3::new(-1.2954, 0.0, 1.2954),
    ///     epsilon = 1e-4
    /// );
    /// let w = Vector3::new(0.1, 0.2, 0.3);
    /// assert_eq!(j * w, kin.wheel_speeds_rad_per_s(&w));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wheel_speed_matrix(&self) -> &Matrix3<T> {
        &self.wheel_speed_from_rel
    }

    /// The matrix `J^-T S` of [`Self::wheel_torques_nm`].
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // Torque and speed maps are dual (power balance): (J^-T S)^T J = S = diag(1, 1, -1).
    /// let s = kin.wheel_torque_matrix().transpose() * kin.wheel_speed_matrix();
    /// approx::assert_relative_eq!(
    ///     s,
    ///     nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -1.0)),
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wheel_torque_matrix(&self) -> &Matrix3<T> {
        &self.wheel_torque_from_planar
    }

    /// The drivetrain's inertia reflected onto the relative rate `omega_rel` (kg m^2): the
    /// matrix `I_rel = (I_w + G^2 I_r) J^T J`, whose kinetic energy `omega_rel^T I_rel
    /// omega_rel / 2` equals that of the three spinning omniwheels (inertia `wheel_inertia_kg_m2`
    /// about the axle each) and their rotors (`rotor_inertia_kg_m2`, turning `G = gear_ratio`
    /// times faster).
    ///
    /// For the symmetric layout it is diagonal, `k^2 (I_w + G^2 I_r) diag(1.5 cos^2 a,
    /// 1.5 cos^2 a, 3 sin^2 a)` with `k = r_S / r_W`: entries 0 and 1 are the `I_W` of the
    /// frontal and sagittal WIP planes ([`crate::WipParams::wheel_inertia_kg_m2`]), entry 2
    /// adds to the spin inertia.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // 1e-3 kg m^2 omniwheels and 1e-5 kg m^2 rotors (x 7.5^2): 1.5625e-3 kg m^2 per wheel,
    /// // times k^2 1.5 cos^2(45 deg) = 2.517 in each WIP plane, k^2 3 sin^2(45 deg) in yaw.
    /// let i_rel = kin.reflected_wheel_inertia_kg_m2(1e-3, 1e-5);
    /// approx::assert_relative_eq!(i_rel[(0, 0)], 3.933e-3, epsilon = 1e-6);
    /// approx::assert_relative_eq!(i_rel[(1, 1)], i_rel[(0, 0)], epsilon = 1e-12);
    /// approx::assert_relative_eq!(i_rel[(2, 2)], 2.0 * i_rel[(0, 0)], epsilon = 1e-12);
    /// approx::assert_abs_diff_eq!(i_rel[(0, 1)], 0.0, epsilon = 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reflected_wheel_inertia_kg_m2(
        &self,
        wheel_inertia_kg_m2: T,
        rotor_inertia_kg_m2: T,
    ) -> Matrix3<T> {
        let g = self.drivetrain.actuator.gear_ratio;
        let per_wheel = wheel_inertia_kg_m2 + g * g * rotor_inertia_kg_m2;
        self.wheel_speed_from_rel.transpose() * self.wheel_speed_from_rel * per_wheel
    }

    // ---- capacity -----------------------------------------------------------------------

    /// The largest planar torque about each axis alone, `[x, y, z]` (N m), that no omniwheel
    /// torque beyond the actuator's `peak_torque_nm` can produce: `peak / max_i |(J^-T S)_ij|`.
    /// MiaPURE: 83.9, 96.9, 167.9 N m.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // MODEL.md section 6: 83.9 (x), 96.9 (y), 167.9 (z) N m from 43.2 N m per actuator.
    /// approx::assert_relative_eq!(
    ///     kin.planar_torque_capacity_nm(),
    ///     Vector3::new(83.9, 96.9, 167.9),
    ///     epsilon = 0.05
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn planar_torque_capacity_nm(&self) -> Vector3<T> {
        self.planar_torque_capacity_nm
    }

    /// Scales `planar_torque_nm` uniformly (keeping its direction) so that no omniwheel torque
    /// exceeds the actuator's `peak_torque_nm` in magnitude. A feasible request passes
    /// unchanged (`scale = 1`); a non-finite one gives zero torque (`scale = 0`).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // Twice the sagittal capacity (96.9 N m) is halved, direction kept.
    /// let s = kin.saturate_planar_torque(&Vector3::new(0.0, 193.8, 0.0));
    /// assert!(s.is_saturated());
    /// approx::assert_relative_eq!(s.planar_torque_nm[1], 96.9, epsilon = 0.1);
    /// assert!(s.wheel_torques_nm.amax() <= 43.2 + 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn saturate_planar_torque(&self, planar_torque_nm: &Vector3<T>) -> TorqueSaturation<T> {
        let peak = self.drivetrain.actuator.peak_torque_nm;
        self.saturate_with(planar_torque_nm, |_| (-peak, peak))
    }

    /// As [`Self::saturate_planar_torque`], with each wheel's speed-dependent limits
    /// [`ActuatorParams::torque_bounds_nm`](crate::ActuatorParams::torque_bounds_nm) at its
    /// current speed `wheel_speeds_rad_per_s` (rad/s, at the omniwheel): motoring torque falls
    /// to zero at the no-load speed, braking torque keeps the peak. A non-finite wheel speed
    /// (a failed measurement) gives zero torque (`scale = 0`).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let request = Vector3::new(0.0, 90.0, 0.0);
    /// // At rest 90 N m about y is feasible (capacity 96.9 N m) ...
    /// assert!(
    ///     !kin.saturate_planar_torque_at_speed(&request, &Vector3::zeros())
    ///         .is_saturated()
    /// );
    /// // ... but with wheels 2 and 3 turning at -+31 rad/s (half the no-load speed) in the
    /// // direction the torque drives them, only about half of it is left.
    /// let s = kin.saturate_planar_torque_at_speed(&request, &Vector3::new(0.0, -31.0, 31.0));
    /// approx::assert_relative_eq!(s.scale, 21.6 / 40.11, epsilon = 1e-3);
    /// // A failed speed measurement gives no torque.
    /// assert_eq!(
    ///     kin.saturate_planar_torque_at_speed(&request, &Vector3::new(0.0, f64::NAN, 0.0))
    ///         .scale,
    ///     0.0
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn saturate_planar_torque_at_speed(
        &self,
        planar_torque_nm: &Vector3<T>,
        wheel_speeds_rad_per_s: &Vector3<T>,
    ) -> TorqueSaturation<T> {
        if !wheel_speeds_rad_per_s.iter().all(|x| x.is_finite()) {
            return TorqueSaturation::zero();
        }
        let actuator = self.drivetrain.actuator;
        self.saturate_with(planar_torque_nm, |i| {
            actuator.torque_bounds_nm(wheel_speeds_rad_per_s[i])
        })
    }

    fn saturate_with(
        &self,
        planar_torque_nm: &Vector3<T>,
        bounds_nm: impl Fn(usize) -> (T, T),
    ) -> TorqueSaturation<T> {
        let wheel = self.wheel_torques_nm(planar_torque_nm);
        if !wheel.iter().all(|x| x.is_finite()) {
            return TorqueSaturation::zero();
        }
        let mut scale = T::one();
        for (i, &torque) in wheel.iter().enumerate() {
            let (lo, hi) = bounds_nm(i);
            let room = if torque > T::zero() {
                hi.max(T::zero())
            } else {
                -lo.min(T::zero())
            };
            let need = torque.abs();
            if need * scale > room {
                scale = room / need;
            }
        }
        TorqueSaturation {
            planar_torque_nm: planar_torque_nm * scale,
            wheel_torques_nm: wheel * scale,
            scale,
        }
    }
}

#[cfg(test)]
mod tests;
