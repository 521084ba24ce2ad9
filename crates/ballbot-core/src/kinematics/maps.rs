//! The kinematic maps of [`OmniKinematics`]: planar rates to wheel and motor speeds, wheel and
//! motor torques to planar torques, and the matrices and reflected inertia behind them.

use nalgebra::{Matrix3, RealField, Vector3};

use super::OmniKinematics;

impl<T: RealField + Copy> OmniKinematics<T> {
    /// Omniwheel speeds `psi_dot_i = (r_S / r_W) u_i . omega_rel` (rad/s, at the omniwheel)
    /// for the relative ball-to-body angular velocity `relative_rate_rad_per_s` (body
    /// coordinates; see [`relative_rate_from_planar`](super::relative_rate_from_planar)).
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

    /// The z part alone of [`Self::relative_rate_rad_per_s`] (rad/s): the one the slip monitor
    /// needs, a third of the work.
    #[inline]
    pub(crate) fn relative_z_rate_rad_per_s(&self, wheel_speeds_rad_per_s: &Vector3<T>) -> T {
        self.rel_from_wheel_speed
            .row(2)
            .transpose()
            .dot(wheel_speeds_rad_per_s)
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
}
