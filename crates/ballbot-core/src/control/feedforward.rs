//! Command states consistent with the model: the lean a WIP needs to accelerate.
//!
//! The paper's speed commands set only the ball rate (`s_c = [0, 0, 0, phi_dot_c]`). While
//! the command accelerates, the body must lean into the acceleration, and a command tilt of 0
//! makes the controller's `k1` term fight that lean: the robot lags the ramp. The command
//! state below carries the lean (and the torque) that hold a constant ball acceleration on the
//! nonlinear model, so a controller tracking it has no steady lag on a ramp.

use crate::check::lit;
use crate::wip::{BALL_RATE, TILT};
use crate::{Wip, WipState};
use nalgebra::{RealField, Vector4};

/// The steady state that accelerates the ball at `ball_accel_rad_per_s2` while rolling at
/// `ball_rate_rad_per_s`: `theta_dot = 0`, `phi_ddot` constant, on `wip`'s nonlinear model
/// (frictions included). Returns `(command_state, torque_nm)`; the ball angle in the state
/// is 0 (controllers ignore it).
///
/// With `theta_dot = 0` the model's rows give `tau = b phi_ddot + (b_m + b_k) phi_dot` and
/// `m_U g l sin(theta) - m_U r l phi_ddot cos(theta) = (b - I_W) phi_ddot + b_k phi_dot`,
/// solved in closed form for `theta` (`R sin(theta - delta) = C`). `None` for a non-finite
/// input or when no lean can hold the acceleration.
///
/// ```
/// use ballbot_core::control::accelerating_command;
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// // 0.5 m/s^2 at 0.5 m/s: lean forward; the model then gives exactly that acceleration.
/// let r = wip.params().ball_radius_m;
/// let (s, tau) = accelerating_command(&wip, 0.5 / r, 0.5 / r).unwrap();
/// assert!(s[0] > 0.0);
/// let q_ddot = wip.accelerations(&s, tau);
/// approx::assert_relative_eq!(q_ddot[0], 0.0, epsilon = 1e-9);
/// approx::assert_relative_eq!(q_ddot[1], 0.5 / r, epsilon = 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn accelerating_command<T: RealField + Copy>(
    wip: &Wip<T>,
    ball_rate_rad_per_s: T,
    ball_accel_rad_per_s2: T,
) -> Option<(WipState<T>, T)> {
    if !(ball_rate_rad_per_s.is_finite() && ball_accel_rad_per_s2.is_finite()) {
        return None;
    }
    let p = wip.params();
    let r = p.ball_radius_m;
    let l = p.com_height_m;
    let m = p.body_mass_kg;
    let b = p.ball_inertia_kg_m2 + (p.ball_mass_kg + m) * r * r + p.wheel_inertia_kg_m2;
    let alpha = ball_accel_rad_per_s2;
    let w = ball_rate_rad_per_s;
    let torque = b * alpha + (p.drive_damping_nm_s_per_rad + p.ball_damping_nm_s_per_rad) * w;
    // A sin(theta) - B cos(theta) = C.
    let a_coef = m * p.gravity_m_per_s2 * l;
    let b_coef = m * r * l * alpha;
    let c_coef = (b - p.wheel_inertia_kg_m2) * alpha + p.ball_damping_nm_s_per_rad * w;
    let radius = (a_coef * a_coef + b_coef * b_coef).sqrt();
    let ratio = c_coef / radius;
    if !(ratio.is_finite() && ratio.abs() <= T::one()) {
        return None;
    }
    // sin(theta - delta) = ratio with delta = atan2(-B, A); the small-lean branch.
    let delta = (-b_coef).atan2(a_coef);
    let tilt = ratio.asin() - delta;
    if !(tilt.is_finite() && tilt.abs() < lit::<T>(1.5)) {
        return None;
    }
    let mut s = Vector4::zeros();
    s[TILT] = tilt;
    s[BALL_RATE] = w;
    Some((s, torque))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::WipParams;

    #[test]
    fn holds_the_acceleration_on_the_nonlinear_model_with_friction() {
        let params = WipParams {
            wheel_inertia_kg_m2: 0.05,
            ball_damping_nm_s_per_rad: 0.3,
            drive_damping_nm_s_per_rad: 0.2,
            ..WipParams::<f64>::piptb()
        };
        let wip = Wip::new(params).unwrap();
        for (w, a) in [
            (0.0, 0.0),
            (0.0, 5.0),
            (3.0, 5.0),
            (-10.0, -20.0),
            (17.0, -8.0),
        ] {
            let (s, tau) = accelerating_command(&wip, w, a).unwrap();
            let q = wip.accelerations(&s, tau);
            assert!(q[0].abs() < 1e-9, "{w} {a}: theta_ddot {}", q[0]);
            assert!((q[1] - a).abs() < 1e-9, "{w} {a}: phi_ddot {}", q[1]);
            // From rest (no friction torque yet) it leans into the acceleration.
            if w == 0.0 && a != 0.0 {
                assert_eq!(s[TILT].signum(), a.signum());
            }
        }
    }

    #[test]
    fn impossible_or_non_finite_requests_give_none() {
        let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
        assert!(accelerating_command(&wip, 0.0, 1e4).is_none());
        assert!(accelerating_command(&wip, f64::NAN, 1.0).is_none());
    }
}
