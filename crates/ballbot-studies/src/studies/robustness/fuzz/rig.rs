//! One fuzzed controller in closed loop: the 3D controller's outer step, the motor speed PIs
//! at 8 kHz and the plant, with the invariants checked on every step.

use super::plant::Plant;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::{
    BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput, OuterOutput,
};
use ballbot_core::command::{Command, LeanInput, VelocityCommand};
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::safety::SafetyStatus;
use ballbot_core::safety::{FaultSet, Mode, ModeRequest, Severity};
use ballbot_core::wip::BALL_RATE;
use nalgebra::RealField;
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
    /// Wheel `wheel`'s speed reads `value` at inner steps `from..from + len`: longer than the
    /// encoder guard's hold (1 ms, 8 steps) when `len > 8`.
    Burst {
        /// First inner step.
        from: usize,
        /// Inner steps.
        len: usize,
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
    /// The outer step's output, as the invariants see it.
    pub out: Observed,
    /// The applied wheel torques of each inner step (zero while the motors are off).
    pub torques: [Vector3<f64>; INNER_PER_OUTER],
    /// The first broken invariant, if any.
    pub broken: Option<&'static str>,
}

/// The controller under test, in `f64` or instantiated in `f32` (the core is generic over
/// its scalar; an `f32` build is what a microcontroller without a double-precision FPU runs).
// The rig is `Copy` (a twin is a copy): the `f64` variant is larger, and boxing it would make
// the twin a heap copy.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Controllers {
    /// `f64`.
    F64 {
        /// The outer loop.
        outer: BallbotController<f64>,
        /// The motor speed PIs.
        inner: MotorSpeedLoop<f64>,
    },
    /// `f32`: the plant's `f64` samples are rounded to `f32` (beyond `f32::MAX` they become
    /// infinite, as an `f32` driver's would), the outputs widened back exactly.
    F32 {
        /// The outer loop.
        outer: BallbotController<f32>,
        /// The motor speed PIs.
        inner: MotorSpeedLoop<f32>,
    },
}

/// Controller, motor loop and plant.
#[derive(Clone, Copy, Debug)]
pub struct FuzzRig {
    /// The configuration (of the `f64` controller; the `f32` one is designed from the same
    /// robot in `f32`).
    pub config: BallbotControllerConfig<f64>,
    /// The controllers.
    pub controllers: Controllers,
    /// The plant.
    pub plant: Plant,
    /// Tolerance of the limit checks (N m, rad/s): 1e-9 in `f64`; in `f32` a limit rounded to
    /// `f32` may exceed the `f64` one by half an ulp, so 1e-5 relative.
    pub tolerance: f64,
}

impl FuzzRig {
    /// The rig of `config` on its robot.
    pub fn new(config: BallbotControllerConfig<f64>) -> Result<Self, ballbot_core::Error> {
        Ok(Self {
            config,
            controllers: Controllers::F64 {
                outer: BallbotController::new(config)?,
                inner: MotorSpeedLoop::new(&config)?,
            },
            plant: Plant::new(&config.robot)?,
            tolerance: 1e-9,
        })
    }

    /// The rig of the `f32` controller `config32` on the robot of `config` (the plant and the
    /// checks in `f64`).
    pub fn new_f32(
        config: BallbotControllerConfig<f64>,
        config32: BallbotControllerConfig<f32>,
    ) -> Result<Self, ballbot_core::Error> {
        Ok(Self {
            config,
            controllers: Controllers::F32 {
                outer: BallbotController::new(config32)?,
                inner: MotorSpeedLoop::new(&config32)?,
            },
            plant: Plant::new(&config.robot)?,
            tolerance: 1e-5 * config.robot.drivetrain.actuator.peak_torque_nm,
        })
    }

    /// The motor speed loop of the `f64` controller, replaced (e.g. configured otherwise).
    pub fn with_inner(mut self, loop_: MotorSpeedLoop<f64>) -> Self {
        if let Controllers::F64 { inner, .. } = &mut self.controllers {
            *inner = loop_;
        }
        self
    }

    /// The controller's mode.
    pub fn mode(&self) -> Mode {
        match &self.controllers {
            Controllers::F64 { outer, .. } => outer.mode(),
            Controllers::F32 { outer, .. } => outer.mode(),
        }
    }

    /// Whether this is the `f32` controller.
    pub fn is_f32(&self) -> bool {
        matches!(self.controllers, Controllers::F32 { .. })
    }

    fn outer_step(&mut self, input: &OuterInput<'_, f64>) -> Observed {
        match &mut self.controllers {
            Controllers::F64 { outer, inner } => {
                let out = outer.step(input);
                inner.set_references(&out.motors);
                observe(&out)
            }
            Controllers::F32 { outer, inner } => {
                let out = outer.step(&narrow_input(input));
                inner.set_references(&out.motors);
                observe(&out)
            }
        }
    }

    fn inner_step(&mut self, speeds: &Vector3<f64>, dt_secs: f64) -> (Vector3<f64>, bool) {
        match &mut self.controllers {
            Controllers::F64 { inner, .. } => {
                let o = inner.step(speeds, dt_secs);
                (o.torque_nm, o.timed_out)
            }
            Controllers::F32 { inner, .. } => {
                let o = inner.step(&speeds.cast::<f32>(), dt_secs as f32);
                (o.torque_nm.cast::<f64>(), o.timed_out)
            }
        }
    }

    /// One outer period on `input`, then 20 inner steps on the plant (with `inner_fault`).
    pub fn period(
        &mut self,
        input: &OuterInput<'_, f64>,
        inner_fault: Option<InnerFault>,
    ) -> Period {
        let previous = self.mode();
        let out = self.outer_step(input);
        let mut broken = check_outer(&self.config.robot, &out, self.tolerance)
            .or_else(|| check_transition(previous, &out, input.request));
        let nominal_dt = 1.0 / 8000.0;
        let mut torques = [Vector3::zeros(); INNER_PER_OUTER];
        for (k, applied) in torques.iter_mut().enumerate() {
            let mut speeds = self.plant.wheel_speeds();
            let mut dt = nominal_dt;
            match inner_fault {
                Some(InnerFault::Encoder { step, wheel, value }) if step == k => {
                    speeds[wheel % 3] = value;
                }
                Some(InnerFault::Burst {
                    from,
                    len,
                    wheel,
                    value,
                }) if k >= from && k < from + len => {
                    speeds[wheel % 3] = value;
                }
                Some(InnerFault::Dt { dt_secs }) => dt = dt_secs,
                _ => {}
            }
            let (torque_nm, timed_out) = self.inner_step(&speeds, dt);
            // The torque-speed line at the speed the controller read (rounded to `f32`, a
            // value beyond `f32::MAX` infinite, for the `f32` one).
            if self.is_f32() {
                speeds = speeds.map(|w| f64::from(w as f32));
            }
            let enabled = self.mode().motors_enabled() && !timed_out;
            if broken.is_none() {
                broken = check_torque(
                    &self.config.robot,
                    &torque_nm,
                    &speeds,
                    out.motors.enabled,
                    self.tolerance,
                );
            }
            *applied = if enabled { torque_nm } else { Vector3::zeros() };
            self.plant.step(applied, nominal_dt);
        }
        Period {
            out,
            torques,
            broken,
        }
    }
}

/// `input` rounded to `f32`. A trajectory command (its samples borrowed in `f64`) becomes a
/// stop: the `f32` episodes draw no trajectories.
fn narrow_input<'a>(input: &OuterInput<'a, f64>) -> OuterInput<'a, f32> {
    let imu = &input.imu;
    let command = match input.command {
        Command::Stop | Command::Trajectory { .. } => Command::Stop,
        Command::Velocity(v) => Command::Velocity(VelocityCommand {
            vx_m_per_s: v.vx_m_per_s as f32,
            vy_m_per_s: v.vy_m_per_s as f32,
            yaw_rate_rad_per_s: v.yaw_rate_rad_per_s as f32,
        }),
        Command::Lean(l) => Command::Lean(LeanInput {
            towards_x_rad: l.towards_x_rad as f32,
            towards_y_rad: l.towards_y_rad as f32,
            yaw_rate_rad_per_s: l.yaw_rate_rad_per_s as f32,
        }),
    };
    OuterInput {
        now_us: input.now_us,
        imu: ImuSample {
            timestamp_us: imu.timestamp_us,
            roll_rad: imu.roll_rad as f32,
            pitch_rad: imu.pitch_rad as f32,
            yaw_rad: imu.yaw_rad as f32,
            angular_velocity_rad_per_s: imu.angular_velocity_rad_per_s.cast::<f32>(),
        },
        encoders: EncoderSample {
            timestamp_us: input.encoders.timestamp_us,
            wheel_speeds_rad_per_s: input.encoders.wheel_speeds_rad_per_s.cast::<f32>(),
        },
        command,
        command_timestamp_us: input.command_timestamp_us,
        request: input.request,
    }
}

/// The motor references of an outer step, in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motors {
    /// Whether the motors are enabled.
    pub enabled: bool,
    /// Reference wheel speeds (rad/s).
    pub speed_rad_per_s: Vector3<f64>,
    /// Reference wheel accelerations (rad/s^2).
    pub accel_rad_per_s2: Vector3<f64>,
    /// Feedforward torques (N m).
    pub feedforward_torque_nm: Vector3<f64>,
}

/// What the invariants look at in an outer step's output, in `f64` whatever the controller's
/// scalar (its own type, so that fields the core adds to its output do not break the fuzzer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observed {
    /// The supervisor's verdict.
    pub safety: SafetyStatus,
    /// The motor references.
    pub motors: Motors,
    /// Whether every intermediate value the output exposes is finite: the estimated states,
    /// the shaped command states, the reference torques and rates, the traction report.
    pub intermediates_finite: bool,
    /// The shaped command's ball rates `[frontal, sagittal]` (rad/s).
    pub command_ball_rate_rad_per_s: [f64; 2],
    /// In a controlled stop, whether the shaped command is at rest.
    pub stopped: bool,
    /// With traction-aware control: the acceleration limit of this step (m/s^2), `None` when
    /// the shaped command did not ask to accelerate.
    pub accel_limit_m_per_s2: Option<Option<f64>>,
    /// With traction-aware control: each wheel's slip flag.
    pub slipping: Option<[bool; 3]>,
}

/// A scalar the controller may be instantiated in, widened exactly to `f64`.
pub trait Wide: RealField + Copy {
    /// `self` as `f64`.
    fn wide(self) -> f64;
}

impl Wide for f64 {
    fn wide(self) -> f64 {
        self
    }
}

impl Wide for f32 {
    fn wide(self) -> f64 {
        f64::from(self)
    }
}

/// The invariants' view of `out`.
pub fn observe<T: Wide>(out: &OuterOutput<T>) -> Observed {
    let m = &out.motors;
    let wide = T::wide;
    let finite = |x: &[T]| x.iter().all(|v| v.is_finite());
    let s = &out.states;
    let c = &out.commands;
    let traction_finite = out.traction.as_ref().is_none_or(|t| {
        t.accel_limit_m_per_s2.is_none_or(|a| a.is_finite())
            && finite(t.slip.slip_speed_m_per_s.as_slice())
            && finite(t.slip.predicted_normal_force_n.as_slice())
            && t.slip.accel_scale.is_finite()
            && t.slip.friction_estimate.is_finite()
    });
    Observed {
        safety: out.safety,
        motors: Motors {
            enabled: m.enabled,
            speed_rad_per_s: m.speed_rad_per_s.map(wide),
            accel_rad_per_s2: m.accel_rad_per_s2.map(wide),
            feedforward_torque_nm: m.feedforward_torque_nm.map(wide),
        },
        intermediates_finite: finite(s.sagittal.as_slice())
            && finite(s.frontal.as_slice())
            && finite(s.spin.as_slice())
            && finite(c.sagittal.as_slice())
            && finite(c.frontal.as_slice())
            && finite(c.spin.as_slice())
            && finite(out.reference_torque_nm.as_slice())
            && finite(out.reference_rate_rad_per_s.as_slice())
            && traction_finite,
        command_ball_rate_rad_per_s: [wide(c.frontal[BALL_RATE]), wide(c.sagittal[BALL_RATE])],
        stopped: out.stopped,
        accel_limit_m_per_s2: out
            .traction
            .as_ref()
            .map(|t| t.accel_limit_m_per_s2.map(wide)),
        slipping: out.traction.as_ref().map(|t| t.slip.slipping),
    }
}

/// Every outer output finite and within the actuator's limits, motors off outside the
/// balancing modes.
fn check_outer(robot: &BallbotParams<f64>, out: &Observed, tol: f64) -> Option<&'static str> {
    let m = &out.motors;
    let a = &robot.drivetrain.actuator;
    let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
    if !(finite(&m.speed_rad_per_s)
        && finite(&m.accel_rad_per_s2)
        && finite(&m.feedforward_torque_nm))
    {
        return Some("a motor reference is not finite");
    }
    if m.feedforward_torque_nm.amax() > a.peak_torque_nm + tol {
        return Some("a feedforward torque exceeds the actuator's peak");
    }
    if m.speed_rad_per_s.amax() > a.no_load_speed_rad_per_s + tol {
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
    tol: f64,
) -> Option<&'static str> {
    let a = &robot.drivetrain.actuator;
    for (t, w) in torque.iter().zip(measured.iter()) {
        if !t.is_finite() {
            return Some("a motor torque is not finite");
        }
        if t.abs() > a.peak_torque_nm + tol {
            return Some("a motor torque exceeds the actuator's peak");
        }
        if w.is_finite() {
            let (lo, hi) = a.torque_bounds_nm(*w);
            if *t < lo - tol || *t > hi + tol {
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
fn check_transition(previous: Mode, out: &Observed, request: ModeRequest) -> Option<&'static str> {
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
