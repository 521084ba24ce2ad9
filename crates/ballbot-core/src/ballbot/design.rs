//! The controller's configuration and its design from the robot's parameters
//! ([`BallbotControllerConfig::design`]), with the per-motor PI gains
//! ([`motor_speed_pi_gains`]).

use super::{BalancePointParams, ImuLeanParams, SpinGains, SpinOuterConfig, WheelMapping};
use crate::check::{lit, positive};
use crate::command::{AxisLimits, CommandShaperParams};
use crate::control::{LqrGains, LqrPiOuterConfig, PiPdGains, SpeedPiGains};
use crate::lqr::{
    SpinLqrWeights, WipLqrWeights, outer_loop_dt_secs, spin_lqr_discrete, wip_lqr_discrete,
};
use crate::safety::SafetyParams;
use crate::traction::TractionParams;
use crate::wip::BALL_RATE;
use crate::{BallbotParams, Error, OmniKinematics, Spin, Wip};
use nalgebra::RealField;

/// Everything the 3D controller needs, validated by [`BallbotController::new`](super::BallbotController::new).
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
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
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
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub outer_dt_secs: T,
    /// How the reference rates map to the omniwheels (see [`WheelMapping`]). Default
    /// [`WheelMapping::RollingBall`].
    pub wheel_mapping: WheelMapping,
    /// Traction-aware control ([`crate::traction`]): on in [`Self::design`] (its
    /// recommended settings, [`Self::with_traction_control`]), off in [`Self::paper`].
    pub traction: TractionParams<T>,
    /// Balance-point estimation ([`super::BalancePoint`]): on in [`Self::design`]
    /// ([`Self::with_balance_point_estimation`]), off in [`Self::paper`].
    pub balance_point: BalancePointParams<T>,
    /// How the two balancing planes turn their state into a reference torque: the paper's
    /// LQR-PI ([`BalancingLaw::LqrPi`], every designed configuration) or, as the paper's
    /// comparison, a cascaded PI-PD ([`Self::with_pi_pd`]).
    pub balancing: BalancingLaw<T>,
    /// The correction for an IMU whose attitude filter leans its estimate into the
    /// acceleration ([`super::ImuLean`]): off in every designed configuration (the IMU
    /// reports the true attitude); [`Self::with_imu_lean_correction`] sets the filter's time
    /// constant.
    pub imu_lean: ImuLeanParams<T>,
}

/// The law of the two balancing planes (frontal and sagittal); the spin loop and everything
/// around the planes (shaping, safety, mapping to the wheels) are the same for every law.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::{BalancingLaw, BallbotControllerConfig};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// // Every designed configuration balances with the LQR-PI; the PI-PD is the comparison.
/// assert_eq!(BallbotControllerConfig::design(&robot)?.balancing, BalancingLaw::LqrPi);
/// let pi_pd = BallbotControllerConfig::paper(&robot)?.with_pi_pd()?;
/// assert!(matches!(pi_pd.balancing, BalancingLaw::PiPd { .. }));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub enum BalancingLaw<T> {
    /// The cascaded LQR-PI's outer loop in each plane ([`crate::control::LqrPiOuter`], with
    /// [`BallbotControllerConfig::frontal`] and [`BallbotControllerConfig::sagittal`]): the
    /// LQR's reference torque and the reference model's ball rate for the motor PIs.
    LqrPi,
    /// The cascaded PI-PD of the CMU ballbot in each plane ([`crate::control::PiPdController`]):
    /// an outer PI on the ball rate gives a reference tilt, an inner PD on the tilt the torque.
    /// The motors' reference rate is the measured one (the PI-PD has no reference model), so
    /// the motor PIs add nothing at the outer steps; with their gains at zero, as
    /// [`BallbotControllerConfig::with_pi_pd`] sets them, the torque goes to the drivers open
    /// loop, as on the paper's testbed.
    PiPd {
        /// Frontal plane (x).
        frontal: PiPdGains<T>,
        /// Sagittal plane (y).
        sagittal: PiPdGains<T>,
    },
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
    /// The shipped controller: [`Self::design_with`] the [`BallbotDesign::paper`] weights, with
    /// every safety layer the project knows on (traction-aware control and balance-point
    /// estimation). This is the configuration to run on a robot.
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
    /// // Safe by default: traction-aware control and balance-point estimation are on.
    /// assert!(config.traction.enabled && config.balance_point.enabled);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn design(robot: &BallbotParams<T>) -> Result<Self, Error> {
        Self::design_with(robot, &BallbotDesign::paper())
    }

    /// The configuration the paper's protocols pin: the same gains, shaping and safety as
    /// [`Self::design`], with traction-aware control and balance-point estimation **off**, as
    /// the paper's controller has neither. The studies that reproduce the paper's figures run
    /// it, so that the comparison with the paper stays reproducible while the default improves;
    /// a robot should run [`Self::design`].
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let paper = BallbotControllerConfig::paper(&robot)?;
    /// assert!(!paper.traction.enabled && !paper.balance_point.enabled);
    /// // The shipped default is exactly the paper's configuration with both layers on.
    /// let shipped = paper.with_traction_control().with_balance_point_estimation();
    /// assert_eq!(shipped, BallbotControllerConfig::design(&robot)?);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn paper(robot: &BallbotParams<T>) -> Result<Self, Error> {
        Self::designed_gains(robot, &BallbotDesign::paper())
    }

    /// Designs every gain from the model, with traction-aware control and balance-point
    /// estimation on as in [`Self::design`]: discrete LQR at the outer period on each plane's
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
        Ok(Self::designed_gains(robot, design)?
            .with_traction_control()
            .with_balance_point_estimation())
    }

    /// Every gain designed from the model, traction-aware control and balance-point estimation
    /// off (the body of [`Self::design_with`] and [`Self::paper`]).
    fn designed_gains(robot: &BallbotParams<T>, design: &BallbotDesign<T>) -> Result<Self, Error> {
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
            wheel_mapping: WheelMapping::RollingBall,
            traction: TractionParams::off(robot),
            balance_point: BalancePointParams::off(),
            balancing: BalancingLaw::LqrPi,
            imu_lean: ImuLeanParams::off(),
        })
    }

    /// **The paper's LQR, for comparison**: this configuration with the motor speed PIs off
    /// (zero gains, the torque limit kept), so the drivers get the LQR's reference torque open
    /// loop, as the paper ran its LQR on the PIPTB ("the torque command was sent to the motor
    /// driver for direct open-loop torque control", Sec. IV-C). Its gains are the LQR's own
    /// design, the same as the LQR-PI's outer loop.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let lqr_pi = BallbotControllerConfig::paper(&robot)?;
    /// let lqr = lqr_pi.with_torque_only_lqr();
    /// assert_eq!((lqr.motor.proportional_nm_s_per_rad, lqr.motor.integral_nm_per_rad), (0.0, 0.0));
    /// assert_eq!(lqr.sagittal, lqr_pi.sagittal);
    /// assert!(BallbotController::new(lqr).is_ok());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[must_use]
    pub fn with_torque_only_lqr(mut self) -> Self {
        self.motor = SpeedPiGains {
            proportional_nm_s_per_rad: T::zero(),
            integral_nm_per_rad: T::zero(),
            anti_windup_per_s: T::zero(),
            ..self.motor
        };
        self
    }

    /// **The paper's cascaded PI-PD, for comparison**: this configuration with a PI-PD in each
    /// balancing plane ([`BalancingLaw::PiPd`]), its gains from its own design rule,
    /// [`PiPdGains::for_wip`] (pole placement at fixed multiples of the plane's unstable pole,
    /// with the plane's LQR torque limit), and the motor speed PIs off as in
    /// [`Self::with_torque_only_lqr`]: the paper sent the PI-PD's torque to the drivers open
    /// loop.
    ///
    /// Errors: from [`PiPdGains::for_wip`] (a plane the design cannot place).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BalancingLaw, BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let pi_pd = BallbotControllerConfig::paper(&robot)?.with_pi_pd()?;
    /// let BalancingLaw::PiPd { sagittal, .. } = pi_pd.balancing else { panic!() };
    /// assert!(sagittal.tilt_p_nm_per_rad < 0.0 && sagittal.speed_i_rad_per_rad > 0.0);
    /// assert_eq!(pi_pd.motor.proportional_nm_s_per_rad, 0.0);
    /// assert!(BallbotController::new(pi_pd).is_ok());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn with_pi_pd(self) -> Result<Self, Error> {
        let frontal = PiPdGains::for_wip(
            &Wip::new(self.robot.frontal)?,
            self.frontal.lqr.max_torque_nm,
        )?;
        let sagittal = PiPdGains::for_wip(
            &Wip::new(self.robot.sagittal)?,
            self.sagittal.lqr.max_torque_nm,
        )?;
        let mut config = self.with_torque_only_lqr();
        config.balancing = BalancingLaw::PiPd { frontal, sagittal };
        Ok(config)
    }

    /// This configuration with traction-aware control on, in its recommended settings
    /// ([`TractionParams::recommended`]): the command shaper follows the traction envelope
    /// and the slip monitor reacts (see [`crate::traction`]). It also turns on the shaper's
    /// reference filter at 0.3 s ([`CommandShaperParams::reference_filter_secs`], unless one
    /// is set already): the envelope bounds the shaped command, and without the filter the
    /// ball overshoots it where an acceleration ends (in the 3D world towards OW1 a ramp
    /// limited to the envelope's 1.30 m/s^2 still reached 1.84 m/s^2 and a stop's run-up made
    /// OW2 slip; with it, 1.45 m/s^2 and no slip).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let config = BallbotControllerConfig::design(&robot)?.with_traction_control();
    /// assert!(config.traction.enabled && config.shaping.reference_filter_secs == 0.3);
    /// assert!(BallbotController::new(config)?.traction().is_some());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[must_use]
    pub fn with_traction_control(mut self) -> Self {
        self.traction = TractionParams::recommended(&self.robot);
        if self.shaping.reference_filter_secs == T::zero() {
            self.shaping.reference_filter_secs = lit(0.3);
        }
        self
    }

    /// This configuration with balance-point estimation on, in its recommended settings
    /// ([`BalancePointParams::recommended`]): the controller learns the tilt at which the
    /// robot really balances (a payload off centre, a crooked IMU) and stops driving off.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let config = BallbotControllerConfig::design(&robot)?.with_balance_point_estimation();
    /// assert!(config.balance_point.enabled);
    /// assert!(BallbotController::new(config)?.balance_point().is_some());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[must_use]
    pub fn with_balance_point_estimation(mut self) -> Self {
        self.balance_point = BalancePointParams::recommended();
        self
    }

    /// This configuration with the tilt corrected for an IMU whose attitude filter pulls its
    /// estimate towards the accelerometer's vertical with the time constant
    /// `filter_time_constant_secs` ([`super::ImuLean`]): what the filter reads into the
    /// commanded acceleration is added back.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let config = BallbotControllerConfig::design(&robot)?.with_imu_lean_correction(2.29);
    /// assert!(config.imu_lean.enabled());
    /// assert!(BallbotController::new(config)?.imu_lean().is_some());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    #[must_use]
    pub fn with_imu_lean_correction(mut self, filter_time_constant_secs: T) -> Self {
        self.imu_lean = ImuLeanParams::for_filter(filter_time_constant_secs);
        self
    }

    /// **An ablation, not a recommendation**: the paper's controller as we read it, built from
    /// [`Self::paper`] with two changes, the upright wheel mapping of MODEL.md section 4
    /// ([`WheelMapping::Upright`]) and no jerk limit on the translation command
    /// ([`AxisLimits::unlimited_jerk_per_s2`]; the paper
    /// describes no command shaping). Everything else (gains, speed and acceleration caps,
    /// safety) is [`Self::paper`]'s. It exists to show in the world what the designed
    /// controller's two departures from the paper change; the default controller
    /// ([`Self::design`]) is the one to run.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::{BallbotController, BallbotControllerConfig, WheelMapping};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let paper = BallbotControllerConfig::with_paper_ablation(&robot)?;
    /// let designed = BallbotControllerConfig::paper(&robot)?;
    /// assert_eq!(paper.wheel_mapping, WheelMapping::Upright);
    /// assert_eq!(paper.shaping.translation.max_jerk_per_s2, f64::INFINITY);
    /// // Nothing else differs.
    /// let mut same = paper;
    /// same.wheel_mapping = designed.wheel_mapping;
    /// same.shaping.translation.max_jerk_per_s2 = designed.shaping.translation.max_jerk_per_s2;
    /// assert_eq!(same, designed);
    /// assert!(BallbotController::new(paper).is_ok());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn with_paper_ablation(robot: &BallbotParams<T>) -> Result<Self, Error> {
        let mut config = Self::paper(robot)?;
        config.wheel_mapping = WheelMapping::Upright;
        config.shaping.translation.max_jerk_per_s2 = AxisLimits::<T>::unlimited_jerk_per_s2();
        Ok(config)
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
