//! One fuzzed controller in closed loop: the 3D controller's outer step, the motor speed PIs
//! at 8 kHz and the plant, with the invariants checked on every step.

use super::plant::Plant;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::{
    BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput, OuterOutput,
};
use ballbot_core::safety::{FaultSet, Mode, ModeRequest, Severity};
use nalgebra::Vector3;

/// Inner steps per outer step (8 kHz over 400 Hz).
pub const INNER_PER_OUTER: usize = 20;

/// The inner-rate fault of one outer period: a corrupted encoder sample at one inner step, or
/// a corrupted step length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InnerFault {
    /// Wheel `wheel`'s speed at inner step `step` reads `value`.
    Encoder {
        /// Inner step (0..20).
        step: usize,
        /// Wheel (0..3).
        wheel: usize,
        /// The value read (rad/s).
        value: f64,
    },
    /// Every inner step of this period is given `dt_secs`.
    Dt {
        /// The step length passed (s).
        dt_secs: f64,
    },
}

/// What one outer period did.
#[derive(Clone, Copy, Debug)]
pub struct Period {
    /// The outer step's output.
    pub out: OuterOutput<f64>,
    /// The applied wheel torques of each inner step (zero while the motors are off).
    pub torques: [Vector3<f64>; INNER_PER_OUTER],
    /// The first broken invariant, if any.
    pub broken: Option<&'static str>,
}

/// Controller, motor loop and plant.
#[derive(Clone, Copy, Debug)]
pub struct FuzzRig {
    /// The configuration.
    pub config: BallbotControllerConfig<f64>,
    /// The outer loop.
    pub controller: BallbotController<f64>,
    /// The motor speed PIs.
    pub inner: MotorSpeedLoop<f64>,
    /// The plant.
    pub plant: Plant,
}

impl FuzzRig {
    /// The rig of `config` on its robot.
    pub fn new(config: BallbotControllerConfig<f64>) -> Result<Self, ballbot_core::Error> {
        Ok(Self {
            config,
            controller: BallbotController::new(config)?,
            inner: MotorSpeedLoop::new(&config)?,
            plant: Plant::new(&config.robot)?,
        })
    }

    /// One outer period on `input`, then 20 inner steps on the plant (with `inner_fault`).
    pub fn period(
        &mut self,
        input: &OuterInput<'_, f64>,
        inner_fault: Option<InnerFault>,
    ) -> Period {
        let previous = self.controller.mode();
        let out = self.controller.step(input);
        let mut broken = check_outer(&self.config.robot, &out)
            .or_else(|| check_transition(previous, &out, input.request));
        self.inner.set_references(&out.motors);
        let nominal_dt = 1.0 / 8000.0;
        let mut torques = [Vector3::zeros(); INNER_PER_OUTER];
        for (k, applied) in torques.iter_mut().enumerate() {
            let mut speeds = self.plant.wheel_speeds();
            let mut dt = nominal_dt;
            match inner_fault {
                Some(InnerFault::Encoder { step, wheel, value }) if step == k => {
                    speeds[wheel % 3] = value;
                }
                Some(InnerFault::Dt { dt_secs }) => dt = dt_secs,
                _ => {}
            }
            let o = self.inner.step(&speeds, dt);
            let enabled = self.controller.mode().motors_enabled() && !o.timed_out;
            if broken.is_none() {
                broken = check_torque(
                    &self.config.robot,
                    &o.torque_nm,
                    &speeds,
                    out.motors.enabled,
                );
            }
            *applied = if enabled {
                o.torque_nm
            } else {
                Vector3::zeros()
            };
            self.plant.step(applied, nominal_dt);
        }
        Period {
            out,
            torques,
            broken,
        }
    }
}

/// Every outer output finite and within the actuator's limits, motors off outside the
/// balancing modes.
fn check_outer(robot: &BallbotParams<f64>, out: &OuterOutput<f64>) -> Option<&'static str> {
    let m = &out.motors;
    let a = &robot.drivetrain.actuator;
    let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
    if !(finite(&m.speed_rad_per_s)
        && finite(&m.accel_rad_per_s2)
        && finite(&m.feedforward_torque_nm))
    {
        return Some("a motor reference is not finite");
    }
    if m.feedforward_torque_nm.amax() > a.peak_torque_nm + 1e-9 {
        return Some("a feedforward torque exceeds the actuator's peak");
    }
    if m.speed_rad_per_s.amax() > a.no_load_speed_rad_per_s + 1e-9 {
        return Some("a reference speed exceeds the no-load speed");
    }
    if m.enabled != out.safety.mode.motors_enabled() {
        return Some("motors enabled outside the balancing modes (or off inside them)");
    }
    if !m.enabled
        && (m.feedforward_torque_nm != Vector3::zeros() || m.speed_rad_per_s != Vector3::zeros())
    {
        return Some("references not zero with the motors off");
    }
    None
}

/// An applied torque finite, within the peak and the torque-speed line at the measured speed,
/// and zero with the motors off.
fn check_torque(
    robot: &BallbotParams<f64>,
    torque: &Vector3<f64>,
    measured: &Vector3<f64>,
    enabled: bool,
) -> Option<&'static str> {
    let a = &robot.drivetrain.actuator;
    for (t, w) in torque.iter().zip(measured.iter()) {
        if !t.is_finite() {
            return Some("a motor torque is not finite");
        }
        if t.abs() > a.peak_torque_nm + 1e-9 {
            return Some("a motor torque exceeds the actuator's peak");
        }
        if w.is_finite() {
            let (lo, hi) = a.torque_bounds_nm(*w);
            if *t < lo - 1e-9 || *t > hi + 1e-9 {
                return Some("a motor torque is outside the torque-speed line");
            }
        }
    }
    if !enabled && torque.iter().any(|t| *t != 0.0) {
        return Some("torque from the motor loop with the motors off");
    }
    None
}

/// The documented mode transitions (docs/embedding.md, section 4): anything else is broken.
fn check_transition(
    previous: Mode,
    out: &OuterOutput<f64>,
    request: ModeRequest,
) -> Option<&'static str> {
    let now = out.safety.mode;
    let faults: FaultSet = out.safety.faults;
    let unrecoverable = faults.any(Severity::Unrecoverable);
    let recoverable = faults.any(Severity::Recoverable);
    let ok = match (previous, now) {
        (a, b) if a == b => true,
        (Mode::Idle, Mode::Balancing) => request == ModeRequest::Arm && faults.is_empty(),
        (Mode::Balancing | Mode::ControlledStop, Mode::Fault) => unrecoverable,
        (Mode::Balancing | Mode::ControlledStop, Mode::Idle) => {
            request == ModeRequest::Disarm && !unrecoverable
        }
        (Mode::Balancing, Mode::ControlledStop) => {
            !unrecoverable && (recoverable || request == ModeRequest::Stop)
        }
        (Mode::ControlledStop, Mode::Balancing) => {
            request == ModeRequest::Resume && faults.is_empty()
        }
        (Mode::Fault, Mode::Idle) => request == ModeRequest::Reset,
        _ => false,
    };
    (!ok).then_some("a mode transition that is not documented")
}
