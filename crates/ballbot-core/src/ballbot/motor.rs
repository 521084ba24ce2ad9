//! The inner loop (motor drivers, 8 kHz): [`MotorSpeedLoop`], one speed PI per omniwheel within
//! the actuator's torque-speed limits.

use super::{BallbotControllerConfig, MotorReferences, SpeedGuard};
use crate::check::{lit, positive};
use crate::control::{SpeedCommand, SpeedPi, SpeedPiGains};
use crate::num::{max, min};
use crate::rates::INNER_LOOP_DT_SECS;
use crate::safety::Fault;
use crate::{ActuatorParams, Error};
use nalgebra::{RealField, Vector3};

/// One inner step's result.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
/// use nalgebra::Vector3;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut inner = MotorSpeedLoop::new(&config)?;
/// inner.set_references(&MotorReferences {
///     enabled: true,
///     speed_rad_per_s: Vector3::new(50.0, 0.0, 0.0),
///     accel_rad_per_s2: Vector3::zeros(),
///     feedforward_torque_nm: Vector3::new(40.0, 0.0, 0.0),
/// });
/// // 40 N m asked of wheel 1 at 50 rad/s: near its 62 rad/s no-load speed it gives 8.4 N m.
/// let out = inner.step(&Vector3::new(50.0, 0.0, 0.0), 1.25e-4);
/// approx::assert_relative_eq!(out.torque_nm[0], 43.2 * (1.0 - 50.0 / 62.0), epsilon = 1e-9);
/// assert!(out.saturation_nm[0] < 0.0 && !out.timed_out);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnerOutput<T: nalgebra::Scalar> {
    /// Omniwheel torques to apply (N m, at the omniwheel; divide by the gear ratio for the
    /// rotor), finite and within the actuator's torque-speed limits.
    pub torque_nm: Vector3<T>,
    /// Applied minus requested torque per wheel (N m): nonzero when saturated.
    pub saturation_nm: Vector3<T>,
    /// The reference speeds used in this step (rad/s).
    pub reference_speed_rad_per_s: Vector3<T>,
    /// Whether the references were older than the timeout (torque 0, integrators cleared).
    pub timed_out: bool,
    /// A fault of the encoders seen by the guards ([`SpeedGuard`]), for the supervisor
    /// ([`crate::ballbot::BallbotController::report`]):
    /// [`Fault::EncoderImplausible`] once a guard has held for longer than
    /// [`SpeedGuard::RESYNC_STEPS`] without a plausible trajectory to follow,
    /// [`Fault::EncoderStale`] once that has lasted the reference timeout (the supervisor's
    /// encoder timeout, 20 ms). `None` otherwise.
    pub encoder_fault: Option<Fault>,
}

/// The inner loop: one speed PI per omniwheel, as the motor drivers run it (see the module
/// docs).
///
/// Each outer period, hand it the new references ([`Self::set_references`]); then call
/// [`Self::step`] at the inner rate. The reference speed ramps with the references'
/// acceleration for at most one outer period (then holds), and references older than
/// [`Self::REFERENCE_TIMEOUT_PERIODS`] outer periods switch the torque off (the main
/// controller is gone; nothing can balance without it).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
/// use nalgebra::Vector3;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut inner = MotorSpeedLoop::new(&config)?;
/// let references = MotorReferences {
///     enabled: true,
///     speed_rad_per_s: Vector3::new(1.0, -0.5, -0.5),
///     accel_rad_per_s2: Vector3::zeros(),
///     feedforward_torque_nm: Vector3::new(2.0, -1.0, -1.0),
/// };
/// inner.set_references(&references);
/// // On reference speed the drivers apply the feedforward torque.
/// let out = inner.step(&references.speed_rad_per_s, 1.25e-4);
/// approx::assert_relative_eq!(out.torque_nm, references.feedforward_torque_nm, epsilon = 1e-12);
/// // The main controller goes silent: after 8 outer periods (20 ms) the torque is switched off.
/// let mut steps_with_torque = 1;
/// while !inner.step(&references.speed_rad_per_s, 1.25e-4).timed_out {
///     steps_with_torque += 1;
/// }
/// assert_eq!(steps_with_torque, 160); // 160 inner steps of 125 us = 20 ms
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorSpeedLoop<T: RealField + Copy> {
    motors: [MotorSpeedPi<T>; 3],
    guards: [SpeedGuard<T>; 3],
    references: MotorReferences<T>,
    outer_dt_secs: T,
    /// Time since the references were set (s), capped just beyond the timeout.
    elapsed_secs: T,
    /// The last plausible step length (s): what an impossible one is replaced by.
    last_dt_secs: T,
}

impl<T: RealField + Copy> MotorSpeedLoop<T> {
    /// How many outer periods a reference stays valid without an update.
    ///
    /// ```
    /// use ballbot_core::ballbot::MotorSpeedLoop;
    /// assert_eq!(MotorSpeedLoop::<f64>::REFERENCE_TIMEOUT_PERIODS * 2.5, 20.0); // ms at 400 Hz
    /// ```
    pub const REFERENCE_TIMEOUT_PERIODS: f64 = 8.0;

    /// The largest omniwheel acceleration the encoder guard believes (rad/s^2): about four
    /// times what MiaPURE's can do (43.2 N m of motor and some 13 N m of traction on a
    /// reflected 9.6e-3 kg m^2: 5,850 rad/s^2). See [`SpeedGuard`]; another robot sets its own
    /// with [`Self::with_max_wheel_accel_rad_per_s2`].
    ///
    /// ```
    /// use ballbot_core::ballbot::MotorSpeedLoop;
    /// assert_eq!(MotorSpeedLoop::<f64>::MAX_WHEEL_ACCEL_RAD_PER_S2, 20_000.0);
    /// ```
    pub const MAX_WHEEL_ACCEL_RAD_PER_S2: f64 = 20_000.0;

    /// Three PIs with `config.motor` gains and the robot's actuator limits; motors disabled
    /// until the first references.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotControllerConfig, MotorSpeedLoop};
    /// use nalgebra::Vector3;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut inner = MotorSpeedLoop::new(&config)?;
    /// // Disabled until the first references arrive.
    /// assert_eq!(inner.step(&Vector3::zeros(), 1.25e-4).torque_nm, Vector3::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(config: &BallbotControllerConfig<T>) -> Result<Self, Error> {
        let motor = MotorSpeedPi::new(config.motor, &config.robot.drivetrain.actuator)?;
        positive(config.outer_dt_secs, "outer_dt_secs")?;
        let guard = SpeedGuard::new(
            lit(Self::MAX_WHEEL_ACCEL_RAD_PER_S2),
            config.safety.encoder_range_rad_per_s,
        );
        Ok(Self {
            motors: [motor; 3],
            guards: [guard; 3],
            references: MotorReferences::disabled(),
            outer_dt_secs: config.outer_dt_secs,
            elapsed_secs: T::zero(),
            last_dt_secs: min(lit(INNER_LOOP_DT_SECS), config.outer_dt_secs),
        })
    }

    /// Clears the integrators.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
    /// use nalgebra::Vector3;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut inner = MotorSpeedLoop::new(&config)?;
    /// let references = MotorReferences {
    ///     enabled: true,
    ///     speed_rad_per_s: Vector3::new(1.0, 1.0, 1.0),
    ///     accel_rad_per_s2: Vector3::zeros(),
    ///     feedforward_torque_nm: Vector3::zeros(),
    /// };
    /// inner.set_references(&references);
    /// let slow = Vector3::new(0.5, 0.5, 0.5);
    /// let first = inner.step(&slow, 1.25e-4).torque_nm; // P only
    /// let later = inner.step(&slow, 1.25e-4).torque_nm; // P plus the integral built up
    /// assert!(later[0] > first[0]);
    /// inner.reset();
    /// assert_eq!(inner.step(&slow, 1.25e-4).torque_nm, first);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        for motor in &mut self.motors {
            motor.reset();
        }
        for guard in &mut self.guards {
            guard.reset();
        }
    }

    /// This loop with the encoder guard believing wheel accelerations up to
    /// `max_accel_rad_per_s2` (see [`SpeedGuard`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotControllerConfig, MotorSpeedLoop};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let inner = MotorSpeedLoop::new(&config)?.with_max_wheel_accel_rad_per_s2(50_000.0)?;
    /// assert!(MotorSpeedLoop::new(&config)?.with_max_wheel_accel_rad_per_s2(-1.0).is_err());
    /// # let _ = inner;
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn with_max_wheel_accel_rad_per_s2(
        mut self,
        max_accel_rad_per_s2: T,
    ) -> Result<Self, Error> {
        positive(max_accel_rad_per_s2, "max_accel_rad_per_s2")?;
        let range = self.guards[0].range_rad_per_s();
        self.guards = [SpeedGuard::new(max_accel_rad_per_s2, range); 3];
        Ok(self)
    }

    /// Takes the outer loop's new references (the ramp restarts). References with a
    /// non-finite number disable the motors.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
    /// use nalgebra::Vector3;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut inner = MotorSpeedLoop::new(&config)?;
    /// // References with a NaN (a corrupted message) disable the motors.
    /// inner.set_references(&MotorReferences {
    ///     enabled: true,
    ///     speed_rad_per_s: Vector3::new(f64::NAN, 0.0, 0.0),
    ///     accel_rad_per_s2: Vector3::zeros(),
    ///     feedforward_torque_nm: Vector3::new(5.0, 5.0, 5.0),
    /// });
    /// assert_eq!(inner.step(&Vector3::zeros(), 1.25e-4).torque_nm, Vector3::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn set_references(&mut self, references: &MotorReferences<T>) {
        let finite = |v: &Vector3<T>| v.iter().all(|x| x.is_finite());
        self.references = if finite(&references.speed_rad_per_s)
            && finite(&references.accel_rad_per_s2)
            && finite(&references.feedforward_torque_nm)
        {
            *references
        } else {
            MotorReferences::disabled()
        };
        self.elapsed_secs = T::zero();
    }

    /// One inner step of `dt_secs` with the measured omniwheel speeds (rad/s). Disabled or
    /// timed-out references give zero torque and clear the integrators. A step length no loop
    /// could have (not finite, not positive, or longer than an outer period) is replaced by
    /// the last plausible one (125 us before the first).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
    /// use nalgebra::Vector3;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut inner = MotorSpeedLoop::new(&config)?;
    /// inner.set_references(&MotorReferences {
    ///     enabled: true,
    ///     speed_rad_per_s: Vector3::new(3.0, 3.0, 3.0),
    ///     accel_rad_per_s2: Vector3::zeros(),
    ///     feedforward_torque_nm: Vector3::zeros(),
    /// });
    /// // Every wheel 1 rad/s slow: each driver pushes with kp * 1 rad/s (the integral starts
    /// // at 0).
    /// let out = inner.step(&Vector3::new(2.0, 2.0, 2.0), 1.25e-4);
    /// let kp = config.motor.proportional_nm_s_per_rad;
    /// assert!(out.torque_nm.iter().all(|t| (t - kp).abs() < 1e-12));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(&mut self, wheel_speeds_rad_per_s: &Vector3<T>, dt_secs: T) -> InnerOutput<T> {
        let mut out = InnerOutput {
            torque_nm: Vector3::zeros(),
            saturation_nm: Vector3::zeros(),
            reference_speed_rad_per_s: Vector3::zeros(),
            timed_out: false,
            encoder_fault: None,
        };
        let timeout = self.outer_dt_secs * lit(Self::REFERENCE_TIMEOUT_PERIODS);
        out.timed_out = self.elapsed_secs > timeout;
        if !self.references.enabled || out.timed_out {
            self.reset();
            return out;
        }
        let dt_secs = self.plausible_step(dt_secs);
        // Reference at the middle of this step, ramping for one outer period at most.
        let t = min(self.elapsed_secs + dt_secs * lit(0.5), self.outer_dt_secs);
        let r = &self.references;
        for (i, (motor, guard)) in self.motors.iter_mut().zip(&mut self.guards).enumerate() {
            let reference = r.speed_rad_per_s[i] + r.accel_rad_per_s2[i] * t;
            let measured = wheel_speeds_rad_per_s[i];
            // Just enabled: the guard starts from the outer loop's reference, not from
            // whatever the encoder reads first.
            guard.seed(reference);
            let guarded = guard.filter(measured, dt_secs);
            // The torque-speed line where the wheel is, if that is known; the error against
            // the guarded speed.
            let line = if measured.is_finite() {
                measured
            } else {
                guarded
            };
            let (torque, saturation) = motor.step_split(
                reference,
                r.feedforward_torque_nm[i],
                guarded,
                line,
                dt_secs,
            );
            out.torque_nm[i] = torque;
            out.saturation_nm[i] = saturation;
            out.reference_speed_rad_per_s[i] = reference;
        }
        self.elapsed_secs = min(self.elapsed_secs + dt_secs, timeout + dt_secs);
        out.encoder_fault = self.encoder_fault(dt_secs, timeout);
        out
    }

    /// `dt_secs` if a loop could have stepped it (finite, positive, at most an outer period);
    /// otherwise the last such step. A step longer than an outer period would wind the
    /// integrators up; taking an impossible one as zero length gave no torque for as long as
    /// it lasted (a whole outer period cut the wheels' torque for 2.5 ms: the fuzzer found
    /// both). A timer that really changed rate is followed on its first plausible step.
    fn plausible_step(&mut self, dt_secs: T) -> T {
        if dt_secs.is_finite() && dt_secs > T::zero() && dt_secs <= self.outer_dt_secs {
            self.last_dt_secs = dt_secs;
        }
        self.last_dt_secs
    }

    /// The guards' verdict on the encoders: implausible past the hold, stale past `timeout`.
    fn encoder_fault(&self, dt_secs: T, timeout_secs: T) -> Option<Fault> {
        let worst = self
            .guards
            .iter()
            .filter(|g| g.implausible())
            .map(SpeedGuard::rejected_steps)
            .max()?;
        let held_secs = nalgebra::convert::<f64, T>(f64::from(worst)) * dt_secs;
        Some(if held_secs > timeout_secs {
            Fault::EncoderStale
        } else {
            Fault::EncoderImplausible
        })
    }
}

/// One motor driver's speed PI: a [`SpeedPi`] within the actuator's torque-speed limits at the
/// measured speed (the same limits as [`ActuatorParams::torque_bounds_nm`], with the slope
/// `peak / no_load_speed` precomputed: this runs at 8 kHz).
///
/// ```
/// use ballbot_core::ActuatorParams;
/// use ballbot_core::ballbot::MotorSpeedPi;
/// use ballbot_core::control::SpeedPiGains;
/// let gains = SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?;
/// let mut motor = MotorSpeedPi::new(gains, &ActuatorParams::miapure())?;
/// // Far too slow at 31 rad/s (half the no-load speed): only 21.6 N m forward are available.
/// let (torque_nm, saturation_nm) = motor.step(60.0, 0.0, 31.0, 1.25e-4);
/// approx::assert_relative_eq!(torque_nm, 21.6, epsilon = 1e-9);
/// assert!(saturation_nm < 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorSpeedPi<T: RealField + Copy> {
    pi: SpeedPi<T>,
    peak_torque_nm: T,
    /// `peak / no_load_speed` (N m s/rad).
    torque_drop_nm_s_per_rad: T,
    /// The smaller of the peak and the PI's symmetric limit (N m): the bounds the PI applies.
    limit_nm: T,
}

impl<T: RealField + Copy> MotorSpeedPi<T> {
    /// Validates the gains and the actuator.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::ballbot::MotorSpeedPi;
    /// use ballbot_core::control::SpeedPiGains;
    /// let gains = SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?;
    /// assert!(MotorSpeedPi::new(gains, &ActuatorParams::miapure()).is_ok());
    /// let no_speed = ActuatorParams { no_load_speed_rad_per_s: 0.0, ..ActuatorParams::miapure() };
    /// assert!(MotorSpeedPi::new(gains, &no_speed).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(gains: SpeedPiGains<T>, actuator: &ActuatorParams<T>) -> Result<Self, Error> {
        actuator.validate()?;
        let peak = actuator.peak_torque_nm;
        Ok(Self {
            pi: SpeedPi::new(gains)?,
            peak_torque_nm: peak,
            torque_drop_nm_s_per_rad: peak / actuator.no_load_speed_rad_per_s,
            limit_nm: min(peak, gains.max_torque_nm),
        })
    }

    /// Clears the integrator.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::ballbot::MotorSpeedPi;
    /// use ballbot_core::control::SpeedPiGains;
    /// let gains = SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?;
    /// let mut motor = MotorSpeedPi::new(gains, &ActuatorParams::miapure())?;
    /// let first = motor.step(1.0, 0.0, 0.0, 1.25e-4).0;
    /// motor.step(1.0, 0.0, 0.0, 1.25e-4);
    /// motor.reset();
    /// assert_eq!(motor.step(1.0, 0.0, 0.0, 1.25e-4).0, first); // the integral starts again at 0
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.pi.reset();
    }

    /// The torque range `(min, max)` (N m) at `speed_rad_per_s`: the peak against the motion,
    /// the torque-speed line along it. A NaN speed gives `(0, 0)`; an infinite one allows
    /// braking only.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::ballbot::MotorSpeedPi;
    /// use ballbot_core::control::SpeedPiGains;
    /// let actuator = ActuatorParams::<f64>::miapure();
    /// let motor = MotorSpeedPi::new(SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?, &actuator)?;
    /// // The same limits as the actuator's: full peak to brake, the torque-speed line to drive.
    /// for speed in [-70.0, -31.0, 0.0, 10.0, 61.0] {
    ///     let (lower, upper) = motor.torque_bounds_nm(speed);
    ///     let (lower_ref, upper_ref) = actuator.torque_bounds_nm(speed);
    ///     approx::assert_relative_eq!(lower, lower_ref, epsilon = 1e-12);
    ///     approx::assert_relative_eq!(upper, upper_ref, epsilon = 1e-12);
    /// }
    /// assert_eq!(motor.torque_bounds_nm(f64::NAN), (0.0, 0.0));
    /// assert_eq!(motor.torque_bounds_nm(f64::INFINITY), (-43.2, 0.0)); // braking only
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[inline]
    pub fn torque_bounds_nm(&self, speed_rad_per_s: T) -> (T, T) {
        // Plain comparisons instead of `max`/`min` (NaN-aware, several instructions each):
        // a NaN speed fails both sign tests below.
        let peak = self.peak_torque_nm;
        let line = peak - self.torque_drop_nm_s_per_rad * speed_rad_per_s.abs();
        let motoring = if line > T::zero() { line } else { T::zero() };
        if speed_rad_per_s >= T::zero() {
            (-peak, motoring)
        } else if speed_rad_per_s < T::zero() {
            (-motoring, peak)
        } else {
            (T::zero(), T::zero())
        }
    }

    /// One step: returns `(torque_nm, saturation_nm)`, the torque finite and within
    /// [`Self::torque_bounds_nm`] at the measured speed (0 for any non-finite input).
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::ballbot::MotorSpeedPi;
    /// use ballbot_core::control::SpeedPiGains;
    /// let gains = SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?;
    /// let mut motor = MotorSpeedPi::new(gains, &ActuatorParams::miapure())?;
    /// // On reference: the feedforward passes through.
    /// assert_eq!(motor.step(3.0, 7.5, 3.0, 1.25e-4), (7.5, 0.0));
    /// // A NaN encoder reading: no torque.
    /// assert_eq!(motor.step(3.0, 7.5, f64::NAN, 1.25e-4), (0.0, 0.0));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[inline]
    pub fn step(
        &mut self,
        reference_speed_rad_per_s: T,
        feedforward_torque_nm: T,
        measured_speed_rad_per_s: T,
        dt_secs: T,
    ) -> (T, T) {
        self.step_split(
            reference_speed_rad_per_s,
            feedforward_torque_nm,
            measured_speed_rad_per_s,
            measured_speed_rad_per_s,
            dt_secs,
        )
    }

    /// [`Self::step`] with the speed error taken at `pi_speed_rad_per_s` (the guarded
    /// speed, [`super::SpeedGuard`]) and the torque-speed line at `line_speed_rad_per_s` (the
    /// measured one, where finite).
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::ballbot::MotorSpeedPi;
    /// use ballbot_core::control::SpeedPiGains;
    /// let gains = SpeedPiGains::from_bandwidth(5.0, 30.0, 43.2)?;
    /// let mut motor = MotorSpeedPi::new(gains, &ActuatorParams::miapure())?;
    /// // On reference by the guarded speed, near the no-load speed by the measured one: the
    /// // feedforward is cut to what the line allows there.
    /// let (torque, _) = motor.step_split(3.0, 7.5, 3.0, 61.0, 1.25e-4);
    /// assert!(torque < 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[inline]
    pub fn step_split(
        &mut self,
        reference_speed_rad_per_s: T,
        feedforward_torque_nm: T,
        pi_speed_rad_per_s: T,
        line_speed_rad_per_s: T,
        dt_secs: T,
    ) -> (T, T) {
        // The range `SpeedPi::step_within` would apply to `Self::torque_bounds_nm`, computed
        // directly against the prepared `limit_nm` (the motoring side never exceeds the peak)
        // with plain min/max, and the PI law without re-checking it. A non-finite speed makes
        // the speed error, and the request, non-finite: the PI rejects it (zero torque).
        let speed = line_speed_rad_per_s;
        let limit = self.limit_nm;
        let line = self.peak_torque_nm - self.torque_drop_nm_s_per_rad * speed.abs();
        let motoring = max(T::zero(), min(limit, line));
        let (lower, upper) = if speed >= T::zero() {
            (-limit, motoring)
        } else {
            (-motoring, limit)
        };
        let out = self.pi.step_in_range(
            pi_speed_rad_per_s,
            &SpeedCommand {
                speed_rad_per_s: reference_speed_rad_per_s,
                feedforward_torque_nm,
            },
            dt_secs,
            lower,
            upper,
        );
        // Finite and within [lower, upper] (the PI's contract; zero torque when rejected).
        (out.torque_nm, out.saturation_nm)
    }
}
