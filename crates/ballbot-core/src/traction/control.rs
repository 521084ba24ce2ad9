//! [`TractionControl`]: the envelope and the slip monitor as the 3D controller runs them, and
//! what it reports ([`TractionStatus`]).

use super::monitor::TiltTerms;
use super::{SlipMonitor, SlipStatus, TractionEnvelope, TractionParams};
use crate::command::AccelLimit;
use crate::estimation::PlanarStates;
use crate::kinematics::relative_rate_from_planar;
use crate::num::{max, min};
use crate::safety::SafetyStatus;
use crate::wip::{BALL_RATE, TILT_RATE};
use crate::{BallbotParams, Error, OmniKinematics};
use nalgebra::{RealField, Vector2, Vector3};

/// What traction-aware control did in one outer step
/// ([`OuterOutput::traction`](crate::ballbot::OuterOutput::traction)).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
/// use ballbot_core::command::Command;
/// use ballbot_core::estimation::{EncoderSample, ImuSample};
/// use ballbot_core::safety::ModeRequest;
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let config = BallbotControllerConfig::design(&robot)?.with_traction_control();
/// let mut outer = BallbotController::new(config)?;
/// let out = outer.step(&OuterInput {
///     now_us: 0,
///     imu: ImuSample::upright(0),
///     encoders: EncoderSample::still(0),
///     command: Command::Stop,
///     command_timestamp_us: Some(0),
///     request: ModeRequest::Arm,
/// });
/// // Standing still: nothing to limit, no slip, the static load predicted on every wheel.
/// let traction = out.traction.ok_or("traction control is on")?;
/// assert!(!traction.limited && traction.accel_limit_m_per_s2.is_none());
/// assert!(!traction.slip.any_slipping() && !traction.slip.lift_off_imminent);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TractionStatus<T: nalgebra::Scalar> {
    /// The acceleration limit along the direction the shaped command wanted to accelerate
    /// in this step (m/s^2): envelope, actuators, slip reaction and braking floor together.
    /// `None` when the command did not ask to accelerate (settled on its target).
    pub accel_limit_m_per_s2: Option<T>,
    /// Whether the envelope limited the command in this step: it asked for more acceleration
    /// than the envelope allows and the shaped command follows the envelope.
    pub limited: bool,
    /// Steps in which the command was limited, since the controller was built (saturating).
    pub limited_steps: u32,
    /// Slip and lift-off detection.
    pub slip: SlipStatus<T>,
}

/// The envelope ([`TractionEnvelope`]) and the slip monitor ([`SlipMonitor`]) of a 3D
/// controller with [`TractionParams::enabled`].
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::traction::{TractionControl, TractionParams};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let control = TractionControl::new(&robot, TractionParams::recommended(&robot))?;
/// assert_eq!(control.limited_steps(), 0);
/// assert!(control.envelope().friction_limit_m_per_s2(1.0, 0.0) > 0.5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TractionControl<T: RealField + Copy> {
    envelope: TractionEnvelope<T>,
    monitor: SlipMonitor<T>,
    limited_steps: u32,
}

impl<T: RealField + Copy> TractionControl<T> {
    /// Builds the envelope and the monitor for `robot` (validates `params`).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionControl, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let bad = TractionParams { min_normal_force_n: -1.0, ..TractionParams::recommended(&robot) };
    /// assert!(TractionControl::new(&robot, bad).is_err());
    /// ```
    pub fn new(robot: &BallbotParams<T>, params: TractionParams<T>) -> Result<Self, Error> {
        Ok(Self {
            envelope: TractionEnvelope::new(robot, &params)?,
            monitor: SlipMonitor::new(robot, params)?,
            limited_steps: 0,
        })
    }

    /// The envelope.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionControl, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let control = TractionControl::new(&robot, TractionParams::recommended(&robot))?;
    /// // Accelerating away from OW1 (180 deg) is allowed more than towards it.
    /// let e = control.envelope();
    /// assert!(e.friction_limit_m_per_s2(-1.0, 0.0) > e.friction_limit_m_per_s2(1.0, 0.0));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn envelope(&self) -> &TractionEnvelope<T> {
        &self.envelope
    }

    /// The slip monitor.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionControl, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let control = TractionControl::new(&robot, TractionParams::recommended(&robot))?;
    /// assert_eq!(control.monitor().status().slip_events, 0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn monitor(&self) -> &SlipMonitor<T> {
        &self.monitor
    }

    /// Steps with a limited command so far (see [`TractionStatus::limited`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionControl, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let control = TractionControl::new(&robot, TractionParams::recommended(&robot))?;
    /// assert_eq!(control.limited_steps(), 0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn limited_steps(&self) -> u32 {
        self.limited_steps
    }

    pub(crate) fn monitor_mut(&mut self) -> &mut SlipMonitor<T> {
        &mut self.monitor
    }

    /// The 3D controller's step before command shaping: the slip monitor's update on this
    /// step's valid samples, with the tilt terms the controller computed. Returns the omniwheel speeds for the actuator limit (measured, or
    /// from the estimate when the encoder sample was rejected) and whether a persisting slip
    /// asks for a controlled stop.
    #[inline]
    pub(crate) fn before_shaping(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        safety: &SafetyStatus,
        measured_wheel_speeds_rad_per_s: Vector3<T>,
        terms: &TiltTerms<T>,
        dt_secs: T,
    ) -> (Vector3<T>, bool) {
        if !safety.encoders_valid {
            let estimated = kinematics.wheel_speeds_rad_per_s(&relative_rate_from_planar(
                [states.frontal[BALL_RATE], states.sagittal[BALL_RATE]],
                [states.frontal[TILT_RATE], states.sagittal[TILT_RATE]],
                states.spin[1],
            ));
            return (estimated, false);
        }
        let speeds = measured_wheel_speeds_rad_per_s;
        if !safety.imu_valid {
            return (speeds, false);
        }
        let rel_z = kinematics.relative_z_rate_rad_per_s(&speeds);
        let stop = self
            .monitor
            .update_with_sin_cos(kinematics, states, rel_z, terms, dt_secs);
        (speeds, stop)
    }

    /// The 3D controller's step after its planes: the contact prediction under this step's
    /// reference planar torque, from the planes' model accelerations `[theta_ddot, phi_ddot]`
    /// (frontal, sagittal). Out of line: the controller without traction control keeps its own
    /// code layout.
    #[inline(never)]
    pub(crate) fn after_planes(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        terms: &TiltTerms<T>,
        accelerations: [Vector2<T>; 2],
        planar_torque_nm: &Vector3<T>,
    ) {
        let tilts = (terms.frontal_sin_cos, terms.sagittal_sin_cos);
        self.monitor.predict_with_accelerations(
            kinematics,
            states,
            tilts,
            accelerations,
            planar_torque_nm,
        );
    }

    /// The limit the shaper applies in this step, with the omniwheels at
    /// `wheel_speeds_rad_per_s`.
    pub(crate) fn step_limit(&self, wheel_speeds_rad_per_s: Vector3<T>) -> StepLimit<'_, T> {
        StepLimit {
            control: self,
            wheel_speeds_rad_per_s,
        }
    }

    /// Counts a limited step and returns the step's status.
    #[inline(always)]
    pub(crate) fn finish_step(
        &mut self,
        accel_limit_m_per_s2: Option<T>,
        limited: bool,
    ) -> TractionStatus<T> {
        if limited {
            self.limited_steps = self.limited_steps.saturating_add(1);
        }
        TractionStatus {
            accel_limit_m_per_s2,
            limited,
            limited_steps: self.limited_steps,
            slip: *self.monitor.status(),
        }
    }
}

/// The envelope of one step, as the command shaper asks it: friction table times the slip
/// reaction's scale, the actuators' limit at the present wheel speeds, and the braking floor.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepLimit<'a, T: RealField + Copy> {
    control: &'a TractionControl<T>,
    wheel_speeds_rad_per_s: Vector3<T>,
}

impl<T: RealField + Copy> AccelLimit<T> for StepLimit<'_, T> {
    fn accel_limit_m_per_s2(&self, dir_x: T, dir_y: T, braking: bool) -> T {
        // Read when asked: a settled command never asks.
        let (envelope, monitor) = (&self.control.envelope, &self.control.monitor);
        let friction = envelope.friction_limit_m_per_s2(dir_x, dir_y) * monitor.envelope_scale();
        let speeds = &self.wheel_speeds_rad_per_s;
        let actuators = envelope.actuator_limit_m_per_s2(dir_x, dir_y, speeds);
        let limit = min(friction, actuators);
        if braking {
            max(limit, monitor.min_braking_decel_m_per_s2())
        } else {
            limit
        }
    }
}
