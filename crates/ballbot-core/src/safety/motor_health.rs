//! Motor health: a dead, stuck or tripped motor driver, found from the drivers' own feedback
//! ([`crate::hal::MotorFeedback`]) in the 8 kHz inner task.
//!
//! # What a healthy driver reports
//!
//! Per wheel and inner step, the feedback received with setpoint `c_k` answers the previous
//! setpoint `c_{k-1}` (a bus round trip). A healthy driver's measured torque `r` then lies in
//! the band
//!
//! ```text
//!   [min(e, c_{k-1}) - tol, max(e, c_{k-1}) + tol],   e_k = e_{k-1} + a (c_{k-1} - e_{k-1})
//! ```
//!
//! where `e` is the setpoint through the current loop, a first-order lag at its bandwidth
//! `w_c` (`a = 1 - exp(-w_c dt)`): anything between a driver as fast as the setpoint and one
//! as slow as its current loop is healthy, so no command step or fast transient reads as a
//! fault. Where the command asks for more than the driver can give, the band's inner edge
//! is the driver's envelope instead: with the actuator's straight torque-speed line (peak
//! `T_p`, no-load speed `w_0` at the nominal bus voltage `V_0`) and the driver's modulation
//! limit `m` at the reported bus voltage `V` and wheel speed `w`, a healthy driver delivers at
//! least
//!
//! ```text
//!   b+ = T_p min(1, m V / V_0 - max(w, 0) / w_0)    (positive torque)
//!   b- = T_p min(1, m V / V_0 - max(-w, 0) / w_0)   (negative torque, as a magnitude)
//! ```
//!
//! the voltage-limited line of a surface PM motor at modulation `m` (the ODrive 0.5.x's
//! `0.8`) when the torque drives the wheel's motion, capped by the current limit `T_p`;
//! beyond the back-EMF speed `b+` is negative (the motor brakes whatever it is told), and the
//! band admits that too. Braking, the back-EMF helps the current, which the bound leaves out
//! (it stays at the stall line, a lower bound). A sagging bus shrinks the envelope; the
//! reported bus voltage says so.
//!
//! The tolerance `tol = torque_tolerance_nm + torque_tolerance_ratio x max(|e|, |c|)` covers the
//! current sense's offset and noise, cogging and torque ripple (the absolute part, 5 % of
//! the peak by default) and the torque constant's spread with magnet temperature (the
//! relative part, 10 %: NdFeB loses about 0.1 %/K, an 80 K rise is 8 %).
//!
//! # Verdicts and latency
//!
//! - **Tripped** ([`Fault::MotorTripped`]): any [`crate::hal::DriverErrors`] flag, at the first
//!   report that carries it (the drivers latch their errors).
//! - **Dead** ([`Fault::MotorDead`]): the measured torque outside the band for
//!   `persistence_secs` without interruption, reporting less than the tolerance's absolute
//!   part (the driver applies nothing while a torque is commanded).
//! - **Stuck** ([`Fault::MotorStuck`]): outside the band as long, reporting a torque (it does
//!   not follow the command), or a non-finite one.
//!
//! The persistence is 5 ms (40 inner steps at 8 kHz) by default: the time for the current
//! loop's response to the largest possible setpoint step (`2 T_p`) to settle within the
//! absolute tolerance, `ln(2 T_p / tol) / w_c = ln(40) / 1000 rad/s = 3.7 ms`, rounded up. A
//! dead, stuck or tripped motor is therefore flagged within `persistence_secs` plus one inner
//! step (the feedback's delay) of its torque leaving the band: at once for a tripped driver,
//! 5.1 ms for a dead or stuck one. The band leaves out a dead motor's zero once the setpoint
//! and its lagged response both exceed the tolerance: a motor that dies while it carries a
//! torque is flagged 5.1 ms later; one that is only then asked for a torque adds the current
//! loop's rise to the tolerance, `ln(c / (c - tol)) / w_c` (0.5 ms for 10 N m). A dead motor
//! commanded less than the tolerance cannot be told from a healthy one, and need not be.
//!
//! ```
//! use ballbot_core::ActuatorParams;
//! use ballbot_core::hal::MotorFeedback;
//! use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams};
//! use nalgebra::Vector3;
//! let params = MotorHealthParams::<f64>::for_actuator(&ActuatorParams::miapure());
//! let mut monitor = MotorHealthMonitor::new(params, 1.0 / 8000.0)?;
//! let command = Vector3::new(10.0, -4.0, 2.0);
//! // The drivers deliver for 10 ms ...
//! let delivered = [10.0, -4.0, 2.0].map(|t| MotorFeedback::healthy(t, 0.0, 45.0));
//! for _ in 0..80 {
//!     assert_eq!(monitor.step(&command, &delivered), None);
//! }
//! // ... then OW1 reports nothing while 10 N m are commanded.
//! let dead = [0.0, -4.0, 2.0].map(|t| MotorFeedback::healthy(t, 0.0, 45.0));
//! let mut steps = 0;
//! let verdict = loop {
//!     steps += 1;
//!     if let Some(v) = monitor.step(&command, &dead) {
//!         break v;
//!     }
//! };
//! assert_eq!((verdict.fault, verdict.wheel), (Fault::MotorDead, 0));
//! assert_eq!(steps, 40); // 5 ms at 8 kHz
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use super::Fault;
use crate::check::{lit, non_negative, positive};
use crate::hal::MotorFeedback;
use crate::{ActuatorParams, Error};
use nalgebra::{RealField, Vector3};

/// The ODrive firmware's default `motor.config.current_control_bandwidth` (rad/s).
///
/// ```
/// use ballbot_core::safety::{MotorHealthParams, ODRIVE_CURRENT_BANDWIDTH_RAD_PER_S};
/// let p = MotorHealthParams::<f64>::miapure();
/// assert_eq!(p.current_bandwidth_rad_per_s, ODRIVE_CURRENT_BANDWIDTH_RAD_PER_S);
/// ```
pub const ODRIVE_CURRENT_BANDWIDTH_RAD_PER_S: f64 = 1000.0;

/// The ODrive 0.5.x's modulation limit (fraction of the linear space-vector range, `foc.cpp`).
///
/// ```
/// use ballbot_core::safety::{MotorHealthParams, ODRIVE_MAX_MODULATION};
/// assert!(ODRIVE_MAX_MODULATION > 0.0 && ODRIVE_MAX_MODULATION <= 1.0);
/// assert_eq!(MotorHealthParams::<f64>::miapure().max_modulation, ODRIVE_MAX_MODULATION);
/// ```
pub const ODRIVE_MAX_MODULATION: f64 = 0.8;

/// The bus voltage at which MiaPURE's actuator line (43.2 N m, 62 rad/s) is stated (V, paper).
///
/// ```
/// use ballbot_core::safety::{MIAPURE_NOMINAL_BUS_VOLTAGE_V, MotorHealthParams};
/// let p = MotorHealthParams::<f64>::miapure();
/// assert_eq!(p.nominal_bus_voltage_v, MIAPURE_NOMINAL_BUS_VOLTAGE_V);
/// ```
pub const MIAPURE_NOMINAL_BUS_VOLTAGE_V: f64 = 45.0;

/// The [`MotorHealthMonitor`]'s model of a healthy driver and its thresholds (see the
/// [module](self) doc for how each enters).
///
/// ```
/// use ballbot_core::ActuatorParams;
/// use ballbot_core::safety::MotorHealthParams;
/// let p = MotorHealthParams::<f64>::for_actuator(&ActuatorParams::miapure());
/// approx::assert_relative_eq!(p.torque_tolerance_nm, 2.16, epsilon = 1e-12); // 5 % of 43.2
/// assert_eq!(p.persistence_secs, 0.005);
/// assert!(p.validate().is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorHealthParams<T> {
    /// The actuator's current limit at the omniwheel (N m): its peak torque.
    pub peak_torque_nm: T,
    /// The actuator's no-load speed at the omniwheel at `nominal_bus_voltage_v` and full
    /// modulation (rad/s).
    pub no_load_speed_rad_per_s: T,
    /// The bus voltage at which the actuator's line is stated (V).
    pub nominal_bus_voltage_v: T,
    /// The driver's largest modulation, a fraction of the linear range in (0, 1].
    pub max_modulation: T,
    /// The driver's current-loop bandwidth (rad/s).
    pub current_bandwidth_rad_per_s: T,
    /// Absolute torque tolerance (N m).
    pub torque_tolerance_nm: T,
    /// Relative torque tolerance (fraction of the commanded torque).
    pub torque_tolerance_ratio: T,
    /// How long the measured torque must stay outside the band before a verdict (s).
    pub persistence_secs: T,
}

impl<T: RealField + Copy> MotorHealthParams<T> {
    /// An ODrive v3.6 (firmware 0.5.x: current-loop bandwidth 1000 rad/s, modulation 0.8)
    /// driving `actuator` at MiaPURE's 45 V; tolerances 5 % of the peak torque plus 10 % of the
    /// command; persistence 5 ms (see the [module](self) doc).
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::safety::MotorHealthParams;
    /// let small = ActuatorParams {
    ///     gear_ratio: 5.0,
    ///     peak_torque_nm: 20.0,
    ///     no_load_speed_rad_per_s: 80.0,
    /// };
    /// let p = MotorHealthParams::for_actuator(&small);
    /// assert_eq!((p.peak_torque_nm, p.no_load_speed_rad_per_s), (20.0, 80.0));
    /// assert_eq!(p.torque_tolerance_nm, 1.0); // 5 % of the peak
    /// ```
    pub fn for_actuator(actuator: &ActuatorParams<T>) -> Self {
        Self {
            peak_torque_nm: actuator.peak_torque_nm,
            no_load_speed_rad_per_s: actuator.no_load_speed_rad_per_s,
            nominal_bus_voltage_v: lit(MIAPURE_NOMINAL_BUS_VOLTAGE_V),
            max_modulation: lit(ODRIVE_MAX_MODULATION),
            current_bandwidth_rad_per_s: lit(ODRIVE_CURRENT_BANDWIDTH_RAD_PER_S),
            torque_tolerance_nm: lit::<T>(0.05) * actuator.peak_torque_nm,
            torque_tolerance_ratio: lit(0.1),
            persistence_secs: lit(0.005),
        }
    }

    /// MiaPURE's actuator ([`Self::for_actuator`]).
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// use ballbot_core::safety::MotorHealthParams;
    /// let p = MotorHealthParams::<f64>::miapure();
    /// assert_eq!(p, MotorHealthParams::for_actuator(&ActuatorParams::miapure()));
    /// assert_eq!(p.peak_torque_nm, 43.2);
    /// ```
    pub fn miapure() -> Self {
        Self::for_actuator(&ActuatorParams::miapure())
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::safety::MotorHealthParams;
    /// let bad = MotorHealthParams { max_modulation: 1.5, ..MotorHealthParams::<f64>::miapure() };
    /// assert!(bad.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.peak_torque_nm, "peak_torque_nm")?;
        positive(self.no_load_speed_rad_per_s, "no_load_speed_rad_per_s")?;
        positive(self.nominal_bus_voltage_v, "nominal_bus_voltage_v")?;
        positive(self.max_modulation, "max_modulation")?;
        if self.max_modulation > T::one() {
            return Err(Error::invalid("max_modulation", "must be in (0, 1]"));
        }
        positive(
            self.current_bandwidth_rad_per_s,
            "current_bandwidth_rad_per_s",
        )?;
        positive(self.torque_tolerance_nm, "torque_tolerance_nm")?;
        non_negative(self.torque_tolerance_ratio, "torque_tolerance_ratio")?;
        positive(self.persistence_secs, "persistence_secs")?;
        Ok(())
    }
}

/// A motor-health verdict: which fault, on which wheel (0-based: OW1 is 0).
///
/// ```
/// use ballbot_core::hal::{DriverErrors, MotorFeedback};
/// use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams, MotorVerdict};
/// use nalgebra::Vector3;
/// // A one-step persistence: OW1 stuck at 20 N m, OW3 tripped; the trip is reported first.
/// let dt = 1.0 / 8000.0;
/// let params = MotorHealthParams { persistence_secs: dt, ..MotorHealthParams::miapure() };
/// let mut monitor = MotorHealthMonitor::<f64>::new(params, dt)?;
/// let ok = MotorFeedback::healthy(0.0, 0.0, 45.0);
/// let tripped = MotorFeedback { errors: DriverErrors::OVER_CURRENT, ..ok };
/// let fb = [MotorFeedback::healthy(20.0, 0.0, 45.0), ok, tripped];
/// let verdict = monitor.step(&Vector3::zeros(), &fb);
/// assert_eq!(verdict, Some(MotorVerdict { fault: Fault::MotorTripped, wheel: 2 }));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotorVerdict {
    /// [`Fault::MotorDead`], [`Fault::MotorStuck`] or [`Fault::MotorTripped`].
    pub fault: Fault,
    /// The wheel.
    pub wheel: usize,
}

/// One wheel's state.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WheelState<T> {
    /// The setpoint the next feedback answers (N m).
    last_command_nm: T,
    /// That setpoint through the current loop (N m).
    expected_nm: T,
    /// Consecutive inner steps outside the band.
    violations: u32,
}

/// Watches the three drivers' feedback against their setpoints (see the [module](self) doc).
/// O(1) per step, allocation-free, panic-free.
///
/// ```
/// use ballbot_core::hal::MotorFeedback;
/// use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams};
/// use nalgebra::Vector3;
/// let mut monitor = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
/// // OW2 reports 20 N m while nothing is commanded: stuck after 40 steps (5 ms).
/// let fb = [0.0, 20.0, 0.0].map(|t| MotorFeedback::healthy(t, 0.0, 45.0));
/// let verdicts: Vec<_> = (0..40).filter_map(|_| monitor.step(&Vector3::zeros(), &fb)).collect();
/// assert_eq!(verdicts.len(), 1);
/// assert_eq!((verdicts[0].fault, verdicts[0].wheel), (Fault::MotorStuck, 1));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorHealthMonitor<T> {
    params: MotorHealthParams<T>,
    /// `1 - exp(-w_c dt)`.
    lag_gain: T,
    /// `persistence_secs / dt`, rounded up, at least 1.
    persistence_steps: u32,
    wheels: [WheelState<T>; 3],
    /// Consecutive inner steps whose write failed (no feedback).
    unanswered_steps: u32,
}

impl<T: RealField + Copy> MotorHealthMonitor<T> {
    /// Validates `params` and `inner_dt_secs` (the period of [`Self::step`], > 0); starts with
    /// the motors at rest.
    ///
    /// ```
    /// use ballbot_core::safety::{MotorHealthMonitor, MotorHealthParams};
    /// let m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
    /// assert_eq!(m.persistence_steps(), 40);
    /// assert!(MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 0.0).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: MotorHealthParams<T>, inner_dt_secs: T) -> Result<Self, Error> {
        params.validate()?;
        positive(inner_dt_secs, "inner_dt_secs")?;
        let lag_gain = T::one() - (-params.current_bandwidth_rad_per_s * inner_dt_secs).exp();
        // Rounded up; 1e-6 absorbs the ratio's rounding (5 ms / 125 us is 40, not 40.000001).
        let steps = (params.persistence_secs / inner_dt_secs - lit(1e-6)).ceil();
        let persistence_steps = if steps >= lit(f64::from(u32::MAX)) {
            u32::MAX
        } else if steps >= T::one() {
            // In [1, u32::MAX): the conversion cannot fail.
            nalgebra::try_convert::<T, f64>(steps).map_or(u32::MAX, |s| s as u32)
        } else {
            1
        };
        Ok(Self {
            params,
            lag_gain,
            persistence_steps,
            wheels: [WheelState {
                last_command_nm: T::zero(),
                expected_nm: T::zero(),
                violations: 0,
            }; 3],
            unanswered_steps: 0,
        })
    }

    /// The thresholds.
    ///
    /// ```
    /// use ballbot_core::safety::{MotorHealthMonitor, MotorHealthParams};
    /// let m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
    /// assert_eq!(*m.params(), MotorHealthParams::miapure());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &MotorHealthParams<T> {
        &self.params
    }

    /// How many consecutive inner steps outside the band make a verdict.
    ///
    /// ```
    /// use ballbot_core::safety::{MotorHealthMonitor, MotorHealthParams};
    /// // 5 ms at 1 kHz is 5 steps.
    /// let m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0e-3)?;
    /// assert_eq!(m.persistence_steps(), 5);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn persistence_steps(&self) -> u32 {
        self.persistence_steps
    }

    /// Forgets the setpoints: the motors are off (call it whenever they are disabled).
    ///
    /// ```
    /// use ballbot_core::hal::MotorFeedback;
    /// use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams};
    /// use nalgebra::Vector3;
    /// let mut m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
    /// let c = Vector3::new(10.0, 0.0, 0.0);
    /// let fb = |t| [t, 0.0, 0.0].map(|t| MotorFeedback::healthy(t, 0.0, 45.0));
    /// (0..80).for_each(|_| assert!(m.step(&c, &fb(10.0)).is_none()));
    /// (0..39).for_each(|_| assert!(m.step(&c, &fb(0.0)).is_none())); // OW1 dead for 39 steps
    /// let mut off = m;
    /// off.reset(); // the motors were switched off: a zero torque is now expected
    /// assert_eq!(m.step(&c, &fb(0.0)).map(|v| v.fault), Some(Fault::MotorDead));
    /// assert_eq!(off.step(&c, &fb(0.0)), None);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        for w in &mut self.wheels {
            w.last_command_nm = T::zero();
            w.expected_nm = T::zero();
            w.violations = 0;
        }
        self.unanswered_steps = 0;
    }

    /// One inner step whose write to the drivers failed: no feedback came, and the drivers
    /// hold whatever they last received (the last setpoint [`Self::step`] took). Returns
    /// [`Fault::MotorUnanswered`] once the writes have failed for
    /// [`Self::persistence_steps`] steps in a row (5 ms at 8 kHz by default, the latency of
    /// a dead motor), and on every failing step after; an answered step ([`Self::step`]) or
    /// [`Self::reset`] starts the count again. A single failed write is a glitch; a driver
    /// that stays silent cannot be said to deliver anything.
    ///
    /// ```
    /// use ballbot_core::hal::MotorFeedback;
    /// use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams};
    /// use nalgebra::Vector3;
    /// let mut m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
    /// let fb = [MotorFeedback::healthy(0.0, 0.0, 45.0); 3];
    /// (0..39).for_each(|_| assert_eq!(m.unanswered(), None));
    /// assert_eq!(m.step(&Vector3::zeros(), &fb), None); // an answer: the count restarts
    /// (0..39).for_each(|_| assert_eq!(m.unanswered(), None));
    /// assert_eq!(m.unanswered(), Some(Fault::MotorUnanswered)); // 40 in a row: 5 ms
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn unanswered(&mut self) -> Option<Fault> {
        self.unanswered_steps = self.unanswered_steps.saturating_add(1);
        (self.unanswered_steps >= self.persistence_steps).then_some(Fault::MotorUnanswered)
    }

    /// One inner step: checks `feedback` (the reply to the previous setpoint) and takes the
    /// new setpoint `commanded_nm`. Returns the first wheel's verdict, if any (a tripped
    /// driver first, then the wheels in order).
    ///
    /// ```
    /// use ballbot_core::hal::{DriverErrors, MotorFeedback};
    /// use ballbot_core::safety::{Fault, MotorHealthMonitor, MotorHealthParams};
    /// use nalgebra::Vector3;
    /// let mut m = MotorHealthMonitor::<f64>::new(MotorHealthParams::miapure(), 1.0 / 8000.0)?;
    /// let mut fb = [MotorFeedback::healthy(0.0, 0.0, 45.0); 3];
    /// assert_eq!(m.step(&Vector3::zeros(), &fb), None);
    /// fb[1].errors = DriverErrors::BUS_UNDER_VOLTAGE; // a tripped driver is flagged at once
    /// let v = m.step(&Vector3::zeros(), &fb).unwrap();
    /// assert_eq!((v.fault, v.wheel), (Fault::MotorTripped, 1));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        commanded_nm: &Vector3<T>,
        feedback: &[MotorFeedback<T>; 3],
    ) -> Option<MotorVerdict> {
        self.unanswered_steps = 0;
        let mut verdict: Option<MotorVerdict> = None;
        // Indexed rather than zipped iterators (nalgebra's column iterator among them): the
        // iterators' bookkeeping was a fifth of this 8 kHz step.
        for wheel in 0..3 {
            let state = &mut self.wheels[wheel];
            let fault = check_wheel(
                &self.params,
                self.lag_gain,
                self.persistence_steps,
                state,
                &feedback[wheel],
            );
            state.last_command_nm = commanded_nm[wheel];
            if let Some(fault) = fault {
                let replace = match verdict {
                    None => true,
                    Some(v) => fault == Fault::MotorTripped && v.fault != Fault::MotorTripped,
                };
                if replace {
                    verdict = Some(MotorVerdict { fault, wheel });
                }
            }
        }
        verdict
    }
}

/// One wheel's check against the setpoint the feedback answers (its lag state advanced first).
fn check_wheel<T: RealField + Copy>(
    p: &MotorHealthParams<T>,
    lag_gain: T,
    persistence_steps: u32,
    state: &mut WheelState<T>,
    fb: &MotorFeedback<T>,
) -> Option<Fault> {
    let c = state.last_command_nm;
    let e = state.expected_nm + lag_gain * (c - state.expected_nm);
    // A non-finite command (it never is: the inner loop's output is finite) restarts the lag.
    state.expected_nm = if e.is_finite() { e } else { T::zero() };
    if !fb.errors.is_empty() {
        state.violations = state.violations.saturating_add(1);
        return Some(Fault::MotorTripped);
    }
    let r = fb.torque_nm;
    if in_band(p, state.expected_nm, c, fb) {
        state.violations = 0;
        return None;
    }
    state.violations = state.violations.saturating_add(1);
    if state.violations < persistence_steps {
        return None;
    }
    Some(if r.is_finite() && r.abs() <= p.torque_tolerance_nm {
        Fault::MotorDead
    } else {
        Fault::MotorStuck
    })
}

/// Whether the measured torque lies in the healthy band for setpoint `c` and its lagged
/// response `e` (see the [module](self) doc). A non-finite report is never in it.
fn in_band<T: RealField + Copy>(
    p: &MotorHealthParams<T>,
    e: T,
    c: T,
    fb: &MotorFeedback<T>,
) -> bool {
    let r = fb.torque_nm;
    if !r.is_finite() {
        return false;
    }
    let (mut lo, mut hi) = if e < c { (e, c) } else { (c, e) };
    let tol = p.torque_tolerance_nm + p.torque_tolerance_ratio * lo.abs().max(hi.abs());
    // A healthy driver delivers the demand clamped to `[-b-, b+]`: short of a demand beyond
    // its envelope, and braking beyond the back-EMF speed (`b+ < 0`) whatever the demand.
    let (b_plus, b_minus) = envelope_floor_nm(p, fb);
    lo = lo.min(b_plus);
    hi = hi.max(-b_minus);
    r >= lo - tol && r <= hi + tol
}

/// The least torque a healthy driver delivers in each direction, `(b+, b-)` (N m; see the
/// [module](self) doc). Unknown voltage or speed (non-finite) gives 0: no envelope claimed.
fn envelope_floor_nm<T: RealField + Copy>(
    p: &MotorHealthParams<T>,
    fb: &MotorFeedback<T>,
) -> (T, T) {
    let v = fb.bus_voltage_v;
    let w = fb.speed_rad_per_s;
    if !(v.is_finite() && w.is_finite()) || v <= T::zero() {
        return (T::zero(), T::zero());
    }
    let head = p.max_modulation * v / p.nominal_bus_voltage_v;
    let s = w / p.no_load_speed_rad_per_s;
    let (zero, one) = (T::zero(), T::one());
    (
        p.peak_torque_nm * (head - s.max(zero)).min(one),
        p.peak_torque_nm * (head + s.min(zero)).min(one),
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
