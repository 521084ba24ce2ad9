//! Normal and traction forces at the three omniwheel contacts, and friction-cone use.
//!
//! # Model and sign conventions
//!
//! The upper body rests on the ball only through the three omniwheel contacts. At contact `i`
//! (body coordinates, see the [parent module](super)) the ball exerts on the **body**
//!
//! ```text
//! f_i = N_i n_i - F_i d_i
//! ```
//!
//! and the body (through wheel `i`) exerts `-f_i = -N_i n_i + F_i d_i` on the **ball**:
//!
//! * `N_i` is the normal force (N), positive in compression (the wheel presses on the ball);
//!   `N_i <= 0` means the contact would have to pull: the wheel lifts off.
//! * `F_i = tau_i / r_W` is the traction (N), the force of wheel `i` on the ball along `d_i`,
//!   set by the omniwheel torque `tau_i` (massless wheel).
//! * The rollers transmit nothing along the axle `u_i`.
//!
//! Normal forces pass through the ball centre, so they carry no torque: the wheel torques alone
//! set the torque between ball and body, and the normal forces follow from the force balance
//! alone. Given the support force `F_s` (N, body coordinates) the body needs from the ball,
//!
//! ```text
//! sum_i N_i n_i = F_s + sum_i F_i d_i     (a 3x3 system in N, solved with a precomputed inverse)
//! ```
//!
//! `F_s` is the net force of the ball on the upper body: `m_U (a_com - g_vec)` when gravity is
//! the only other force, i.e. `m_U g z` at rest upright ([`support_force_in_body_n`]). Static
//! load for MiaPURE with 60 kg: `N_i = m_U g / (3 cos a) = 344 N`.
//!
//! Friction-cone utilisation is `|F_i| / (mu N_i)` with `mu` the drivetrain's
//! `wheel_ball_friction`; above 1 the wheel slips on the ball.
//!
//! All maps are linear: a trajectory optimiser can use [`OmniKinematics::normal_force_matrices`]
//! to write `N = P F_s + Q tau_wheel` and the cone as the two linear inequalities
//! `-mu N_i <= F_i <= mu N_i`.

use super::{OmniKinematics, planar_torque_at_heading};
use crate::wip::{BALL_RATE, TILT, TILT_RATE};
use crate::{WHEEL_COUNT, Wip, WipParams, WipState};
use nalgebra::{Matrix3, RealField, UnitQuaternion, Vector2, Vector3};

/// The forces at one omniwheel contact. See the [module docs](self) for signs.
///
/// ```
/// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
/// use nalgebra::Vector4;
/// let params = BallbotParams::<f64>::miapure_60kg();
/// let (kin, wip) = (
///     OmniKinematics::from_ballbot(&params)?,
///     Wip::new(params.sagittal)?,
/// );
/// // 10 N m forward from upright at rest: wheel 1 idles, wheels 2 and 3 push the ball
/// // with opposite tractions, all in compression and inside their friction cones.
/// let c = kin.wip_contact_forces(&wip, 0.0, &Vector4::zeros(), 10.0);
/// let [w1, w2, w3] = c.wheels;
/// approx::assert_abs_diff_eq!(w1.traction_n, 0.0, epsilon = 1e-9);
/// approx::assert_relative_eq!(w2.traction_n, -w3.traction_n, epsilon = 1e-9);
/// assert!(!w2.lifted_off && w2.friction_utilisation < 1.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelContact<T> {
    /// Normal force `N_i` (N), positive in compression. The ball pushes the body with
    /// `N_i n_i`.
    pub normal_force_n: T,
    /// Traction `F_i = tau_i / r_W` (N): the force of the wheel on the ball along the rolling
    /// direction `d_i` (the ball pushes the body with `-F_i d_i`).
    pub traction_n: T,
    /// Friction-cone utilisation `|F_i| / (mu N_i)` (dimensionless): the contact holds below 1.
    /// Positive infinity when the wheel lifts off (`N_i <= 0`).
    pub friction_utilisation: T,
    /// Whether the contact would need tension (`N_i <= 0`): the wheel lifts off the ball.
    pub lifted_off: bool,
}

impl<T: RealField + Copy> WheelContact<T> {
    /// Whether the contact holds: in compression and inside its friction cone
    /// (`utilisation <= 1`).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
    /// use nalgebra::Vector4;
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let (kin, wip) = (
    ///     OmniKinematics::from_ballbot(&params)?,
    ///     Wip::new(params.sagittal)?,
    /// );
    /// // From rest, the contacts carry up to 17.1 N m forward (heading 0) before a wheel slips.
    /// let holds = |tau| {
    ///     kin.wip_contact_forces(&wip, 0.0, &Vector4::zeros(), tau)
    ///         .wheels[1]
    ///         .holds()
    /// };
    /// assert!(holds(17.0));
    /// assert!(!holds(17.2));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn holds(&self) -> bool {
        !self.lifted_off && self.friction_utilisation <= T::one()
    }
}

/// The forces at all three omniwheel contacts.
///
/// ```
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// use nalgebra::Vector3;
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// // Standing still, 74.3 kg rest on the three wheels: 343.6 N each, no traction.
/// let c = kin.contact_forces(&Vector3::new(0.0, 0.0, 74.3 * 9.81), &Vector3::zeros());
/// approx::assert_relative_eq!(c.normal_forces_n(), Vector3::repeat(343.6), epsilon = 0.05);
/// assert_eq!(c.max_friction_utilisation(), 0.0);
/// assert!(c.all_hold() && !c.any_lifted_off());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForces<T> {
    /// Per wheel, in wheel order.
    pub wheels: [WheelContact<T>; WHEEL_COUNT],
}

impl<T: RealField + Copy> ContactForces<T> {
    /// The normal forces `[N_1, N_2, N_3]` (N).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let weight = Vector3::new(0.0, 0.0, 74.3 * 9.81);
    /// // The normals carry the weight: sum_i N_i n_i = F_s without wheel torque.
    /// let n = kin
    ///     .contact_forces(&weight, &Vector3::zeros())
    ///     .normal_forces_n();
    /// let carried = kin
    ///     .wheels()
    ///     .iter()
    ///     .zip(n.iter())
    ///     .fold(Vector3::zeros(), |acc, (w, f)| acc + w.contact_normal * *f);
    /// approx::assert_relative_eq!(carried, weight, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn normal_forces_n(&self) -> Vector3<T> {
        Vector3::from_fn(|i, _| self.wheels[i].normal_force_n)
    }

    /// The largest friction-cone utilisation over the wheels (infinite if one lifts off).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let weight = Vector3::new(0.0, 0.0, 74.3 * 9.81);
    /// // Yaw torque loads all wheels alike: the utilisation grows linearly with it.
    /// let use_at = |tau_z| {
    ///     let wheels = kin.wheel_torques_nm(&Vector3::new(0.0, 0.0, tau_z));
    ///     kin.contact_forces(&weight, &wheels)
    ///         .max_friction_utilisation()
    /// };
    /// approx::assert_relative_eq!(use_at(20.0), 2.0 * use_at(10.0), max_relative = 1e-9);
    /// assert!(use_at(10.0) > 0.0 && use_at(10.0) < 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn max_friction_utilisation(&self) -> T {
        self.wheels
            .iter()
            .fold(T::zero(), |acc, w| acc.max(w.friction_utilisation))
    }

    /// Whether any wheel lifts off.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
    /// use nalgebra::Vector4;
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let (kin, wip) = (
    ///     OmniKinematics::from_ballbot(&params)?,
    ///     Wip::new(params.sagittal)?,
    /// );
    /// // 50 N m forward from rest is far beyond the contacts: wheels 2 and 3 would need tension.
    /// let c = kin.wip_contact_forces(&wip, 0.0, &Vector4::zeros(), 50.0);
    /// assert!(c.any_lifted_off());
    /// assert_eq!(c.max_friction_utilisation(), f64::INFINITY);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn any_lifted_off(&self) -> bool {
        self.wheels.iter().any(|w| w.lifted_off)
    }

    /// Whether every contact holds (no lift-off, no slip).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
    /// use nalgebra::Vector4;
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let (kin, wip) = (
    ///     OmniKinematics::from_ballbot(&params)?,
    ///     Wip::new(params.sagittal)?,
    /// );
    /// let upright = Vector4::zeros();
    /// assert!(kin.wip_contact_forces(&wip, 0.0, &upright, 10.0).all_hold());
    /// // 25 N m does not lift a wheel off but makes one slip.
    /// let c = kin.wip_contact_forces(&wip, 0.0, &upright, 25.0);
    /// assert!(!c.all_hold() && !c.any_lifted_off());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn all_hold(&self) -> bool {
        self.wheels.iter().all(WheelContact::holds)
    }
}

/// The support force `F_s` (N, body coordinates) the upper body needs from the ball when
/// gravity is the only other force on it: `m_U (a_com + g z_world)` rotated into the body.
///
/// `body_mass_kg` is `m_U`, `gravity_m_per_s2` is `g` (> 0, acting along `-z_world`),
/// `world_from_body` the body's attitude, `com_acceleration_world_m_per_s2` the acceleration of
/// the upper body's centre of mass in world coordinates (including the rotational terms of a
/// leaning body, e.g. `l theta_ddot`).
///
/// ```
/// use ballbot_core::kinematics::support_force_in_body_n;
/// use nalgebra::{UnitQuaternion, Vector3};
/// let f = support_force_in_body_n(74.3, 9.81, &UnitQuaternion::identity(), &Vector3::zeros());
/// approx::assert_relative_eq!(f, Vector3::new(0.0, 0.0, 74.3 * 9.81));
/// ```
pub fn support_force_in_body_n<T: RealField + Copy>(
    body_mass_kg: T,
    gravity_m_per_s2: T,
    world_from_body: &UnitQuaternion<T>,
    com_acceleration_world_m_per_s2: &Vector3<T>,
) -> Vector3<T> {
    let world = (com_acceleration_world_m_per_s2 + Vector3::z() * gravity_m_per_s2) * body_mass_kg;
    world_from_body.inverse_transform_vector(&world)
}

/// The support force `F_s` (N, body coordinates) of a planar WIP motion at heading
/// `heading_rad` (see [`plane_axis_at_heading`](super::plane_axis_at_heading)): the net force
/// of the ball on the upper body, from Newton's law for the body's centre of mass.
///
/// `s = [theta, phi, theta_dot, phi_dot]` is the WIP state in that plane and
/// `accelerations_rad_per_s2 = [theta_ddot, phi_ddot]` (e.g. [`Wip::accelerations`]). With
/// `m = m_U`, `l` the COM height, `r` the ball radius and `e = [cos h, sin h, 0]` the direction
/// of travel, in body coordinates (x_b along the leaning body's `e`, z_b along its axis):
///
/// ```text
/// F_s . e_b = m (r phi_ddot cos(theta) + l theta_ddot - g sin(theta))
/// F_s . z   = m (r phi_ddot sin(theta) - l theta_dot^2 + g cos(theta))
/// ```
///
/// (the COM moves by `r phi + l sin(theta)` along `e` and `l cos(theta)` up). The body's
/// rotational equation of the WIP is `I_U theta_ddot = -tau_c - l F_s . e_b`, `tau_c` the
/// torque transmitted through the contacts.
///
/// ```
/// use ballbot_core::kinematics::planar_support_force_n;
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::{Vector2, Vector4};
/// let params = WipParams::<f64>::miapure_60kg();
/// let weight_n = params.body_mass_kg * params.gravity_m_per_s2;
/// // Held still at 0.1 rad (no acceleration): the ball carries the weight, tilted into body axes.
/// let s = Vector4::new(0.1, 0.0, 0.0, 0.0);
/// let still = planar_support_force_n(&params, 0.0, &s, &Vector2::zeros());
/// approx::assert_relative_eq!(still.norm(), weight_n, epsilon = 1e-9);
/// approx::assert_relative_eq!(still.x, -weight_n * 0.1f64.sin(), epsilon = 1e-9);
/// // Falling freely from there (no torque), the body presses less on the ball.
/// let falling =
///     planar_support_force_n(&params, 0.0, &s, &Wip::new(params)?.accelerations(&s, 0.0));
/// assert!(falling.z < still.z);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn planar_support_force_n<T: RealField + Copy>(
    params: &WipParams<T>,
    heading_rad: T,
    s: &WipState<T>,
    accelerations_rad_per_s2: &Vector2<T>,
) -> Vector3<T> {
    let m = params.body_mass_kg;
    let l = params.com_height_m;
    let r = params.ball_radius_m;
    let g = params.gravity_m_per_s2;
    let (sin_t, cos_t) = s[TILT].sin_cos();
    let tilt_rate = s[TILT_RATE];
    let (tilt_acc, ball_acc) = (accelerations_rad_per_s2[0], accelerations_rad_per_s2[1]);
    let along = m * (r * ball_acc * cos_t + l * tilt_acc - g * sin_t);
    let up = m * (r * ball_acc * sin_t - l * tilt_rate * tilt_rate + g * cos_t);
    let (sin_h, cos_h) = heading_rad.sin_cos();
    Vector3::new(along * cos_h, along * sin_h, up)
}

/// The support force `F_s` (N, body coordinates) of the decoupled 3D model (MODEL.md
/// sections 1 to 3): the sagittal WIP (about y, travel +x) and the frontal WIP (about x,
/// travel -y) at the same time.
///
/// Gravity is exact for the attitude with roll `theta_x` and pitch `theta_y` in the ZYX
/// convention of [`crate::estimation`] (`m g [-sin theta_y, sin theta_x cos theta_y,
/// cos theta_x cos theta_y]`); the inertial terms of the two planes add, as in
/// [`planar_support_force_n`] (exact when either plane is upright and still, first order
/// otherwise, like the decoupled model itself). The yaw motion adds nothing: the COM is on the
/// spin axis. Mass and gravity of the gravity term are the sagittal plane's.
///
/// ```
/// use ballbot_core::kinematics::{decoupled_support_force_n, planar_support_force_n};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::{Vector2, Vector4};
/// let params = WipParams::<f64>::miapure_60kg();
/// let wip = Wip::new(params)?;
/// // With the frontal plane upright and still, the sagittal WIP alone: heading 0.
/// let s = Vector4::new(0.05, 0.0, 0.2, 3.0);
/// let acc = wip.accelerations(&s, 8.0);
/// let (upright, still) = (Vector4::zeros(), Vector2::zeros());
/// let both = decoupled_support_force_n((&params, &s, &acc), (&params, &upright, &still));
/// approx::assert_relative_eq!(
///     both,
///     planar_support_force_n(&params, 0.0, &s, &acc),
///     epsilon = 1e-9
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn decoupled_support_force_n<T: RealField + Copy>(
    sagittal: (&WipParams<T>, &WipState<T>, &Vector2<T>),
    frontal: (&WipParams<T>, &WipState<T>, &Vector2<T>),
) -> Vector3<T> {
    decoupled_support_force_sin_cos_n(
        (
            sagittal.0,
            sagittal.1,
            sagittal.2,
            sagittal.1[TILT].sin_cos(),
        ),
        (frontal.0, frontal.1, frontal.2, frontal.1[TILT].sin_cos()),
    )
}

/// [`decoupled_support_force_n`] with each plane's `(sin, cos)` of its tilt given.
fn decoupled_support_force_sin_cos_n<T: RealField + Copy>(
    sagittal: (&WipParams<T>, &WipState<T>, &Vector2<T>, (T, T)),
    frontal: (&WipParams<T>, &WipState<T>, &Vector2<T>, (T, T)),
) -> Vector3<T> {
    // Inertial part of one plane: (along its travel, up).
    let inertial = |p: &WipParams<T>, s: &WipState<T>, acc: &Vector2<T>, (sin_t, cos_t): (T, T)| {
        let m = p.body_mass_kg;
        (
            m * (p.ball_radius_m * acc[1] * cos_t + p.com_height_m * acc[0]),
            m * (p.ball_radius_m * acc[1] * sin_t - p.com_height_m * s[TILT_RATE] * s[TILT_RATE]),
        )
    };
    let (along_x, up_sagittal) = inertial(sagittal.0, sagittal.1, sagittal.2, sagittal.3);
    let (along_minus_y, up_frontal) = inertial(frontal.0, frontal.1, frontal.2, frontal.3);
    let weight = sagittal.0.body_mass_kg * sagittal.0.gravity_m_per_s2;
    let (sin_y, cos_y) = sagittal.3;
    let (sin_x, cos_x) = frontal.3;
    Vector3::new(
        along_x - weight * sin_y,
        -along_minus_y + weight * sin_x * cos_y,
        up_sagittal + up_frontal + weight * cos_x * cos_y,
    )
}

impl<T: RealField + Copy> OmniKinematics<T> {
    /// The normal forces `[N_1, N_2, N_3]` (N, positive in compression) for the support force
    /// `support_force_n` (N, body coordinates: the net force of the ball on the upper body) and
    /// the omniwheel torques `wheel_torques_nm` (N m, at the omniwheel): the solution of
    /// `sum_i N_i n_i = F_s + sum_i (tau_i / r_W) d_i`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let weight = Vector3::new(0.0, 0.0, 74.3 * 9.81);
    /// // Static load m_U g / (3 cos 45 deg) = 343.6 N per wheel.
    /// approx::assert_relative_eq!(
    ///     kin.normal_forces_n(&weight, &Vector3::zeros()),
    ///     Vector3::repeat(343.6),
    ///     epsilon = 0.05
    /// );
    /// // Driving torque moves load between the wheels: wheel 2 pushing along +d_2 unloads it.
    /// let n = kin.normal_forces_n(&weight, &Vector3::new(0.0, 10.0, 0.0));
    /// assert!(n[1] < 343.6);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn normal_forces_n(
        &self,
        support_force_n: &Vector3<T>,
        wheel_torques_nm: &Vector3<T>,
    ) -> Vector3<T> {
        self.normal_from_force * support_force_n + self.normal_from_wheel_torque * wheel_torques_nm
    }

    /// The matrices `(P, Q)` of `N = P F_s + Q tau_wheel` ([`Self::normal_forces_n`]):
    /// `P = [n_1 n_2 n_3]^-1`, `Q = P [d_1 d_2 d_3] / r_W`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let (p, q) = kin.normal_force_matrices();
    /// // N = P F_s + Q tau_wheel, for use as linear constraints in an optimiser.
    /// let (f_s, tau) = (
    ///     Vector3::new(30.0, -10.0, 729.0),
    ///     Vector3::new(5.0, -12.0, 7.0),
    /// );
    /// approx::assert_relative_eq!(
    ///     p * f_s + q * tau,
    ///     kin.normal_forces_n(&f_s, &tau),
    ///     epsilon = 1e-9
    /// );
    /// // Equal wheel torques (pure yaw) leave the normal forces unchanged.
    /// approx::assert_abs_diff_eq!(q * Vector3::repeat(10.0), Vector3::zeros(), epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn normal_force_matrices(&self) -> (&Matrix3<T>, &Matrix3<T>) {
        (&self.normal_from_force, &self.normal_from_wheel_torque)
    }

    /// Normal force, traction, friction-cone utilisation and lift-off of each contact for the
    /// support force `support_force_n` (N, body coordinates) and the omniwheel torques
    /// `wheel_torques_nm` (N m), with the drivetrain's `wheel_ball_friction`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // At rest: 74.3 kg on three wheels at 45 deg carry m_U g / (3 cos a) = 344 N each.
    /// let contacts = kin.contact_forces(&Vector3::new(0.0, 0.0, 74.3 * 9.81), &Vector3::zeros());
    /// approx::assert_relative_eq!(contacts.wheels[0].normal_force_n, 343.6, epsilon = 0.1);
    /// assert!(contacts.all_hold());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn contact_forces(
        &self,
        support_force_n: &Vector3<T>,
        wheel_torques_nm: &Vector3<T>,
    ) -> ContactForces<T> {
        let normal = self.normal_forces_n(support_force_n, wheel_torques_nm);
        ContactForces {
            wheels: core::array::from_fn(|i| self.wheel_contact(normal[i], wheel_torques_nm[i])),
        }
    }

    /// One contact from its normal force (N) and its omniwheel's torque (N m).
    pub(crate) fn wheel_contact(&self, normal_force_n: T, wheel_torque_nm: T) -> WheelContact<T> {
        let mu = self.drivetrain.wheel_ball_friction;
        let traction_n = wheel_torque_nm / self.drivetrain.wheel_radius_m;
        let lifted_off = normal_force_n <= T::zero();
        let friction_utilisation = if lifted_off {
            nalgebra::convert(f64::INFINITY)
        } else {
            traction_n.abs() / (mu * normal_force_n)
        };
        WheelContact {
            normal_force_n,
            traction_n,
            friction_utilisation,
            lifted_off,
        }
    }

    /// The contact forces of a planar WIP motion at heading `heading_rad` (body frame, 0 =
    /// towards omniwheel 1): the WIP `wip` in state `s` with torque `torque_nm` (the torque
    /// the body applies to the ball in that plane, the WIP input).
    ///
    /// The accelerations come from [`Wip::accelerations`]; the support force from
    /// [`planar_support_force_n`]. The wheels transmit the contact torque
    /// `tau_c = tau - I_W (phi_ddot - theta_ddot) - b_m (phi_dot - theta_dot)` (reflected wheel
    /// inertia and drivetrain friction take their share before the contact), mapped to the
    /// omniwheels with [`Self::wheel_torques_nm`] of [`planar_torque_at_heading`]. The
    /// tractions of the result are therefore at the contact; the motor torques are `tau`'s.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
    /// use nalgebra::Vector4;
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let kin = OmniKinematics::from_ballbot(&params)?;
    /// let wip = Wip::new(params.sagittal)?;
    /// // Upright at rest, no torque: the static load, 344 N per wheel.
    /// let c = kin.wip_contact_forces(&wip, 0.0, &Vector4::zeros(), 0.0);
    /// approx::assert_relative_eq!(c.wheels[2].normal_force_n, 343.6, epsilon = 0.1);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wip_contact_forces(
        &self,
        wip: &Wip<T>,
        heading_rad: T,
        s: &WipState<T>,
        torque_nm: T,
    ) -> ContactForces<T> {
        let (acc, contact_torque_nm) = transmitted_torque(wip, s, s[TILT].sin_cos(), torque_nm);
        let wheel =
            self.wheel_torques_nm(&planar_torque_at_heading(heading_rad, contact_torque_nm));
        let support = planar_support_force_n(wip.params(), heading_rad, s, &acc);
        self.contact_forces(&support, &wheel)
    }

    /// The contact forces of the decoupled 3D model: the sagittal WIP `sagittal.0` in state
    /// `sagittal.1`, the frontal WIP `frontal.0` in state `frontal.1`, driven by the planar
    /// torque `planar_torque_nm = [tau_x, tau_y, tau_z]` (`tau_x` is the frontal WIP input,
    /// `tau_y` the sagittal one, `tau_z` the yaw torque on the body).
    ///
    /// Each plane's accelerations come from [`Wip::accelerations`] and its transmitted torque
    /// loses reflected wheel inertia and drivetrain friction as in
    /// [`Self::wip_contact_forces`]; the support force is [`decoupled_support_force_n`]. With
    /// one plane upright and still and no yaw torque this equals [`Self::wip_contact_forces`]
    /// of the other (heading 0 for the sagittal plane, -90 deg for the frontal one).
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
    /// use nalgebra::{Vector3, Vector4};
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let kin = OmniKinematics::from_ballbot(&params)?;
    /// let (sagittal, frontal) = (Wip::new(params.sagittal)?, Wip::new(params.frontal)?);
    /// // Sagittal motion only: the same as the planar WIP at heading 0.
    /// let s = Vector4::new(0.02, 0.0, 0.1, 4.0);
    /// let upright = Vector4::zeros();
    /// let both = kin.decoupled_contact_forces(
    ///     (&sagittal, &s),
    ///     (&frontal, &upright),
    ///     &Vector3::new(0.0, 6.0, 0.0),
    /// );
    /// let planar = kin.wip_contact_forces(&sagittal, 0.0, &s, 6.0);
    /// approx::assert_relative_eq!(
    ///     both.normal_forces_n(),
    ///     planar.normal_forces_n(),
    ///     epsilon = 1e-9
    /// );
    /// // Adding yaw torque adds traction but no normal force.
    /// let turning = kin.decoupled_contact_forces(
    ///     (&sagittal, &s),
    ///     (&frontal, &upright),
    ///     &Vector3::new(0.0, 6.0, 5.0),
    /// );
    /// approx::assert_relative_eq!(
    ///     turning.normal_forces_n(),
    ///     planar.normal_forces_n(),
    ///     epsilon = 1e-9
    /// );
    /// assert!(turning.max_friction_utilisation() != planar.max_friction_utilisation());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn decoupled_contact_forces(
        &self,
        sagittal: (&Wip<T>, &WipState<T>),
        frontal: (&Wip<T>, &WipState<T>),
        planar_torque_nm: &Vector3<T>,
    ) -> ContactForces<T> {
        let (normal, wheel) = self.decoupled_normal_forces_sin_cos_n(
            (sagittal.0, sagittal.1, sagittal.1[TILT].sin_cos()),
            (frontal.0, frontal.1, frontal.1[TILT].sin_cos()),
            planar_torque_nm,
        );
        ContactForces {
            wheels: core::array::from_fn(|i| self.wheel_contact(normal[i], wheel[i])),
        }
    }

    /// The normal forces (N) and omniwheel torques (N m) of
    /// [`Self::decoupled_contact_forces`], with each plane's `(sin, cos)` of its tilt given.
    pub(crate) fn decoupled_normal_forces_sin_cos_n(
        &self,
        sagittal: (&Wip<T>, &WipState<T>, (T, T)),
        frontal: (&Wip<T>, &WipState<T>, (T, T)),
        planar_torque_nm: &Vector3<T>,
    ) -> (Vector3<T>, Vector3<T>) {
        let acceleration = |wip: &Wip<T>, s: &WipState<T>, (sin, cos): (T, T), torque_nm: T| {
            wip.accelerations_with_sin_cos(s, sin, cos, torque_nm)
        };
        let acc_y = acceleration(sagittal.0, sagittal.1, sagittal.2, planar_torque_nm[1]);
        let acc_x = acceleration(frontal.0, frontal.1, frontal.2, planar_torque_nm[0]);
        self.decoupled_normal_forces_with_accelerations_n(
            (sagittal.0, sagittal.1, &acc_y, sagittal.2),
            (frontal.0, frontal.1, &acc_x, frontal.2),
            planar_torque_nm,
        )
    }

    /// [`Self::decoupled_normal_forces_sin_cos_n`] with each plane's accelerations
    /// `[theta_ddot, phi_ddot]` under its torque given too (the 3D controller's LQR-PI planes
    /// compute them for their reference models: the slip monitor's every-step prediction then
    /// needs neither trigonometry nor the dynamics).
    pub(crate) fn decoupled_normal_forces_with_accelerations_n(
        &self,
        sagittal: (&Wip<T>, &WipState<T>, &Vector2<T>, (T, T)),
        frontal: (&Wip<T>, &WipState<T>, &Vector2<T>, (T, T)),
        planar_torque_nm: &Vector3<T>,
    ) -> (Vector3<T>, Vector3<T>) {
        let tau_y = contact_torque(sagittal.0, sagittal.1, sagittal.2, planar_torque_nm[1]);
        let tau_x = contact_torque(frontal.0, frontal.1, frontal.2, planar_torque_nm[0]);
        let wheel = self.wheel_torques_nm(&Vector3::new(tau_x, tau_y, planar_torque_nm[2]));
        let support = decoupled_support_force_sin_cos_n(
            (sagittal.0.params(), sagittal.1, sagittal.2, sagittal.3),
            (frontal.0.params(), frontal.1, frontal.2, frontal.3),
        );
        (self.normal_forces_n(&support, &wheel), wheel)
    }
}

/// The WIP accelerations `[theta_ddot, phi_ddot]` under `torque_nm` (with `(sin, cos)` of the
/// tilt), and the torque the wheels transmit to the ball through the contacts
/// ([`contact_torque`]).
fn transmitted_torque<T: RealField + Copy>(
    wip: &Wip<T>,
    s: &WipState<T>,
    (sin_t, cos_t): (T, T),
    torque_nm: T,
) -> (Vector2<T>, T) {
    let acc = wip.accelerations_with_sin_cos(s, sin_t, cos_t, torque_nm);
    (acc, contact_torque(wip, s, &acc, torque_nm))
}

/// The torque the wheels transmit to the ball through the contacts when the WIP `wip` in
/// state `s` accelerates at `acc = [theta_ddot, phi_ddot]` under `torque_nm`:
/// `tau - I_W (phi_ddot - theta_ddot) - b_m (phi_dot - theta_dot)` (reflected wheel inertia
/// and drivetrain friction take their share before the contact).
fn contact_torque<T: RealField + Copy>(
    wip: &Wip<T>,
    s: &WipState<T>,
    acc: &Vector2<T>,
    torque_nm: T,
) -> T {
    let p = wip.params();
    torque_nm
        - p.wheel_inertia_kg_m2 * (acc[1] - acc[0])
        - p.drive_damping_nm_s_per_rad * (s[BALL_RATE] - s[TILT_RATE])
}
