//! Recording a planar run into an MCAP log ([`super::McapLogger`]): one typed JSON
//! channel per concern, stamped with simulated time, written at every tick of the main
//! controller.
//!
//! | topic | message | content |
//! | --- | --- | --- |
//! | `/planar/state` | [`PlanarStateMsg`] | true and measured state |
//! | `/planar/command` | [`PlanarCommandMsg`] | the command state |
//! | `/planar/control` | [`PlanarControlMsg`] | setpoint, requested and applied torque, per-term controller output |
//! | `/planar/friction` | [`FrictionMsg`] | transmission friction torque and stick-slip branch |
//! | `/faults` | [`FaultMsg`] | actuator saturation on/off, fall, non-finite state |

use super::{Channel, LogError, McapLogger, topics};
use ballbot_core::WipState;
use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};
use ballbot_world::planar::{Fault, FaultKind, Observer, OuterTick, PlantStep};
use std::collections::BTreeMap;

/// Topic of the transmission friction channel.
pub const PLANAR_FRICTION: &str = "/planar/friction";

/// True and measured state at a tick of the main controller.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct PlanarStateMsg {
    /// True tilt `theta` (rad).
    pub tilt_rad: f64,
    /// True ball (wheel) angle `phi` (rad).
    pub ball_angle_rad: f64,
    /// True tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// True ball rate `phi_dot` (rad/s).
    pub ball_rate_rad_per_s: f64,
    /// True ball speed `r phi_dot` (m/s).
    pub ball_speed_m_per_s: f64,
    /// True joint rate `phi_dot - theta_dot` (rad/s).
    pub joint_rate_rad_per_s: f64,
    /// Measured tilt (rad).
    pub measured_tilt_rad: f64,
    /// Measured tilt rate (rad/s).
    pub measured_tilt_rate_rad_per_s: f64,
    /// Measured ball rate (rad/s).
    pub measured_ball_rate_rad_per_s: f64,
}

/// The command state.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct PlanarCommandMsg {
    /// Commanded tilt (rad).
    pub tilt_rad: f64,
    /// Commanded tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// Commanded ball rate (rad/s).
    pub ball_rate_rad_per_s: f64,
    /// Commanded ball speed (m/s).
    pub ball_speed_m_per_s: f64,
}

/// What the controller computed and what reached the wheel.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct PlanarControlMsg {
    /// Torque part of the setpoint the main controller computed this tick (N m).
    pub setpoint_torque_nm: f64,
    /// Joint-rate reference of the setpoint, if the drive runs a speed loop (rad/s).
    pub setpoint_joint_rate_rad_per_s: Option<f64>,
    /// Torque the drive requested for the step starting now (N m).
    pub requested_torque_nm: f64,
    /// Torque the actuator delivered (N m).
    pub applied_torque_nm: f64,
    /// Whether the actuator limited the request.
    pub saturated: bool,
    /// The controller's per-term contributions (names carry units).
    pub terms: BTreeMap<String, f64>,
}

/// Transmission friction.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct FrictionMsg {
    /// Friction torque on the joint (N m).
    pub friction_torque_nm: f64,
    /// Branch: 0 free, 1 slipping, 2 stuck, 3 breaking away.
    pub mode_code: u8,
    /// Branch name.
    pub mode: String,
}

/// A fault or failure event.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct FaultMsg {
    /// What happened: `actuator_saturated`, `actuator_unsaturated`, `fell`, `non_finite`.
    pub kind: String,
    /// Tilt at the event (rad).
    pub tilt_rad: f64,
    /// The torque involved, if any (N m).
    pub torque_nm: Option<f64>,
}

/// An [`Observer`] that writes a run into an MCAP log. Errors are kept (the observer cannot
/// return them) and reported by [`McapRecorder::finish`].
pub struct McapRecorder<'a> {
    log: &'a mut McapLogger,
    ball_radius_m: f64,
    state: Channel<PlanarStateMsg>,
    command: Channel<PlanarCommandMsg>,
    control: Channel<PlanarControlMsg>,
    friction: Channel<FrictionMsg>,
    faults: Channel<FaultMsg>,
    saturated: bool,
    time_offset_secs: f64,
    error: Option<LogError>,
}

impl std::fmt::Debug for McapRecorder<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapRecorder")
            .field("log", &self.log)
            .finish_non_exhaustive()
    }
}

impl<'a> McapRecorder<'a> {
    /// Registers the planar channels on `log`. `ball_radius_m` converts rates to speeds.
    pub fn new(log: &'a mut McapLogger, ball_radius_m: f64) -> Result<Self, LogError> {
        let state = log.channel::<PlanarStateMsg>(topics::PLANAR_STATE)?;
        let command = log.channel::<PlanarCommandMsg>(topics::PLANAR_COMMAND)?;
        let control = log.channel::<PlanarControlMsg>(topics::PLANAR_CONTROL)?;
        let friction = log.channel::<FrictionMsg>(PLANAR_FRICTION)?;
        let faults = log.channel::<FaultMsg>(topics::FAULTS)?;
        Ok(Self {
            log,
            ball_radius_m,
            state,
            command,
            control,
            friction,
            faults,
            saturated: false,
            time_offset_secs: 0.0,
            error: None,
        })
    }

    /// Shifts every later time stamp by `offset_secs` (to append several runs to one log).
    pub fn set_time_offset_secs(&mut self, offset_secs: f64) {
        self.time_offset_secs = offset_secs;
    }

    /// The first write error, if any.
    pub fn finish(self) -> Result<(), LogError> {
        match self.error {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn keep<T>(&mut self, result: Result<T, LogError>) {
        if let (Err(e), None) = (result, &self.error) {
            self.error = Some(e);
        }
    }

    fn fault_event(&mut self, time_secs: f64, kind: &str, tilt_rad: f64, torque_nm: Option<f64>) {
        let msg = FaultMsg {
            kind: kind.to_owned(),
            tilt_rad,
            torque_nm,
        };
        let r = self
            .log
            .write(&self.faults, time_secs + self.time_offset_secs, &msg);
        self.keep(r);
    }
}

impl Observer for McapRecorder<'_> {
    fn plant_step(&mut self, time_secs: f64, _dt: f64, state: &WipState<f64>, step: &PlantStep) {
        if step.saturated != self.saturated {
            self.saturated = step.saturated;
            let kind = if step.saturated {
                "actuator_saturated"
            } else {
                "actuator_unsaturated"
            };
            self.fault_event(time_secs, kind, state[TILT], Some(step.requested_torque_nm));
        }
    }

    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        if self.error.is_some() {
            return;
        }
        let t = tick.time_secs + self.time_offset_secs;
        let s = &tick.state;
        let r = self.ball_radius_m;
        let state = PlanarStateMsg {
            tilt_rad: s[TILT],
            ball_angle_rad: s[BALL_ANGLE],
            tilt_rate_rad_per_s: s[TILT_RATE],
            ball_rate_rad_per_s: s[BALL_RATE],
            ball_speed_m_per_s: r * s[BALL_RATE],
            joint_rate_rad_per_s: s[BALL_RATE] - s[TILT_RATE],
            measured_tilt_rad: tick.measured.tilt_rad,
            measured_tilt_rate_rad_per_s: tick.measured.tilt_rate_rad_per_s,
            measured_ball_rate_rad_per_s: tick.measured.ball_rate_rad_per_s,
        };
        let command = PlanarCommandMsg {
            tilt_rad: tick.command.tilt_rad,
            tilt_rate_rad_per_s: tick.command.tilt_rate_rad_per_s,
            ball_rate_rad_per_s: tick.command.ball_rate_rad_per_s,
            ball_speed_m_per_s: r * tick.command.ball_rate_rad_per_s,
        };
        let control = PlanarControlMsg {
            setpoint_torque_nm: tick.setpoint.torque_nm,
            setpoint_joint_rate_rad_per_s: tick.setpoint.joint_rate_rad_per_s,
            requested_torque_nm: tick.step.requested_torque_nm,
            applied_torque_nm: tick.step.applied_torque_nm,
            saturated: tick.step.saturated,
            terms: tick
                .terms
                .iter()
                .map(|(k, v)| ((*k).to_owned(), *v))
                .collect(),
        };
        let friction = FrictionMsg {
            friction_torque_nm: tick.step.friction_torque_nm,
            mode_code: tick.step.friction_mode.code(),
            mode: tick.step.friction_mode.as_str().to_owned(),
        };
        let r1 = self.log.write(&self.state, t, &state);
        self.keep(r1);
        let r2 = self.log.write(&self.command, t, &command);
        self.keep(r2);
        let r3 = self.log.write(&self.control, t, &control);
        self.keep(r3);
        let r4 = self.log.write(&self.friction, t, &friction);
        self.keep(r4);
    }

    fn fault(&mut self, fault: &Fault) {
        match fault.kind {
            FaultKind::Fell { tilt_rad } => {
                self.fault_event(fault.time_secs, "fell", tilt_rad, None);
            }
            FaultKind::NonFinite => {
                self.fault_event(fault.time_secs, "non_finite", f64::NAN, None);
            }
        }
    }
}
