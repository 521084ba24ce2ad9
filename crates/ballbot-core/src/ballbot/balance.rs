//! Balance-point estimation: the tilt at which the real robot balances.
//!
//! The LQR regulates each plane's tilt to its command, upright plus the feedforward lean of an
//! acceleration. When the centre of mass is not above the ball's centre in the upright body
//! (a payload off centre, a rider sitting off axis, an IMU mounted crooked), the robot can only
//! balance leaning by some `theta_eq`, and the LQR settles where its tilt error is balanced by a
//! speed error: `k_theta theta_eq + k_v (v - v_c) = 0`. On MiaPURE with 60 kg, a payload 5 cm
//! off centre made the robot drive off at 0.62 m/s on a zero command, for good (the fault
//! matrix, `ballbot robustness`).
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
//! and within a bound.
//!
//! **Leans that accelerate the ball are not a balance point.** A body that accelerates its
//! ball at `phi_ddot` leans by `K phi_ddot`, `K = (b + m_U r l) / (m_U g l)` (the shaper's
//! equilibrium lean, [`crate::command::CommandShaper`]): after a push the controller brakes
//! the ball for seconds on a slowly decaying lean, with small tilt rates and a still command,
//! and an estimator that took that lean for a balance point learnt the braking and made the
//! robot creep at 0.09 m/s three seconds after a 40 N s push (the safe-by-default review
//! found it). So the departure learnt is the tilt's departure from its command less the lean
//! of the ball's measured acceleration relative to the command's, `K d/dt (phi_dot -
//! phi_dot_c)`, a finite difference of the speed error, low-passed over 0.1 s ([`BalancePoint::ACCEL_FILTER_SECS`]:
//! a single 2.5 ms difference of the encoders' rates is noisy enough to leave the departure
//! bound, and without the low-pass the fault matrix's payload-shift cells drifted at 0.35 m/s).
//! An off-centre payload drives the ball at a steady speed (no acceleration) and is learnt as
//! before.
//! [`BalancePointParams::off`] (the paper's configuration,
//! [`super::BallbotControllerConfig::paper`]) disables it; the shipped
//! [`super::BallbotControllerConfig::design`] has it on.
//!
//! **Lifetime.** The offset is learnt for the payload on the ball now, and is forgotten
//! ([`BalancePoint::reset`]) whenever the motors are off: after a disarm, a fault, a reset,
//! and before the first arming. With the motors off the robot stands supported, and its
//! payload can change without the controller seeing it (a rider steps off, a load is moved):
//! an offset kept from before is a bias of up to `max_offset_rad` in a direction nobody
//! knows, and it made a re-armed robot drift at up to about 0.3 m/s on a stop command until it
//! had relearnt (the same review found it). Zero is the calibrated upright, the one point that
//! does not depend on the payload; an off-centre payload then costs what it costs at the first arming (a
//! drift for about `time_constant_secs` while the estimate learns it). With the motors on
//! (balancing or in a controlled stop, whose fault kept them on) the payload is the one the
//! robot is balancing, and the estimate keeps following it.

use crate::BallbotParams;
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
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct BalancePointParams<T> {
    /// Whether the controller estimates and uses the balance point.
    pub enabled: bool,
    /// Time constant of the estimate's low-pass (s). Recommended 2: ten times slower than
    /// the body's falling time constant (about 0.2 s on MiaPURE).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub time_constant_secs: T,
    /// Largest offset learnt, per plane (rad). Recommended 0.12 (6.9 deg: the centre of mass
    /// 6 cm off the axis at MiaPURE's 0.50 m height).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_offset_rad: T,
    /// Learning only while the shaped command accelerates less than this (m/s^2).
    /// Recommended 0.05.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub steady_accel_m_per_s2: T,
    /// ... and every tilt rate is below this (rad/s). Recommended 0.1.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub steady_tilt_rate_rad_per_s: T,
    /// ... and the tilt's departure from its command is within this (rad), with and without
    /// the lean of the ball's acceleration (see the module docs). Recommended 0.15.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
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

/// One outer step's inputs of [`BalancePoint::update`], per plane `[frontal, sagittal]`.
///
/// ```
/// use ballbot_core::ballbot::BalanceSample;
/// let standing = BalanceSample::<f64>::still();
/// assert_eq!(standing.tilt_rad, nalgebra::Vector2::zeros());
/// assert_eq!(standing.command_accel_m_per_s2, 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalanceSample<T: RealField + Copy> {
    /// The measured tilts (rad).
    pub tilt_rad: Vector2<T>,
    /// Their rates (rad/s).
    pub tilt_rate_rad_per_s: Vector2<T>,
    /// The measured ball rates (rad/s).
    pub ball_rate_rad_per_s: Vector2<T>,
    /// The tilt commands, with the feedforward lean and without the offset (rad).
    pub tilt_command_rad: Vector2<T>,
    /// The ball-rate commands (rad/s).
    pub ball_rate_command_rad_per_s: Vector2<T>,
    /// The shaped command's acceleration magnitude (m/s^2).
    pub command_accel_m_per_s2: T,
}

impl<T: RealField + Copy> BalanceSample<T> {
    /// Standing still upright on a still command: every field zero.
    ///
    /// ```
    /// use ballbot_core::ballbot::BalanceSample;
    /// assert_eq!(BalanceSample::<f32>::still().ball_rate_rad_per_s[1], 0.0);
    /// ```
    pub fn still() -> Self {
        Self {
            tilt_rad: Vector2::zeros(),
            tilt_rate_rad_per_s: Vector2::zeros(),
            ball_rate_rad_per_s: Vector2::zeros(),
            tilt_command_rad: Vector2::zeros(),
            ball_rate_command_rad_per_s: Vector2::zeros(),
            command_accel_m_per_s2: T::zero(),
        }
    }
}

/// The estimator (see the module docs).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BalancePoint, BalancePointParams, BalanceSample};
/// use nalgebra::Vector2;
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
/// // Standing steadily 0.05 rad off the command in the sagittal plane for 10 s:
/// let leaning = BalanceSample { tilt_rad: Vector2::new(0.0, 0.05), ..BalanceSample::still() };
/// for _ in 0..4000 {
///     bp.update(&leaning, 0.0025);
/// }
/// approx::assert_relative_eq!(bp.offset_rad()[1], 0.05, epsilon = 0.001);
/// // While the command accelerates, nothing is learnt.
/// let held = bp.offset_rad();
/// let accelerating = BalanceSample { command_accel_m_per_s2: 1.0, ..leaning };
/// bp.update(&accelerating, 0.0025);
/// assert_eq!(bp.offset_rad(), held);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalancePoint<T: RealField + Copy> {
    params: BalancePointParams<T>,
    offset_rad: Vector2<T>,
    /// `K` per plane: the lean of a unit ball acceleration (rad per rad/s^2, i.e. s^2).
    lean_per_ball_accel_s2: Vector2<T>,
    /// The last step's speed error `phi_dot - phi_dot_c` (rad/s), when finite.
    last_rate_error: Option<Vector2<T>>,
    /// The lean of the ball's relative acceleration, low-passed over
    /// [`BalancePoint::ACCEL_FILTER_SECS`] (rad).
    accel_lean_rad: Vector2<T>,
}

impl<T: RealField + Copy> BalancePoint<T> {
    /// Time constant of the low-pass on the acceleration's lean (s): a tenth of a second,
    /// short against the estimate's seconds and the braking after a push, long against the
    /// 2.5 ms finite difference of the encoders' rates.
    ///
    /// ```
    /// assert_eq!(ballbot_core::ballbot::BalancePoint::<f64>::ACCEL_FILTER_SECS, 0.1);
    /// ```
    pub const ACCEL_FILTER_SECS: f64 = 0.1;

    /// Validates `params`; the estimate starts at zero. `robot` gives each plane's lean per
    /// ball acceleration `K = (b + m_U r l) / (m_U g l)` ([`crate::WipParams::lean_per_ball_accel_s2`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
    /// assert_eq!(bp.offset_rad(), nalgebra::Vector2::zeros());
    /// // The shaper's equilibrium lean: 7.3 deg per m/s^2 on MiaPURE with 60 kg.
    /// let r = robot.sagittal.ball_radius_m;
    /// let lean_deg_per_m_per_s2 = bp.lean_per_ball_accel_s2()[1].to_degrees() / r;
    /// assert!((lean_deg_per_m_per_s2 - 7.3).abs() < 0.1, "{lean_deg_per_m_per_s2}");
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: BalancePointParams<T>, robot: &BallbotParams<T>) -> Result<Self, Error> {
        params.validate()?;
        robot.validate()?;
        Ok(Self {
            params,
            offset_rad: Vector2::zeros(),
            lean_per_ball_accel_s2: Vector2::new(
                robot.frontal.lean_per_ball_accel_s2(),
                robot.sagittal.lean_per_ball_accel_s2(),
            ),
            last_rate_error: None,
            accel_lean_rad: Vector2::zeros(),
        })
    }

    /// Each plane's lean per unit ball acceleration `K` (s^2; see the module docs).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
    /// assert!(bp.lean_per_ball_accel_s2().iter().all(|k| *k > 0.0));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn lean_per_ball_accel_s2(&self) -> Vector2<T> {
        self.lean_per_ball_accel_s2
    }

    /// Forgets the learnt offset: the estimate starts again from zero, the calibrated
    /// upright. The controller calls it whenever the motors are off (disarmed, faulted,
    /// reset, or not yet armed; see the module docs for why).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams, BalanceSample};
    /// use nalgebra::Vector2;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
    /// let leaning = BalanceSample { tilt_rad: Vector2::new(0.0, 0.05), ..BalanceSample::still() };
    /// for _ in 0..4000 {
    ///     bp.update(&leaning, 0.0025);
    /// }
    /// assert!(bp.offset_rad()[1] > 0.04);
    /// bp.reset();
    /// assert_eq!(bp.offset_rad(), Vector2::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.offset_rad = Vector2::zeros();
        self.last_rate_error = None;
        self.accel_lean_rad = Vector2::zeros();
    }

    /// The learnt offset `[frontal, sagittal]` of the tilt command (rad).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams};
    /// let robot = BallbotParams::<f32>::miapure_60kg();
    /// let bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
    /// assert_eq!(bp.offset_rad()[0], 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn offset_rad(&self) -> Vector2<T> {
        self.offset_rad
    }

    /// One outer step of `dt_secs`: learns the tilt's departure from its command, less the
    /// lean of the ball's acceleration relative to the command's (the speed error's finite
    /// difference from the last step), if the motion is steady (see [`BalancePointParams`]).
    /// Non-finite inputs are ignored; the first step after [`reset`](Self::reset) (or a
    /// non-finite speed) only records the speed error.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancePoint, BalancePointParams, BalanceSample};
    /// use nalgebra::Vector2;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut bp = BalancePoint::new(BalancePointParams::recommended(), &robot)?;
    /// let dt = 0.0025;
    /// // Braking after a push: the ball slows at 0.2 m/s^2 (1.6 rad/s^2) on the lean that
    /// // decelerates it, slowly enough to pass every steadiness gate. Not a balance point.
    /// let k = bp.lean_per_ball_accel_s2()[1];
    /// let (accel, mut rate) = (-1.6, 4.0);
    /// for _ in 0..800 {
    ///     rate += accel * dt;
    ///     let braking = BalanceSample {
    ///         tilt_rad: Vector2::new(0.0, k * accel),
    ///         ball_rate_rad_per_s: Vector2::new(0.0, rate),
    ///         ..BalanceSample::still()
    ///     };
    ///     bp.update(&braking, dt);
    /// }
    /// // (Only while the acceleration's low-pass settles, 0.1 s, is a little learnt.)
    /// assert!(bp.offset_rad()[1].abs() < 1e-3, "{}", bp.offset_rad()[1]);
    /// // A fast tilt rate: a push, not a balance point; NaN changes nothing either.
    /// let pushed = BalanceSample { tilt_rate_rad_per_s: Vector2::new(0.5, 0.0), ..BalanceSample::still() };
    /// bp.update(&pushed, dt);
    /// let nan = BalanceSample { tilt_rad: Vector2::new(f64::NAN, 0.0), ..BalanceSample::still() };
    /// bp.update(&nan, dt);
    /// assert!(bp.offset_rad()[0].abs() < 1e-3);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn update(&mut self, sample: &BalanceSample<T>, dt_secs: T) {
        let p = &self.params;
        let rate_error = sample.ball_rate_rad_per_s - sample.ball_rate_command_rad_per_s;
        let last = self.last_rate_error;
        self.last_rate_error = rate_error
            .iter()
            .all(|x| x.is_finite())
            .then_some(rate_error);
        let departure = sample.tilt_rad - sample.tilt_command_rad;
        let finite = departure.iter().all(|x| x.is_finite())
            && sample.tilt_rate_rad_per_s.iter().all(|x| x.is_finite())
            && sample.command_accel_m_per_s2.is_finite()
            && dt_secs.is_finite();
        let steady = finite
            && sample.command_accel_m_per_s2.abs() <= p.steady_accel_m_per_s2
            && sample
                .tilt_rate_rad_per_s
                .iter()
                .all(|w| w.abs() <= p.steady_tilt_rate_rad_per_s)
            && departure.iter().all(|d| d.abs() <= p.max_departure_rad);
        let (Some(last), Some(now)) = (last, self.last_rate_error) else {
            return;
        };
        if !(dt_secs.is_finite() && dt_secs > T::zero()) {
            return;
        }
        // The lean that accelerates the ball relative to the command is not a balance point.
        // A finite difference of encoder rates is noisy (a single step's can exceed the
        // departure bound): low-passed, on every step, learning or not.
        let raw = (now - last).component_mul(&self.lean_per_ball_accel_s2) / dt_secs;
        let filter_gain = (dt_secs / lit(Self::ACCEL_FILTER_SECS)).min(T::one());
        let filtered = self.accel_lean_rad + (raw - self.accel_lean_rad) * filter_gain;
        if filtered.iter().all(|x| x.is_finite()) {
            self.accel_lean_rad = filtered;
        }
        if !p.enabled || !steady {
            return;
        }
        let learnt = departure - self.accel_lean_rad;
        // Within the same bound: the onset of a push accelerates the ball before the tilt
        // rates show it.
        if !learnt.iter().all(|d| d.abs() <= p.max_departure_rad) {
            return;
        }
        let gain = (dt_secs / p.time_constant_secs).min(T::one());
        for (o, d) in self.offset_rad.iter_mut().zip(learnt.iter()) {
            let next = *o + gain * (*d - *o);
            *o = next.max(-p.max_offset_rad).min(p.max_offset_rad);
        }
    }
}
