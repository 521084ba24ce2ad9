//! The outer loop (400 Hz): [`BallbotController`], from IMU, encoders and command to the
//! [`MotorReferences`] sent to the motor drivers.

use super::balancing::pi_pd_plane;
use super::feedforward::InputFeedforward;
use super::outer_io::{MotorReferences, OuterInput, OuterOutput};
use super::{
    BalancePoint, BalanceSample, BalancingLaw, BallbotControllerConfig, ImuLean, SpinOuter,
    WheelMapping,
};
use crate::check::{lit, positive};
use crate::command::{
    Command, CommandShaper, PlanarCommands, ShapedCommand, Trajectory, TrajectoryLimits,
};
use crate::control::{LqrPiOuter, PiPdController, StepStatus};
use crate::estimation::{Estimator, PlanarStates, ball_body_z_rate_per_ball_rate_sin_cos};
use crate::kinematics::TorqueSaturation;
use crate::num::clamp_sym;
use crate::safety::{Fault, Mode, SafetyInput, SafetyStatus, SafetySupervisor};
use crate::spin::SpinState;
use crate::traction::{TiltTerms, TractionControl};
use crate::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{Error, OmniKinematics, Spin, Wip};
use nalgebra::{RealField, Vector2, Vector3};

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
/// for k in 0..6 * 400 {
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
/// // After 6 s the ball rolls forward at 1 m/s (x = r phi_y), the body upright; nothing moved
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
    /// The planes' PI-PD (frontal, sagittal) when [`BalancingLaw::PiPd`] replaces the LQR-PI.
    pi_pd: Option<[PiPdController<T>; 2]>,
    spin: SpinOuter<T>,
    feedforward: InputFeedforward<T>,
    traction: Option<TractionControl<T>>,
    balance_point: Option<BalancePoint<T>>,
    imu_lean: Option<ImuLean<T>>,
    trajectory_limits: TrajectoryLimits<T>,
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
        config.traction.validate()?;
        let traction = if config.traction.enabled {
            Some(TractionControl::new(&config.robot, config.traction)?)
        } else {
            None
        };
        let balance_point = if config.balance_point.enabled {
            Some(BalancePoint::new(config.balance_point, &config.robot)?)
        } else {
            config.balance_point.validate()?;
            None
        };
        config.imu_lean.validate()?;
        let gravity = config.robot.sagittal.gravity_m_per_s2;
        let imu_lean = if config.imu_lean.enabled() {
            Some(ImuLean::new(
                config.imu_lean,
                config.outer_dt_secs,
                gravity,
            )?)
        } else {
            None
        };
        Ok(Self {
            config,
            kinematics,
            supervisor: SafetySupervisor::new(config.safety)?,
            estimator: Estimator::new(kinematics),
            shaper: CommandShaper::new(config.shaping, &config.robot)?,
            frontal: LqrPiOuter::new(Wip::new(config.robot.frontal)?, config.frontal)?,
            sagittal: LqrPiOuter::new(Wip::new(config.robot.sagittal)?, config.sagittal)?,
            pi_pd: match config.balancing {
                BalancingLaw::LqrPi => None,
                BalancingLaw::PiPd { frontal, sagittal } => Some([
                    PiPdController::new(frontal)?,
                    PiPdController::new(sagittal)?,
                ]),
            },
            spin: SpinOuter::new(Spin::new(config.robot.spin)?, config.spin)?,
            feedforward: InputFeedforward::new(&config),
            traction,
            balance_point,
            imu_lean,
            trajectory_limits: config.trajectory_limits()?,
        })
    }

    /// The bounds a trajectory must keep for this controller to follow it
    /// ([`BallbotControllerConfig::trajectory_limits`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let outer = BallbotController::new(config)?;
    /// assert_eq!(outer.trajectory_limits(), &config.trajectory_limits()?);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn trajectory_limits(&self) -> &TrajectoryLimits<T> {
        &self.trajectory_limits
    }

    /// Accepts a trajectory for this controller: [`Trajectory::new`] against
    /// [`Self::trajectory_limits`]. The error names the field and the bound it broke. Build
    /// every trajectory the robot is to follow this way: [`Self::step`] follows any
    /// [`Trajectory`] it is given, and one built against looser limits
    /// ([`Trajectory::limits`], [`TrajectoryLimits::is_within`]) may ask for what the robot
    /// cannot do.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, Error};
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// use nalgebra::Vector4;
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// let outer = BallbotController::new(config)?;
    /// // Up to 1 rad/s in 1 s, leaning into the acceleration, then cruising upright.
    /// let lean = config.trajectory_limits()?.lean_per_ball_accel_s2 * 1.0;
    /// let go = [Vector4::new(lean, 0.0, 0.0, 0.0), Vector4::new(0.0, 0.5, 0.0, 1.0)];
    /// assert!(outer.accept_trajectory(&go, 1.0, 0.0).is_ok());
    /// // Leaning 0.1 rad the other way: not what the acceleration needs, refused.
    /// let wrong = [Vector4::new(-0.1, 0.0, 0.0, 0.0), Vector4::new(0.0, 0.5, 0.0, 1.0)];
    /// assert!(outer.accept_trajectory(&wrong, 1.0, 0.0).is_err());
    /// // A tilt near the largest double is refused, naming the samples.
    /// let absurd = [Vector4::new(1e308, 0.0, 0.0, 0.0)];
    /// assert!(matches!(
    ///     outer.accept_trajectory(&absurd, 0.1, 0.0),
    ///     Err(Error::InvalidParameter { field: "samples", .. })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn accept_trajectory<'a>(
        &self,
        samples: &'a [WipState<T>],
        sample_period_secs: T,
        heading_rad: T,
    ) -> Result<Trajectory<'a, T>, Error> {
        Trajectory::new(
            samples,
            sample_period_secs,
            heading_rad,
            &self.trajectory_limits,
        )
    }

    /// Traction-aware control (envelope, slip monitor), when enabled.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// // On in the shipped configuration, off in the paper's.
    /// let config = BallbotControllerConfig::design(&robot)?;
    /// assert!(BallbotController::new(config)?.traction().is_some());
    /// let paper = BallbotControllerConfig::paper(&robot)?;
    /// assert!(BallbotController::new(paper)?.traction().is_none());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn traction(&self) -> Option<&TractionControl<T>> {
        self.traction.as_ref()
    }

    /// The balance-point estimator, when enabled ([`BallbotControllerConfig::balance_point`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// // On in the shipped configuration, off in the paper's.
    /// let config = BallbotControllerConfig::design(&robot)?;
    /// assert!(BallbotController::new(config)?.balance_point().is_some());
    /// let paper = BallbotControllerConfig::paper(&robot)?;
    /// assert!(BallbotController::new(paper)?.balance_point().is_none());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn balance_point(&self) -> Option<&BalancePoint<T>> {
        self.balance_point.as_ref()
    }

    /// The IMU filter's lean as the controller tracks it, when the correction is on
    /// ([`BallbotControllerConfig::imu_lean`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let config = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert!(BallbotController::new(config)?.imu_lean().is_none());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn imu_lean(&self) -> Option<&ImuLean<T>> {
        self.imu_lean.as_ref()
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
    /// the actuator's limits. Its phases: the supervisor's step, the estimate, the slip monitor,
    /// the command's shaping and feedforward, the three planes, the contacts' prediction, the
    /// motors' references and the output; with the motors off, only the first two.
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
        let mut safety = self.supervise(input);
        let mut states = self.estimate(input, &safety, dt);
        if !safety.mode.motors_enabled() {
            return self.at_rest(safety, states);
        }
        let terms = tilt_terms(&states);
        let wheel_speeds = self.watch_traction(input, &mut safety, &mut states, &terms, dt);
        let shaped = self.shape(&input.command, safety.mode, wheel_speeds, dt);
        let c = self.feedforward_commands(&shaped);
        let a = &shaped.acceleration;
        // The planes see the tilt from the learnt balance point (see `BalancePoint`): there
        // the body's centre of mass is above the ball, and the reference models' upright.
        let shifted = self
            .balance_point
            .as_mut()
            .map(|bp| shift_to_balance_point(bp, &states, &c, a.x.hypot(a.y), dt));
        let (fro_state, sag_state, fro_sin_cos, sag_sin_cos) =
            plane_states(shifted.as_ref(), &states, &terms);
        // The planes step here rather than in a phase function: returning their outputs from one
        // costs about 40 instructions a step (callgrind, `scripts/icount.sh`), as they are then
        // written out whole.
        let (fro, sag) = match &mut self.pi_pd {
            None => (
                self.frontal
                    .step_with_tilt_sin_cos(fro_state, &c.frontal, dt, fro_sin_cos),
                self.sagittal
                    .step_with_tilt_sin_cos(sag_state, &c.sagittal, dt, sag_sin_cos),
            ),
            Some([frontal, sagittal]) => (
                pi_pd_plane(frontal, fro_state, &c.frontal, dt),
                pi_pd_plane(sagittal, sag_state, &c.sagittal, dt),
            ),
        };
        let spin = self.spin.step(&states.spin, &c.spin, dt);
        let planar_torque = Vector3::new(
            fro.reference_torque_nm,
            sag.reference_torque_nm,
            spin.reference_torque_nm,
        );
        let saturation = self.kinematics.saturate_planar_torque(&planar_torque);
        let rate = Vector3::new(
            fro.reference_ball_rate_rad_per_s,
            sag.reference_ball_rate_rad_per_s,
            spin.reference_rate_rad_per_s,
        );
        let accel = Vector3::new(
            fro.reference_ball_accel_rad_per_s2,
            sag.reference_ball_accel_rad_per_s2,
            spin.reference_accel_rad_per_s2,
        );
        let tilt_accel = [
            fro.reference_tilt_accel_rad_per_s2,
            sag.reference_tilt_accel_rad_per_s2,
        ];
        self.predict_contacts(&states, &terms, tilt_accel, &accel, &planar_torque);
        let motors = self.motor_references(&rate, &accel, &terms, &states, &saturation);
        let rejected = |s: StepStatus| s == StepStatus::InvalidInput;
        let all_finite = motors_finite(&motors) && rate.iter().all(|x| x.is_finite());
        if rejected(fro.status) || rejected(sag.status) || rejected(spin.status) || !all_finite {
            let safety = SafetyStatus {
                mode: self.supervisor.report(Fault::StateNonFinite),
                ..safety
            };
            return self.disabled(safety, states);
        }
        self.output(motors, safety, states, &shaped, rate, &saturation)
    }

    /// The supervisor's step: the mode, the faults, and which sensor samples are valid.
    #[inline(always)]
    fn supervise(&mut self, input: &OuterInput<'_, T>) -> SafetyStatus {
        self.supervisor.step(&SafetyInput {
            now_us: input.now_us,
            imu: input.imu,
            encoders: input.encoders,
            command_timestamp_us: input.command_timestamp_us,
            command_finite: input.command.is_finite(),
            request: input.request,
        })
    }

    /// The planar states from the valid samples (an invalid one holds the estimate), with the
    /// IMU's lean correction when that filter is on.
    #[inline(always)]
    fn estimate(
        &mut self,
        input: &OuterInput<'_, T>,
        safety: &SafetyStatus,
        dt: T,
    ) -> PlanarStates<T> {
        let mut states = self.estimator.update(
            safety.imu_valid.then_some(&input.imu),
            safety.encoders_valid.then_some(&input.encoders),
            dt,
        );
        if let Some(lean) = &self.imu_lean {
            let [roll, pitch] = lean.correction_rad();
            states.frontal[TILT] += roll;
            states.sagittal[TILT] += pitch;
        }
        states
    }

    /// Motors off by the mode: at rest on its support, the lean filter decays, and every
    /// controller state clears.
    #[inline(always)]
    fn at_rest(&mut self, safety: SafetyStatus, states: PlanarStates<T>) -> OuterOutput<T> {
        if let Some(lean) = &mut self.imu_lean {
            lean.follow(T::zero(), T::zero());
        }
        self.disabled(safety, states)
    }

    /// The slip monitor on this step's encoders (with traction control on): a slip that
    /// lasts raises [`Fault::WheelSlip`], and a slipping wheel's false ball rate is taken off
    /// the states. Returns the wheel speeds the traction limit works from.
    #[inline(always)]
    fn watch_traction(
        &mut self,
        input: &OuterInput<'_, T>,
        safety: &mut SafetyStatus,
        states: &mut PlanarStates<T>,
        terms: &TiltTerms<T>,
        dt: T,
    ) -> Vector3<T> {
        let measured = input.encoders.wheel_speeds_rad_per_s;
        let Some(traction) = &mut self.traction else {
            return measured;
        };
        let kinematics = &self.kinematics;
        let (speeds, stop) =
            traction.before_shaping(kinematics, states, safety, measured, terms, dt);
        if stop {
            safety.mode = self.supervisor.report(Fault::WheelSlip);
            safety.faults.insert(Fault::WheelSlip);
        }
        let [dx, dy] = traction.monitor().ball_rate_correction_rad_per_s();
        states.frontal[BALL_RATE] -= dx;
        states.sagittal[BALL_RATE] -= dy;
        speeds
    }

    /// The shaped command: the application's while balancing, "come to rest" in every other
    /// mode; within the traction envelope when traction control is on (a slip reaction's lower
    /// envelope reached within the jerk limit, [`CommandShaper::step_within`]).
    #[inline(always)]
    fn shape(
        &mut self,
        command: &Command<'_, T>,
        mode: Mode,
        wheel_speeds_rad_per_s: Vector3<T>,
        dt: T,
    ) -> ShapedCommand<T> {
        // By reference: the command is a large enum (a trajectory borrows its samples).
        let stop = Command::Stop;
        let command = if mode == Mode::Balancing {
            command
        } else {
            &stop
        };
        let Some(traction) = &self.traction else {
            return self.shaper.step(command, dt);
        };
        let limit = traction.step_limit(wheel_speeds_rad_per_s);
        self.shaper.step_within(command, dt, &limit)
    }

    /// The command states with the equilibrium-input feedforward (see the type's docs): the
    /// tilt commands shifted for the commanded acceleration (and a trajectory's tilt
    /// acceleration), the heading command for the yaw motion. The IMU lean filter follows the
    /// commanded acceleration.
    #[inline(always)]
    fn feedforward_commands(&mut self, shaped: &ShapedCommand<T>) -> PlanarCommands<T> {
        let mut c = shaped.planar;
        let ff = &self.feedforward;
        let a = &shaped.acceleration;
        if let Some(lean) = &mut self.imu_lean {
            lean.follow(a.x, a.y);
        }
        let [tilt_accel_x, tilt_accel_y] = shaped.tilt_accel_rad_per_s2;
        let tilt_shift_x = ff.frontal_tilt.shift(c.frontal[TILT], tilt_accel_x);
        let tilt_shift_y = ff.sagittal_tilt.shift(c.sagittal[TILT], tilt_accel_y);
        c.frontal[TILT] += ff.frontal_rad_per_m_per_s2 * a.y + tilt_shift_x;
        c.sagittal[TILT] += ff.sagittal_rad_per_m_per_s2 * a.x + tilt_shift_y;
        let yaw_rate_c = c.spin[1];
        c.spin[0] +=
            ff.heading_per_yaw_accel_s2 * a.yaw + ff.heading_per_yaw_rate_secs * yaw_rate_c;
        c
    }

    /// The slip monitor's prediction of the contacts under this step's planar torque, from
    /// the frontal and sagittal reference models' tilt and ball accelerations (with traction
    /// control on).
    #[inline(always)]
    fn predict_contacts(
        &mut self,
        states: &PlanarStates<T>,
        terms: &TiltTerms<T>,
        [tilt_x, tilt_y]: [T; 2],
        ball_accel: &Vector3<T>,
        planar_torque_nm: &Vector3<T>,
    ) {
        if let Some(traction) = &mut self.traction {
            let accelerations = [
                Vector2::new(tilt_x, ball_accel.x),
                Vector2::new(tilt_y, ball_accel.y),
            ];
            let kinematics = &self.kinematics;
            traction.after_planes(kinematics, states, terms, accelerations, planar_torque_nm);
        }
    }

    /// The motor drivers' references from the planes' reference rates and accelerations
    /// (frontal and sagittal ball, yaw): relative to the body, mapped to wheel speeds at the
    /// start of the period and a ramp over it, each within the actuator's speed range.
    #[inline(always)]
    fn motor_references(
        &self,
        reference_rate: &Vector3<T>,
        reference_accel: &Vector3<T>,
        terms: &TiltTerms<T>,
        states: &PlanarStates<T>,
        saturation: &TorqueSaturation<T>,
    ) -> MotorReferences<T> {
        // The reference ball motion does not spin about the vertical: leaning, its rolling has
        // a component about the body's z axis that the wheels see like a yaw rate (see
        // `ball_body_z_rate_per_ball_rate`). The upright mapping (an ablation) drops it.
        let k = match self.config.wheel_mapping {
            WheelMapping::RollingBall => terms.k,
            WheelMapping::Upright => [T::zero(); 2],
        };
        let (rate, acc) = (reference_rate, reference_accel);
        let relative = Vector3::new(
            rate[0] - states.frontal[TILT_RATE],
            rate[1] - states.sagittal[TILT_RATE],
            k[0] * rate[0] + k[1] * rate[1] - rate[2],
        );
        // The planes report the mean reference rate over the period; the drivers ramp from the
        // start value with the reference models' accelerations (tilt rate held).
        let relative_accel = Vector3::new(acc[0], acc[1], k[0] * acc[0] + k[1] * acc[1] - acc[2]);
        let dt = self.config.outer_dt_secs;
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
        MotorReferences {
            enabled: true,
            speed_rad_per_s: speed,
            accel_rad_per_s2: accel.map(|a| clamp_sym(a, accel_limit)),
            feedforward_torque_nm: saturation.wheel_torques_nm,
        }
    }

    /// The step's output, with the traction status counted.
    #[inline(always)]
    fn output(
        &mut self,
        motors: MotorReferences<T>,
        safety: SafetyStatus,
        states: PlanarStates<T>,
        shaped: &ShapedCommand<T>,
        reference_rate_rad_per_s: Vector3<T>,
        saturation: &TorqueSaturation<T>,
    ) -> OuterOutput<T> {
        let traction = self
            .traction
            .as_mut()
            .map(|t| t.finish_step(shaped.accel_limit_m_per_s2, shaped.limited));
        OuterOutput {
            motors,
            safety,
            states,
            commands: shaped.planar,
            reference_torque_nm: saturation.planar_torque_nm,
            reference_rate_rad_per_s,
            // Not while a slip is flagged: its correction may hold the estimate at rest while
            // the ball moves (the monitor bounds how long, `TractionParams::max_coast_secs`).
            stopped: safety.mode == Mode::ControlledStop
                && self.shaper.is_at_rest()
                && !traction.is_some_and(|t| t.slip.any_slipping()),
            traction,
        }
    }

    /// Motors off: clears every controller state so that arming starts from the measured
    /// state (heading and ball-angle commands from the estimate).
    fn disabled(&mut self, safety: SafetyStatus, states: PlanarStates<T>) -> OuterOutput<T> {
        self.frontal.reset();
        self.sagittal.reset();
        if let Some(planes) = &mut self.pi_pd {
            planes.iter_mut().for_each(PiPdController::reset);
        }
        self.spin.reset();
        // Motors off: the robot is supported and its payload may change (a rider steps off);
        // the next arming starts from the calibrated upright (see `BalancePoint`).
        if let Some(bp) = &mut self.balance_point {
            bp.reset();
        }
        let traction = self.traction.as_mut().map(|t| {
            t.monitor_mut().reset();
            t.finish_step(None, false)
        });
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
            traction,
        }
    }
}

/// The tilts' sines and cosines, computed once for the slip monitor, the planes' reference
/// models and the wheel mapping, and the ball's body-z rate per ball rate when it does not spin
/// about the vertical (see `ball_body_z_rate_per_ball_rate`).
#[inline(always)]
fn tilt_terms<T: RealField + Copy>(states: &PlanarStates<T>) -> TiltTerms<T> {
    let frontal_sin_cos = states.frontal[TILT].sin_cos();
    let sagittal_sin_cos = states.sagittal[TILT].sin_cos();
    TiltTerms {
        frontal_sin_cos,
        sagittal_sin_cos,
        k: ball_body_z_rate_per_ball_rate_sin_cos(frontal_sin_cos, sagittal_sin_cos),
    }
}

/// Every motor reference is finite.
#[inline(always)]
fn motors_finite<T: RealField + Copy>(m: &MotorReferences<T>) -> bool {
    let finite = |v: &Vector3<T>| v.iter().all(|x| x.is_finite());
    finite(&m.speed_rad_per_s) && finite(&m.accel_rad_per_s2) && finite(&m.feedforward_torque_nm)
}

/// The states and tilts' `(sin, cos)` the frontal and sagittal planes see: from the balance
/// point when that estimator is on (`shifted`), else the estimate's.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn plane_states<'a, T: RealField + Copy>(
    shifted: Option<&'a (WipState<T>, WipState<T>, (T, T), (T, T))>,
    states: &'a PlanarStates<T>,
    terms: &TiltTerms<T>,
) -> (&'a WipState<T>, &'a WipState<T>, (T, T), (T, T)) {
    match shifted {
        Some((f, s, fsc, ssc)) => (f, s, *fsc, *ssc),
        None => (
            &states.frontal,
            &states.sagittal,
            terms.frontal_sin_cos,
            terms.sagittal_sin_cos,
        ),
    }
}

/// The planes' states measured from the balance point after `bp` learnt from this step (see
/// [`BalancePoint`]), with the sines and cosines of the shifted tilts. Out of line: the
/// estimator is opt-in, and the designed controller's step stays as lean as it was.
#[inline(never)]
#[allow(clippy::type_complexity)]
fn shift_to_balance_point<T: RealField + Copy>(
    bp: &mut BalancePoint<T>,
    states: &PlanarStates<T>,
    commands: &PlanarCommands<T>,
    command_accel_m_per_s2: T,
    dt: T,
) -> (WipState<T>, WipState<T>, (T, T), (T, T)) {
    let (f, s) = (&states.frontal, &states.sagittal);
    let (cf, cs) = (&commands.frontal, &commands.sagittal);
    let sample = BalanceSample {
        tilt_rad: Vector2::new(f[TILT], s[TILT]),
        tilt_rate_rad_per_s: Vector2::new(f[TILT_RATE], s[TILT_RATE]),
        ball_rate_rad_per_s: Vector2::new(f[BALL_RATE], s[BALL_RATE]),
        tilt_command_rad: Vector2::new(cf[TILT], cs[TILT]),
        ball_rate_command_rad_per_s: Vector2::new(cf[BALL_RATE], cs[BALL_RATE]),
        command_accel_m_per_s2,
    };
    bp.update(&sample, dt);
    let offset = bp.offset_rad();
    let (mut frontal, mut sagittal) = (states.frontal, states.sagittal);
    frontal[TILT] -= offset[0];
    sagittal[TILT] -= offset[1];
    let (fsc, ssc) = (frontal[TILT].sin_cos(), sagittal[TILT].sin_cos());
    (frontal, sagittal, fsc, ssc)
}
