//! The paper's LQR torque controller (Fig. "controller" a):
//!
//! ```text
//! tau = k (s_c - s),   k = [k1, 0, k2, k3]
//!     = k1 (theta_c - theta) + k2 (theta_dot_c - theta_dot) + k3 (phi_dot_c - phi_dot)
//! ```
//!
//! saturated to `[-max_torque_nm, max_torque_nm]`. The ball angle `phi` is not fed back (the
//! paper controls speed, not position). The controller is static: it has no state and ignores
//! the step length.

use super::{StepStatus, check_gain, check_limit, saturate, state_is_finite};
use crate::lqr::{WipLqr, WipLqrWeights, wip_lqr, wip_lqr_discrete};
use crate::{Error, Wip, WipState};
use nalgebra::{RealField, Vector3, Vector4};

/// Gains and torque limit of [`LqrController`], in the paper's form `tau = k (s_c - s)`.
///
/// A balancing gain has negative entries (MODEL.md section 6: MiaPURE with 60 kg, `Q =
/// diag(100, 10, 1)`, `R = 0.1` gives `[-234.8, -45.70, -3.162]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrGains<T> {
    /// `k1`, on the tilt error `theta_c - theta` (N m/rad).
    pub tilt_nm_per_rad: T,
    /// `k2`, on the tilt-rate error `theta_dot_c - theta_dot` (N m s/rad).
    pub tilt_rate_nm_s_per_rad: T,
    /// `k3`, on the ball-rate error `phi_dot_c - phi_dot` (N m s/rad).
    pub ball_rate_nm_s_per_rad: T,
    /// Torque saturation, symmetric (N m, > 0). For a ballbot plane, the planar torque
    /// capacity (83.9 N m in x for MiaPURE); for the PIPTB, the actuator peak (43.2 N m).
    pub max_torque_nm: T,
}

impl<T: RealField + Copy> LqrGains<T> {
    /// Gains from the reduced-state vector `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]`.
    pub fn from_reduced(k: [T; 3], max_torque_nm: T) -> Self {
        Self {
            tilt_nm_per_rad: k[0],
            tilt_rate_nm_s_per_rad: k[1],
            ball_rate_nm_s_per_rad: k[2],
            max_torque_nm,
        }
    }

    /// Gains designed by the continuous LQR ([`crate::lqr::wip_lqr`]) on `wip`'s upright
    /// linearisation with `weights` on `[theta, theta_dot, phi_dot]` and the torque.
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// use ballbot_core::lqr::WipLqrWeights;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let g = LqrGains::design(&wip, &WipLqrWeights::model_default(), 83.9)?;
    /// // MODEL.md section 6: k = [-234.8, -45.70, -3.162].
    /// approx::assert_relative_eq!(g.tilt_nm_per_rad, -234.8, max_relative = 1e-3);
    /// approx::assert_relative_eq!(g.ball_rate_nm_s_per_rad, -3.162, max_relative = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    ///
    /// Errors: the synthesis' errors (weights naming `q` or `r`, no stabilising gain), and
    /// `max_torque_nm` when not finite and positive.
    pub fn design(
        wip: &Wip<T>,
        weights: &WipLqrWeights<T>,
        max_torque_nm: T,
    ) -> Result<Self, Error> {
        Self::from_lqr(&wip_lqr(wip, weights)?, max_torque_nm)
    }

    /// Gains designed by the discrete LQR at the controller's period `dt_secs`
    /// ([`crate::lqr::wip_lqr_discrete`], zero-order hold): the better choice when the loop
    /// is slow relative to the closed-loop poles.
    pub fn design_discrete(
        wip: &Wip<T>,
        weights: &WipLqrWeights<T>,
        dt_secs: T,
        max_torque_nm: T,
    ) -> Result<Self, Error> {
        Self::from_lqr(&wip_lqr_discrete(wip, weights, dt_secs)?, max_torque_nm)
    }

    /// The documented default for `wip`: [`Self::design`] with MODEL.md's weights
    /// [`WipLqrWeights::model_default`] (`Q = diag(100, 10, 1)`, `R = 0.1`).
    pub fn for_wip(wip: &Wip<T>, max_torque_nm: T) -> Result<Self, Error> {
        Self::design(wip, &WipLqrWeights::model_default(), max_torque_nm)
    }

    /// The gains of a finished design, with the torque limit `max_torque_nm`; validated.
    pub fn from_lqr(lqr: &WipLqr<T>, max_torque_nm: T) -> Result<Self, Error> {
        let gains = Self::from_reduced(lqr.reduced_gains(), max_torque_nm);
        gains.validate()?;
        Ok(gains)
    }

    /// The reduced-state gain `[k1, k2, k3]`.
    pub fn reduced(&self) -> Vector3<T> {
        Vector3::new(
            self.tilt_nm_per_rad,
            self.tilt_rate_nm_s_per_rad,
            self.ball_rate_nm_s_per_rad,
        )
    }

    /// The paper's full-state gain `[k1, 0, k2, k3]` on `[theta, phi, theta_dot, phi_dot]`.
    pub fn full(&self) -> Vector4<T> {
        Vector4::new(
            self.tilt_nm_per_rad,
            T::zero(),
            self.tilt_rate_nm_s_per_rad,
            self.ball_rate_nm_s_per_rad,
        )
    }

    /// Checks every field; the error names the first one out of range.
    pub fn validate(&self) -> Result<(), Error> {
        check_gain(self.tilt_nm_per_rad, "tilt_nm_per_rad")?;
        check_gain(self.tilt_rate_nm_s_per_rad, "tilt_rate_nm_s_per_rad")?;
        check_gain(self.ball_rate_nm_s_per_rad, "ball_rate_nm_s_per_rad")?;
        check_limit(self.max_torque_nm, "max_torque_nm")
    }

    /// The three feedback terms `[k1 e_theta, k2 e_theta_dot, k3 e_phi_dot]` (N m), unsaturated.
    #[inline]
    pub(crate) fn terms(&self, measured: &WipState<T>, command: &WipState<T>) -> [T; 3] {
        use crate::wip::{BALL_RATE, TILT, TILT_RATE};
        [
            self.tilt_nm_per_rad * (command[TILT] - measured[TILT]),
            self.tilt_rate_nm_s_per_rad * (command[TILT_RATE] - measured[TILT_RATE]),
            self.ball_rate_nm_s_per_rad * (command[BALL_RATE] - measured[BALL_RATE]),
        ]
    }
}

/// One LQR step's result, with each term for logging.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrOutput<T> {
    /// The torque to apply, after saturation (N m). Always finite.
    pub torque_nm: T,
    /// `k1 (theta_c - theta)` (N m).
    pub tilt_term_nm: T,
    /// `k2 (theta_dot_c - theta_dot)` (N m).
    pub tilt_rate_term_nm: T,
    /// `k3 (phi_dot_c - phi_dot)` (N m).
    pub ball_rate_term_nm: T,
    /// Applied minus requested torque (N m): zero unless saturated.
    pub saturation_nm: T,
    /// Whether the step was nominal, saturated or rejected.
    pub status: StepStatus,
}

impl<T: RealField + Copy> LqrOutput<T> {
    fn rejected() -> Self {
        let z = T::zero();
        Self {
            torque_nm: z,
            tilt_term_nm: z,
            tilt_rate_term_nm: z,
            ball_rate_term_nm: z,
            saturation_nm: z,
            status: StepStatus::InvalidInput,
        }
    }
}

/// The paper's LQR torque controller, `tau = k (s_c - s)`, saturated.
///
/// ```
/// use ballbot_core::control::{LqrController, LqrGains, StepStatus};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// // MiaPURE with 60 kg, MODEL.md's weights Q = diag(100, 10, 1), R = 0.1, 83.9 N m limit.
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut lqr = LqrController::new(LqrGains::for_wip(&wip, 83.9)?)?;
/// // Leaning forward 0.1 rad: push the ball forward, under the body (k1 = -234.8).
/// let out = lqr.step(&Vector4::new(0.1, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
/// approx::assert_relative_eq!(out.torque_nm, 23.48, max_relative = 1e-3);
/// assert_eq!(out.status, StepStatus::Nominal);
/// // A NaN measurement gives zero torque, flagged.
/// let out = lqr.step(&Vector4::new(f64::NAN, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
/// assert_eq!((out.torque_nm, out.status), (0.0, StepStatus::InvalidInput));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrController<T> {
    gains: LqrGains<T>,
}

impl<T: RealField + Copy> LqrController<T> {
    /// Validates `gains`.
    pub fn new(gains: LqrGains<T>) -> Result<Self, Error> {
        gains.validate()?;
        Ok(Self { gains })
    }

    /// The gains in use.
    pub fn gains(&self) -> &LqrGains<T> {
        &self.gains
    }

    /// Nothing to clear (the LQR has no state); present for the common controller shape.
    pub fn reset(&mut self) {}

    /// `tau = k (s_c - s)`, saturated. `measured` and `command` are full WIP states
    /// `[theta, phi, theta_dot, phi_dot]`; `phi` is ignored in both. `_dt_secs` is not used (the
    /// law is static).
    ///
    /// ```
    /// use ballbot_core::control::{LqrController, LqrGains};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let mut lqr = LqrController::new(LqrGains::for_wip(&wip, 83.9)?)?;
    /// // Leaning forward 0.1 rad at rest: the ball is driven forward, under the body (tau > 0).
    /// let out = lqr.step(&Vector4::new(0.1, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
    /// approx::assert_relative_eq!(out.torque_nm, 23.48, epsilon = 0.01);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        measured: &WipState<T>,
        command: &WipState<T>,
        _dt_secs: T,
    ) -> LqrOutput<T> {
        if !(state_is_finite(measured) && state_is_finite(command)) {
            return LqrOutput::rejected();
        }
        let [tilt, tilt_rate, ball_rate] = self.gains.terms(measured, command);
        let requested = tilt + tilt_rate + ball_rate;
        if !requested.is_finite() {
            return LqrOutput::rejected();
        }
        let (torque_nm, status) = saturate(requested, self.gains.max_torque_nm);
        LqrOutput {
            torque_nm,
            tilt_term_nm: tilt,
            tilt_rate_term_nm: tilt_rate,
            ball_rate_term_nm: ball_rate,
            saturation_nm: torque_nm - requested,
            status,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::Error;

    fn gains() -> LqrGains<f64> {
        let wip = Wip::new(crate::WipParams::miapure_60kg()).unwrap();
        LqrGains::for_wip(&wip, 83.9).unwrap()
    }

    #[test]
    fn designed_gains_match_model_md_and_discrete_tends_to_continuous() {
        let g = gains();
        let expected = [-234.8, -45.70, -3.162];
        for (k, e) in g.reduced().iter().zip(expected) {
            approx::assert_relative_eq!(*k, e, max_relative = 1e-3);
        }
        let wip = Wip::new(crate::WipParams::miapure_60kg()).unwrap();
        let weights = WipLqrWeights::model_default();
        let d = LqrGains::design_discrete(&wip, &weights, 1.0 / 400.0, 83.9).unwrap();
        // At 400 Hz the sampled design differs from the continuous one by O(dt).
        assert!((d.reduced() - g.reduced()).norm() < 0.05 * g.reduced().norm());
        assert!(matches!(
            LqrGains::design(&wip, &weights, -1.0),
            Err(Error::InvalidParameter {
                field: "max_torque_nm",
                ..
            })
        ));
    }

    #[test]
    fn validation_names_the_field() {
        let mut g = gains();
        g.ball_rate_nm_s_per_rad = f64::NAN;
        assert_eq!(
            g.validate(),
            Err(Error::invalid("ball_rate_nm_s_per_rad", "must be finite"))
        );
        let mut g = gains();
        g.max_torque_nm = 0.0;
        assert!(matches!(
            LqrController::new(g),
            Err(Error::InvalidParameter {
                field: "max_torque_nm",
                ..
            })
        ));
    }

    #[test]
    fn law_matches_paper_form_and_ignores_ball_angle() {
        let mut c = LqrController::new(gains()).unwrap();
        let s = Vector4::new(0.05, 123.0, -0.2, 1.0);
        let sc = Vector4::new(0.01, -7.0, 0.1, 3.0);
        let out = c.step(&s, &sc, 0.0025);
        let expected = gains().full().dot(&(sc - s)) + 0.0 * (sc[1] - s[1]);
        // phi enters with gain 0.
        approx::assert_relative_eq!(out.torque_nm, expected, epsilon = 1e-12);
        approx::assert_relative_eq!(
            out.tilt_term_nm + out.tilt_rate_term_nm + out.ball_rate_term_nm,
            expected,
            epsilon = 1e-12
        );
        assert_eq!(out.saturation_nm, 0.0);
    }

    #[test]
    fn saturation_is_reported_with_its_size() {
        let mut c = LqrController::new(gains()).unwrap();
        let out = c.step(&Vector4::new(1.0, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
        assert_eq!(out.torque_nm, 83.9);
        assert_eq!(out.status, StepStatus::Saturated);
        let requested = -gains().tilt_nm_per_rad;
        approx::assert_relative_eq!(out.saturation_nm, 83.9 - requested, epsilon = 1e-9);
    }

    #[test]
    fn overflowing_arithmetic_is_rejected() {
        let mut c = LqrController::new(gains()).unwrap();
        // Finite inputs whose terms overflow to +inf and -inf: their sum is NaN.
        let s = Vector4::new(-1e308, 0.0, 1e308, 0.0);
        let out = c.step(&s, &Vector4::zeros(), 0.0025);
        assert_eq!(out.status, StepStatus::InvalidInput);
        assert_eq!(out.torque_nm, 0.0);
    }
}
