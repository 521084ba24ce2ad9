//! The messages of a world log: per-step telemetry, the controller's outer loop, commands and
//! events.

use ballbot_core::ballbot::OuterOutput;
use ballbot_core::command::VelocityCommand;
use ballbot_core::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use ballbot_world::world::failure::{Failure, tilt_from_vertical_rad};
use ballbot_world::world::telemetry::StepTelemetry;

/// The world's state after one step, in world coordinates (z up); topic
/// [`topics::WORLD_TELEMETRY`](crate::topics::WORLD_TELEMETRY).
///
/// The step's [`StepTelemetry`] as it is (its fields at the top level of the message: the
/// schema is the telemetry type's own), followed by quantities derived from it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldTelemetryMsg {
    /// The step's telemetry; `time_secs` equals the log time.
    #[serde(flatten)]
    pub step: StepTelemetry,
    /// Horizontal ball speed `|(v_x, v_y)|` (m/s).
    pub ball_speed_m_per_s: f64,
    /// Angle between the body axis and the vertical (rad).
    pub tilt_from_vertical_rad: f64,
    /// Body yaw (ZYX Euler) (rad).
    pub yaw_rad: f64,
    /// Largest cone utilisation of the three wheels.
    pub max_cone_utilisation: f64,
    /// Whether the world has detected a failure at or before this step.
    pub failed: bool,
}

impl WorldTelemetryMsg {
    /// The message of one step's telemetry; `failed` says whether a failure has been detected.
    pub fn new(t: &StepTelemetry, failed: bool) -> Self {
        let (_, _, yaw_rad) = t.body_orientation.euler_angles();
        let v = &t.ball_velocity_m_per_s;
        Self {
            step: *t,
            ball_speed_m_per_s: v.x.hypot(v.y),
            tilt_from_vertical_rad: tilt_from_vertical_rad(t),
            yaw_rad,
            max_cone_utilisation: t
                .wheels
                .iter()
                .map(|w| w.cone_utilisation)
                .fold(0.0, f64::max),
            failed,
        }
    }
}

/// A wheeled-inverted-pendulum plane's state `[theta, phi, theta_dot, phi_dot]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlaneStateMsg {
    /// Tilt `theta` (rad).
    pub tilt_rad: f64,
    /// Ball angle `phi` (rad).
    pub ball_angle_rad: f64,
    /// Tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// Ball rate `phi_dot` (rad/s).
    pub ball_rate_rad_per_s: f64,
}

impl PlaneStateMsg {
    fn new(s: &ballbot_core::WipState<f64>) -> Self {
        Self {
            tilt_rad: s[TILT],
            ball_angle_rad: s[BALL_ANGLE],
            tilt_rate_rad_per_s: s[TILT_RATE],
            ball_rate_rad_per_s: s[BALL_RATE],
        }
    }
}

/// The three planar states of the controller: sagittal and frontal planes, spin.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlanarStatesMsg {
    /// Sagittal plane (tilt about y, ball rolling along x).
    pub sagittal: PlaneStateMsg,
    /// Frontal plane (tilt about x, ball rolling along y).
    pub frontal: PlaneStateMsg,
    /// Heading `theta_z` (rad, unwrapped).
    pub yaw_rad: f64,
    /// Yaw rate `theta_dot_z` (rad/s).
    pub yaw_rate_rad_per_s: f64,
}

impl PlanarStatesMsg {
    fn new(
        sagittal: &ballbot_core::WipState<f64>,
        frontal: &ballbot_core::WipState<f64>,
        spin: &ballbot_core::spin::SpinState<f64>,
    ) -> Self {
        Self {
            sagittal: PlaneStateMsg::new(sagittal),
            frontal: PlaneStateMsg::new(frontal),
            yaw_rad: spin[0],
            yaw_rate_rad_per_s: spin[1],
        }
    }
}

/// One outer-loop step of the core's controller ([`OuterOutput`]); topic
/// [`topics::WORLD_CONTROLLER`](crate::topics::WORLD_CONTROLLER).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldControllerMsg {
    /// Safety mode: `idle`, `balancing`, `controlled_stop` or `fault`.
    pub mode: String,
    /// Whether the motors are driven.
    pub motors_enabled: bool,
    /// Faults raised this step, one bit per `ballbot_core::safety::Fault` code.
    pub fault_bits: u32,
    /// In a controlled stop, whether the shaped command has come to rest.
    pub stopped: bool,
    /// Reference omniwheel speeds `psi_dot_r` sent to the motor drivers (rad/s).
    pub wheel_speed_reference_rad_per_s: [f64; 3],
    /// Reference omniwheel accelerations over the period (rad/s^2).
    pub wheel_accel_reference_rad_per_s2: [f64; 3],
    /// Feedforward omniwheel torques `tau_r` (N m).
    pub feedforward_torque_nm: [f64; 3],
    /// Reference planar torques `[tau_rx, tau_ry, tau_rz]` (N m).
    pub reference_torque_nm: [f64; 3],
    /// Reference planar rates `[phi_dot_rx, phi_dot_ry, theta_dot_rz]` (rad/s).
    pub reference_rate_rad_per_s: [f64; 3],
    /// The estimated planar states.
    pub estimate: PlanarStatesMsg,
    /// The shaped planar command states.
    pub command: PlanarStatesMsg,
}

impl From<&OuterOutput<f64>> for WorldControllerMsg {
    fn from(out: &OuterOutput<f64>) -> Self {
        let m = &out.motors;
        Self {
            mode: out.safety.mode.as_str().to_owned(),
            motors_enabled: m.enabled,
            fault_bits: out.safety.faults.bits(),
            stopped: out.stopped,
            wheel_speed_reference_rad_per_s: m.speed_rad_per_s.into(),
            wheel_accel_reference_rad_per_s2: m.accel_rad_per_s2.into(),
            feedforward_torque_nm: m.feedforward_torque_nm.into(),
            reference_torque_nm: out.reference_torque_nm.into(),
            reference_rate_rad_per_s: out.reference_rate_rad_per_s.into(),
            estimate: PlanarStatesMsg::new(
                &out.states.sagittal,
                &out.states.frontal,
                &out.states.spin,
            ),
            command: PlanarStatesMsg::new(
                &out.commands.sagittal,
                &out.commands.frontal,
                &out.commands.spin,
            ),
        }
    }
}

/// A velocity command given to the robot; topic
/// [`topics::WORLD_COMMAND`](crate::topics::WORLD_COMMAND).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldCommandMsg {
    /// Commanded velocity along the body x axis (towards OW1) (m/s).
    pub vx_m_per_s: f64,
    /// Commanded velocity along the body y axis (m/s).
    pub vy_m_per_s: f64,
    /// Commanded yaw rate (rad/s).
    pub yaw_rate_rad_per_s: f64,
    /// Commanded speed `|(vx, vy)|` (m/s).
    pub speed_m_per_s: f64,
    /// Commanded heading in the body frame, `atan2(vy, vx)` (deg; 0 is towards OW1).
    pub heading_deg: f64,
}

impl From<&VelocityCommand<f64>> for WorldCommandMsg {
    fn from(c: &VelocityCommand<f64>) -> Self {
        Self {
            vx_m_per_s: c.vx_m_per_s,
            vy_m_per_s: c.vy_m_per_s,
            yaw_rate_rad_per_s: c.yaw_rate_rad_per_s,
            speed_m_per_s: c.vx_m_per_s.hypot(c.vy_m_per_s),
            heading_deg: c.vy_m_per_s.atan2(c.vx_m_per_s).to_degrees(),
        }
    }
}

/// A failure or another event of a world run; topic
/// [`topics::FAULTS`](crate::topics::FAULTS).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WorldEventMsg {
    /// What happened: a failure by its canonical name ([`FailureKind::as_str`]: `tilt`,
    /// `body_touched_floor`, `sustained_slip`, `lift_off`, `driver_trip`), a safety-mode change
    /// (`mode`), or
    /// a user event (e.g. `push`).
    ///
    /// [`FailureKind::as_str`]: ballbot_world::world::FailureKind::as_str
    pub kind: String,
    /// A human-readable description (for a failure its `Display`, e.g.
    /// `lift-off OW1 at 6.086 s`).
    pub description: String,
    /// The wheel concerned, `OW1`..`OW3` ([`wheel_name`](ballbot_world::world::wheel_name)), if any.
    pub wheel: Option<String>,
    /// Angle between the body axis and the vertical at the event (rad).
    pub tilt_rad: f64,
}

impl WorldEventMsg {
    /// The event of a detected failure; `tilt_rad` is the tilt from the vertical at detection.
    pub fn failure(failure: &Failure, tilt_rad: f64) -> Self {
        Self {
            kind: failure.kind.as_str().to_owned(),
            description: failure.to_string(),
            wheel: failure.kind.wheel_name().map(str::to_owned),
            tilt_rad,
        }
    }
}
