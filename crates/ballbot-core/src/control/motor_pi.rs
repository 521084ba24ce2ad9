//! The inner speed PI of the cascaded LQR-PI: the part that runs on the motor driver (8 kHz on
//! MiaPURE and the PIPTB).
//!
//! ```text
//! e     = speed_ref - speed
//! tau   = sat(tau_ff + kp e + I)
//! I    <- I + dt (ki e + k_aw (tau - (tau_ff + kp e + I)))      (back-calculation)
//! ```
//!
//! `tau_ff` is the feedforward torque from the outer loop (the LQR reference torque `tau_r`),
//! `speed_ref` the reference speed (`phi_dot_r`). One instance controls one speed: the planar
//! ball rate for the PIPTB, or one omniwheel's speed on a ballbot (torques then at the wheel).
//!
//! **Anti-windup** is back-calculation driven by the torque actually applied: after
//! saturation, the integrator is pulled back by `k_aw (tau_applied - tau_requested)`, so while
//! the actuator is saturated the integral settles where the request sits on the limit instead of
//! growing. The correction per step is capped at the full excess (`dt k_aw <= 1`), so a large
//! `k_aw` cannot make it overshoot; and the integral term alone is clamped to the torque limit.
//! The integrator is committed only when its new value is finite.

use super::terms::impl_terms;
use super::{StepStatus, check_limit, dt_is_valid};
use crate::check::{non_negative, positive};
use crate::num::{max, min};
use crate::wip::BALL_RATE;
use crate::{Error, Wip};
use nalgebra::RealField;

/// Gains and limits of [`SpeedPi`].
///
/// ```
/// use ballbot_core::control::SpeedPiGains;
/// // The MiaPURE actuator's 43.2 N m peak; hand-picked gains with k_aw = ki / kp.
/// let gains = SpeedPiGains {
///     proportional_nm_s_per_rad: 10.0,
///     integral_nm_per_rad: 100.0,
///     anti_windup_per_s: 10.0,
///     max_torque_nm: 43.2,
/// };
/// gains.validate()?;
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct SpeedPiGains<T> {
    /// Proportional gain `kp` on the speed error (N m s/rad, >= 0).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub proportional_nm_s_per_rad: T,
    /// Integral gain `ki` on the integrated speed error (N m/rad, >= 0).
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub integral_nm_per_rad: T,
    /// Back-calculation anti-windup gain `k_aw` (1/s, >= 0): how fast the integral is pulled
    /// back by the saturation excess. 0 disables back-calculation (the integral then stays
    /// bounded only by the torque-limit clamp). A usual choice is `ki / kp`.
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub anti_windup_per_s: T,
    /// Symmetric torque limit (N m, > 0): 43.2 N m at the wheel for the MiaPURE actuator.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_torque_nm: T,
}

impl<T: RealField + Copy> SpeedPiGains<T> {
    /// Gains that place the speed-error dynamics `e_dot = -b (kp e + ki int e)` at a
    /// critically damped double pole at `-bandwidth_rad_per_s`: `kp = 2 w / b`,
    /// `ki = w^2 / b`, `k_aw = ki / kp = w / 2`.
    ///
    /// `accel_per_torque` is `b`, the plant's speed acceleration per unit torque
    /// (rad/s^2 per N m). For the ball rate of a WIP it is `B4` of the upright linearisation
    /// (see [`Self::for_wip_ball_rate`]); for one omniwheel it is the inverse of the inertia
    /// that wheel sees.
    ///
    /// Errors name `accel_per_torque`, `bandwidth_rad_per_s` or `max_torque_nm` when they are
    /// not finite and positive.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    /// // A 0.5 kg m^2 inertia (b = 2 rad/s^2 per N m) against a constant 3 N m friction torque.
    /// let (b, friction_nm, dt) = (2.0, 3.0, 1.0 / 8000.0);
    /// let gains = SpeedPiGains::from_bandwidth(b, 30.0, 43.2)?;
    /// approx::assert_relative_eq!(gains.proportional_nm_s_per_rad, 30.0); // 2 w / b
    /// approx::assert_relative_eq!(gains.integral_nm_per_rad, 450.0); // w^2 / b
    /// let mut pi = SpeedPi::new(gains)?;
    /// let command = SpeedCommand { speed_rad_per_s: 5.0, feedforward_torque_nm: 0.0 };
    /// let mut speed = 0.0;
    /// for _ in 0..8000 {
    ///     let tau = pi.step(speed, &command, dt).torque_nm;
    ///     speed += dt * b * (tau - friction_nm);
    /// }
    /// // After 1 s the integral has learned the friction and the speed error is gone.
    /// assert!((speed - 5.0_f64).abs() < 1e-3);
    /// approx::assert_relative_eq!(pi.integral_nm(), friction_nm, epsilon = 1e-2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn from_bandwidth(
        accel_per_torque: T,
        bandwidth_rad_per_s: T,
        max_torque_nm: T,
    ) -> Result<Self, Error> {
        positive(accel_per_torque, "accel_per_torque")?;
        positive(bandwidth_rad_per_s, "bandwidth_rad_per_s")?;
        let w = bandwidth_rad_per_s;
        let two = T::one() + T::one();
        let gains = Self {
            proportional_nm_s_per_rad: two * w / accel_per_torque,
            integral_nm_per_rad: w * w / accel_per_torque,
            anti_windup_per_s: w / two,
            max_torque_nm,
        };
        gains.validate()?;
        Ok(gains)
    }

    /// [`Self::from_bandwidth`] for the ball rate `phi_dot` of a WIP, with `b = B4`, the ball
    /// acceleration per unit torque of `wip`'s upright linearisation.
    ///
    /// With the LQR-PI's reference model equal to the plant, the speed error obeys exactly
    /// `e_dot = -B4(theta) tau_e + B4(theta) tau_d` for a torque disturbance `tau_d` on the
    /// drive (friction): the inner loop is decoupled from the balance loop, and these gains
    /// reject a constant `tau_d` with the chosen double pole.
    ///
    /// ```
    /// use ballbot_core::control::SpeedPiGains;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let g = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9)?;
    /// // B4 = 4.4545 (MODEL.md section 6): kp = 60 / 4.4545.
    /// approx::assert_relative_eq!(g.proportional_nm_s_per_rad, 13.47, epsilon = 0.01);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn for_wip_ball_rate(
        wip: &Wip<T>,
        bandwidth_rad_per_s: T,
        max_torque_nm: T,
    ) -> Result<Self, Error> {
        let b4 = wip.linearize_upright().B[BALL_RATE];
        Self::from_bandwidth(b4, bandwidth_rad_per_s, max_torque_nm)
    }

    /// Checks every field; the error names the first one out of range.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::control::SpeedPiGains;
    /// let mut gains = SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?;
    /// assert!(gains.validate().is_ok());
    /// gains.integral_nm_per_rad = -1.0;
    /// assert!(matches!(
    ///     gains.validate(),
    ///     Err(Error::InvalidParameter { field: "integral_nm_per_rad", .. })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        non_negative(self.proportional_nm_s_per_rad, "proportional_nm_s_per_rad")?;
        non_negative(self.integral_nm_per_rad, "integral_nm_per_rad")?;
        non_negative(self.anti_windup_per_s, "anti_windup_per_s")?;
        check_limit(self.max_torque_nm, "max_torque_nm")
    }
}

/// What the outer loop sends to one speed PI: a reference speed and a feedforward torque.
///
/// ```
/// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
/// let mut pi = SpeedPi::new(SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?)?;
/// // On reference, the PI passes the feedforward torque through unchanged.
/// let command = SpeedCommand { speed_rad_per_s: 3.0, feedforward_torque_nm: 12.5 };
/// assert_eq!(pi.step(3.0, &command, 1.0 / 8000.0).torque_nm, 12.5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedCommand<T> {
    /// Reference speed (rad/s): `phi_dot_r`, or a wheel's reference speed `psi_dot_r`.
    pub speed_rad_per_s: T,
    /// Feedforward torque (N m): `tau_r`, or a wheel's reference torque.
    pub feedforward_torque_nm: T,
}

/// One speed-PI step's result, with each term for logging.
///
/// ```
/// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains, StepStatus};
/// let mut pi = SpeedPi::new(SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?)?;
/// let command = SpeedCommand { speed_rad_per_s: 10.0, feedforward_torque_nm: 20.0 };
/// // 10 rad/s too slow: 20 N m + 134.7 N m requested, 43.2 N m applied.
/// let out = pi.step(0.0, &command, 1.0 / 8000.0);
/// assert_eq!((out.torque_nm, out.status), (43.2, StepStatus::Saturated));
/// let requested = out.feedforward_nm + out.proportional_nm + out.integral_nm;
/// approx::assert_relative_eq!(out.saturation_nm, 43.2 - requested, epsilon = 1e-12);
/// assert_eq!(out.speed_error_rad_per_s, 10.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedPiOutput<T> {
    /// The torque to apply, after saturation (N m). Always finite and within the limit.
    pub torque_nm: T,
    /// The feedforward torque that was added (N m).
    pub feedforward_nm: T,
    /// `kp e` (N m).
    pub proportional_nm: T,
    /// The integral term used in this step (N m).
    pub integral_nm: T,
    /// Applied minus requested torque (N m): zero unless saturated. This drives the
    /// anti-windup.
    pub saturation_nm: T,
    /// The speed error `e = speed_ref - speed` (rad/s).
    pub speed_error_rad_per_s: T,
    /// Whether the step was nominal, saturated or rejected.
    pub status: StepStatus,
}

impl_terms!(SpeedPiOutput {
    torque_nm,
    feedforward_nm,
    proportional_nm,
    integral_nm,
    saturation_nm,
    speed_error_rad_per_s,
});

impl<T: RealField + Copy> SpeedPiOutput<T> {
    fn rejected() -> Self {
        let z = T::zero();
        Self {
            torque_nm: z,
            feedforward_nm: z,
            proportional_nm: z,
            integral_nm: z,
            saturation_nm: z,
            speed_error_rad_per_s: z,
            status: StepStatus::InvalidInput,
        }
    }
}

/// Speed PI with feedforward and back-calculation anti-windup (see the module docs).
///
/// ```
/// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains, StepStatus};
/// let gains = SpeedPiGains {
///     proportional_nm_s_per_rad: 10.0,
///     integral_nm_per_rad: 100.0,
///     anti_windup_per_s: 10.0,
///     max_torque_nm: 43.2,
/// };
/// let mut pi = SpeedPi::new(gains)?;
/// let cmd = SpeedCommand { speed_rad_per_s: 2.0, feedforward_torque_nm: 5.0 };
/// let out = pi.step(1.5, &cmd, 1.0 / 8000.0);
/// // 5 N m feedforward + 10 * 0.5 proportional; the integral starts at 0.
/// approx::assert_relative_eq!(out.torque_nm, 10.0);
/// assert_eq!(out.status, StepStatus::Nominal);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedPi<T> {
    gains: SpeedPiGains<T>,
    /// The integral term `I` (N m), always finite and within the torque limit.
    integral_nm: T,
}

impl<T: RealField + Copy> SpeedPi<T> {
    /// Validates `gains`; the integral starts at zero.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedPi, SpeedPiGains};
    /// let gains = SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?;
    /// assert_eq!(SpeedPi::new(gains)?.integral_nm(), 0.0);
    /// // Gains are validated here: a zero torque limit is refused.
    /// assert!(SpeedPi::new(SpeedPiGains { max_torque_nm: 0.0, ..gains }).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(gains: SpeedPiGains<T>) -> Result<Self, Error> {
        gains.validate()?;
        Ok(Self {
            gains,
            integral_nm: T::zero(),
        })
    }

    /// The gains in use.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedPi, SpeedPiGains};
    /// let pi = SpeedPi::new(SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?)?;
    /// assert_eq!(pi.gains().max_torque_nm, 43.2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn gains(&self) -> &SpeedPiGains<T> {
        &self.gains
    }

    /// The integral term `I` (N m) that the next step will use.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    /// let gains = SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?;
    /// let mut pi = SpeedPi::new(gains)?;
    /// let command = SpeedCommand { speed_rad_per_s: 1.0, feedforward_torque_nm: 0.0 };
    /// pi.step(0.0, &command, 0.001);
    /// // One step of ki * e * dt.
    /// let ki = gains.integral_nm_per_rad;
    /// approx::assert_relative_eq!(pi.integral_nm(), ki * 0.001, epsilon = 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn integral_nm(&self) -> T {
        self.integral_nm
    }

    /// Clears the integral.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    /// let mut pi = SpeedPi::new(SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?)?;
    /// let command = SpeedCommand { speed_rad_per_s: 1.0, feedforward_torque_nm: 0.0 };
    /// pi.step(0.0, &command, 0.001);
    /// assert!(pi.integral_nm() > 0.0);
    /// pi.reset();
    /// assert_eq!(pi.integral_nm(), 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.integral_nm = T::zero();
    }

    /// One PI step with the symmetric limit `max_torque_nm`.
    ///
    /// `measured_speed_rad_per_s` is the measured speed, `command` the outer loop's reference
    /// speed and feedforward torque, `dt_secs` the time since the previous step (s). A
    /// non-finite input, or `dt_secs <= 0`, gives zero torque with
    /// [`StepStatus::InvalidInput`] and leaves the integral unchanged.
    ///
    /// ```
    /// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    /// let gains = SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?;
    /// let mut pi = SpeedPi::new(gains)?;
    /// let command = SpeedCommand { speed_rad_per_s: 2.0, feedforward_torque_nm: 5.0 };
    /// // 0.1 rad/s too slow: feedforward plus kp * 0.1, the integral starts to build.
    /// let out = pi.step(1.9, &command, 1.0 / 8000.0);
    /// approx::assert_relative_eq!(out.proportional_nm, gains.proportional_nm_s_per_rad * 0.1, epsilon = 1e-12);
    /// assert!(out.torque_nm > 5.0 && pi.integral_nm() > 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        measured_speed_rad_per_s: T,
        command: &SpeedCommand<T>,
        dt_secs: T,
    ) -> SpeedPiOutput<T> {
        let max_nm = self.gains.max_torque_nm;
        self.step_in_range(measured_speed_rad_per_s, command, dt_secs, -max_nm, max_nm)
    }

    /// One PI step with the torque range `[lower_nm, upper_nm]` intersected with the symmetric
    /// limit: pass an actuator's speed-dependent range (e.g.
    /// [`crate::ActuatorParams::torque_bounds_nm`] at the measured speed) so the anti-windup
    /// sees the torque the motor can actually give. A non-finite bound is ignored (the
    /// symmetric limit applies); a range that excludes zero after the intersection is
    /// rejected like a non-finite input.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::control::{SpeedCommand, SpeedPi, SpeedPiGains};
    /// let actuator = ActuatorParams::<f64>::miapure();
    /// let mut pi = SpeedPi::new(SpeedPiGains::from_bandwidth(4.4545, 30.0, 43.2)?)?;
    /// let command = SpeedCommand { speed_rad_per_s: 100.0, feedforward_torque_nm: 40.0 };
    /// // Near the no-load speed the motor gives less than its peak: the PI is clipped there.
    /// let speed_rad_per_s = 0.9 * actuator.no_load_speed_rad_per_s;
    /// let (lower_nm, upper_nm) = actuator.torque_bounds_nm(speed_rad_per_s);
    /// let out = pi.step_within(speed_rad_per_s, &command, 1.0 / 8000.0, lower_nm, upper_nm);
    /// assert!(upper_nm < 43.2 && out.torque_nm == upper_nm);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step_within(
        &mut self,
        measured_speed_rad_per_s: T,
        command: &SpeedCommand<T>,
        dt_secs: T,
        lower_nm: T,
        upper_nm: T,
    ) -> SpeedPiOutput<T> {
        // Plain comparisons (`max`/`min` are NaN-aware and cost several instructions each): a
        // NaN or infinite bound fails `is_finite`, one beyond the limit the comparison.
        let max_nm = self.gains.max_torque_nm;
        let lower = if lower_nm.is_finite() && lower_nm > -max_nm {
            lower_nm
        } else {
            -max_nm
        };
        let upper = if upper_nm.is_finite() && upper_nm < max_nm {
            upper_nm
        } else {
            max_nm
        };
        if lower > T::zero() || upper < T::zero() {
            return SpeedPiOutput::rejected();
        }
        self.step_in_range(measured_speed_rad_per_s, command, dt_secs, lower, upper)
    }

    /// The PI law within `[lower, upper]`, a range the caller guarantees to satisfy
    /// `-max_torque_nm <= lower <= 0 <= upper <= max_torque_nm` (no intersection, no check:
    /// the motor drivers' hot path, whose torque-speed bounds are prepared against the limit).
    #[inline(always)]
    pub(crate) fn step_in_range(
        &mut self,
        measured_speed_rad_per_s: T,
        command: &SpeedCommand<T>,
        dt_secs: T,
        lower: T,
        upper: T,
    ) -> SpeedPiOutput<T> {
        let g = &self.gains;
        let error = command.speed_rad_per_s - measured_speed_rad_per_s;
        let proportional = g.proportional_nm_s_per_rad * error;
        let integral = self.integral_nm;
        let requested = command.feedforward_torque_nm + proportional + integral;
        // A non-finite speed or reference makes `error` non-finite and with it `requested`
        // (`kp e` is infinite, or NaN for `kp = 0`); so does a non-finite feedforward or an
        // overflow. One check covers them all.
        if !(requested.is_finite() && dt_is_valid(dt_secs)) {
            return SpeedPiOutput::rejected();
        }
        // `requested` is finite and `lower <= upper`: a plain clamp (ties keep `requested`).
        let torque = min(upper, max(lower, requested));
        let status = if torque == requested {
            StepStatus::Nominal
        } else {
            StepStatus::Saturated
        };
        let saturation = torque - requested;
        // Back-calculation, the correction capped at the full excess (plain comparisons: both
        // operands are finite here).
        let aw_step = min(g.anti_windup_per_s * dt_secs, T::one());
        let next =
            self.integral_nm + g.integral_nm_per_rad * error * dt_secs + aw_step * saturation;
        if next.is_finite() {
            let max_nm = g.max_torque_nm;
            self.integral_nm = min(max_nm, max(-max_nm, next));
        }
        SpeedPiOutput {
            torque_nm: torque,
            feedforward_nm: command.feedforward_torque_nm,
            proportional_nm: proportional,
            integral_nm: integral,
            saturation_nm: saturation,
            speed_error_rad_per_s: error,
            status,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::WipParams;

    fn gains() -> SpeedPiGains<f64> {
        SpeedPiGains {
            proportional_nm_s_per_rad: 2.0,
            integral_nm_per_rad: 20.0,
            anti_windup_per_s: 10.0,
            max_torque_nm: 10.0,
        }
    }

    fn cmd(speed: f64, ff: f64) -> SpeedCommand<f64> {
        SpeedCommand {
            speed_rad_per_s: speed,
            feedforward_torque_nm: ff,
        }
    }

    #[test]
    fn validation_names_the_field() {
        let mut g = gains();
        g.integral_nm_per_rad = -1.0;
        assert!(matches!(
            SpeedPi::new(g),
            Err(Error::InvalidParameter {
                field: "integral_nm_per_rad",
                ..
            })
        ));
        assert!(matches!(
            SpeedPiGains::from_bandwidth(0.0, 10.0, 5.0),
            Err(Error::InvalidParameter {
                field: "accel_per_torque",
                ..
            })
        ));
    }

    #[test]
    fn integrates_the_error_and_sums_the_terms() {
        let mut pi = SpeedPi::new(gains()).unwrap();
        let dt = 0.001;
        let first = pi.step(0.0, &cmd(1.0, 0.5), dt);
        assert_eq!(first.integral_nm, 0.0);
        approx::assert_relative_eq!(first.torque_nm, 0.5 + 2.0);
        let second = pi.step(0.0, &cmd(1.0, 0.5), dt);
        approx::assert_relative_eq!(second.integral_nm, 20.0 * 1.0 * dt, epsilon = 1e-15);
        approx::assert_relative_eq!(
            second.torque_nm,
            second.feedforward_nm + second.proportional_nm + second.integral_nm,
            epsilon = 1e-15
        );
    }

    #[test]
    fn closed_loop_on_an_inertia_removes_a_constant_disturbance() {
        // Plant: speed_dot = b (tau - d); the PI must drive the speed to the reference.
        let b = 4.0;
        let d = 3.0;
        let g = SpeedPiGains::from_bandwidth(b, 20.0, 50.0).unwrap();
        let mut pi = SpeedPi::new(g).unwrap();
        let dt = 1.0 / 8000.0;
        let mut speed = 0.0;
        for _ in 0..8000 {
            let out = pi.step(speed, &cmd(2.0, 0.0), dt);
            speed += dt * b * (out.torque_nm - d);
        }
        assert!((speed - 2.0).abs() < 1e-6, "speed {speed}");
        approx::assert_relative_eq!(pi.integral_nm(), d, epsilon = 1e-4);
    }

    /// The integral clamp alone keeps this test green (the back-calculation term is checked
    /// exactly by `back_calculation_settles_the_integral_at_its_fixed_point` in
    /// `tests/controllers.rs`, which fails when that term is removed or its sign flipped).
    #[test]
    fn saturation_keeps_the_integral_within_the_limit() {
        let mut pi = SpeedPi::new(gains()).unwrap();
        // A long, unreachable reference: the request saturates.
        for _ in 0..100_000 {
            let out = pi.step(0.0, &cmd(100.0, 0.0), 0.001);
            assert!(out.torque_nm <= 10.0);
        }
        // Request sits at the limit: kp e + I = 10 + (kI e / k_aw) at equilibrium, and the
        // integral is clamped to the limit; it has not grown without bound.
        assert!(pi.integral_nm() <= 10.0);
        // Once the error reverses, the output leaves saturation at once.
        let out = pi.step(100.5, &cmd(100.0, 0.0), 0.001);
        assert!(out.torque_nm < 10.0, "{out:?}");
    }

    #[test]
    fn bounds_restrict_and_invalid_bounds_are_rejected() {
        let mut pi = SpeedPi::new(gains()).unwrap();
        let out = pi.step_within(0.0, &cmd(10.0, 0.0), 0.001, -3.0, 4.0);
        assert_eq!((out.torque_nm, out.status), (4.0, StepStatus::Saturated));
        let out = pi.step_within(0.0, &cmd(10.0, 0.0), 0.001, f64::NAN, f64::INFINITY);
        assert_eq!(out.torque_nm, 10.0);
        let before = pi.integral_nm();
        let out = pi.step_within(0.0, &cmd(10.0, 0.0), 0.001, 1.0, 4.0);
        assert_eq!((out.torque_nm, out.status), (0.0, StepStatus::InvalidInput));
        assert_eq!(pi.integral_nm(), before);
    }

    #[test]
    fn non_finite_inputs_hold_the_integral() {
        let mut pi = SpeedPi::new(gains()).unwrap();
        pi.step(0.0, &cmd(1.0, 0.0), 0.01);
        let before = pi.integral_nm();
        for (m, c, dt) in [
            (f64::NAN, cmd(1.0, 0.0), 0.01),
            (0.0, cmd(f64::INFINITY, 0.0), 0.01),
            (0.0, cmd(1.0, f64::NEG_INFINITY), 0.01),
            (0.0, cmd(1.0, 0.0), f64::NAN),
            (0.0, cmd(1.0, 0.0), 0.0),
        ] {
            let out = pi.step(m, &c, dt);
            assert_eq!((out.torque_nm, out.status), (0.0, StepStatus::InvalidInput));
            assert_eq!(pi.integral_nm(), before);
        }
        pi.reset();
        assert_eq!(pi.integral_nm(), 0.0);
    }

    #[test]
    fn wip_ball_rate_gains_use_b4() {
        let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
        let g = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9).unwrap();
        let b4 = 4.4545;
        approx::assert_relative_eq!(g.proportional_nm_s_per_rad, 60.0 / b4, epsilon = 1e-3);
        approx::assert_relative_eq!(g.integral_nm_per_rad, 900.0 / b4, epsilon = 1e-2);
    }
}
