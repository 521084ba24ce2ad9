//! The planar wheeled inverted pendulum (WIP): one plane of a ballbot, or the PIPTB.
//!
//! Generalised coordinates `q = [theta, phi]`: body tilt and ball rotation, both absolute
//! angles about the same horizontal axis, positive `phi` rolling the ball towards +travel and
//! positive `theta` leaning the body towards +travel. State `s = [theta, phi, theta_dot,
//! phi_dot]`. Input `tau`: the torque the body applies to the ball (the body feels `-tau`).
//!
//! ```text
//! M(theta) q_ddot + c(q, q_dot) + G(q) + D(q_dot) = [-1, 1]^T tau
//! M = [[a, c(theta)], [c(theta), b]]
//! a = I_U + m_U l^2 + I_W,  b = I_S + (m_S + m_U) r^2 + I_W,  c(theta) = m_U r l cos(theta) - I_W
//! ```
//!
//! Closed form with `Delta = a b - c^2`:
//!
//! ```text
//! g1 = m_U g l sin(theta) - tau + b_m (phi_dot - theta_dot)
//! g2 = m_U r l sin(theta) theta_dot^2 + tau - b_m (phi_dot - theta_dot) - b_k phi_dot
//! theta_ddot = (b g1 - c g2) / Delta,   phi_ddot = (a g2 - c g1) / Delta
//! ```
//!
//! ```
//! use ballbot_core::{Wip, WipParams};
//! use nalgebra::Vector4;
//! let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
//! // Leaning forward with no torque, the body falls forward and the ball rolls back.
//! let q_ddot = wip.accelerations(&Vector4::new(0.1, 0.0, 0.0, 0.0), 0.0);
//! assert!(q_ddot[0] > 0.0 && q_ddot[1] < 0.0);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

mod dynamics;
mod energy;
mod linearization;
mod momentum;
#[cfg(test)]
mod tests;

pub use linearization::WipLinearization;

use crate::{Error, WipParams};
use nalgebra::{RealField, Vector3, Vector4};

/// WIP state `[theta (rad), phi (rad), theta_dot (rad/s), phi_dot (rad/s)]`.
///
/// ```
/// use ballbot_core::WipState;
/// use ballbot_core::wip::{BALL_RATE, TILT};
/// // Leaning 0.05 rad forward while the ball rolls at 10 rad/s.
/// let s: WipState<f64> = WipState::new(0.05, 0.0, 0.0, 10.0);
/// assert_eq!((s[TILT], s[BALL_RATE]), (0.05, 10.0));
/// ```
pub type WipState<T> = Vector4<T>;

/// Reduced WIP state `[theta (rad), theta_dot (rad/s), phi_dot (rad/s)]`: the paper does not
/// feed back the ball angle `phi`, so controllers are designed on this state.
///
/// ```
/// use ballbot_core::WipReducedState;
/// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
/// use ballbot_core::{Wip, WipParams};
/// // The LQR acts on [theta, theta_dot, phi_dot]: the ball angle is not fed back.
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
/// let measured: WipReducedState<f64> = WipReducedState::new(0.0, 0.0, 1.0);
/// // Ball rolling forward at 1 rad/s, reference at rest: k3 = -3.162 asks for 3.162 N m.
/// approx::assert_relative_eq!(
///     lqr.control(&WipReducedState::zeros(), &measured),
///     3.162,
///     epsilon = 1e-3
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub type WipReducedState<T> = Vector3<T>;

/// Index of `theta` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::TILT;
/// assert_eq!(nalgebra::Vector4::new(0.1, 2.0, 0.0, 0.0)[TILT], 0.1);
/// ```
pub const TILT: usize = 0;
/// Index of `phi` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::BALL_ANGLE;
/// assert_eq!(nalgebra::Vector4::new(0.1, 2.0, 0.0, 0.0)[BALL_ANGLE], 2.0);
/// ```
pub const BALL_ANGLE: usize = 1;
/// Index of `theta_dot` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::TILT_RATE;
/// assert_eq!(nalgebra::Vector4::new(0.0, 0.0, 0.3, 9.0)[TILT_RATE], 0.3);
/// ```
pub const TILT_RATE: usize = 2;
/// Index of `phi_dot` in [`WipState`].
///
/// ```
/// use ballbot_core::wip::BALL_RATE;
/// assert_eq!(nalgebra::Vector4::new(0.0, 0.0, 0.3, 9.0)[BALL_RATE], 9.0);
/// ```
pub const BALL_RATE: usize = 3;

/// A validated WIP model with its constant inertia terms precomputed.
///
/// ```
/// use ballbot_core::{Wip, WipParams, rk4_step};
/// use nalgebra::Vector4;
/// // Without control the upright is unstable: a 1 mrad lean grows about e-fold every
/// // 1 / 8.04 s, so it is 20 times larger after 0.37 s.
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut s = Vector4::new(1e-3, 0.0, 0.0, 0.0);
/// for _ in 0..370 {
///     s = rk4_step(|x| wip.derivative(x, 0.0), &s, 1e-3);
/// }
/// approx::assert_relative_eq!(s[0], 1e-3 * (8.04f64 * 0.37).cosh(), max_relative = 0.01);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wip<T> {
    params: WipParams<T>,
    /// `a = I_U + m_U l^2 + I_W`.
    a: T,
    /// `b = I_S + (m_S + m_U) r^2 + I_W`.
    b: T,
    /// `m_U r l`.
    mrl: T,
    /// `m_U g l`.
    mgl: T,
}

impl<T: RealField + Copy> Wip<T> {
    /// Validates `params` and precomputes the model's constants.
    ///
    /// ```
    /// use ballbot_core::{Error, Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f32>::miapure_60kg())?;
    /// assert_eq!(wip.params().com_height_m, 0.5);
    /// // Invalid parameters are rejected once, here, naming the field.
    /// let bad = WipParams {
    ///     com_height_m: 0.0,
    ///     ..WipParams::<f32>::miapure_60kg()
    /// };
    /// assert_eq!(
    ///     Wip::new(bad),
    ///     Err(Error::invalid("com_height_m", "must be finite and > 0"))
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: WipParams<T>) -> Result<Self, Error> {
        params.validate()?;
        let p = &params;
        let r = p.ball_radius_m;
        let l = p.com_height_m;
        let a = p.body_inertia_kg_m2 + p.body_mass_kg * l * l + p.wheel_inertia_kg_m2;
        let b = p.ball_inertia_kg_m2
            + (p.ball_mass_kg + p.body_mass_kg) * r * r
            + p.wheel_inertia_kg_m2;
        let mrl = p.body_mass_kg * r * l;
        let mgl = p.body_mass_kg * p.gravity_m_per_s2 * l;
        // M is positive definite at every tilt for any valid parameters: with a0 = I_U + m_U l^2
        // and b0 = I_S + (m_S + m_U) r^2, a0 b0 > (m_U r l)^2 and a0 + b0 > 2 m_U r l, so
        // Delta = a0 b0 - (m_U r l cos)^2 + I_W (a0 + b0 - 2 m_U r l cos) > 0 (tested).
        Ok(Self {
            params,
            a,
            b,
            mrl,
            mgl,
        })
    }

    /// The parameters this model was built from.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// assert_eq!(*wip.params(), WipParams::piptb());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &WipParams<T> {
        &self.params
    }
}
