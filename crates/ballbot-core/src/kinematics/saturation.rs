//! Torque saturation: the planar torque capacity of the three actuators and the uniform
//! scaling of a planar torque into it ([`TorqueSaturation`]).

use nalgebra::{RealField, Vector3};

use super::OmniKinematics;

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

impl<T: RealField + Copy> OmniKinematics<T> {
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
