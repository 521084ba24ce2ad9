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

use super::terms::impl_terms;
use super::{StepStatus, check_gain, check_limit, saturate, state_is_finite};
use crate::lqr::{WipLqr, WipLqrWeights, wip_lqr, wip_lqr_discrete};
use crate::{Error, Wip, WipState};
use nalgebra::{RealField, Vector3, Vector4};

/// Gains and torque limit of [`LqrController`], in the paper's form `tau = k (s_c - s)`.
///
/// A balancing gain has negative entries (MODEL.md section 6: MiaPURE with 60 kg, `Q =
/// diag(100, 10, 1)`, `R = 0.1` gives `[-234.8, -45.70, -3.162]`).
///
/// ```
/// use ballbot_core::control::LqrGains;
/// // MODEL.md section 6's gains for MiaPURE with 60 kg, written out, 83.9 N m planar limit.
/// let g = LqrGains { tilt_nm_per_rad: -234.8, tilt_rate_nm_s_per_rad: -45.70,
///                    ball_rate_nm_s_per_rad: -3.162, max_torque_nm: 83.9 };
/// g.validate()?;
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct LqrGains<T> {
    /// `k1`, on the tilt error `theta_c - theta` (N m/rad).
    pub tilt_nm_per_rad: T,
    /// `k2`, on the tilt-rate error `theta_dot_c - theta_dot` (N m s/rad).
    pub tilt_rate_nm_s_per_rad: T,
    /// `k3`, on the ball-rate error `phi_dot_c - phi_dot` (N m s/rad).
    pub ball_rate_nm_s_per_rad: T,
    /// Torque saturation, symmetric (N m, > 0). For a ballbot plane, the planar torque
    /// capacity (83.9 N m in x for MiaPURE); for the PIPTB, the actuator peak (43.2 N m).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_torque_nm: T,
}

impl<T: RealField + Copy> LqrGains<T> {
    /// Gains from the reduced-state vector `[k1, k2, k3]` on `[theta, theta_dot, phi_dot]`.
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// let g = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// assert_eq!((g.tilt_nm_per_rad, g.ball_rate_nm_s_per_rad), (-234.8, -3.162));
    /// ```
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
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// use ballbot_core::lqr::WipLqrWeights;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let weights = WipLqrWeights::model_default();
    /// let discrete = LqrGains::design_discrete(&wip, &weights, 1.0 / 400.0, 83.9)?;
    /// let continuous = LqrGains::design(&wip, &weights, 83.9)?;
    /// // At 400 Hz the sampled design is within a few percent of the continuous one.
    /// let gap = (discrete.reduced() - continuous.reduced()).norm();
    /// assert!(gap < 0.05 * continuous.reduced().norm());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
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
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let g = LqrGains::for_wip(&wip, 83.9)?;
    /// approx::assert_relative_eq!(g.tilt_rate_nm_s_per_rad, -45.70, max_relative = 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn for_wip(wip: &Wip<T>, max_torque_nm: T) -> Result<Self, Error> {
        Self::design(wip, &WipLqrWeights::model_default(), max_torque_nm)
    }

    /// The gains of a finished design, with the torque limit `max_torque_nm`; validated.
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
    /// use ballbot_core::{Error, Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
    /// let g = LqrGains::from_lqr(&lqr, 83.9)?;
    /// assert_eq!(g.reduced().as_slice(), &lqr.reduced_gains()[..]);
    /// // A torque limit that is not positive is rejected, naming the field.
    /// assert!(matches!(
    ///     LqrGains::from_lqr(&lqr, 0.0),
    ///     Err(Error::InvalidParameter { field: "max_torque_nm", .. })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn from_lqr(lqr: &WipLqr<T>, max_torque_nm: T) -> Result<Self, Error> {
        let gains = Self::from_reduced(lqr.reduced_gains(), max_torque_nm);
        gains.validate()?;
        Ok(gains)
    }

    /// The reduced-state gain `[k1, k2, k3]`.
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// let g = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// assert_eq!(g.reduced(), nalgebra::Vector3::new(-234.8, -45.70, -3.162));
    /// ```
    pub fn reduced(&self) -> Vector3<T> {
        Vector3::new(
            self.tilt_nm_per_rad,
            self.tilt_rate_nm_s_per_rad,
            self.ball_rate_nm_s_per_rad,
        )
    }

    /// The paper's full-state gain `[k1, 0, k2, k3]` on `[theta, phi, theta_dot, phi_dot]`.
    ///
    /// ```
    /// use ballbot_core::control::LqrGains;
    /// let g = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// // The ball angle phi is not fed back: its entry is 0.
    /// assert_eq!(g.full(), nalgebra::Vector4::new(-234.8, 0.0, -45.70, -3.162));
    /// ```
    pub fn full(&self) -> Vector4<T> {
        Vector4::new(
            self.tilt_nm_per_rad,
            T::zero(),
            self.tilt_rate_nm_s_per_rad,
            self.ball_rate_nm_s_per_rad,
        )
    }

    /// Checks every field; the error names the first one out of range.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::control::LqrGains;
    /// let mut g = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// assert!(g.validate().is_ok());
    /// g.tilt_rate_nm_s_per_rad = f64::NAN;
    /// assert!(matches!(
    ///     g.validate(),
    ///     Err(Error::InvalidParameter { field: "tilt_rate_nm_s_per_rad", .. })
    /// ));
    /// ```
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
///
/// ```
/// use ballbot_core::control::{LqrController, LqrGains, StepStatus};
/// use nalgebra::Vector4;
/// let mut lqr = LqrController::new(LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9))?;
/// // Leaning 0.5 rad forward asks for 117.4 N m: clipped to the limit, the excess reported.
/// let out = lqr.step(&Vector4::new(0.5, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
/// assert_eq!((out.torque_nm, out.status), (83.9, StepStatus::Saturated));
/// let requested = out.tilt_term_nm + out.tilt_rate_term_nm + out.ball_rate_term_nm;
/// approx::assert_relative_eq!(out.torque_nm - requested, out.saturation_nm, epsilon = 1e-12);
/// assert!(out.saturation_nm < -30.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
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

impl_terms!(LqrOutput {
    torque_nm,
    tilt_term_nm,
    tilt_rate_term_nm,
    ball_rate_term_nm,
    saturation_nm,
});

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
    ///
    /// ```
    /// use ballbot_core::control::{LqrController, LqrGains};
    /// let gains = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// assert!(LqrController::new(gains).is_ok());
    /// // Gains are validated once, here: a NaN gain is refused.
    /// let nan_tilt = LqrGains { tilt_nm_per_rad: f64::NAN, ..gains };
    /// assert!(LqrController::new(nan_tilt).is_err());
    /// ```
    pub fn new(gains: LqrGains<T>) -> Result<Self, Error> {
        gains.validate()?;
        Ok(Self { gains })
    }

    /// The gains in use.
    ///
    /// ```
    /// use ballbot_core::control::{LqrController, LqrGains};
    /// let lqr = LqrController::new(LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9))?;
    /// assert_eq!(lqr.gains().max_torque_nm, 83.9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn gains(&self) -> &LqrGains<T> {
        &self.gains
    }

    /// Nothing to clear (the LQR has no state); present for the common controller shape.
    ///
    /// ```
    /// use ballbot_core::control::{LqrController, LqrGains};
    /// use nalgebra::Vector4;
    /// let mut lqr = LqrController::new(LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9))?;
    /// let s = Vector4::new(0.1, 0.0, 0.0, 0.0);
    /// let before = lqr.step(&s, &Vector4::zeros(), 0.0025);
    /// lqr.reset();
    /// // Static law: the same input gives the same torque after a reset.
    /// assert_eq!(lqr.step(&s, &Vector4::zeros(), 0.0025), before);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
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
