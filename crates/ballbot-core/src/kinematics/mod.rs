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
pub fn plane_axis_at_heading<T: RealField + Copy>(heading_rad: T) -> Vector3<T> {
    let (sin_h, cos_h) = heading_rad.sin_cos();
    Vector3::new(-sin_h, cos_h, T::zero())
}

/// `omega_rel` (rad/s, body coordinates) of a planar WIP motion at heading `heading_rad`:
/// `(phi_dot - theta_dot) a` ([`plane_axis_at_heading`]), no yaw.
pub fn relative_rate_at_heading<T: RealField + Copy>(
    heading_rad: T,
    ball_rate_rad_per_s: T,
    tilt_rate_rad_per_s: T,
) -> Vector3<T> {
    plane_axis_at_heading(heading_rad) * (ball_rate_rad_per_s - tilt_rate_rad_per_s)
}

/// The planar torque vector `[tau_x, tau_y, 0]` (N m) of a planar WIP torque `torque_nm` (the
/// torque the body applies to the ball in that plane) at heading `heading_rad`: `torque_nm a`.
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
    pub fn from_ballbot(params: &BallbotParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Self::new(params.drivetrain, params.ball_radius_m())
    }

    /// The drivetrain this was built from.
    pub fn drivetrain(&self) -> &DrivetrainParams<T> {
        &self.drivetrain
    }

    /// The ball radius `r_S` (m).
    pub fn ball_radius_m(&self) -> T {
        self.ball_radius_m
    }

    /// The geometry of each wheel's contact, in body coordinates.
    pub fn wheels(&self) -> &[WheelGeometry<T>; WHEEL_COUNT] {
        &self.wheels
    }

    // ---- speeds -------------------------------------------------------------------------

    /// Omniwheel speeds `psi_dot_i = (r_S / r_W) u_i . omega_rel` (rad/s, at the omniwheel)
    /// for the relative ball-to-body angular velocity `relative_rate_rad_per_s` (body
    /// coordinates; see [`relative_rate_from_planar`]).
    pub fn wheel_speeds_rad_per_s(&self, relative_rate_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.wheel_speed_from_rel * relative_rate_rad_per_s
    }

    /// The exact inverse of [`Self::wheel_speeds_rad_per_s`]: `omega_rel` (rad/s) from the
    /// omniwheel speeds.
    pub fn relative_rate_rad_per_s(&self, wheel_speeds_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.rel_from_wheel_speed * wheel_speeds_rad_per_s
    }

    /// Motor rotor speeds (rad/s): `gear_ratio` times [`Self::wheel_speeds_rad_per_s`].
    pub fn motor_speeds_rad_per_s(&self, relative_rate_rad_per_s: &Vector3<T>) -> Vector3<T> {
        self.wheel_speeds_rad_per_s(relative_rate_rad_per_s) * self.drivetrain.actuator.gear_ratio
    }

    /// The exact inverse of [`Self::motor_speeds_rad_per_s`]: `omega_rel` (rad/s) from the
    /// motor rotor speeds.
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
    pub fn planar_torque_nm(&self, wheel_torques_nm: &Vector3<T>) -> Vector3<T> {
        self.planar_from_wheel_torque * wheel_torques_nm
    }

    /// Motor rotor torques (N m): [`Self::wheel_torques_nm`] divided by `gear_ratio`.
    pub fn motor_torques_nm(&self, planar_torque_nm: &Vector3<T>) -> Vector3<T> {
        self.wheel_torques_nm(planar_torque_nm) / self.drivetrain.actuator.gear_ratio
    }

    /// The exact inverse of [`Self::motor_torques_nm`]: the planar torque (N m) from the motor
    /// rotor torques.
    pub fn planar_torque_from_motor_torques_nm(&self, motor_torques_nm: &Vector3<T>) -> Vector3<T> {
        self.planar_torque_nm(&(motor_torques_nm * self.drivetrain.actuator.gear_ratio))
    }

    /// The matrix `J = (r_S / r_W) U` of [`Self::wheel_speeds_rad_per_s`] (for building linear
    /// constraints, e.g. in a trajectory optimiser).
    pub fn wheel_speed_matrix(&self) -> &Matrix3<T> {
        &self.wheel_speed_from_rel
    }

    /// The matrix `J^-T S` of [`Self::wheel_torques_nm`].
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
