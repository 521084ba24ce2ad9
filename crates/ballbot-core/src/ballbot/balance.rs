//! Balance-point estimation: the tilt at which the real robot balances.
//!
//! The LQR regulates each plane's tilt to its command, upright plus the feedforward lean of an
//! acceleration. When the centre of mass is not above the ball's centre in the upright body
//! (a payload off centre, a rider sitting off axis, an IMU mounted crooked), the robot can only
//! balance leaning by some `theta_eq`, and the LQR settles where its tilt error is balanced by a
//! speed error: `k_theta theta_eq + k_v (v - v_c) = 0`. On MiaPURE with 60 kg, a payload 5 cm
//! off centre made the robot drive off at 0.62 m/s on a zero command, for good (the fault
//! matrix of issue 15, `ballbot robustness`).
//!
//! [`BalancePoint`] learns `theta_eq - theta_c` per plane, a first-order low-pass of the
//! measured tilt's departure from its command, and the controller's planes measure the tilt
//! from the learnt point: for the LQR and for the reference model (whose body is upright
//! there, as the real one is balanced), so at the balance point neither asks for torque and
//! the speed error goes. (Shifting only the LQR's tilt command is not enough: the reference
//! model, seeing a body that leans by `theta_eq`, then needs torque, and that torque still
//! comes from a speed error, 0.22 m/s with this payload.) It
//! learns only in steady motion (the shaped command's acceleration and the tilt rates small,
//! the departure within a bound), slowly (seconds, against the balance's fraction of a second),
//! and within a bound; [`BalancePointParams::off`] (the paper's configuration,
//! [`super::BallbotControllerConfig::paper`]) disables it; the shipped
//! [`super::BallbotControllerConfig::design`] has it on.
//!
//! **Lifetime.** The offset is learnt for the payload on the ball now, and is forgotten
//! ([`BalancePoint::reset`]) whenever the motors are off: after a disarm, a fault, a reset,
//! and before the first arming. With the motors off the robot stands supported, and its
//! payload can change without the controller seeing it (a rider steps off, a load is moved):
//! an offset kept from before is a bias of up to `max_offset_rad` in a direction nobody
//! knows, and it made a re-armed robot drift at up to about 0.3 m/s on a stop command until it
//! had relearnt (issue 26). Zero is the calibrated upright, the one point that does not depend
//! on the payload; an off-centre payload then costs what it costs at the first arming (a
//! drift for about `time_constant_secs` while the estimate learns it). With the motors on
//! (balancing or in a controlled stop, whose fault kept them on) the payload is the one the
//! robot is balancing, and the estimate keeps following it.

use crate::check::{lit, positive};
use crate::error::Error;
use nalgebra::{RealField, Vector2};

/// Settings of the balance-point estimator.
///
/// ```
/// use ballbot_core::ballbot::BalancePointParams;
/// let p = BalancePointParams::<f64>::recommended();
/// assert!(p.enabled && p.validate().is_ok());
/// assert!(!BalancePointParams::<f64>::off().enabled);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalancePointParams<T> {
    /// Whether the controller estimates and uses the balance point.
    pub enabled: bool,
    /// Time constant of the estimate's low-pass (s). Recommended 2: ten times slower than
    /// the body's falling time constant (about 0.2 s on MiaPURE).
    pub time_constant_secs: T,
    /// Largest offset learnt, per plane (rad). Recommended 0.12 (6.9 deg: the centre of mass
    /// 6 cm off the axis at MiaPURE's 0.50 m height).
    pub max_offset_rad: T,
    /// Learning only while the shaped command accelerates less than this (m/s^2).
    /// Recommended 0.05.
    pub steady_accel_m_per_s2: T,
    /// ... and every tilt rate is below this (rad/s). Recommended 0.1.
    pub steady_tilt_rate_rad_per_s: T,
    /// ... and the tilt's departure from its command is within this (rad). Recommended 0.15.
    pub max_departure_rad: T,
}

impl<T: RealField + Copy> BalancePointParams<T> {
    /// Off: the paper's configuration ([`super::BallbotControllerConfig::paper`]).
    ///
    /// ```
    /// use ballbot_core::ballbot::BalancePointParams;
    /// assert!(!BalancePointParams::<f32>::off().enabled);
    /// ```
    pub fn off() -> Self {
        Self {
            enabled: false,
            ..Self::recommended()
        }
    }

    /// On, with the recommended settings (see the fields).
    ///
    /// ```
    /// use ballbot_core::ballbot::BalancePointParams;
    /// assert_eq!(BalancePointParams::<f64>::recommended().time_constant_secs, 2.0);
    /// ```
    pub fn recommended() -> Self {
        Self {
            enabled: true,
            time_constant_secs: lit(2.0),
            max_offset_rad: lit(0.12),
            steady_accel_m_per_s2: lit(0.05),
            steady_tilt_rate_rad_per_s: lit(0.1),
            max_departure_rad: lit(0.15),
        }
    }

    /// Checks every field: finite and > 0 (also when disabled).
    ///
    /// ```
    /// use ballbot_core::ballbot::BalancePointParams;
    /// let bad = BalancePointParams { time_constant_secs: 0.0, ..BalancePointParams::<f64>::recommended() };
    /// assert!(bad.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.time_constant_secs, "balance_point.time_constant_secs")?;
        positive(self.max_offset_rad, "balance_point.max_offset_rad")?;
        positive(
            self.steady_accel_m_per_s2,
            "balance_point.steady_accel_m_per_s2",
        )?;
        positive(
            self.steady_tilt_rate_rad_per_s,
            "balance_point.steady_tilt_rate_rad_per_s",
        )?;
        positive(self.max_departure_rad, "balance_point.max_departure_rad")
    }
}

/// The estimator (see the module docs).
///
/// ```
/// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
/// use nalgebra::Vector2;
/// let mut bp = BalancePoint::new(BalancePointParams::<f64>::recommended())?;
/// // Standing steadily 0.05 rad off the command in the sagittal plane for 10 s:
/// for _ in 0..4000 {
///     bp.update(Vector2::new(0.0, 0.05), Vector2::zeros(), Vector2::zeros(), 0.0, 0.0025);
/// }
/// approx::assert_relative_eq!(bp.offset_rad()[1], 0.05, epsilon = 0.001);
/// // While the command accelerates, nothing is learnt.
/// let held = bp.offset_rad();
/// bp.update(Vector2::new(0.0, 0.1), Vector2::zeros(), Vector2::zeros(), 1.0, 0.0025);
/// assert_eq!(bp.offset_rad(), held);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalancePoint<T: RealField + Copy> {
    params: BalancePointParams<T>,
    offset_rad: Vector2<T>,
}

impl<T: RealField + Copy> BalancePoint<T> {
    /// Validates `params`; the estimate starts at zero.
    ///
    /// ```
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// let bp = BalancePoint::new(BalancePointParams::<f64>::recommended())?;
    /// assert_eq!(bp.offset_rad(), nalgebra::Vector2::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: BalancePointParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self {
            params,
            offset_rad: Vector2::zeros(),
        })
    }

    /// Forgets the learnt offset: the estimate starts again from zero, the calibrated
    /// upright. The controller calls it whenever the motors are off (disarmed, faulted,
    /// reset, or not yet armed; see the module docs for why).
    ///
    /// ```
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// use nalgebra::Vector2;
    /// let mut bp = BalancePoint::new(BalancePointParams::<f64>::recommended())?;
    /// for _ in 0..4000 {
    ///     bp.update(Vector2::new(0.0, 0.05), Vector2::zeros(), Vector2::zeros(), 0.0, 0.0025);
    /// }
    /// assert!(bp.offset_rad()[1] > 0.04);
    /// bp.reset();
    /// assert_eq!(bp.offset_rad(), Vector2::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.offset_rad = Vector2::zeros();
    }

    /// The learnt offset `[frontal, sagittal]` of the tilt command (rad).
    ///
    /// ```
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// let bp = BalancePoint::new(BalancePointParams::<f32>::recommended())?;
    /// assert_eq!(bp.offset_rad()[0], 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn offset_rad(&self) -> Vector2<T> {
        self.offset_rad
    }

    /// One outer step: learns from the measured tilts `[frontal, sagittal]`, their rates, the
    /// tilt commands (with the feedforward lean, without the offset) and the shaped command's
    /// acceleration magnitude, if the motion is steady (see [`BalancePointParams`]).
    /// Non-finite inputs are ignored.
    ///
    /// ```
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// use nalgebra::Vector2;
    /// let mut bp = BalancePoint::new(BalancePointParams::<f64>::recommended())?;
    /// // A fast tilt rate: a push, not a balance point.
    /// bp.update(Vector2::new(0.05, 0.0), Vector2::new(0.5, 0.0), Vector2::zeros(), 0.0, 0.0025);
    /// assert_eq!(bp.offset_rad()[0], 0.0);
    /// // NaN changes nothing either.
    /// bp.update(Vector2::new(f64::NAN, 0.0), Vector2::zeros(), Vector2::zeros(), 0.0, 0.0025);
    /// assert_eq!(bp.offset_rad()[0], 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn update(
        &mut self,
        tilt_rad: Vector2<T>,
        tilt_rate_rad_per_s: Vector2<T>,
        tilt_command_rad: Vector2<T>,
        command_accel_m_per_s2: T,
        dt_secs: T,
    ) {
        let p = &self.params;
        let departure = tilt_rad - tilt_command_rad;
        let finite = departure.iter().all(|x| x.is_finite())
            && tilt_rate_rad_per_s.iter().all(|x| x.is_finite())
            && command_accel_m_per_s2.is_finite()
            && dt_secs.is_finite();
        let steady = finite
            && command_accel_m_per_s2.abs() <= p.steady_accel_m_per_s2
            && tilt_rate_rad_per_s
                .iter()
                .all(|w| w.abs() <= p.steady_tilt_rate_rad_per_s)
            && departure.iter().all(|d| d.abs() <= p.max_departure_rad);
        if !p.enabled || !steady || dt_secs <= T::zero() {
            return;
        }
        let gain = (dt_secs / p.time_constant_secs).min(T::one());
        for (o, d) in self.offset_rad.iter_mut().zip(departure.iter()) {
            let next = *o + gain * (*d - *o);
            *o = next.max(-p.max_offset_rad).min(p.max_offset_rad);
        }
    }
}
