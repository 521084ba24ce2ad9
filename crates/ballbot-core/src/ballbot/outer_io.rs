//! What the outer loop (400 Hz) reads and writes in one step: [`OuterInput`] from the IMU,
//! encoders and operator, [`MotorReferences`] for the motor drivers and the [`OuterOutput`]
//! record of everything that made them.

use crate::command::{Command, PlanarCommands};
use crate::estimation::{EncoderSample, ImuSample, PlanarStates};
use crate::safety::{ModeRequest, SafetyStatus};
use crate::traction::TractionStatus;
use nalgebra::{RealField, Vector3};

/// What the outer loop reads in one step.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
/// use ballbot_core::command::Command;
/// use ballbot_core::estimation::{EncoderSample, ImuSample};
/// use ballbot_core::safety::{Mode, ModeRequest};
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut outer = BallbotController::new(config)?;
/// let input = OuterInput {
///     now_us: 0,
///     imu: ImuSample::upright(0),
///     encoders: EncoderSample::still(0),
///     command: Command::Stop,
///     command_timestamp_us: Some(0),
///     request: ModeRequest::Arm,
/// };
/// assert_eq!(outer.step(&input).safety.mode, Mode::Balancing);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OuterInput<'a, T: nalgebra::Scalar> {
    /// Now, on the robot's monotonic clock (us).
    pub now_us: u64,
    /// The latest IMU sample.
    pub imu: ImuSample<T>,
    /// The latest encoder sample.
    pub encoders: EncoderSample<T>,
    /// The operator's command.
    pub command: Command<'a, T>,
    /// When the command was last received (us); `None`: never.
    pub command_timestamp_us: Option<u64>,
    /// The operator's mode request.
    pub request: ModeRequest,
}

/// What the main controller sends to the three motor drivers once per outer period.
///
/// The reference speed of each omniwheel over the coming period is the ramp
/// `speed_rad_per_s + accel_rad_per_s2 * t`, `t` the time since the references were produced:
/// the reference models' acceleration, so the motor drivers follow the reference speed between
/// outer updates instead of holding it (a held reference leaves a speed error of
/// `±accel dt / 2` that the PIs would fight every period; see
/// [`MotorSpeedLoop::set_references`](super::MotorSpeedLoop::set_references)). A driver that can only hold a speed should hold the
/// period's mean, `speed_rad_per_s + accel_rad_per_s2 * dt / 2`.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotControllerConfig, MotorReferences, MotorSpeedLoop};
/// use nalgebra::Vector3;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut inner = MotorSpeedLoop::new(&config)?;
/// // Wheel 1 at 2 rad/s, accelerating at 40 rad/s^2: halfway through the 2.5 ms period the
/// // driver's reference has ramped to 2.05 rad/s.
/// inner.set_references(&MotorReferences {
///     enabled: true,
///     speed_rad_per_s: Vector3::new(2.0, 0.0, 0.0),
///     accel_rad_per_s2: Vector3::new(40.0, 0.0, 0.0),
///     feedforward_torque_nm: Vector3::zeros(),
/// });
/// let mut out = inner.step(&Vector3::new(2.0, 0.0, 0.0), 1.25e-4);
/// for _ in 0..9 {
///     out = inner.step(&Vector3::new(2.0, 0.0, 0.0), 1.25e-4);
/// }
/// let expected = 2.0 + 40.0 * 9.5 * 1.25e-4; // at the middle of the 10th inner step
/// approx::assert_relative_eq!(out.reference_speed_rad_per_s[0], expected, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorReferences<T: nalgebra::Scalar> {
    /// Whether the drivers may apply torque; when `false` every other field is 0.
    pub enabled: bool,
    /// Reference omniwheel speeds `psi_dot_r` at the start of the period (rad/s, at the
    /// omniwheel), within the actuator's no-load speed.
    pub speed_rad_per_s: Vector3<T>,
    /// Reference omniwheel accelerations over the period (rad/s^2).
    pub accel_rad_per_s2: Vector3<T>,
    /// Feedforward omniwheel torques `tau_r` (N m, at the omniwheel), within the actuator's
    /// peak torque.
    pub feedforward_torque_nm: Vector3<T>,
}

impl<T: RealField + Copy> MotorReferences<T> {
    /// Motors off.
    ///
    /// ```
    /// use ballbot_core::ballbot::MotorReferences;
    /// let off = MotorReferences::<f64>::disabled();
    /// assert!(!off.enabled && off.feedforward_torque_nm.norm() == 0.0);
    /// ```
    pub fn disabled() -> Self {
        Self {
            enabled: false,
            speed_rad_per_s: Vector3::zeros(),
            accel_rad_per_s2: Vector3::zeros(),
            feedforward_torque_nm: Vector3::zeros(),
        }
    }
}

/// One outer step: the motor references and everything that made them (for logging).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
/// use ballbot_core::command::Command;
/// use ballbot_core::estimation::{EncoderSample, ImuSample};
/// use ballbot_core::safety::ModeRequest;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut outer = BallbotController::new(config)?;
/// // Armed while pitched 2 deg forward: the sagittal plane pushes the ball forward (tau_ry > 0),
/// // the frontal and spin planes have nothing to do.
/// let imu = ImuSample { pitch_rad: 2f64.to_radians(), ..ImuSample::upright(0) };
/// let input = OuterInput {
///     now_us: 0,
///     imu,
///     encoders: EncoderSample::still(0),
///     command: Command::Stop,
///     command_timestamp_us: Some(0),
///     request: ModeRequest::Arm,
/// };
/// let out = outer.step(&input);
/// assert!(out.motors.enabled && out.reference_torque_nm[1] > 0.0);
/// assert_eq!((out.reference_torque_nm[0], out.reference_torque_nm[2]), (0.0, 0.0));
/// assert_eq!(out.states.sagittal[0], 2f64.to_radians());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OuterOutput<T: nalgebra::Scalar> {
    /// For the motor drivers.
    pub motors: MotorReferences<T>,
    /// The supervisor's verdict (mode, faults of this step).
    pub safety: SafetyStatus,
    /// The estimated planar states (with traction-aware control, while a wheel slips, the
    /// ball rates without the slip the monitor estimated).
    pub states: PlanarStates<T>,
    /// The shaped planar command states (zero when the motors are off).
    pub commands: PlanarCommands<T>,
    /// Reference planar torques `[tau_rx, tau_ry, tau_rz]` actually fed forward, after the
    /// uniform scaling into the actuator limits (N m).
    pub reference_torque_nm: Vector3<T>,
    /// Reference planar rates `[phi_dot_rx, phi_dot_ry, theta_dot_rz]` (rad/s).
    pub reference_rate_rad_per_s: Vector3<T>,
    /// In a controlled stop, whether the shaped command has come to rest (the robot is
    /// holding).
    pub stopped: bool,
    /// Traction-aware control's report (envelope, limiting, slip and lift-off); `None` when
    /// it is off ([`BallbotControllerConfig::traction`](super::BallbotControllerConfig::traction)).
    pub traction: Option<TractionStatus<T>>,
}
