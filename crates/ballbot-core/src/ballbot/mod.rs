//! The 3D ballbot controller: the paper's cascaded LQR-PI on MiaPURE (Sec. IV-D, Fig.
//! "PURE_control"), with command shaping and safety supervision.
//!
//! Two pieces, because on the robot they run on different processors:
//!
//! - [`BallbotController`], the **outer loop** (main controller, 400 Hz):
//!   1. [`SafetySupervisor`] checks the samples, timing and command link, runs the mode
//!      machine;
//!   2. [`Estimator`] builds the sagittal, frontal and spin states (inverse kinematics);
//!   3. [`CommandShaper`] turns the command (or, in a controlled stop, "come to rest") into
//!      jerk-limited planar command states;
//!   4. two [`LqrPiOuter`] planes (frontal x, sagittal y) and a [`SpinOuter`] give the reference
//!      planar torques `u_r = [tau_rx, tau_ry, tau_rz]` and reference rates
//!      `[phi_dot_rx, phi_dot_ry, theta_dot_rz]` (reference WIP and spin models);
//!   5. the kinematics ([`OmniKinematics`]) maps them to per-omniwheel feedforward torques
//!      `tau_r = J^-T S u_r` (scaled uniformly into the actuator limits) and reference
//!      omniwheel speeds `psi_dot_r = J [phi_dot_rx - theta_dot_x, phi_dot_ry - theta_dot_y,
//!      k . [phi_dot_rx, phi_dot_ry] - theta_dot_rz]` (measured tilt rates: the motor driver
//!      controls the relative rate). `k` ([`ball_body_z_rate_per_ball_rate`], 0 upright) is
//!      the rolling ball's rate about the leaning body's z axis when it does not spin about
//!      the vertical; without it the wheels turn a sideways lean at speed into a yaw rate
//!      (`-tan(roll) phi_dot_y`), which made the closed loop's yaw diverge above 2.6 m/s.
//!
//!   Its output is a small [`MotorReferences`] value: what the main controller sends to the
//!   motor drivers.
//! - [`MotorSpeedLoop`], the **inner loop** (motor drivers, 8 kHz): one [`SpeedPi`] per
//!   omniwheel, `tau_i = sat(tau_ri + kp (psi_dot_ri - psi_dot_i) + I_i)` within the actuator's
//!   torque-speed limits ([`ActuatorParams::torque_bounds_nm`]), back-calculation anti-windup
//!   driven by the applied torque.
//!
//! **Guarantees**, whatever the input (tested with proptest): no panic, no allocation, bounded
//! time; every output finite; feedforward torques within the actuator peak, reference speeds
//! within the no-load speed, applied torques within the actuator's torque-speed limits; motors
//! disabled (zero torque, integrators cleared) outside [`Mode::Balancing`] and
//! [`Mode::ControlledStop`].
//!
//! **Per-motor PI gains** ([`motor_speed_pi_gains`]). With the reference model equal to the
//! plant, each plane's ball-rate error obeys `e_dot = -B4 tau_e`. The wheel error is
//! `J e` and a wheel PI `tau_w = kp e_w` gives the planar torque `S J^T kp J e`; for the
//! symmetric layout `J^T J = (r_S / r_W)^2 diag(3/2 cos^2 a, 3/2 cos^2 a, 3 sin^2 a)`, so in
//! translation the wheel loop acts like a planar PI on the plant `b_w = B4 (J^T J)_xx`.
//! Designing the wheel PI for `b_w` reproduces the planar PI of the paper exactly.
//!
//! ```
//! use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput};
//! use ballbot_core::command::{Command, VelocityCommand};
//! use ballbot_core::estimation::{EncoderSample, ImuSample};
//! use ballbot_core::safety::{Mode, ModeRequest};
//! use ballbot_core::BallbotParams;
//! let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
//! let mut outer = BallbotController::new(config)?;
//! let mut inner = MotorSpeedLoop::new(&config)?;
//! let input = OuterInput {
//!     now_us: 0,
//!     imu: ImuSample::upright(0),
//!     encoders: EncoderSample::still(0),
//!     command: Command::Velocity(VelocityCommand::zero()),
//!     command_timestamp_us: Some(0),
//!     request: ModeRequest::Arm,
//! };
//! let out = outer.step(&input);
//! assert_eq!(out.safety.mode, Mode::Balancing);
//! // 20 inner steps per outer step at 8 kHz.
//! inner.set_references(&out.motors);
//! let torques = inner.step(&input.encoders.wheel_speeds_rad_per_s, 1.25e-4);
//! assert!(torques.torque_nm.iter().all(|t| t.abs() <= 43.2));
//! # Ok::<(), ballbot_core::Error>(())
//! ```
//!
//! [`ball_body_z_rate_per_ball_rate`]: crate::estimation::ball_body_z_rate_per_ball_rate

use crate::check::{lit, positive};
use crate::command::{Command, CommandShaper, CommandShaperParams, PlanarCommands};
use crate::control::{
    LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains, StepStatus,
};
use crate::estimation::{
    EncoderSample, Estimator, ImuSample, PlanarStates, ball_body_z_rate_per_ball_rate_sin_cos,
};
use crate::lqr::{
    SpinLqrWeights, WipLqrWeights, outer_loop_dt_secs, spin_lqr_discrete, wip_lqr_discrete,
};
use crate::num::{clamp_sym, max, min};
use crate::safety::{
    Fault, Mode, ModeRequest, SafetyInput, SafetyParams, SafetyStatus, SafetySupervisor,
};
use crate::spin::SpinState;
use crate::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{ActuatorParams, BallbotParams, Error, OmniKinematics, Spin, Wip};
use nalgebra::{RealField, Vector3};

/// Gains of the spin LQR `tau_rz = k_heading (theta_zc - theta_z) + k_rate (theta_dot_zc -
/// theta_dot_z)`, saturated.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::BallbotControllerConfig;
/// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// let g = config.spin.gains;
/// // Turning left (positive yaw) needs positive torque: both gains are positive.
/// assert!(g.heading_nm_per_rad > 0.0 && g.rate_nm_s_per_rad > 0.0);
/// // The limit is the drivetrain's yaw torque capacity, 167.9 N m for MiaPURE.
/// approx::assert_relative_eq!(g.max_torque_nm, 167.9, epsilon = 0.05);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinGains<T> {
    /// On the heading error (N m/rad).
    pub heading_nm_per_rad: T,
    /// On the yaw-rate error (N m s/rad).
    pub rate_nm_s_per_rad: T,
    /// Symmetric yaw-torque limit (N m, > 0).
    pub max_torque_nm: T,
}

/// Configuration of [`SpinOuter`].
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuterConfig};
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// config.validate()?;
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinOuterConfig<T> {
    /// The LQR gains.
    pub gains: SpinGains<T>,
    /// Largest distance between the integrated reference yaw rate and the measured yaw rate
    /// (rad/s, > 0), as [`LqrPiOuterConfig::max_speed_error_rad_per_s`].
    pub max_rate_error_rad_per_s: T,
}

impl<T: RealField + Copy> SpinOuterConfig<T> {
    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::ballbot::{SpinGains, SpinOuterConfig};
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 0.0 };
    /// assert!(matches!(
    ///     config.validate(),
    ///     Err(Error::InvalidParameter { field: "max_rate_error_rad_per_s", .. })
    /// ));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let g = &self.gains;
        crate::check::finite(g.heading_nm_per_rad, "heading_nm_per_rad")?;
        crate::check::finite(g.rate_nm_s_per_rad, "rate_nm_s_per_rad")?;
        positive(g.max_torque_nm, "max_torque_nm")?;
        positive(self.max_rate_error_rad_per_s, "max_rate_error_rad_per_s")
    }
}

/// One [`SpinOuter`] step.
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
/// use ballbot_core::control::StepStatus;
/// use ballbot_core::{Spin, SpinParams};
/// use nalgebra::Vector2;
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// let mut spin = SpinOuter::new(Spin::new(SpinParams::<f64>::miapure_60kg())?, config)?;
/// // 0.5 rad short of the commanded heading: 5 N m of yaw torque, the model accelerates.
/// let o = spin.step(&Vector2::zeros(), &Vector2::new(0.5, 0.0), 0.0025);
/// assert_eq!((o.reference_torque_nm, o.status), (5.0, StepStatus::Nominal));
/// assert!(o.reference_accel_rad_per_s2 > 0.0);
/// approx::assert_relative_eq!(
///     o.reference_rate_rad_per_s,
///     0.5 * 0.0025 * o.reference_accel_rad_per_s2,
///     epsilon = 1e-12
/// );
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinOuterOutput<T> {
    /// Reference yaw torque `tau_rz` after saturation (N m).
    pub reference_torque_nm: T,
    /// Reference yaw rate `theta_dot_rz` over the coming period (rad/s).
    pub reference_rate_rad_per_s: T,
    /// Reference yaw acceleration of the spin model (rad/s^2).
    pub reference_accel_rad_per_s2: T,
    /// Nominal, saturated or rejected.
    pub status: StepStatus,
}

/// The spin plane of the cascaded LQR-PI: LQR reference torque, reference spin model
/// `theta_ddot_rz = (tau_rz - D_z theta_dot_z) / I_z` at the measured state, integrated to the
/// reference yaw rate (anchored to the measured rate as [`LqrPiOuter`] does).
///
/// ```
/// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
/// use ballbot_core::{Spin, SpinParams, rk4_step};
/// use nalgebra::Vector2;
/// // Turning the robot 90 deg with the spin outer loop alone (its reference torque applied).
/// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
/// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
/// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
/// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
/// let mut spin = SpinOuter::new(model, config)?;
/// let command = Vector2::new(core::f64::consts::FRAC_PI_2, 0.0);
/// let mut s = Vector2::zeros();
/// for _ in 0..10 * 400 {
///     let tau = spin.step(&s, &command, 0.0025).reference_torque_nm;
///     s = rk4_step(|x| model.derivative(x, tau), &s, 0.0025);
/// }
/// approx::assert_relative_eq!(s[0], core::f64::consts::FRAC_PI_2, epsilon = 1e-3);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinOuter<T> {
    model: Spin<T>,
    config: SpinOuterConfig<T>,
    reference_rate_rad_per_s: Option<T>,
}

impl<T: RealField + Copy> SpinOuter<T> {
    /// Validates `config`; `model` is the reference spin model.
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::{Spin, SpinParams};
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// assert!(SpinOuter::new(model, config).is_ok());
    /// let nan_gain = SpinGains { heading_nm_per_rad: f64::NAN, ..gains };
    /// let bad = SpinOuterConfig { gains: nan_gain, max_rate_error_rad_per_s: 2.0 };
    /// assert!(SpinOuter::new(model, bad).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(model: Spin<T>, config: SpinOuterConfig<T>) -> Result<Self, Error> {
        config.validate()?;
        Ok(Self {
            model,
            config,
            reference_rate_rad_per_s: None,
        })
    }

    /// Forgets the reference integral (re-anchored at the next step).
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 167.9 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// let mut spin = SpinOuter::new(model, config)?;
    /// spin.step(&Vector2::zeros(), &Vector2::new(1.0, 0.0), 0.0025);
    /// spin.reset();
    /// // Re-anchored at the measured 0.3 rad/s, on command: no torque; the reference starts
    /// // at the measurement.
    /// let s = Vector2::new(0.0, 0.3);
    /// let o = spin.step(&s, &s, 0.0025);
    /// let damping = model.params().damping_nm_s_per_rad;
    /// assert_eq!(o.reference_torque_nm, 0.0);
    /// let accel = o.reference_accel_rad_per_s2;
    /// approx::assert_relative_eq!(accel, -damping * 0.3 / model.params().inertia_kg_m2);
    /// approx::assert_relative_eq!(o.reference_rate_rad_per_s, 0.3 + 0.5 * 0.0025 * accel);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.reference_rate_rad_per_s = None;
    }

    /// One step: `measured` and `command` are `[theta_z, theta_dot_z]`. A non-finite input or
    /// a bad `dt_secs` gives zero torque, the held reference and
    /// [`StepStatus::InvalidInput`].
    ///
    /// ```
    /// use ballbot_core::ballbot::{SpinGains, SpinOuter, SpinOuterConfig};
    /// use ballbot_core::control::StepStatus;
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// let model = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (heading_nm_per_rad, rate_nm_s_per_rad) = (10.0, 8.0);
    /// let gains = SpinGains { heading_nm_per_rad, rate_nm_s_per_rad, max_torque_nm: 20.0 };
    /// let config = SpinOuterConfig { gains, max_rate_error_rad_per_s: 2.0 };
    /// let mut spin = SpinOuter::new(model, config)?;
    /// // Half a turn away: 31 N m asked, clipped to the 20 N m limit.
    /// let o = spin.step(&Vector2::zeros(), &Vector2::new(core::f64::consts::PI, 0.0), 0.0025);
    /// assert_eq!((o.reference_torque_nm, o.status), (20.0, StepStatus::Saturated));
    /// // A NaN heading: zero torque, flagged.
    /// let o = spin.step(&Vector2::new(f64::NAN, 0.0), &Vector2::zeros(), 0.0025);
    /// assert_eq!((o.reference_torque_nm, o.status), (0.0, StepStatus::InvalidInput));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        measured: &SpinState<T>,
        command: &SpinState<T>,
        dt_secs: T,
    ) -> SpinOuterOutput<T> {
        let g = &self.config.gains;
        let requested = g.heading_nm_per_rad * (command[0] - measured[0])
            + g.rate_nm_s_per_rad * (command[1] - measured[1]);
        let rate = measured[1];
        if !(requested.is_finite() && rate.is_finite() && dt_secs.is_finite())
            || dt_secs <= T::zero()
        {
            return SpinOuterOutput {
                reference_torque_nm: T::zero(),
                reference_rate_rad_per_s: self.reference_rate_rad_per_s.unwrap_or(T::zero()),
                reference_accel_rad_per_s2: T::zero(),
                status: StepStatus::InvalidInput,
            };
        }
        let torque = clamp_sym(requested, g.max_torque_nm);
        let status = if torque == requested {
            StepStatus::Nominal
        } else {
            StepStatus::Saturated
        };
        let accel = self.model.acceleration(measured, torque);
        let band = self.config.max_rate_error_rad_per_s;
        // Plain min/max: the stored rate, the measured rate and the band are finite.
        let stored = self.reference_rate_rad_per_s.unwrap_or(rate);
        let anchored = min(rate + band, max(rate - band, stored));
        self.reference_rate_rad_per_s = Some(anchored + accel * dt_secs);
        SpinOuterOutput {
            reference_torque_nm: torque,
            reference_rate_rad_per_s: anchored + accel * dt_secs * lit(0.5),
            reference_accel_rad_per_s2: accel,
            status,
        }
    }
}

/// Everything the 3D controller needs, validated by [`BallbotController::new`].
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
/// // The designed configuration, then one engineering change: no remote, no link supervision.
/// let mut config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
/// config.safety.command_timeout_us = None;
/// let controller = BallbotController::new(config)?;
/// assert_eq!(controller.config().safety.command_timeout_us, None);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallbotControllerConfig<T> {
    /// The robot (reference models and kinematics).
    pub robot: BallbotParams<T>,
    /// Frontal plane (x) outer LQR-PI.
    pub frontal: LqrPiOuterConfig<T>,
    /// Sagittal plane (y) outer LQR-PI.
    pub sagittal: LqrPiOuterConfig<T>,
    /// Spin outer loop.
    pub spin: SpinOuterConfig<T>,
    /// The per-omniwheel speed PI (torques at the omniwheel).
    pub motor: SpeedPiGains<T>,
    /// Command shaping.
    pub shaping: CommandShaperParams<T>,
    /// Safety thresholds.
    pub safety: SafetyParams<T>,
    /// Outer-loop period (s): 1/400 on MiaPURE.
    pub outer_dt_secs: T,
}

/// LQR weights and bandwidths for [`BallbotControllerConfig::design_with`].
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BallbotControllerConfig, BallbotDesign};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// // A stiffer motor loop: 60 rad/s instead of 30.
/// let stiff = BallbotDesign { motor_bandwidth_rad_per_s: 60.0, ..BallbotDesign::paper() };
/// let a = BallbotControllerConfig::design_with(&robot, &stiff)?;
/// let b = BallbotControllerConfig::design(&robot)?;
/// // kp grows with the bandwidth, ki with its square.
/// let (a, b) = (a.motor, b.motor);
/// approx::assert_relative_eq!(a.proportional_nm_s_per_rad, 2.0 * b.proportional_nm_s_per_rad);
/// approx::assert_relative_eq!(a.integral_nm_per_rad, 4.0 * b.integral_nm_per_rad);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallbotDesign<T: RealField + Copy> {
    /// Weights of both WIP planes on `[theta, theta_dot, phi_dot]` and the torque.
    pub plane_weights: WipLqrWeights<T>,
    /// Weights of the spin plane on `[theta_z, theta_dot_z]` and the yaw torque.
    pub spin_weights: SpinLqrWeights<T>,
    /// Bandwidth of the per-motor speed PI (rad/s): critically damped double pole.
    pub motor_bandwidth_rad_per_s: T,
    /// Outer-loop period (s).
    pub outer_dt_secs: T,
}

impl<T: RealField + Copy> BallbotDesign<T> {
    /// MODEL.md's plane weights `Q = diag(100, 10, 1)`, `R = 0.1`; spin `Q = diag(100, 10)`,
    /// `R = 1` (an engineering choice: heading error 0.1 rad costs like 1 N m); a 30 rad/s
    /// motor PI; 400 Hz.
    ///
    /// ```
    /// use ballbot_core::ballbot::BallbotDesign;
    /// let d = BallbotDesign::<f64>::paper();
    /// assert_eq!((d.motor_bandwidth_rad_per_s, d.outer_dt_secs), (30.0, 1.0 / 400.0));
    /// assert_eq!(d.plane_weights.r, 0.1);
    /// ```
    pub fn paper() -> Self {
        Self {
            plane_weights: WipLqrWeights::model_default(),
            spin_weights: SpinLqrWeights::diagonal([lit(100.0), lit(10.0)], T::one()),
            motor_bandwidth_rad_per_s: lit(30.0),
            outer_dt_secs: outer_loop_dt_secs(),
        }
    }
}

impl<T: RealField + Copy> BallbotControllerConfig<T> {
    /// [`Self::design_with`] the [`BallbotDesign::paper`] weights.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// // Discrete LQR at 400 Hz, close to MODEL.md's continuous k1 = -234.8.
    /// let k1 = config.sagittal.lqr.tilt_nm_per_rad;
    /// approx::assert_relative_eq!(k1, -234.8, max_relative = 0.1);
    /// // The frontal plane has the smaller torque capacity (83.9 vs 96.9 N m).
    /// approx::assert_relative_eq!(config.frontal.lqr.max_torque_nm, 83.9, epsilon = 0.05);
    /// approx::assert_relative_eq!(config.sagittal.lqr.max_torque_nm, 96.9, epsilon = 0.05);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn design(robot: &BallbotParams<T>) -> Result<Self, Error> {
        Self::design_with(robot, &BallbotDesign::paper())
    }

    /// Designs every gain from the model: discrete LQR at the outer period on each plane's
    /// upright linearisation and on the spin model (torque limits: the planar torque
    /// capacity of the drivetrain), the motor PI from [`motor_speed_pi_gains`], and the
    /// MiaPURE shaping and safety defaults (wheel-speed limits from the robot's actuator).
    ///
    /// ```
    /// use ballbot_core::ballbot::{BallbotControllerConfig, BallbotDesign};
    /// use ballbot_core::{BallbotParams, Error};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// // A 200 Hz outer loop.
    /// let slow = BallbotDesign { outer_dt_secs: 1.0 / 200.0, ..BallbotDesign::paper() };
    /// let config = BallbotControllerConfig::design_with(&robot, &slow)?;
    /// assert_eq!(config.outer_dt_secs, 0.005);
    /// // A period that is not positive is refused, naming the field.
    /// let broken = BallbotDesign { outer_dt_secs: 0.0, ..BallbotDesign::paper() };
    /// assert!(matches!(
    ///     BallbotControllerConfig::design_with(&robot, &broken),
    ///     Err(Error::InvalidParameter { field: "outer_dt_secs", .. })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn design_with(robot: &BallbotParams<T>, design: &BallbotDesign<T>) -> Result<Self, Error> {
        let kin = OmniKinematics::from_ballbot(robot)?;
        let capacity = kin.planar_torque_capacity_nm();
        let dt = design.outer_dt_secs;
        positive(dt, "outer_dt_secs")?;
        let motor = motor_speed_pi_gains(robot, &kin, design.motor_bandwidth_rad_per_s)?;
        let plane = |params, max_torque_nm| -> Result<LqrPiOuterConfig<T>, Error> {
            let wip = Wip::new(params)?;
            let lqr = wip_lqr_discrete(&wip, &design.plane_weights, dt)?;
            let gains = LqrGains::from_reduced(lqr.reduced_gains(), max_torque_nm);
            // The anchor band: the speed error at which the planar-equivalent P term alone
            // saturates (see LqrPiOuterConfig::new), from the wheel PI's planar equivalent.
            let planar_pi = SpeedPiGains::for_wip_ball_rate(
                &wip,
                design.motor_bandwidth_rad_per_s,
                max_torque_nm,
            )?;
            LqrPiOuterConfig::new(gains, &planar_pi)
        };
        let spin = Spin::new(robot.spin)?;
        let spin_lqr = spin_lqr_discrete(&spin, &design.spin_weights, dt)?;
        let spin_config = SpinOuterConfig {
            gains: SpinGains {
                heading_nm_per_rad: spin_lqr.gain[0],
                rate_nm_s_per_rad: spin_lqr.gain[1],
                max_torque_nm: capacity[2],
            },
            max_rate_error_rad_per_s: lit(2.0),
        };
        Ok(Self {
            robot: *robot,
            frontal: plane(robot.frontal, capacity[0])?,
            sagittal: plane(robot.sagittal, capacity[1])?,
            spin: spin_config,
            motor,
            shaping: CommandShaperParams::miapure(),
            safety: SafetyParams::for_actuator(&robot.drivetrain.actuator),
            outer_dt_secs: dt,
        })
    }
}

/// Per-omniwheel speed PI gains (torques at the omniwheel) with a critically damped double
/// pole at `-bandwidth_rad_per_s` for translation (see the module docs): the plant gain is
/// `b_w = B4 (J^T J)_xy`, averaged over the two planes' `B4` and the x and y diagonal entries.
///
/// ```
/// use ballbot_core::ballbot::motor_speed_pi_gains;
/// use ballbot_core::control::SpeedPiGains;
/// use ballbot_core::{BallbotParams, OmniKinematics, Wip};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let kin = OmniKinematics::from_ballbot(&robot)?;
/// let wheel = motor_speed_pi_gains(&robot, &kin, 30.0)?;
/// // Seen from the plane, the three wheel PIs act as the planar PI of the paper:
/// // S J^T kp J = kp (J^T J)_xx, so kp_wheel (J^T J)_xx equals the planar kp (to the
/// // difference between the two planes' B4, averaged here).
/// let j = kin.wheel_speed_matrix();
/// let jtj = j.transpose() * j;
/// let planar = SpeedPiGains::for_wip_ball_rate(&Wip::new(robot.sagittal)?, 30.0, 96.9)?;
/// let kp_planar_equivalent = wheel.proportional_nm_s_per_rad * jtj[(1, 1)];
/// let kp_planar = planar.proportional_nm_s_per_rad;
/// approx::assert_relative_eq!(kp_planar_equivalent, kp_planar, max_relative = 0.05);
/// assert_eq!(wheel.max_torque_nm, 43.2); // the actuator's peak, at the omniwheel
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn motor_speed_pi_gains<T: RealField + Copy>(
    robot: &BallbotParams<T>,
    kinematics: &OmniKinematics<T>,
    bandwidth_rad_per_s: T,
) -> Result<SpeedPiGains<T>, Error> {
    let b4 = |p| -> Result<T, Error> { Ok(Wip::new(p)?.linearize_upright().B[BALL_RATE]) };
    let b4_mean = (b4(robot.frontal)? + b4(robot.sagittal)?) * lit(0.5);
    let j = kinematics.wheel_speed_matrix();
    let jtj = j.transpose() * j;
    let b_w = b4_mean * (jtj[(0, 0)] + jtj[(1, 1)]) * lit(0.5);
    SpeedPiGains::from_bandwidth(
        b_w,
        bandwidth_rad_per_s,
        robot.drivetrain.actuator.peak_torque_nm,
    )
}

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
/// [`MotorSpeedLoop::set_references`]). A driver that can only hold a speed should hold the
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
    /// The estimated planar states.
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
}

/// The outer loop of the 3D controller (see the module docs).
///
/// **Input feedforward.** The LQR `tau = k (s_c - s)` has no torque feedforward; at a
/// commanded steady acceleration `phi_ddot_c` the plane needs `tau = b phi_ddot_c` with the
/// body at its equilibrium lean, and without help the LQR would find it only through a
/// standing speed error (0.35 m/s at 1 m/s^2 on MiaPURE). The controller shifts each tilt
/// command by `b phi_ddot_c / k1`, so the LQR's output at the accelerating equilibrium is
/// exactly that torque, and the heading command by `(I_z theta_ddot_zc + D_z theta_dot_zc) /
/// k_heading` for the spin plane. A trajectory also tilts the body: its tilt command is shifted
/// by a further `c(theta_c) theta_ddot_c / k1`, `c(theta) = m_U r l cos(theta) - I_W`, so that
/// the feedforward is the second row of the WIP equations, `c(theta_c) theta_ddot_c + b
/// phi_ddot_c`, with the slopes of the trajectory's interpolated rates (on MiaPURE `c` is four
/// times `b`: braking's onset tips the body back hard). The logged [`OuterOutput::commands`] are the unshifted,
/// physical command states.
///
/// ```
/// use ballbot_core::ballbot::{
///     BallbotController, BallbotControllerConfig, MotorSpeedLoop, OuterInput,
/// };
/// use ballbot_core::command::{Command, VelocityCommand};
/// use ballbot_core::estimation::{PlanarStates, synthesize_sensors};
/// use ballbot_core::kinematics::relative_rate_from_planar;
/// use ballbot_core::safety::{Mode, ModeRequest};
/// use ballbot_core::{BallbotParams, OmniKinematics, Spin, Wip, rk4_step};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let config = BallbotControllerConfig::design(&robot)?;
/// let (mut outer, mut inner) = (BallbotController::new(config)?, MotorSpeedLoop::new(&config)?);
/// // The plant: the three planar models, coupled through the omniwheel kinematics.
/// let kin = OmniKinematics::from_ballbot(&robot)?;
/// let (fro, sag) = (Wip::new(robot.frontal)?, Wip::new(robot.sagittal)?);
/// let spin = Spin::new(robot.spin)?;
/// let mut s = PlanarStates::zeros();
/// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
/// let dt_inner = 1.0 / 8000.0;
/// for k in 0..4 * 400 {
///     let now_us = k * 2500;
///     let (imu, encoders) = synthesize_sensors(&kin, &s, now_us);
///     let request = if k == 0 { ModeRequest::Arm } else { ModeRequest::None };
///     let input = OuterInput {
///         now_us,
///         imu,
///         encoders,
///         command: go,
///         command_timestamp_us: Some(now_us),
///         request,
///     };
///     let out = outer.step(&input);
///     inner.set_references(&out.motors);
///     for _ in 0..20 {
///         let rel = relative_rate_from_planar(
///             [s.frontal[3], s.sagittal[3]],
///             [s.frontal[2], s.sagittal[2]],
///             s.spin[1],
///         );
///         let wheel_torques_nm = inner.step(&kin.wheel_speeds_rad_per_s(&rel), dt_inner).torque_nm;
///         let tau = kin.planar_torque_nm(&wheel_torques_nm);
///         s.frontal = rk4_step(|x| fro.derivative(x, tau[0]), &s.frontal, dt_inner);
///         s.sagittal = rk4_step(|x| sag.derivative(x, tau[1]), &s.sagittal, dt_inner);
///         s.spin = rk4_step(|x| spin.derivative(x, tau[2]), &s.spin, dt_inner);
///     }
/// }
/// assert_eq!(outer.mode(), Mode::Balancing);
/// // After 4 s the ball rolls forward at 1 m/s (x = r phi_y), the body upright; nothing moved
/// // sideways or turned.
/// let r = robot.sagittal.ball_radius_m;
/// assert!((s.sagittal[3] * r - 1.0).abs() < 0.01 && s.sagittal[0].abs() < 1e-3);
/// assert!(s.frontal[3].abs() < 1e-9 && s.spin[1].abs() < 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallbotController<T: RealField + Copy> {
    config: BallbotControllerConfig<T>,
    kinematics: OmniKinematics<T>,
    supervisor: SafetySupervisor<T>,
    estimator: Estimator<T>,
    shaper: CommandShaper<T>,
    frontal: LqrPiOuter<T>,
    sagittal: LqrPiOuter<T>,
    spin: SpinOuter<T>,
    feedforward: InputFeedforward<T>,
}

/// The shifts of the command states that make each LQR's output equal the torque its plane
/// needs to follow the commanded acceleration (see [`BallbotController`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct InputFeedforward<T> {
    /// Frontal tilt-command shift per m/s^2 of body-y acceleration (rad s^2/m).
    frontal_rad_per_m_per_s2: T,
    /// Sagittal tilt-command shift per m/s^2 of body-x acceleration (rad s^2/m).
    sagittal_rad_per_m_per_s2: T,
    /// Heading-command shift per rad/s^2 of yaw acceleration (s^2).
    heading_per_yaw_accel_s2: T,
    /// Heading-command shift per rad/s of yaw rate (s).
    heading_per_yaw_rate_s: T,
    /// Frontal tilt-command shift per rad/s^2 of commanded tilt acceleration.
    frontal_tilt: TiltFeedforward<T>,
    /// Sagittal tilt-command shift per rad/s^2 of commanded tilt acceleration.
    sagittal_tilt: TiltFeedforward<T>,
}

/// A plane's tilt-command shift `c(theta_c) theta_ddot_c / k1` for a commanded tilt
/// acceleration, `c(theta) = m_U r l cos(theta) - I_W` (the mass matrix's coupling).
#[derive(Clone, Copy, Debug, PartialEq)]
struct TiltFeedforward<T> {
    /// `m_U r l / k1` (s^2).
    coupling_per_k1_s2: T,
    /// `I_W / k1` (s^2).
    wheel_per_k1_s2: T,
}

impl<T: RealField + Copy> TiltFeedforward<T> {
    fn new(p: &crate::WipParams<T>, k1: T) -> Self {
        let per = |x: T| {
            let v = x / k1;
            if v.is_finite() { v } else { T::zero() }
        };
        Self {
            coupling_per_k1_s2: per(p.body_mass_kg * p.ball_radius_m * p.com_height_m),
            wheel_per_k1_s2: per(p.wheel_inertia_kg_m2),
        }
    }

    /// The shift for tilt command `tilt_rad` and its acceleration (rad).
    #[inline]
    fn shift(&self, tilt_rad: T, tilt_accel_rad_per_s2: T) -> T {
        if tilt_accel_rad_per_s2 == T::zero() {
            return T::zero();
        }
        (self.coupling_per_k1_s2 * tilt_rad.cos() - self.wheel_per_k1_s2) * tilt_accel_rad_per_s2
    }
}

impl<T: RealField + Copy> InputFeedforward<T> {
    fn new(config: &BallbotControllerConfig<T>) -> Self {
        // The torque that accelerates the ball at phi_ddot with the body steadily leaning is
        // b phi_ddot, b = I_S + (m_S + m_U) r^2 + I_W (second row of the WIP equations).
        let plane = |p: &crate::WipParams<T>, k1: T| {
            let b = p.ball_inertia_kg_m2
                + (p.ball_mass_kg + p.body_mass_kg) * p.ball_radius_m * p.ball_radius_m
                + p.wheel_inertia_kg_m2;
            let shift = b / (k1 * p.ball_radius_m);
            if shift.is_finite() { shift } else { T::zero() }
        };
        let k_heading = config.spin.gains.heading_nm_per_rad;
        let per = |x: T| {
            let v = x / k_heading;
            if v.is_finite() { v } else { T::zero() }
        };
        Self {
            frontal_rad_per_m_per_s2: -plane(
                &config.robot.frontal,
                config.frontal.lqr.tilt_nm_per_rad,
            ),
            sagittal_rad_per_m_per_s2: plane(
                &config.robot.sagittal,
                config.sagittal.lqr.tilt_nm_per_rad,
            ),
            heading_per_yaw_accel_s2: per(config.robot.spin.inertia_kg_m2),
            heading_per_yaw_rate_s: per(config.robot.spin.damping_nm_s_per_rad),
            frontal_tilt: TiltFeedforward::new(
                &config.robot.frontal,
                config.frontal.lqr.tilt_nm_per_rad,
            ),
            sagittal_tilt: TiltFeedforward::new(
                &config.robot.sagittal,
                config.sagittal.lqr.tilt_nm_per_rad,
            ),
        }
    }
}

impl<T: RealField + Copy> BallbotController<T> {
    /// Validates `config` and builds every piece; starts in [`Mode::Idle`].
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// use ballbot_core::safety::Mode;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert_eq!(BallbotController::new(config)?.mode(), Mode::Idle);
    /// let bad = BallbotControllerConfig { outer_dt_secs: -0.0025, ..config };
    /// assert!(BallbotController::new(bad).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(config: BallbotControllerConfig<T>) -> Result<Self, Error> {
        let kinematics = OmniKinematics::from_ballbot(&config.robot)?;
        positive(config.outer_dt_secs, "outer_dt_secs")?;
        config.motor.validate()?;
        Ok(Self {
            config,
            kinematics,
            supervisor: SafetySupervisor::new(config.safety)?,
            estimator: Estimator::new(kinematics),
            shaper: CommandShaper::new(config.shaping, &config.robot)?,
            frontal: LqrPiOuter::new(Wip::new(config.robot.frontal)?, config.frontal)?,
            sagittal: LqrPiOuter::new(Wip::new(config.robot.sagittal)?, config.sagittal)?,
            spin: SpinOuter::new(Spin::new(config.robot.spin)?, config.spin)?,
            feedforward: InputFeedforward::new(&config),
        })
    }

    /// The configuration.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert_eq!(BallbotController::new(config)?.config().outer_dt_secs, 1.0 / 400.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn config(&self) -> &BallbotControllerConfig<T> {
        &self.config
    }

    /// The current mode.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// use ballbot_core::safety::{Fault, Mode};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut outer = BallbotController::new(config)?;
    /// assert_eq!(outer.mode(), Mode::Idle);
    /// // While idle a reported fault changes nothing.
    /// outer.report(Fault::LoopOverrun);
    /// assert_eq!(outer.mode(), Mode::Idle);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn mode(&self) -> Mode {
        self.supervisor.mode()
    }

    /// The supervisor (latched faults, thresholds).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let outer = BallbotController::new(config)?;
    /// assert!(outer.supervisor().latched_faults().is_empty());
    /// // The wheel-speed limit follows MiaPURE's actuator: 90 % of 62 rad/s.
    /// let limit = outer.supervisor().params().wheel_speed_limit_rad_per_s;
    /// approx::assert_relative_eq!(limit, 55.8, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn supervisor(&self) -> &SafetySupervisor<T> {
        &self.supervisor
    }

    /// Reports a fault found by the application (e.g. a measured compute overrun); see
    /// [`SafetySupervisor::report`]. The next [`Self::step`] acts on the new mode.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
    /// use ballbot_core::command::Command;
    /// use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// use ballbot_core::safety::{Fault, Mode, ModeRequest};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut outer = BallbotController::new(config)?;
    /// let input = |now_us: u64, request| OuterInput {
    ///     now_us,
    ///     imu: ImuSample::upright(now_us),
    ///     encoders: EncoderSample::still(now_us),
    ///     command: Command::Stop,
    ///     command_timestamp_us: Some(now_us),
    ///     request,
    /// };
    /// outer.step(&input(0, ModeRequest::Arm));
    /// // The application measured a compute overrun: a controlled stop, motors still on.
    /// assert_eq!(outer.report(Fault::LoopOverrun), Mode::ControlledStop);
    /// assert!(outer.step(&input(2500, ModeRequest::None)).motors.enabled);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn report(&mut self, fault: Fault) -> Mode {
        self.supervisor.report(fault)
    }

    /// One outer step (see the module docs). Never panics; every output is finite and within
    /// the actuator's limits.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, OuterInput};
    /// use ballbot_core::command::{Command, VelocityCommand};
    /// use ballbot_core::estimation::{EncoderSample, ImuSample};
    /// use ballbot_core::safety::{Fault, Mode, ModeRequest};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut outer = BallbotController::new(config)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
    /// let input = |now_us: u64, request| OuterInput {
    ///     now_us,
    ///     imu: ImuSample::upright(now_us),
    ///     encoders: EncoderSample::still(now_us),
    ///     command: go,
    ///     command_timestamp_us: Some(now_us),
    ///     request,
    /// };
    /// assert!(outer.step(&input(0, ModeRequest::Arm)).motors.enabled);
    /// // A non-finite IMU sample: rejected, the estimate held, and a controlled stop begins; the
    /// // motors stay on (zero torque would drop a rider) and the command becomes "come to rest".
    /// let mut glitch = input(2500, ModeRequest::None);
    /// glitch.imu.roll_rad = f64::NAN;
    /// let out = outer.step(&glitch);
    /// assert!(out.safety.faults.contains(Fault::ImuNonFinite));
    /// assert_eq!(out.safety.mode, Mode::ControlledStop);
    /// assert!(out.motors.enabled && out.states.is_finite());
    /// assert!(out.motors.feedforward_torque_nm.iter().all(|t| t.is_finite() && t.abs() <= 43.2));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(&mut self, input: &OuterInput<'_, T>) -> OuterOutput<T> {
        let dt = self.config.outer_dt_secs;
        let safety = self.supervisor.step(&SafetyInput {
            now_us: input.now_us,
            imu: input.imu,
            encoders: input.encoders,
            command_timestamp_us: input.command_timestamp_us,
            command_finite: input.command.is_finite(),
            request: input.request,
        });
        let states = self.estimator.update(
            safety.imu_valid.then_some(&input.imu),
            safety.encoders_valid.then_some(&input.encoders),
            dt,
        );
        if !safety.mode.motors_enabled() {
            return self.disabled(safety, states);
        }
        // By reference: the command is a large enum (a trajectory borrows its samples).
        let stop = Command::Stop;
        let command = if safety.mode == Mode::Balancing {
            &input.command
        } else {
            &stop
        };
        let shaped = self.shaper.step(command, dt);
        // Equilibrium-input feedforward through the command states (see the type's docs).
        let mut c = shaped.planar;
        let ff = &self.feedforward;
        let a = &shaped.acceleration;
        let [tilt_accel_x, tilt_accel_y] = shaped.tilt_accel_rad_per_s2;
        let tilt_shift_x = ff.frontal_tilt.shift(c.frontal[TILT], tilt_accel_x);
        let tilt_shift_y = ff.sagittal_tilt.shift(c.sagittal[TILT], tilt_accel_y);
        c.frontal[TILT] += ff.frontal_rad_per_m_per_s2 * a.y + tilt_shift_x;
        c.sagittal[TILT] += ff.sagittal_rad_per_m_per_s2 * a.x + tilt_shift_y;
        let yaw_rate_c = c.spin[1];
        c.spin[0] += ff.heading_per_yaw_accel_s2 * a.yaw + ff.heading_per_yaw_rate_s * yaw_rate_c;
        // One sin_cos of each tilt serves the plane's reference model and the wheel mapping.
        let roll_sin_cos = states.frontal[TILT].sin_cos();
        let pitch_sin_cos = states.sagittal[TILT].sin_cos();
        let fro =
            self.frontal
                .step_with_tilt_sin_cos(&states.frontal, &c.frontal, dt, roll_sin_cos);
        let sag =
            self.sagittal
                .step_with_tilt_sin_cos(&states.sagittal, &c.sagittal, dt, pitch_sin_cos);
        let spin = self.spin.step(&states.spin, &c.spin, dt);
        let planar_torque = Vector3::new(
            fro.reference_torque_nm,
            sag.reference_torque_nm,
            spin.reference_torque_nm,
        );
        let saturation = self.kinematics.saturate_planar_torque(&planar_torque);
        let reference_rate = Vector3::new(
            fro.reference_ball_rate_rad_per_s,
            sag.reference_ball_rate_rad_per_s,
            spin.reference_rate_rad_per_s,
        );
        // The reference ball motion does not spin about the vertical: leaning, its rolling has
        // a component about the body's z axis that the wheels see like a yaw rate (see
        // `ball_body_z_rate_per_ball_rate`).
        let k = ball_body_z_rate_per_ball_rate_sin_cos(roll_sin_cos, pitch_sin_cos);
        let relative = Vector3::new(
            reference_rate[0] - states.frontal[TILT_RATE],
            reference_rate[1] - states.sagittal[TILT_RATE],
            k[0] * reference_rate[0] + k[1] * reference_rate[1] - reference_rate[2],
        );
        // The planes report the mean reference rate over the period; the drivers ramp from the
        // start value with the reference models' accelerations (tilt rate held).
        let relative_accel = Vector3::new(
            fro.reference_ball_accel_rad_per_s2,
            sag.reference_ball_accel_rad_per_s2,
            k[0] * fro.reference_ball_accel_rad_per_s2 + k[1] * sag.reference_ball_accel_rad_per_s2
                - spin.reference_accel_rad_per_s2,
        );
        let accel = self.kinematics.wheel_speeds_rad_per_s(&relative_accel);
        let limit = self
            .config
            .robot
            .drivetrain
            .actuator
            .no_load_speed_rad_per_s;
        let half_dt = dt * lit(0.5);
        let speed = (self.kinematics.wheel_speeds_rad_per_s(&relative) - accel * half_dt)
            .map(|w| clamp_sym(w, limit));
        // A ramp may not leave the speed range within the period either.
        let accel_limit = limit / dt;
        let accel = accel.map(|a| clamp_sym(a, accel_limit));
        let rejected = |s: StepStatus| s == StepStatus::InvalidInput;
        let all_finite = speed.iter().all(|x| x.is_finite())
            && accel.iter().all(|x| x.is_finite())
            && saturation.wheel_torques_nm.iter().all(|x| x.is_finite())
            && reference_rate.iter().all(|x| x.is_finite());
        if rejected(fro.status) || rejected(sag.status) || rejected(spin.status) || !all_finite {
            let safety = SafetyStatus {
                mode: self.supervisor.report(Fault::StateNonFinite),
                ..safety
            };
            return self.disabled(safety, states);
        }
        OuterOutput {
            motors: MotorReferences {
                enabled: true,
                speed_rad_per_s: speed,
                accel_rad_per_s2: accel,
                feedforward_torque_nm: saturation.wheel_torques_nm,
            },
            safety,
            states,
            commands: shaped.planar,
            reference_torque_nm: saturation.planar_torque_nm,
            reference_rate_rad_per_s: reference_rate,
            stopped: safety.mode == Mode::ControlledStop && self.shaper.is_at_rest(),
        }
    }

    /// Motors off: clears every controller state so that arming starts from the measured
    /// state (heading and ball-angle commands from the estimate).
    fn disabled(&mut self, safety: SafetyStatus, states: PlanarStates<T>) -> OuterOutput<T> {
        self.frontal.reset();
        self.sagittal.reset();
        self.spin.reset();
        self.shaper.reset(
            states.spin[0],
            states.frontal[BALL_ANGLE],
            states.sagittal[BALL_ANGLE],
        );
        OuterOutput {
            motors: MotorReferences::disabled(),
            safety,
            states,
            commands: PlanarCommands {
                frontal: WipState::zeros(),
                sagittal: WipState::zeros(),
                spin: SpinState::zeros(),
            },
            reference_torque_nm: Vector3::zeros(),
            reference_rate_rad_per_s: Vector3::zeros(),
            stopped: false,
        }
    }
}

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
    references: MotorReferences<T>,
    outer_dt_secs: T,
    /// Time since the references were set (s), capped just beyond the timeout.
    elapsed_secs: T,
}

impl<T: RealField + Copy> MotorSpeedLoop<T> {
    /// How many outer periods a reference stays valid without an update.
    ///
    /// ```
    /// use ballbot_core::ballbot::MotorSpeedLoop;
    /// assert_eq!(MotorSpeedLoop::<f64>::REFERENCE_TIMEOUT_PERIODS * 2.5, 20.0); // ms at 400 Hz
    /// ```
    pub const REFERENCE_TIMEOUT_PERIODS: f64 = 8.0;

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
        Ok(Self {
            motors: [motor; 3],
            references: MotorReferences::disabled(),
            outer_dt_secs: config.outer_dt_secs,
            elapsed_secs: T::zero(),
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
    /// timed-out references give zero torque and clear the integrators.
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
        };
        let timeout = self.outer_dt_secs * lit(Self::REFERENCE_TIMEOUT_PERIODS);
        out.timed_out = self.elapsed_secs > timeout;
        if !self.references.enabled || out.timed_out {
            self.reset();
            return out;
        }
        let step_ok = dt_secs.is_finite() && dt_secs > T::zero();
        // Reference at the middle of this step, ramping for one outer period at most.
        let t = if step_ok {
            min(self.elapsed_secs + dt_secs * lit(0.5), self.outer_dt_secs)
        } else {
            min(self.elapsed_secs, self.outer_dt_secs)
        };
        let r = &self.references;
        for (i, motor) in self.motors.iter_mut().enumerate() {
            let reference = r.speed_rad_per_s[i] + r.accel_rad_per_s2[i] * t;
            let (torque, saturation) = motor.step(
                reference,
                r.feedforward_torque_nm[i],
                wheel_speeds_rad_per_s[i],
                dt_secs,
            );
            out.torque_nm[i] = torque;
            out.saturation_nm[i] = saturation;
            out.reference_speed_rad_per_s[i] = reference;
        }
        if step_ok {
            self.elapsed_secs = min(self.elapsed_secs + dt_secs, timeout + dt_secs);
        }
        out
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
        // The range `SpeedPi::step_within` would apply to `Self::torque_bounds_nm`, computed
        // directly against the prepared `limit_nm` (the motoring side never exceeds the peak)
        // with plain min/max, and the PI law without re-checking it. A non-finite speed makes
        // the speed error, and the request, non-finite: the PI rejects it (zero torque).
        let speed = measured_speed_rad_per_s;
        let limit = self.limit_nm;
        let line = self.peak_torque_nm - self.torque_drop_nm_s_per_rad * speed.abs();
        let motoring = max(T::zero(), min(limit, line));
        let (lower, upper) = if speed >= T::zero() {
            (-limit, motoring)
        } else {
            (-motoring, limit)
        };
        let out = self.pi.step_in_range(
            speed,
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

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn config() -> BallbotControllerConfig<f64> {
        BallbotControllerConfig::design(&BallbotParams::miapure_60kg()).unwrap()
    }

    proptest! {
        #[test]
        fn motor_bounds_match_the_actuator_model(speed in -200.0f64..200.0) {
            let c = config();
            let actuator = c.robot.drivetrain.actuator;
            let motor = MotorSpeedPi::new(c.motor, &actuator).unwrap();
            let (lo, hi) = motor.torque_bounds_nm(speed);
            let (lo_ref, hi_ref) = actuator.torque_bounds_nm(speed);
            prop_assert!((lo - lo_ref).abs() < 1e-12 && (hi - hi_ref).abs() < 1e-12);
        }
    }

    #[test]
    fn motor_bounds_of_a_nan_speed_allow_nothing() {
        let c = config();
        let mut motor = MotorSpeedPi::new(c.motor, &c.robot.drivetrain.actuator).unwrap();
        assert_eq!(motor.torque_bounds_nm(f64::NAN), (0.0, 0.0));
        assert_eq!(motor.step(1.0, 5.0, f64::NAN, 1.25e-4), (0.0, 0.0));
    }

    #[test]
    fn motor_pi_equals_the_planar_pi_in_translation() {
        // The wheel PI acts on the ball-rate error like the planar PI designed on B4.
        let c = config();
        let robot = c.robot;
        let kin = OmniKinematics::from_ballbot(&robot).unwrap();
        let wip = Wip::new(robot.sagittal).unwrap();
        let planar = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 96.9).unwrap();
        // A unit sagittal ball-rate error -> wheel errors -> wheel P torques -> planar torque.
        let wheel_error = kin.wheel_speeds_rad_per_s(&Vector3::new(0.0, 1.0, 0.0));
        let wheel_torque = wheel_error * c.motor.proportional_nm_s_per_rad;
        let planar_torque = kin.planar_torque_nm(&wheel_torque);
        assert_relative_eq!(
            planar_torque[1],
            planar.proportional_nm_s_per_rad,
            max_relative = 1e-9
        );
        assert!(planar_torque[0].abs() < 1e-9 && planar_torque[2].abs() < 1e-9);
    }

    #[test]
    fn spin_outer_turns_towards_the_heading_command_and_anchors() {
        let c = config();
        let mut spin = SpinOuter::new(Spin::new(c.robot.spin).unwrap(), c.spin).unwrap();
        let measured = SpinState::new(0.0, 0.3);
        let out = spin.step(&measured, &SpinState::new(0.5, 0.3), 0.0025);
        assert!(out.reference_torque_nm > 0.0);
        assert_eq!(out.status, StepStatus::Nominal);
        // Anchored at the measured rate, advanced by half a period of the model's acceleration.
        let accel = (out.reference_torque_nm - 1.0 * 0.3) / 1.8;
        assert_relative_eq!(out.reference_accel_rad_per_s2, accel, epsilon = 1e-12);
        assert_relative_eq!(
            out.reference_rate_rad_per_s,
            0.3 + accel * 0.00125,
            epsilon = 1e-12
        );
        // Saturation and rejection.
        let out = spin.step(&measured, &SpinState::new(1e6, 0.0), 0.0025);
        assert_eq!(out.status, StepStatus::Saturated);
        assert_eq!(out.reference_torque_nm, c.spin.gains.max_torque_nm);
        let out = spin.step(&SpinState::new(f64::NAN, 0.0), &measured, 0.0025);
        assert_eq!(out.status, StepStatus::InvalidInput);
        assert_eq!(out.reference_torque_nm, 0.0);
    }

    #[test]
    fn wheel_references_do_not_spin_the_ball_about_the_vertical() {
        // Leaning sideways and pitched while the ball rolls: the wheel references (mid-period)
        // must describe a ball rolling at the reference rates with no spin about the world's
        // vertical, and the body yawing at the spin plane's reference rate. (The upright
        // mapping `omega_rel_z = -theta_dot_rz` made the body yaw by `-tan(roll) phi_dot_y`
        // instead: the high-speed yaw divergence of docs/world.md.)
        use crate::command::VelocityCommand;
        use crate::safety::ModeRequest;
        let c = config();
        let kin = OmniKinematics::from_ballbot(&c.robot).unwrap();
        let mut outer = BallbotController::new(c).unwrap();
        let (roll, pitch) = (0.03, -0.02);
        // Body-frame ball rates of a ball rolling at 20 rad/s forward, -5 rad/s sideways,
        // without vertical spin.
        let k = crate::estimation::ball_body_z_rate_per_ball_rate(roll, pitch);
        let ball = Vector3::new(-5.0, 20.0, k[0] * -5.0 + k[1] * 20.0);
        let command = Command::Velocity(VelocityCommand {
            vx_m_per_s: 1.0,
            vy_m_per_s: 0.5,
            yaw_rate_rad_per_s: 0.2,
        });
        let mut last = None;
        for step in 0..40u64 {
            let now_us = step * 2500;
            let imu = ImuSample {
                timestamp_us: now_us,
                roll_rad: roll + 1e-6 * (step % 3) as f64,
                pitch_rad: pitch,
                yaw_rad: 0.0,
                angular_velocity_rad_per_s: Vector3::zeros(),
            };
            let encoders = EncoderSample {
                timestamp_us: now_us,
                wheel_speeds_rad_per_s: kin.wheel_speeds_rad_per_s(&ball),
            };
            let out = outer.step(&OuterInput {
                now_us,
                imu,
                encoders,
                command,
                command_timestamp_us: Some(now_us),
                request: if step == 0 {
                    ModeRequest::Arm
                } else {
                    ModeRequest::None
                },
            });
            assert!(out.motors.enabled, "{:?}", out.safety);
            last = Some(out);
        }
        let out = last.unwrap();
        let mid = out.motors.speed_rad_per_s + out.motors.accel_rad_per_s2 * 0.00125;
        let relative = kin.relative_rate_rad_per_s(&mid);
        // Ball = relative + body (measured tilt rates 0, yaw at the spin reference).
        let reference = out.reference_rate_rad_per_s;
        let implied = relative + Vector3::new(0.0, 0.0, reference[2]);
        assert_relative_eq!(implied[0], reference[0], epsilon = 1e-9);
        assert_relative_eq!(implied[1], reference[1], epsilon = 1e-9);
        assert!(reference[1].abs() > 1.0, "{reference}");
        let (sr, cr) = f64::sin_cos(roll);
        let (sp, cp) = f64::sin_cos(pitch);
        let vertical = Vector3::new(-sp, cp * sr, cp * cr);
        assert!(vertical.dot(&implied).abs() < 1e-9, "{implied}");
    }

    #[test]
    fn inner_loop_times_out_without_fresh_references() {
        let c = config();
        let mut inner = MotorSpeedLoop::new(&c).unwrap();
        let refs = MotorReferences {
            enabled: true,
            speed_rad_per_s: Vector3::new(1.0, 1.0, 1.0),
            accel_rad_per_s2: Vector3::new(100.0, 0.0, 0.0),
            feedforward_torque_nm: Vector3::new(2.0, 2.0, 2.0),
        };
        inner.set_references(&refs);
        let first = inner.step(&Vector3::zeros(), 1.25e-4);
        assert!(first.torque_nm.iter().all(|t| *t > 2.0));
        // The ramp runs for one outer period, then holds.
        assert_relative_eq!(first.reference_speed_rad_per_s[0], 1.0 + 100.0 * 0.625e-4);
        let mut last = first;
        for _ in 0..200 {
            last = inner.step(&Vector3::zeros(), 1.25e-4);
            if last.timed_out {
                break;
            }
            assert!(last.reference_speed_rad_per_s[0] <= 1.0 + 100.0 * 0.0025 + 1e-12);
        }
        assert!(last.timed_out);
        assert_eq!(last.torque_nm, Vector3::zeros());
        // Non-finite references disable.
        let mut bad = refs;
        bad.accel_rad_per_s2[2] = f64::NAN;
        inner.set_references(&bad);
        assert_eq!(
            inner.step(&Vector3::zeros(), 1.25e-4).torque_nm,
            Vector3::zeros()
        );
    }

    #[test]
    fn config_validation_reaches_every_piece() {
        let mut c = config();
        c.outer_dt_secs = 0.0;
        assert!(BallbotController::new(c).is_err());
        let mut c = config();
        c.spin.max_rate_error_rad_per_s = -1.0;
        assert!(BallbotController::new(c).is_err());
        let mut c = config();
        c.safety.imu_timeout_us = 0;
        assert!(BallbotController::new(c).is_err());
    }
}
