//! Closed-loop rollouts of the core's planar controllers on the ideal WIP, run by the planar
//! simulator's scheduler ([`PlanarSim`]): the loop behind the Python `closed_loop_rollout`.
//!
//! The plant is the WIP without transmission friction and with an actuator that never limits
//! (the controllers' own torque limits still apply); the sensors are perfect and every output
//! takes effect at once (no computation delay). The main controller runs every `dt_secs`, the
//! drive `substeps` times per period, and the plant takes one RK4 step per drive step. An
//! LQR-PI's speed PI runs in the drive on what the drive measures on the robot: the joint
//! (motor) rate from its encoder, the outer loop's ball-rate reference mapped to a joint-rate
//! reference with the tilt rate of its sample (as the PIPTB's [`super::LqrPiCascade`] does).
//!
//! ```
//! use ballbot_core::control::{LqrController, LqrGains};
//! use ballbot_core::{Wip, WipParams, WipState};
//! use ballbot_world::planar::{RolloutController, RolloutSettings, rollout};
//! let plane = WipParams::miapure_60kg();
//! let gains = LqrGains::for_wip(&Wip::new(plane)?, 83.9)?;
//! let lqr = RolloutController::Lqr(LqrController::new(gains)?);
//! let settings = RolloutSettings { dt_secs: 0.0025, n_steps: 2000, substeps: 20 };
//! let start = WipState::new(0.1, 0.0, 0.0, 0.0);
//! let run = rollout(plane, &lqr, start, &[WipState::zeros()], &settings)?;
//! assert_eq!(run.states.len(), 2001);
//! assert!(run.states[2000][0].abs() < 1e-3); // upright again after 5 s
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::{
    DriveMeasurement, DriveSetpoint, Observer, OuterMeasurement, PlanarCommand, PlanarController,
    PlanarError, PlanarSim, PlantStep, SensorParams, SimConfig, TransmissionFriction,
};
use ballbot_core::control::{
    LqrController, LqrPiOuter, PiPdController, PlaneController, PlaneOutput, SpeedCommand, SpeedPi,
    StepStatus,
};
use ballbot_core::{ActuatorParams, PlanarRobotParams, WipParams, WipState};

/// One of the core's planar controllers, as it is now (a rollout steps a copy).
#[derive(Clone, Debug)]
pub enum RolloutController {
    /// LQR in torque mode.
    Lqr(LqrController<f64>),
    /// Cascaded PI-PD in torque mode.
    PiPd(PiPdController<f64>),
    /// Cascaded LQR-PI: the outer loop every period, its speed PI in the drive.
    LqrPi {
        /// The outer loop (LQR and reference model).
        outer: LqrPiOuter<f64>,
        /// The drive's speed PI.
        inner: SpeedPi<f64>,
    },
}

/// Timing of a rollout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RolloutSettings {
    /// The main controller's period (s); > 0.
    pub dt_secs: f64,
    /// Controller periods to run.
    pub n_steps: usize,
    /// Drive and plant steps per period (>= 1): the paper's 400 Hz / 8 kHz is 20.
    pub substeps: usize,
}

/// A rollout's trajectory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rollout {
    /// The state at the start of every period and at the end: `n_steps + 1` states.
    pub states: Vec<WipState<f64>>,
    /// The mean torque applied over each period (N m): `n_steps` values.
    pub torque_nm: Vec<f64>,
    /// Each period's status: the first non-nominal status of its outer or drive steps.
    pub status: Vec<StepStatus>,
}

/// The controller behind [`PlanarController`], with the full command state of the period.
struct Adapter {
    controller: RolloutController,
    command: WipState<f64>,
    status: StepStatus,
}

impl Adapter {
    fn note(&mut self, status: StepStatus) {
        if self.status == StepStatus::Nominal {
            self.status = status;
        }
    }
}

fn measured_state(m: &OuterMeasurement) -> WipState<f64> {
    WipState::new(
        m.tilt_rad,
        m.ball_angle_rad,
        m.tilt_rate_rad_per_s,
        m.ball_rate_rad_per_s,
    )
}

/// One step of a plane controller in torque mode: its torque, no joint-rate reference, its
/// status.
fn torque_mode<C: PlaneController<f64>>(
    controller: &mut C,
    measured: &WipState<f64>,
    command: &WipState<f64>,
    dt_secs: f64,
) -> (f64, Option<f64>, StepStatus) {
    let o = PlaneController::step(controller, measured, command, dt_secs);
    (o.torque_nm(), None, o.status())
}

impl PlanarController for Adapter {
    fn name(&self) -> &str {
        match self.controller {
            RolloutController::Lqr(_) => "lqr",
            RolloutController::PiPd(_) => "pi_pd",
            RolloutController::LqrPi { .. } => "lqr_pi",
        }
    }

    fn outer_step(&mut self, m: &OuterMeasurement, _: &PlanarCommand, dt: f64) -> DriveSetpoint {
        let s = measured_state(m);
        let command = self.command;
        let (torque_nm, joint_rate_rad_per_s, status) = match &mut self.controller {
            RolloutController::Lqr(c) => torque_mode(c, &s, &command, dt),
            RolloutController::PiPd(c) => torque_mode(c, &s, &command, dt),
            RolloutController::LqrPi { outer, .. } => {
                let o = outer.step(&s, &command, dt);
                let joint_rate = o.reference_ball_rate_rad_per_s - m.tilt_rate_rad_per_s;
                (o.reference_torque_nm, Some(joint_rate), o.status)
            }
        };
        self.note(status);
        DriveSetpoint {
            torque_nm,
            joint_rate_rad_per_s,
        }
    }

    fn drive_step(&mut self, m: &DriveMeasurement, sp: &DriveSetpoint, dt: f64) -> f64 {
        let (RolloutController::LqrPi { inner, .. }, Some(reference)) =
            (&mut self.controller, sp.joint_rate_rad_per_s)
        else {
            return sp.torque_nm;
        };
        let command = SpeedCommand {
            speed_rad_per_s: reference,
            feedforward_torque_nm: sp.torque_nm,
        };
        let o = inner.step(m.joint_rate_rad_per_s, &command, dt);
        self.note(o.status);
        o.torque_nm
    }

    fn reset(&mut self) {
        match &mut self.controller {
            RolloutController::Lqr(c) => PlaneController::reset(c),
            RolloutController::PiPd(c) => PlaneController::reset(c),
            RolloutController::LqrPi { outer, inner } => {
                outer.reset();
                inner.reset();
            }
        }
    }
}

/// Sums the torque applied in each plant step of a period.
#[derive(Default)]
struct TorqueSum(f64);

impl Observer for TorqueSum {
    fn plant_step(&mut self, _: f64, _: f64, _: &WipState<f64>, step: &PlantStep) {
        self.0 += step.applied_torque_nm;
    }
}

/// An actuator that never limits a finite torque.
fn unlimited_actuator() -> ActuatorParams<f64> {
    ActuatorParams {
        gear_ratio: 1.0,
        peak_torque_nm: f64::MAX,
        no_load_speed_rad_per_s: f64::MAX,
    }
}

/// Runs a copy of `controller` on the ideal WIP `plane` from `initial` for
/// `settings.n_steps` periods. `commands` holds one command state for the whole run or one per
/// period. A run whose state becomes non-finite ends there: the remaining states and torques
/// are NaN and their status [`StepStatus::InvalidInput`].
///
/// Errors name the setting: `dt_secs` not finite and > 0, `substeps` zero, `commands` of
/// another length, or a plane the plant rejects.
pub fn rollout(
    plane: WipParams<f64>,
    controller: &RolloutController,
    initial: WipState<f64>,
    commands: &[WipState<f64>],
    settings: &RolloutSettings,
) -> Result<Rollout, PlanarError> {
    let RolloutSettings {
        dt_secs,
        n_steps,
        substeps,
    } = *settings;
    if !(dt_secs.is_finite() && dt_secs > 0.0) {
        return Err(PlanarError::invalid("dt_secs", "must be finite and > 0"));
    }
    if substeps == 0 {
        return Err(PlanarError::invalid("substeps", "must be >= 1"));
    }
    if !(commands.len() == 1 || commands.len() == n_steps) {
        return Err(PlanarError::invalid(
            "commands",
            format!("must hold 1 or n_steps = {n_steps} command states"),
        ));
    }
    let plant_rate_hz = substeps as f64 / dt_secs;
    let config = SimConfig {
        plant_rate_hz,
        drive_rate_hz: plant_rate_hz,
        outer_rate_hz: 1.0 / dt_secs,
        computation_delay: false,
        max_tilt_rad: f64::MAX,
    };
    let robot = PlanarRobotParams {
        plane,
        actuator: unlimited_actuator(),
    };
    let mut sim = PlanarSim::new(
        robot,
        TransmissionFriction::none(),
        SensorParams::ideal(),
        config,
        0,
    )?;
    sim.reset(initial);
    let mut adapter = Adapter {
        controller: controller.clone(),
        command: commands[0],
        status: StepStatus::Nominal,
    };
    let mut run = Rollout {
        states: Vec::with_capacity(n_steps + 1),
        torque_nm: Vec::with_capacity(n_steps),
        status: Vec::with_capacity(n_steps),
    };
    run.states.push(initial);
    for k in 0..n_steps {
        adapter.command = commands[if commands.len() == 1 { 0 } else { k }];
        adapter.status = StepStatus::Nominal;
        let c = adapter.command;
        let profile = move |_: f64| PlanarCommand {
            tilt_rad: c[0],
            tilt_rate_rad_per_s: c[2],
            ball_rate_rad_per_s: c[3],
        };
        let mut sum = TorqueSum::default();
        let outcome = sim.run(&mut adapter, &profile, dt_secs, &mut sum);
        if outcome.fault.is_some() || outcome.plant_steps != substeps as u64 {
            // Non-finite state (the tilt limit is off): the rest of the run is undefined.
            let nan = WipState::from_element(f64::NAN);
            run.states.resize(n_steps + 1, nan);
            run.torque_nm.resize(n_steps, f64::NAN);
            run.status.resize(n_steps, StepStatus::InvalidInput);
            break;
        }
        run.states.push(*sim.plant().state());
        run.torque_nm.push(sum.0 / substeps as f64);
        run.status.push(adapter.status);
    }
    Ok(run)
}
