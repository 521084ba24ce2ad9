//! The multi-rate scheduler: plant, motor drive and main controller each at their own rate.
//!
//! Time advances in plant steps of `1 / plant_rate_hz`. The drive runs every
//! `plant_rate_hz / drive_rate_hz` steps, the main controller every
//! `plant_rate_hz / outer_rate_hz` steps (both ratios must be whole numbers). At a tick the loop
//! samples its sensors at the true state of that instant; with `computation_delay` its output
//! takes effect one period of that loop later (the value computed at tick `k` is applied from
//! tick `k + 1`), as on hardware that computes during the period and writes at the next
//! interrupt. Between ticks every output is held.

use super::{
    CommandProfile, DriveMeasurement, DriveSetpoint, OuterMeasurement, PlanarCommand,
    PlanarController, PlanarError, PlanarPlant, PlantStep, SensorParams, Sensors, SpeedEstimator,
    TransmissionFriction,
};
use ballbot_core::PlanarRobotParams;
use ballbot_core::WipState;
use ballbot_core::rates::{INNER_LOOP_RATE_HZ, OUTER_LOOP_RATE_HZ};
use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};

/// Rates and timing of a simulation.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// RK4 steps per second (Hz). Default 8000.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub plant_rate_hz: f64,
    /// Motor drive loop rate (Hz); divides `plant_rate_hz`. Default 8000.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub drive_rate_hz: f64,
    /// Main controller rate (Hz); divides `drive_rate_hz`. Default 400.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub outer_rate_hz: f64,
    /// Apply every loop's output one period after the sample it was computed from.
    pub computation_delay: bool,
    /// The run stops with [`FaultKind::Fell`] beyond this tilt magnitude (rad). Default 0.6.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub max_tilt_rad: f64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            plant_rate_hz: INNER_LOOP_RATE_HZ,
            drive_rate_hz: INNER_LOOP_RATE_HZ,
            outer_rate_hz: OUTER_LOOP_RATE_HZ,
            computation_delay: true,
            max_tilt_rad: 0.6,
        }
    }
}

/// `numerator / denominator` as a whole number, or an error naming `key`.
fn whole_ratio(numerator: f64, denominator: f64, key: &str) -> Result<u64, PlanarError> {
    if !(denominator.is_finite() && denominator > 0.0) {
        return Err(PlanarError::invalid(key, "must be finite and > 0"));
    }
    let ratio = numerator / denominator;
    let rounded = ratio.round();
    if rounded < 1.0 || (ratio - rounded).abs() > 1e-9 * ratio {
        return Err(PlanarError::invalid(
            key,
            format!("must divide {numerator} Hz into a whole number of steps (ratio is {ratio})"),
        ));
    }
    // `rounded` is a positive whole number well inside u64.
    Ok(rounded as u64)
}

impl SimConfig {
    /// Checks the rates and returns `(plant steps per drive tick, drive ticks per outer tick)`.
    pub fn dividers(&self) -> Result<(u64, u64), PlanarError> {
        if !(self.plant_rate_hz.is_finite() && self.plant_rate_hz > 0.0) {
            return Err(PlanarError::invalid(
                "sim.plant_rate_hz",
                "must be finite and > 0",
            ));
        }
        let drive = whole_ratio(self.plant_rate_hz, self.drive_rate_hz, "sim.drive_rate_hz")?;
        let outer = whole_ratio(self.drive_rate_hz, self.outer_rate_hz, "sim.outer_rate_hz")?;
        if !(self.max_tilt_rad.is_finite() && self.max_tilt_rad > 0.0) {
            return Err(PlanarError::invalid(
                "sim.max_tilt_rad",
                "must be finite and > 0",
            ));
        }
        Ok((drive, outer))
    }
}

/// Why a run stopped early.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FaultKind {
    /// The tilt exceeded [`SimConfig::max_tilt_rad`].
    Fell {
        /// The tilt when it was detected (rad).
        tilt_rad: f64,
    },
    /// The state became NaN or infinite.
    NonFinite,
}

/// A fault and when it happened.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Fault {
    /// Simulated time (s).
    pub time_secs: f64,
    /// What happened.
    pub kind: FaultKind,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunOutcome {
    /// Simulated time at the end (s).
    pub end_time_secs: f64,
    /// Plant steps taken.
    pub plant_steps: u64,
    /// The fault that stopped the run early, if any.
    pub fault: Option<Fault>,
}

/// Everything known at one tick of the main controller.
#[derive(Clone, Copy, Debug)]
pub struct OuterTick<'a> {
    /// Simulated time (s).
    pub time_secs: f64,
    /// True state at the tick.
    pub state: WipState<f64>,
    /// What the controller measured.
    pub measured: OuterMeasurement,
    /// What it was commanded.
    pub command: PlanarCommand,
    /// What it computed this tick (applied now, or one period later with delay).
    pub setpoint: DriveSetpoint,
    /// The plant step starting at this tick (torques, friction).
    pub step: PlantStep,
    /// The controller's per-term contributions.
    pub terms: &'a [(&'static str, f64)],
}

/// Receives what happens during a run. Every method defaults to doing nothing.
pub trait Observer {
    /// After every plant step: the time at its start, its length, the state before it, and
    /// what it applied.
    fn plant_step(
        &mut self,
        time_secs: f64,
        dt_secs: f64,
        state_before: &WipState<f64>,
        step: &PlantStep,
    ) {
        let _ = (time_secs, dt_secs, state_before, step);
    }
    /// After the plant step that starts at a tick of the main controller.
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        let _ = tick;
    }
    /// When a fault stops the run.
    fn fault(&mut self, fault: &Fault) {
        let _ = fault;
    }
}

/// The observer that ignores everything.
impl Observer for () {}

/// Two observers, both told everything (first `.0`, then `.1`).
impl<A: Observer, B: Observer> Observer for (A, B) {
    fn plant_step(&mut self, t: f64, dt: f64, s: &WipState<f64>, step: &PlantStep) {
        self.0.plant_step(t, dt, s, step);
        self.1.plant_step(t, dt, s, step);
    }
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        self.0.outer_tick(tick);
        self.1.outer_tick(tick);
    }
    fn fault(&mut self, fault: &Fault) {
        self.0.fault(fault);
        self.1.fault(fault);
    }
}

/// An observer behind a mutable reference.
impl<O: Observer + ?Sized> Observer for &mut O {
    fn plant_step(&mut self, t: f64, dt: f64, s: &WipState<f64>, step: &PlantStep) {
        (**self).plant_step(t, dt, s, step);
    }
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        (**self).outer_tick(tick);
    }
    fn fault(&mut self, fault: &Fault) {
        (**self).fault(fault);
    }
}

/// The multi-rate planar simulator.
///
/// ```
/// use ballbot_core::PlanarRobotParams;
/// use ballbot_world::planar::*;
/// // A proportional-derivative torque on tilt and ball rate, enough to balance the PIPTB.
/// struct Pd;
/// impl PlanarController for Pd {
///     fn name(&self) -> &str { "pd" }
///     fn outer_step(&mut self, m: &OuterMeasurement, _c: &PlanarCommand, _dt: f64)
///         -> DriveSetpoint {
///         let torque_nm = 60.0 * m.tilt_rad + 8.0 * m.tilt_rate_rad_per_s
///             + 0.3 * m.ball_rate_rad_per_s;
///         DriveSetpoint { torque_nm, joint_rate_rad_per_s: None }
///     }
///     fn reset(&mut self) {}
/// }
/// let mut sim = PlanarSim::new(
///     PlanarRobotParams::piptb(),
///     TransmissionFriction::none(),
///     SensorParams::ideal(),
///     SimConfig::default(),
///     1,
/// )?;
/// sim.reset(nalgebra::Vector4::new(0.05, 0.0, 0.0, 0.0));
/// let outcome = sim.run(&mut Pd, &|_t: f64| PlanarCommand::default(), 3.0, &mut ());
/// assert!(outcome.fault.is_none());
/// assert!(sim.plant().state()[0].abs() < 1e-3);
/// # Ok::<(), PlanarError>(())
/// ```
#[derive(Clone, Debug)]
pub struct PlanarSim {
    plant: PlanarPlant,
    sensors: Sensors,
    config: SimConfig,
    plant_per_drive: u64,
    drive_per_outer: u64,
    outer_speed: SpeedEstimator,
    drive_speed: SpeedEstimator,
    time_secs: f64,
    step_index: u64,
    terms: Vec<(&'static str, f64)>,
}

impl PlanarSim {
    /// Builds a simulator; `seed` fixes every noise sample.
    pub fn new(
        robot: PlanarRobotParams<f64>,
        friction: TransmissionFriction,
        sensors: SensorParams,
        config: SimConfig,
        seed: u64,
    ) -> Result<Self, PlanarError> {
        let (plant_per_drive, drive_per_outer) = config.dividers()?;
        let plant = PlanarPlant::new(robot, friction, config.plant_rate_hz)?;
        let sensors = Sensors::new(sensors, robot.actuator.gear_ratio, seed)?;
        let drive_dt = 1.0 / config.drive_rate_hz;
        let outer_dt = 1.0 / config.outer_rate_hz;
        let cutoff = sensors.params().speed_filter_cutoff_hz;
        let mut sim = Self {
            plant,
            sensors,
            config,
            plant_per_drive,
            drive_per_outer,
            outer_speed: SpeedEstimator::new(outer_dt, cutoff),
            drive_speed: SpeedEstimator::new(drive_dt, cutoff),
            time_secs: 0.0,
            step_index: 0,
            terms: Vec::new(),
        };
        sim.reset(WipState::zeros());
        Ok(sim)
    }

    /// The plant.
    pub fn plant(&self) -> &PlanarPlant {
        &self.plant
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Simulated time (s).
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }

    /// Restarts at time 0 from `state`, the speed estimators primed with its true joint angle
    /// and rate (a robot that has been running; the noise stream continues).
    pub fn reset(&mut self, state: WipState<f64>) {
        self.plant.set_state(state);
        self.time_secs = 0.0;
        self.step_index = 0;
        let joint_angle = self
            .sensors
            .encoder_angle_rad(state[BALL_ANGLE] - state[TILT]);
        let joint_rate = state[BALL_RATE] - state[TILT_RATE];
        self.outer_speed.reset(joint_angle, joint_rate);
        self.drive_speed.reset(joint_angle, joint_rate);
    }

    /// Runs `controller` on `command` for `duration_secs` of simulated time from the present
    /// state, reporting to `observer`. Stops early on a fault. The controller is not reset.
    pub fn run<C, P, O>(
        &mut self,
        controller: &mut C,
        command: &P,
        duration_secs: f64,
        observer: &mut O,
    ) -> RunOutcome
    where
        C: PlanarController + ?Sized,
        P: CommandProfile + ?Sized,
        O: Observer + ?Sized,
    {
        let dt = self.plant.dt_secs();
        let drive_dt = dt * self.plant_per_drive as f64;
        let outer_dt = drive_dt * self.drive_per_outer as f64;
        let plant_per_outer = self.plant_per_drive * self.drive_per_outer;
        let start = self.step_index;
        // Whole steps; the tolerance keeps 5.4 s at 8 kHz from becoming 43201 steps.
        let steps = (duration_secs * self.config.plant_rate_hz - 1e-6)
            .ceil()
            .max(0.0) as u64;
        let delay = self.config.computation_delay;
        let exact_encoder = self.sensors.encoder_resolution_rad() == 0.0;

        let mut active_setpoint = DriveSetpoint::default();
        let mut pending_setpoint = DriveSetpoint::default();
        let mut active_torque = 0.0;
        let mut pending_torque = 0.0;
        let mut last_applied = 0.0;
        let mut outer_record: Option<(OuterMeasurement, PlanarCommand, DriveSetpoint)> = None;
        let mut fault = None;

        for _ in 0..steps {
            let k = self.step_index;
            let t = k as f64 * dt;
            self.time_secs = t;
            let s = *self.plant.state();
            if !s.iter().all(|x| x.is_finite()) {
                fault = Some(Fault {
                    time_secs: t,
                    kind: FaultKind::NonFinite,
                });
                break;
            }
            if s[TILT].abs() > self.config.max_tilt_rad {
                fault = Some(Fault {
                    time_secs: t,
                    kind: FaultKind::Fell { tilt_rad: s[TILT] },
                });
                break;
            }
            let local = k - start;
            let joint_angle = if local.is_multiple_of(self.plant_per_drive) {
                self.sensors.encoder_angle_rad(s[BALL_ANGLE] - s[TILT])
            } else {
                0.0
            };
            if local.is_multiple_of(plant_per_outer) {
                let imu = self.sensors.imu(s[TILT], s[TILT_RATE]);
                let joint_rate = if exact_encoder {
                    s[BALL_RATE] - s[TILT_RATE]
                } else {
                    self.outer_speed.update(joint_angle)
                };
                let measured = OuterMeasurement {
                    time_secs: t,
                    tilt_rad: imu.tilt_rad,
                    tilt_rate_rad_per_s: imu.tilt_rate_rad_per_s,
                    ball_angle_rad: joint_angle + imu.tilt_rad,
                    ball_rate_rad_per_s: joint_rate + imu.tilt_rate_rad_per_s,
                    joint_rate_rad_per_s: joint_rate,
                    applied_torque_nm: last_applied,
                };
                let cmd = command.command(t);
                let setpoint = controller.outer_step(&measured, &cmd, outer_dt);
                if delay {
                    active_setpoint = pending_setpoint;
                    pending_setpoint = setpoint;
                } else {
                    active_setpoint = setpoint;
                }
                outer_record = Some((measured, cmd, setpoint));
            }
            if local.is_multiple_of(self.plant_per_drive) {
                let joint_rate = if exact_encoder {
                    s[BALL_RATE] - s[TILT_RATE]
                } else {
                    self.drive_speed.update(joint_angle)
                };
                let measured = DriveMeasurement {
                    time_secs: t,
                    joint_angle_rad: joint_angle,
                    joint_rate_rad_per_s: joint_rate,
                    applied_torque_nm: last_applied,
                };
                let torque = controller.drive_step(&measured, &active_setpoint, drive_dt);
                if delay {
                    active_torque = pending_torque;
                    pending_torque = torque;
                } else {
                    active_torque = torque;
                }
            }
            let step = self.plant.step(active_torque);
            last_applied = step.applied_torque_nm;
            self.step_index += 1;
            observer.plant_step(t, dt, &s, &step);
            if let Some((measured, command, setpoint)) = outer_record.take() {
                self.terms.clear();
                controller.terms(&mut self.terms);
                observer.outer_tick(&OuterTick {
                    time_secs: t,
                    state: s,
                    measured,
                    command,
                    setpoint,
                    step,
                    terms: &self.terms,
                });
            }
        }
        self.time_secs = self.step_index as f64 * dt;
        if let Some(f) = &fault {
            observer.fault(f);
        }
        RunOutcome {
            end_time_secs: self.time_secs,
            plant_steps: self.step_index - start,
            fault,
        }
    }
}
