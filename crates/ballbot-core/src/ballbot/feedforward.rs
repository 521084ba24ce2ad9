//! The outer loop's input and tilt feedforward: reference planar torques and the commanded
//! tilt's contribution, computed from the shaped command.

use super::BallbotControllerConfig;
use nalgebra::RealField;

/// The shifts of the command states that make each LQR's output equal the torque its plane
/// needs to follow the commanded acceleration (see [`BallbotController`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct InputFeedforward<T> {
    /// Frontal tilt-command shift per m/s^2 of body-y acceleration (rad s^2/m).
    pub(super) frontal_rad_per_m_per_s2: T,
    /// Sagittal tilt-command shift per m/s^2 of body-x acceleration (rad s^2/m).
    pub(super) sagittal_rad_per_m_per_s2: T,
    /// Heading-command shift per rad/s^2 of yaw acceleration (s^2).
    pub(super) heading_per_yaw_accel_s2: T,
    /// Heading-command shift per rad/s of yaw rate (s).
    pub(super) heading_per_yaw_rate_secs: T,
    /// Frontal tilt-command shift per rad/s^2 of commanded tilt acceleration.
    pub(super) frontal_tilt: TiltFeedforward<T>,
    /// Sagittal tilt-command shift per rad/s^2 of commanded tilt acceleration.
    pub(super) sagittal_tilt: TiltFeedforward<T>,
}

/// A plane's tilt-command shift `c(theta_c) theta_ddot_c / k1` for a commanded tilt
/// acceleration, `c(theta) = m_U r l cos(theta) - I_W` (the mass matrix's coupling).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TiltFeedforward<T> {
    /// `m_U r l / k1` (s^2).
    pub(super) coupling_per_k1_s2: T,
    /// `I_W / k1` (s^2).
    pub(super) wheel_per_k1_s2: T,
}

impl<T: RealField + Copy> TiltFeedforward<T> {
    pub(super) fn new(p: &crate::WipParams<T>, k1: T) -> Self {
        let per = |x: T| {
            let v = x / k1;
            if v.is_finite() { v } else { T::zero() }
        };
        Self {
            coupling_per_k1_s2: per(p.body_mass_kg * p.ball_radius_m * p.com_height_m),
            wheel_per_k1_s2: per(p.wheel_inertia_kg_m2),
        }
    }

    /// The shift for tilt command `tilt_rad` and its acceleration (rad).
    #[inline]
    pub(super) fn shift(&self, tilt_rad: T, tilt_accel_rad_per_s2: T) -> T {
        if tilt_accel_rad_per_s2 == T::zero() {
            return T::zero();
        }
        (self.coupling_per_k1_s2 * tilt_rad.cos() - self.wheel_per_k1_s2) * tilt_accel_rad_per_s2
    }
}

impl<T: RealField + Copy> InputFeedforward<T> {
    pub(super) fn new(config: &BallbotControllerConfig<T>) -> Self {
        // The torque that accelerates the ball at phi_ddot with the body steadily leaning is
        // b phi_ddot, b = I_S + (m_S + m_U) r^2 + I_W (second row of the WIP equations).
        let plane = |p: &crate::WipParams<T>, k1: T| {
            let b = p.ball_inertia_kg_m2
                + (p.ball_mass_kg + p.body_mass_kg) * p.ball_radius_m * p.ball_radius_m
                + p.wheel_inertia_kg_m2;
            let shift = b / (k1 * p.ball_radius_m);
            if shift.is_finite() { shift } else { T::zero() }
        };
        let k_heading = config.spin.gains.heading_nm_per_rad;
        let per = |x: T| {
            let v = x / k_heading;
            if v.is_finite() { v } else { T::zero() }
        };
        Self {
            frontal_rad_per_m_per_s2: -plane(
                &config.robot.frontal,
                config.frontal.lqr.tilt_nm_per_rad,
            ),
            sagittal_rad_per_m_per_s2: plane(
                &config.robot.sagittal,
                config.sagittal.lqr.tilt_nm_per_rad,
            ),
            heading_per_yaw_accel_s2: per(config.robot.spin.inertia_kg_m2),
            heading_per_yaw_rate_secs: per(config.robot.spin.damping_nm_s_per_rad),
            frontal_tilt: TiltFeedforward::new(
                &config.robot.frontal,
                config.frontal.lqr.tilt_nm_per_rad,
            ),
            sagittal_tilt: TiltFeedforward::new(
                &config.robot.sagittal,
                config.sagittal.lqr.tilt_nm_per_rad,
            ),
        }
    }
}
