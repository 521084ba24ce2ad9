//! The balancing planes' PI-PD ([`super::BalancingLaw::PiPd`]) in the LQR-PI outer loop's
//! output form, so that the rest of the outer step (mapping, traction, the motors' references)
//! is the same for every law.

use crate::control::{LqrPiOuterOutput, PiPdController};
use crate::wip::{BALL_RATE, WipState};
use nalgebra::RealField;

/// One plane's PI-PD step in the LQR-PI outer loop's output form: its torque as the reference
/// torque, the measured ball rate as the motors' reference (no reference model), no reference
/// accelerations.
pub(super) fn pi_pd_plane<T: RealField + Copy>(
    controller: &mut PiPdController<T>,
    measured: &WipState<T>,
    command: &WipState<T>,
    dt_secs: T,
) -> LqrPiOuterOutput<T> {
    let out = controller.step(measured, command, dt_secs);
    LqrPiOuterOutput {
        reference_torque_nm: out.torque_nm,
        reference_ball_rate_rad_per_s: measured[BALL_RATE],
        reference_ball_accel_rad_per_s2: T::zero(),
        reference_tilt_accel_rad_per_s2: T::zero(),
        tilt_term_nm: out.tilt_p_term_nm,
        tilt_rate_term_nm: out.tilt_d_term_nm,
        ball_rate_term_nm: T::zero(),
        saturation_nm: out.saturation_nm,
        anchor_correction_rad_per_s: T::zero(),
        status: out.status,
    }
}
