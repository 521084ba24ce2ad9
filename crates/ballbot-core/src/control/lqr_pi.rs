//! The outer part of the paper's cascaded LQR-PI controller (Sec. IV-A, Fig. "controller" c),
//! the part that runs on the main controller (400 Hz on MiaPURE and the PIPTB):
//!
//! ```text
//! tau_r       = sat(k (s_c - s))                          LQR reference torque
//! phi_ddot_r  = f_d(s, tau_r)[phi]                        nonlinear reference WIP model,
//!                                                         at the MEASURED state s
//! phi_dot_r  <- phi_dot_r + dt phi_ddot_r                 integrated over the outer period
//! ```
//!
//! It sends `(tau_r, phi_dot_r)` to the inner speed PI ([`super::SpeedPi`], on the motor driver),
//! which adds `tau_e = kp (phi_dot_r - phi_dot) + ki int (phi_dot_r - phi_dot)`.
//!
//! Why it rejects friction: with the reference model equal to the plant, the speed error
//! `e = phi_dot_r - phi_dot` obeys `e_dot = -B4(theta) (tau_e - tau_d)` for any drive torque
//! disturbance `tau_d` (stiction, Coulomb friction): the inner PI drives `tau_e` to `tau_d`
//! and the plant then moves as the nominal model under the LQR. Without disturbance `tau_e`
//! stays 0 and the loop is exactly the LQR.
//!
//! **Anchoring the reference integrator.** The paper integrates `phi_ddot_r`. We do too, with
//! two rules that keep the integral from drifting away from the measured speed:
//!
//! 1. after [`LqrPiOuter::reset`] (and at the first step) the integral starts at the measured
//!    ball rate, so the inner loop starts with zero error;
//! 2. at every step, before integrating, the stored reference is clamped into
//!    `[phi_dot - max_speed_error, phi_dot + max_speed_error]` around the measured ball rate
//!    ([`LqrPiOuterConfig::max_speed_error_rad_per_s`]). In normal operation the error is far
//!    smaller and the clamp is inactive (the output's `anchor_correction_rad_per_s` is 0); when
//!    the actuator saturates for long, the reference would otherwise run away from the plant
//!    and the inner PI would later drive the ball to catch up (a large overshoot). A good
//!    band is the error at which the inner P term alone reaches the torque limit,
//!    `max_torque / kp` ([`LqrPiOuterConfig::new`]): beyond it the inner loop is saturated anyway.
//!
//! **Which speed the inner loop tracks.** As in the paper's equations, the planar inner loop
//! tracks the ball rate `phi_dot` (absolute), for which the decoupling above is exact. A motor
//! encoder measures the wheel relative to the body, `phi_dot - theta_dot` (times the kinematic
//! ratio): a driver-side loop on that speed is given `phi_dot_r - theta_dot` with the tilt rate
//! measured at the outer rate, and its plant gain is the relative one, `B4 - B3`, not `B4`.
//!
//! **Timing.** The integral is advanced over the outer period; the reference sent to the inner
//! loop is the mean over the coming period, `phi_dot_r + dt phi_ddot_r / 2`, so that a
//! steady acceleration leaves no mean tracking error in the inner loop (which holds the
//! reference between outer updates).

use super::terms::impl_terms;
use super::{LqrGains, SpeedPiGains, StepStatus, dt_is_valid, saturate};
use crate::check::positive;
use crate::num::{max, min};
use crate::wip::{BALL_ANGLE, BALL_RATE, TILT};
use crate::{Error, Wip, WipState};
use nalgebra::RealField;

/// Configuration of [`LqrPiOuter`]: the LQR gains and the reference integrator's anchor band.
///
/// ```
/// use ballbot_core::control::{LqrGains, LqrPiOuterConfig};
/// use ballbot_core::{Wip, WipParams};
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let config = LqrPiOuterConfig {
///     lqr: LqrGains::for_wip(&wip, 83.9)?,
///     max_speed_error_rad_per_s: 3.0,
/// };
/// config.validate()?;
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct LqrPiOuterConfig<T> {
    /// The LQR gains; their `max_torque_nm` saturates the reference torque `tau_r`.
    pub lqr: LqrGains<T>,
    /// Largest allowed distance between the integrated reference ball rate and the measured
    /// ball rate (rad/s, > 0); see the module docs ("anchoring").
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_speed_error_rad_per_s: T,
}

impl<T: RealField + Copy> LqrPiOuterConfig<T> {
    /// The configuration with the anchor band `max_torque_nm / kp` of the inner PI `inner`:
    /// the speed error at which the inner P term alone saturates the actuator. With `kp = 0`
    /// the band falls back to `100 rad/s`, a value that never binds in practice.
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuterConfig, SpeedPiGains};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let inner = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 43.2)?;
    /// let config = LqrPiOuterConfig::new(LqrGains::for_wip(&wip, 83.9)?, &inner)?;
    /// // The band is the speed error at which the inner P term alone reaches 43.2 N m.
    /// let band = config.max_speed_error_rad_per_s;
    /// approx::assert_relative_eq!(band * inner.proportional_nm_s_per_rad, 43.2, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(lqr: LqrGains<T>, inner: &SpeedPiGains<T>) -> Result<Self, Error> {
        let kp = inner.proportional_nm_s_per_rad;
        let band = if kp > T::zero() {
            inner.max_torque_nm / kp
        } else {
            nalgebra::convert(100.0)
        };
        let config = Self {
            lqr,
            max_speed_error_rad_per_s: band,
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks every field; the error names the first one out of range.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::control::{LqrGains, LqrPiOuterConfig};
    /// let lqr = LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9);
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// assert!(config.validate().is_ok());
    /// let zero_band = LqrPiOuterConfig { max_speed_error_rad_per_s: 0.0, ..config };
    /// assert!(matches!(
    ///     zero_band.validate(),
    ///     Err(Error::InvalidParameter { field: "max_speed_error_rad_per_s", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.lqr.validate()?;
        positive(self.max_speed_error_rad_per_s, "max_speed_error_rad_per_s")
    }
}

/// One outer LQR-PI step's result: what goes to the motor driver, and every term for logging.
///
/// ```
/// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig, StepStatus};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let lqr = LqrGains::for_wip(&wip, 83.9)?;
/// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
/// let mut outer = LqrPiOuter::new(wip, config)?;
/// let o = outer.step(&Vector4::new(0.02, 0.0, 0.0, 1.0), &Vector4::zeros(), 1.0 / 400.0);
/// // The reference torque is the sum of the LQR terms (not saturated here).
/// let sum = o.tilt_term_nm + o.tilt_rate_term_nm + o.ball_rate_term_nm;
/// approx::assert_relative_eq!(o.reference_torque_nm, sum, epsilon = 1e-12);
/// assert_eq!((o.saturation_nm, o.anchor_correction_rad_per_s), (0.0, 0.0));
/// assert_eq!(o.status, StepStatus::Nominal);
/// // The rate sent to the inner loop is the mean over the coming period.
/// approx::assert_relative_eq!(
///     o.reference_ball_rate_rad_per_s,
///     1.0 + 0.5 / 400.0 * o.reference_ball_accel_rad_per_s2,
///     epsilon = 1e-12
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrPiOuterOutput<T> {
    /// Reference (feedforward) torque `tau_r` for the inner loop, after saturation (N m).
    pub reference_torque_nm: T,
    /// Reference ball rate `phi_dot_r` for the inner loop over the coming period (rad/s).
    pub reference_ball_rate_rad_per_s: T,
    /// Reference ball acceleration `phi_ddot_r` of the reference model (rad/s^2).
    pub reference_ball_accel_rad_per_s2: T,
    /// The reference model's tilt acceleration `theta_ddot_r` under the reference torque
    /// (rad/s^2): with the ball's, what the 3D controller's slip monitor predicts the
    /// contacts from.
    pub reference_tilt_accel_rad_per_s2: T,
    /// LQR term `k1 (theta_c - theta)` (N m).
    pub tilt_term_nm: T,
    /// LQR term `k2 (theta_dot_c - theta_dot)` (N m).
    pub tilt_rate_term_nm: T,
    /// LQR term `k3 (phi_dot_c - phi_dot)` (N m).
    pub ball_rate_term_nm: T,
    /// Applied minus requested reference torque (N m): zero unless saturated.
    pub saturation_nm: T,
    /// How far the anchor band moved the stored reference this step (rad/s); 0 in normal
    /// operation.
    pub anchor_correction_rad_per_s: T,
    /// Whether the step was nominal, saturated (reference torque) or rejected.
    pub status: StepStatus,
}

impl_terms!(LqrPiOuterOutput {
    reference_torque_nm,
    reference_ball_rate_rad_per_s,
    reference_ball_accel_rad_per_s2,
    reference_tilt_accel_rad_per_s2,
    tilt_term_nm,
    tilt_rate_term_nm,
    ball_rate_term_nm,
    saturation_nm,
    anchor_correction_rad_per_s,
});

/// The outer part of the cascaded LQR-PI controller (see the module docs).
///
/// ```
/// use ballbot_core::control::{
///     LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains,
/// };
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let inner_gains = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9)?;
/// // MODEL.md's LQR weights, 83.9 N m planar torque limit.
/// let lqr = LqrGains::for_wip(&wip, 83.9)?;
/// let mut outer = LqrPiOuter::new(wip, LqrPiOuterConfig::new(lqr, &inner_gains)?)?;
/// let mut inner = SpeedPi::new(inner_gains)?;
/// let s = Vector4::new(0.05, 0.0, 0.0, 0.0);
/// let o = outer.step(&s, &Vector4::zeros(), 1.0 / 400.0);
/// // Forward lean: positive reference torque, the reference model accelerates the ball.
/// assert!(o.reference_torque_nm > 0.0 && o.reference_ball_accel_rad_per_s2 > 0.0);
/// let cmd = SpeedCommand {
///     speed_rad_per_s: o.reference_ball_rate_rad_per_s,
///     feedforward_torque_nm: o.reference_torque_nm,
/// };
/// let tau = inner.step(s[3], &cmd, 1.0 / 8000.0).torque_nm;
/// assert!(tau >= o.reference_torque_nm);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LqrPiOuter<T> {
    model: Wip<T>,
    config: LqrPiOuterConfig<T>,
    /// The integrated reference ball rate at the start of the next period (rad/s); `None`
    /// until the first valid step after construction or reset.
    reference_ball_rate_rad_per_s: Option<T>,
}

impl<T: RealField + Copy> LqrPiOuter<T> {
    /// Validates `config`; `model` is the reference WIP model (usually the nominal plant).
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = LqrGains::for_wip(&wip, 83.9)?;
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// let outer = LqrPiOuter::new(wip, config)?;
    /// assert_eq!(outer.reference_ball_rate_rad_per_s(), None);
    /// // The configuration is validated: a NaN band is refused.
    /// let bad = LqrPiOuterConfig { max_speed_error_rad_per_s: f64::NAN, ..config };
    /// assert!(LqrPiOuter::new(wip, bad).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(model: Wip<T>, config: LqrPiOuterConfig<T>) -> Result<Self, Error> {
        config.validate()?;
        Ok(Self {
            model,
            config,
            reference_ball_rate_rad_per_s: None,
        })
    }

    /// The configuration in use.
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = LqrGains::for_wip(&wip, 83.9)?;
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// assert_eq!(LqrPiOuter::new(wip, config)?.config(), &config);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn config(&self) -> &LqrPiOuterConfig<T> {
        &self.config
    }

    /// The reference model.
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = LqrGains::for_wip(&wip, 83.9)?;
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// let outer = LqrPiOuter::new(wip, config)?;
    /// assert_eq!(outer.model().params().body_mass_kg, wip.params().body_mass_kg);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn model(&self) -> &Wip<T> {
        &self.model
    }

    /// The stored reference ball rate (rad/s), `None` before the first valid step.
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = LqrGains::for_wip(&wip, 83.9)?;
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// let mut outer = LqrPiOuter::new(wip, config)?;
    /// assert_eq!(outer.reference_ball_rate_rad_per_s(), None);
    /// // Upright at 2 rad/s on command: no torque, no acceleration, the integral holds 2 rad/s.
    /// let s = Vector4::new(0.0, 0.0, 0.0, 2.0);
    /// outer.step(&s, &s, 1.0 / 400.0);
    /// assert_eq!(outer.reference_ball_rate_rad_per_s(), Some(2.0));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reference_ball_rate_rad_per_s(&self) -> Option<T> {
        self.reference_ball_rate_rad_per_s
    }

    /// Forgets the reference integral: the next step re-anchors it at the measured ball rate.
    ///
    /// ```
    /// use ballbot_core::control::{LqrGains, LqrPiOuter, LqrPiOuterConfig};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let lqr = LqrGains::for_wip(&wip, 83.9)?;
    /// let config = LqrPiOuterConfig { lqr, max_speed_error_rad_per_s: 3.0 };
    /// let mut outer = LqrPiOuter::new(wip, config)?;
    /// outer.step(&Vector4::new(0.0, 0.0, 0.0, 2.0), &Vector4::zeros(), 1.0 / 400.0);
    /// outer.reset();
    /// assert_eq!(outer.reference_ball_rate_rad_per_s(), None);
    /// // The next step re-anchors at the measured 7 rad/s.
    /// let s = Vector4::new(0.0, 0.0, 0.0, 7.0);
    /// assert_eq!(outer.step(&s, &s, 1.0 / 400.0).reference_ball_rate_rad_per_s, 7.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.reference_ball_rate_rad_per_s = None;
    }

    /// One outer step. `measured` and `command` are full WIP states `[theta, phi, theta_dot,
    /// phi_dot]` (`phi` ignored), `dt_secs` the outer period (s).
    ///
    /// A non-finite input or `dt_secs <= 0` gives zero reference torque, the held reference
    /// rate (0 before the first valid step), and [`StepStatus::InvalidInput`]; the integral is
    /// not touched.
    ///
    /// ```
    /// use ballbot_core::control::{
    ///     LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi,
    ///     SpeedPiGains,
    /// };
    /// use ballbot_core::{Wip, WipParams, rk4_step};
    /// use nalgebra::Vector4;
    /// // The PIPTB driving at 5 rad/s with a constant -2 N m friction torque on the drive that
    /// // the model lacks, once under the LQR-PI (outer 400 Hz, inner 8 kHz) and once under the
    /// // plain LQR.
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// let lqr_gains = LqrGains::for_wip(&wip, 43.2)?;
    /// let inner_gains = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 43.2)?;
    /// let mut outer = LqrPiOuter::new(wip, LqrPiOuterConfig::new(lqr_gains, &inner_gains)?)?;
    /// let mut inner = SpeedPi::new(inner_gains)?;
    /// let mut lqr = LqrController::new(lqr_gains)?;
    /// let (friction_nm, dt) = (-2.0, 1.0 / 8000.0);
    /// let command = Vector4::new(0.0, 0.0, 0.0, 5.0);
    /// let (mut s_pi, mut s_lqr) = (Vector4::zeros(), Vector4::zeros());
    /// let mut reference = SpeedCommand { speed_rad_per_s: 0.0, feedforward_torque_nm: 0.0 };
    /// let mut tau_lqr = 0.0;
    /// for k in 0..8 * 8000 {
    ///     if k % 20 == 0 {
    ///         let o = outer.step(&s_pi, &command, 1.0 / 400.0);
    ///         reference = SpeedCommand {
    ///             speed_rad_per_s: o.reference_ball_rate_rad_per_s,
    ///             feedforward_torque_nm: o.reference_torque_nm,
    ///         };
    ///         tau_lqr = lqr.step(&s_lqr, &command, 1.0 / 400.0).torque_nm;
    ///     }
    ///     let tau_pi = inner.step(s_pi[3], &reference, dt).torque_nm;
    ///     s_pi = rk4_step(|x| wip.derivative(x, tau_pi + friction_nm), &s_pi, dt);
    ///     s_lqr = rk4_step(|x| wip.derivative(x, tau_lqr + friction_nm), &s_lqr, dt);
    /// }
    /// // The LQR settles where its speed term cancels the friction: an error of tau_d / k3.
    /// let k3 = lqr_gains.ball_rate_nm_s_per_rad;
    /// approx::assert_relative_eq!(s_lqr[3] - 5.0, friction_nm / k3, epsilon = 1e-6);
    /// assert!((s_lqr[3] - 5.0_f64).abs() > 0.6);
    /// // The LQR-PI's inner integral has learned the friction: no speed error left.
    /// assert!((s_pi[3] - 5.0_f64).abs() < 1e-6);
    /// approx::assert_relative_eq!(inner.integral_nm(), -friction_nm, epsilon = 1e-6);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    // Always inlined: the 3D controller calls it twice per outer step, and inlined its output
    // struct no longer goes through memory (callgrind: one plane 249 -> 171 instructions, the
    // 3D outer step 1565 -> 1519).
    #[inline(always)]
    pub fn step(
        &mut self,
        measured: &WipState<T>,
        command: &WipState<T>,
        dt_secs: T,
    ) -> LqrPiOuterOutput<T> {
        self.step_with(measured, command, dt_secs, None)
    }

    /// [`Self::step`] with `(sin, cos)` of the measured tilt already computed (the 3D
    /// controller needs them for its wheel mapping too): the same result, one `sin_cos` less.
    #[inline(always)]
    pub(crate) fn step_with_tilt_sin_cos(
        &mut self,
        measured: &WipState<T>,
        command: &WipState<T>,
        dt_secs: T,
        tilt_sin_cos: (T, T),
    ) -> LqrPiOuterOutput<T> {
        self.step_with(measured, command, dt_secs, Some(tilt_sin_cos))
    }

    #[inline(always)]
    fn step_with(
        &mut self,
        measured: &WipState<T>,
        command: &WipState<T>,
        dt_secs: T,
        tilt_sin_cos: Option<(T, T)>,
    ) -> LqrPiOuterOutput<T> {
        let [tilt, tilt_rate, ball_rate] = self.config.lqr.terms(measured, command);
        let requested = tilt + tilt_rate + ball_rate;
        // `requested` is finite exactly when the six entries the terms use are (finite gains: a
        // non-finite entry makes its term infinite or NaN, and the sum with it); only the ball
        // angles, which the law ignores, need their own check. The same rejections as checking
        // both whole states, in fewer instructions (this runs for two planes every outer step).
        if !(requested.is_finite()
            && measured[BALL_ANGLE].is_finite()
            && command[BALL_ANGLE].is_finite()
            && dt_is_valid(dt_secs))
        {
            return self.rejected();
        }
        let (torque, status) = saturate(requested, self.config.lqr.max_torque_nm);
        let (sin, cos) = tilt_sin_cos.unwrap_or_else(|| measured[TILT].sin_cos());
        let accelerations = self
            .model
            .accelerations_with_sin_cos(measured, sin, cos, torque);
        let accel = accelerations[1];

        let measured_rate = measured[BALL_RATE];
        let band = self.config.max_speed_error_rad_per_s;
        let stored = self.reference_ball_rate_rad_per_s.unwrap_or(measured_rate);
        // Plain comparisons: `stored`, the measured rate and the band are finite.
        let anchored = min(measured_rate + band, max(measured_rate - band, stored));
        let half = dt_secs / (T::one() + T::one());
        let next = anchored + accel * dt_secs;
        let output_rate = anchored + accel * half;
        // `anchored` is finite and `dt_secs` finite and positive, so a finite `next` means a
        // finite `accel * dt_secs`, hence a finite `accel` and a finite `output_rate` (which
        // lies between `anchored` and `next`): one check for all three.
        if !next.is_finite() {
            return self.rejected();
        }
        self.reference_ball_rate_rad_per_s = Some(next);
        LqrPiOuterOutput {
            reference_torque_nm: torque,
            reference_ball_rate_rad_per_s: output_rate,
            reference_ball_accel_rad_per_s2: accel,
            reference_tilt_accel_rad_per_s2: accelerations[0],
            tilt_term_nm: tilt,
            tilt_rate_term_nm: tilt_rate,
            ball_rate_term_nm: ball_rate,
            saturation_nm: torque - requested,
            anchor_correction_rad_per_s: anchored - stored,
            status,
        }
    }

    fn rejected(&self) -> LqrPiOuterOutput<T> {
        let z = T::zero();
        LqrPiOuterOutput {
            reference_torque_nm: z,
            reference_ball_rate_rad_per_s: self.reference_ball_rate_rad_per_s.unwrap_or(z),
            reference_ball_accel_rad_per_s2: z,
            reference_tilt_accel_rad_per_s2: z,
            tilt_term_nm: z,
            tilt_rate_term_nm: z,
            ball_rate_term_nm: z,
            saturation_nm: z,
            anchor_correction_rad_per_s: z,
            status: StepStatus::InvalidInput,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::WipParams;
    use nalgebra::Vector4;

    fn outer() -> LqrPiOuter<f64> {
        let wip = Wip::new(WipParams::miapure_60kg()).unwrap();
        let config = LqrPiOuterConfig {
            lqr: LqrGains::for_wip(&wip, 83.9).unwrap(),
            max_speed_error_rad_per_s: 2.0,
        };
        LqrPiOuter::new(wip, config).unwrap()
    }

    #[test]
    fn first_step_anchors_at_measured_rate_and_integrates_the_model() {
        let mut o = outer();
        let s = Vector4::new(0.02, 0.0, 0.1, 3.0);
        let sc = Vector4::new(0.0, 0.0, 0.0, 3.5);
        let dt = 0.0025;
        let out = o.step(&s, &sc, dt);
        let tau = out.reference_torque_nm;
        let accel = o.model().accelerations(&s, tau)[1];
        approx::assert_relative_eq!(out.reference_ball_accel_rad_per_s2, accel);
        approx::assert_relative_eq!(out.reference_ball_rate_rad_per_s, 3.0 + 0.5 * dt * accel);
        approx::assert_relative_eq!(o.reference_ball_rate_rad_per_s().unwrap(), 3.0 + dt * accel);
        assert_eq!(out.anchor_correction_rad_per_s, 0.0);
        // The integral continues from its own value, not from the measurement.
        let out2 = o.step(&s, &sc, dt);
        approx::assert_relative_eq!(
            o.reference_ball_rate_rad_per_s().unwrap(),
            3.0 + dt * accel + dt * out2.reference_ball_accel_rad_per_s2
        );
    }

    #[test]
    fn anchor_band_keeps_reference_near_measurement() {
        let mut o = outer();
        let s = Vector4::new(0.0, 0.0, 0.0, 0.0);
        o.step(&s, &s, 0.0025);
        // The plant is suddenly measured 10 rad/s faster: the reference is pulled to the band.
        let fast = Vector4::new(0.0, 0.0, 0.0, 10.0);
        let out = o.step(&fast, &fast, 0.0025);
        approx::assert_relative_eq!(out.anchor_correction_rad_per_s, 8.0, epsilon = 1e-9);
        assert!((out.reference_ball_rate_rad_per_s - 10.0).abs() <= 2.0 + 1e-9);
    }

    #[test]
    fn reset_reanchors() {
        let mut o = outer();
        o.step(&Vector4::new(0.0, 0.0, 0.0, 1.0), &Vector4::zeros(), 0.0025);
        o.reset();
        assert_eq!(o.reference_ball_rate_rad_per_s(), None);
        let s = Vector4::new(0.0, 0.0, 0.0, 5.0);
        let out = o.step(&s, &s, 0.0025);
        // At rest upright on command: zero torque, zero acceleration, reference = measurement.
        assert_eq!(out.reference_ball_rate_rad_per_s, 5.0);
    }

    #[test]
    fn invalid_input_holds_the_integral() {
        let mut o = outer();
        o.step(
            &Vector4::new(0.01, 0.0, 0.0, 1.0),
            &Vector4::zeros(),
            0.0025,
        );
        let held = o.reference_ball_rate_rad_per_s();
        let out = o.step(
            &Vector4::new(f64::NAN, 0.0, 0.0, 1.0),
            &Vector4::zeros(),
            0.0025,
        );
        assert_eq!(out.status, StepStatus::InvalidInput);
        assert_eq!(out.reference_torque_nm, 0.0);
        assert_eq!(Some(out.reference_ball_rate_rad_per_s), held);
        assert_eq!(o.reference_ball_rate_rad_per_s(), held);
        let out = o.step(&Vector4::zeros(), &Vector4::zeros(), -1.0);
        assert_eq!(out.status, StepStatus::InvalidInput);
    }

    #[test]
    fn config_band_from_inner_gains() {
        let wip = Wip::new(WipParams::miapure_60kg()).unwrap();
        let lqr = LqrGains::for_wip(&wip, 83.9).unwrap();
        let inner = SpeedPiGains {
            proportional_nm_s_per_rad: 10.0,
            integral_nm_per_rad: 100.0,
            anti_windup_per_s: 5.0,
            max_torque_nm: 40.0,
        };
        let c = LqrPiOuterConfig::new(lqr, &inner).unwrap();
        assert_eq!(c.max_speed_error_rad_per_s, 4.0);
        let mut bad = c;
        bad.max_speed_error_rad_per_s = f64::NAN;
        assert!(matches!(
            bad.validate(),
            Err(Error::InvalidParameter {
                field: "max_speed_error_rad_per_s",
                ..
            })
        ));
    }
}
