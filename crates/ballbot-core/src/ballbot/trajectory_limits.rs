//! The [`TrajectoryLimits`] of a controller configuration
//! ([`BallbotControllerConfig::trajectory_limits`]).

use super::BallbotControllerConfig;
use crate::command::TrajectoryLimits;
use crate::num::{hypot, max, min};
use crate::{Error, OmniKinematics, WipParams};
use nalgebra::{Matrix3, RealField};

impl<T: RealField + Copy> BallbotControllerConfig<T> {
    /// The bounds a trajectory must keep for this controller to follow it (see
    /// [`TrajectoryLimits`]), each derived from the configuration:
    ///
    /// - `min_sample_period_secs = outer_dt_secs`: the controller samples the trajectory once
    ///   per outer period, so samples closer than that are skipped (their slopes, the
    ///   accelerations fed forward, would belong to intervals it never sees);
    /// - `max_tilt_rad = min(shaping.max_tilt_command_rad, safety.tilt_limit_rad -
    ///   safety.arm_tilt_limit_rad)`: the shaper clamps a tilt command beyond the first; the
    ///   supervisor declares a fall at `tilt_limit_rad`, and the trajectory (its tilts, and the
    ///   lean its accelerations need) keeps from it the margin the supervisor itself trusts
    ///   the controller to catch from rest, `arm_tilt_limit_rad` (17 deg on MiaPURE). Measured
    ///   (tests/trajectories.rs): a trajectory that needs the whole 20 deg without commanding
    ///   any lean for it overshoots to 20.2 deg and trips the supervisor;
    /// - `max_tilt_rate_rad_per_s = shaping.max_tilt_rate_command_rad_per_s` (the shaper's
    ///   clamp);
    /// - `max_ball_rate_rad_per_s = min(v_max / r, w_max / g_w - max_tilt_rate)`: the shaper
    ///   clamps the speed to `v_max = shaping.translation.max_value` (`r` the sagittal ball
    ///   radius it converts with), and the omniwheels reach the supervisor's
    ///   `w_max = safety.wheel_speed_limit_rad_per_s` at a ball-to-body rate of `w_max / g_w`,
    ///   `g_w` the largest wheel speed per unit planar relative rate along any heading (the
    ///   largest norm of a row's planar part of the wheel-speed matrix), of which the tilt rate
    ///   may take `max_tilt_rate`;
    /// - `max_ball_accel_rad_per_s2 = shaping.translation.max_rate_per_s / r`: the shaper's
    ///   acceleration limit, which caps the ball acceleration it feeds forward;
    /// - `max_torque_nm = peak / g_t`: the planar torque the omniwheels give along any heading
    ///   without one exceeding the actuator's `peak_torque_nm` (`g_t`: the largest norm of a
    ///   row's planar part of the wheel-torque matrix);
    /// - `tilt_inertia_kg_m2 = c0 = m_U r l - I_W` and `ball_inertia_kg_m2 = b = I_S + (m_S +
    ///   m_U) r^2 + I_W`, the larger of the two planes': the coefficients of the feedforward
    ///   torque `c0 theta_ddot + b phi_ddot` (see [`BallbotController`](super::BallbotController));
    /// - `lean_per_tilt_accel_s2 = (a + c0) / (m_U g l)` and `lean_per_ball_accel_s2 = (b +
    ///   c0) / (m_U g l)`, the larger of the two planes': the lean the body needs for an
    ///   acceleration, from the linearised WIP equations with the torque eliminated.
    ///
    /// MiaPURE with 60 kg and the designed shaping: 2.5 ms, 0.2 rad, 1 rad/s, 17.5 rad/s (the
    /// 2 m/s speed limit), 8.7 rad/s^2 (1 m/s^2) and 83.9 N m.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let l = config.trajectory_limits()?;
    /// assert_eq!((l.min_sample_period_secs, l.max_tilt_rad, l.max_tilt_rate_rad_per_s), (0.0025, 0.2, 1.0));
    /// approx::assert_relative_eq!(l.max_ball_rate_rad_per_s, 2.0 / 0.1145, epsilon = 1e-9);
    /// approx::assert_relative_eq!(l.max_ball_accel_rad_per_s2, 1.0 / 0.1145, epsilon = 1e-9);
    /// assert!((l.max_torque_nm - 83.9).abs() < 0.1, "{}", l.max_torque_nm);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn trajectory_limits(&self) -> Result<TrajectoryLimits<T>, Error> {
        let kinematics = OmniKinematics::from_ballbot(&self.robot)?;
        self.shaping.validate()?;
        self.safety.validate()?;
        let shaping = &self.shaping;
        let radius = self.robot.sagittal.ball_radius_m;
        let max_tilt_rate = shaping.max_tilt_rate_command_rad_per_s;
        let wheel_per_rate = largest_planar_row(kinematics.wheel_speed_matrix());
        let wheel_per_torque = largest_planar_row(kinematics.wheel_torque_matrix());
        let wheel_bound = self.safety.wheel_speed_limit_rad_per_s / wheel_per_rate - max_tilt_rate;
        let (frontal, sagittal) = (
            inertias(&self.robot.frontal),
            inertias(&self.robot.sagittal),
        );
        let limits = TrajectoryLimits {
            min_sample_period_secs: self.outer_dt_secs,
            max_tilt_rad: min(
                shaping.max_tilt_command_rad,
                self.safety.tilt_limit_rad - self.safety.arm_tilt_limit_rad,
            ),
            max_tilt_rate_rad_per_s: max_tilt_rate,
            max_ball_rate_rad_per_s: min(shaping.translation.max_value / radius, wheel_bound),
            max_ball_accel_rad_per_s2: shaping.translation.max_rate_per_s / radius,
            max_torque_nm: self.robot.drivetrain.actuator.peak_torque_nm / wheel_per_torque,
            tilt_inertia_kg_m2: max(frontal.0, sagittal.0),
            ball_inertia_kg_m2: max(frontal.1, sagittal.1),
            lean_per_tilt_accel_s2: max(frontal.2, sagittal.2),
            lean_per_ball_accel_s2: max(frontal.3, sagittal.3),
        };
        limits.validate()?;
        Ok(limits)
    }
}

/// The largest norm of a row's first two entries: the largest wheel quantity per unit planar
/// quantity along the worst heading.
fn largest_planar_row<T: RealField + Copy>(m: &Matrix3<T>) -> T {
    (0..3).fold(T::zero(), |acc, i| max(acc, hypot(m[(i, 0)], m[(i, 1)])))
}

/// `(c0, b, (a + c0) / (m_U g l), (b + c0) / (m_U g l))` of a plane, with `c0 = m_U r l -
/// I_W`, `b = I_S + (m_S + m_U) r^2 + I_W`, `a = I_U + m_U l^2 + I_W` (kg m^2, s^2).
fn inertias<T: RealField + Copy>(p: &WipParams<T>) -> (T, T, T, T) {
    let (r, l, m) = (p.ball_radius_m, p.com_height_m, p.body_mass_kg);
    let c0 = m * r * l - p.wheel_inertia_kg_m2;
    let b = p.ball_inertia_kg_m2 + (p.ball_mass_kg + m) * r * r + p.wheel_inertia_kg_m2;
    let a = p.body_inertia_kg_m2 + m * l * l + p.wheel_inertia_kg_m2;
    let mgl = m * p.gravity_m_per_s2 * l;
    (c0, b, (a + c0) / mgl, (b + c0) / mgl)
}
