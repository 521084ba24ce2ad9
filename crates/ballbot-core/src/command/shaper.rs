//! The [`CommandShaper`]: any [`Command`] made into smooth, feasible planar command states
//! ([`PlanarCommands`]) with the lean feedforward `theta_ff = (b + c0) a / (r m_U g l)` (see the
//! [module](super) doc).

use super::envelope::{Envelope, Targets, envelope, held_back};
use super::limit::NoLimit;
use super::{AccelLimit, AxisLimits, Command, JerkLimiter, LeanToDrive, LeanToDriveParams};
use crate::check::{lit, non_negative, positive};
use crate::control::dt_is_valid;
use crate::num::{clamp_sym, direction, max, min};
use crate::spin::SpinState;
use crate::wip::{BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{BallbotParams, Error, WipParams};
use nalgebra::RealField;

/// Limits and settings of the [`CommandShaper`].
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{AxisLimits, CommandShaper, CommandShaperParams};
/// // A cautious setting: 0.5 m/s and 0.3 m/s^2 at most.
/// let params = CommandShaperParams {
///     translation: AxisLimits { max_value: 0.5, max_rate_per_s: 0.3, max_jerk_per_s2: 1.0 },
///     ..CommandShaperParams::miapure()
/// };
/// let shaper = CommandShaper::new(params, &BallbotParams::<f64>::miapure_60kg())?;
/// assert_eq!(shaper.params().translation.max_value, 0.5);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct CommandShaperParams<T> {
    /// Limits of each translation axis, body x and body y (m/s, m/s^2, m/s^3).
    pub translation: AxisLimits<T>,
    /// Limits of the yaw rate (rad/s, rad/s^2, rad/s^3).
    pub yaw: AxisLimits<T>,
    /// Lean-to-drive settings.
    pub lean_to_drive: LeanToDriveParams<T>,
    /// Largest commanded tilt (rad), feedforward or from a trajectory.
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_tilt_command_rad: T,
    /// Largest commanded tilt rate (rad/s).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_tilt_rate_command_rad_per_s: T,
    /// Time constant of the reference filter (s, >= 0; 0 = off). When positive, velocity and
    /// lean commands build the planar reference from the jerk-limited speed `v` passed through
    /// `v_f' = (v - v_f) / tau`: tilt `k a_f`, tilt rate `k j_f`, ball rate `v_f / r`, with
    /// `a_f = (v - v_f) / tau` and `j_f = (a - a_f) / tau` (and [`ShapedCommand::acceleration`]
    /// is `a_f`). That reference is consistent (the tilt rate is the tilt's derivative) and
    /// continuous, so the LQR no longer rights the body by running the ball ahead when the
    /// acceleration ends: on MiaPURE with 60 kg a ramp at 1 m/s^2 to 1.5 m/s peaks at 1.786 m/s
    /// ball speed with 0, 1.500 m/s with 0.3 s, at the price of a delay of about `tau`
    /// (docs/embedding.md, "Speed overshoot"). Trajectories are not filtered.
    #[cfg_attr(feature = "schema", schemars(range(min = 0)))]
    pub reference_filter_secs: T,
}

impl<T: RealField + Copy> CommandShaperParams<T> {
    /// Defaults for MiaPURE with a payload (engineering choices): 2.0 m/s (the paper's design
    /// target), 1.0 m/s^2, 2.0 m/s^3 (the lean changes by 7 deg over 0.5 s); yaw 1.5 rad/s, 3 rad/s^2, 20 rad/s^3; the rider
    /// lean-to-drive defaults; tilt command within 0.2 rad and 1.0 rad/s.
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let p = CommandShaperParams::<f64>::miapure();
    /// // The paper's 2 m/s design target.
    /// assert_eq!((p.translation.max_value, p.yaw.max_value), (2.0, 1.5));
    /// ```
    pub fn miapure() -> Self {
        Self {
            translation: AxisLimits {
                max_value: lit(2.0),
                max_rate_per_s: lit(1.0),
                max_jerk_per_s2: lit(2.0),
            },
            yaw: AxisLimits {
                max_value: lit(1.5),
                max_rate_per_s: lit(3.0),
                max_jerk_per_s2: lit(20.0),
            },
            lean_to_drive: LeanToDriveParams::rider(),
            max_tilt_command_rad: lit(0.2),
            max_tilt_rate_command_rad_per_s: lit(1.0),
            reference_filter_secs: T::zero(),
        }
    }

    /// The tilt-command caps a raised acceleration cap comes with ([`Self::admitting_ramp`]):
    /// 0.5 rad and 5 rad/s, far above the lean and lean rate any feasible ramp needs (the
    /// equilibrium lean of 3 m/s^2 on MiaPURE is about 0.3 rad), so that the command, not the
    /// caps, is what a ramp study measures.
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let (lean_rad, lean_rate_rad_per_s) = CommandShaperParams::<f64>::RAMP_TILT_CAPS;
    /// // Above the rider's own caps, which a ramp would otherwise run into.
    /// let rider = CommandShaperParams::<f64>::miapure();
    /// assert!(lean_rad > rider.max_tilt_command_rad);
    /// assert!(lean_rate_rad_per_s > rider.max_tilt_rate_command_rad_per_s);
    /// ```
    pub const RAMP_TILT_CAPS: (f64, f64) = (0.5, 5.0);

    /// These caps raised so that a speed ramp to `top_speed_m_per_s` at `accel_m_per_s2` is
    /// not cut by them: the translation speed cap to the top speed and the acceleration cap to
    /// the ramp's where they are below, and with a raised acceleration cap the tilt-command
    /// caps to at least [`Self::RAMP_TILT_CAPS`]. The jerk limit and everything else stay.
    /// (A non-finite or smaller value raises nothing.)
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let core = CommandShaperParams::<f64>::miapure();
    /// let ramp = core.admitting_ramp(3.0, 2.0);
    /// assert_eq!((ramp.translation.max_value, ramp.translation.max_rate_per_s), (3.0, 2.0));
    /// assert_eq!((ramp.max_tilt_command_rad, ramp.max_tilt_rate_command_rad_per_s), (0.5, 5.0));
    /// assert_eq!(ramp.translation.max_jerk_per_s2, core.translation.max_jerk_per_s2);
    /// // Within the caps, nothing moves.
    /// assert_eq!(core.admitting_ramp(1.0, 0.5), core);
    /// ```
    pub fn admitting_ramp(mut self, top_speed_m_per_s: T, accel_m_per_s2: T) -> Self {
        let translation = &mut self.translation;
        if top_speed_m_per_s > translation.max_value {
            translation.max_value = top_speed_m_per_s;
        }
        if accel_m_per_s2 > translation.max_rate_per_s {
            translation.max_rate_per_s = accel_m_per_s2;
            let (tilt, tilt_rate) = Self::RAMP_TILT_CAPS;
            self.max_tilt_command_rad = max(self.max_tilt_command_rad, lit(tilt));
            self.max_tilt_rate_command_rad_per_s =
                max(self.max_tilt_rate_command_rad_per_s, lit(tilt_rate));
        }
        self
    }

    /// Checks every field.
    ///
    /// ```
    /// use ballbot_core::command::CommandShaperParams;
    /// let mut p = CommandShaperParams::<f64>::miapure();
    /// assert!(p.validate().is_ok());
    /// p.max_tilt_command_rad = 0.0;
    /// assert!(p.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.translation.validate()?;
        self.yaw.validate()?;
        self.lean_to_drive.validate()?;
        positive(self.max_tilt_command_rad, "max_tilt_command_rad")?;
        positive(
            self.max_tilt_rate_command_rad_per_s,
            "max_tilt_rate_command_rad_per_s",
        )?;
        non_negative(self.reference_filter_secs, "reference_filter_secs")
    }
}

/// Body-frame motion: velocity, or one of its derivatives.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let turn = Command::Velocity(VelocityCommand { yaw_rate_rad_per_s: 1.0, ..Default::default() });
/// // The yaw acceleration after one step is the 20 rad/s^3 jerk limit times 2.5 ms.
/// let a = shaper.step(&turn, 0.0025).acceleration;
/// assert_eq!((a.x, a.y), (0.0, 0.0));
/// approx::assert_relative_eq!(a.yaw, 20.0 * 0.0025, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyMotion<T> {
    /// Along body x (m/s, m/s^2 or m/s^3).
    pub x: T,
    /// Along body y (m/s, m/s^2 or m/s^3).
    pub y: T,
    /// About body z (rad/s, rad/s^2 or rad/s^3).
    pub yaw: T,
}

/// The command state of each planar controller.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// // Sideways to the left: the frontal plane travels along -y, so its ball rate is negative.
/// let left = Command::Velocity(VelocityCommand { vy_m_per_s: 0.5, ..VelocityCommand::zero() });
/// let mut planar = shaper.step(&left, 0.0025).planar;
/// for _ in 0..800 {
///     planar = shaper.step(&left, 0.0025).planar;
/// }
/// let r = robot.frontal.ball_radius_m;
/// approx::assert_relative_eq!(planar.frontal[3], -0.5 / r, epsilon = 1e-9);
/// assert_eq!(planar.sagittal[3], 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarCommands<T: nalgebra::Scalar> {
    /// Sagittal plane `s_cy = [theta_y, phi_y, theta_dot_y, phi_dot_y]`.
    pub sagittal: WipState<T>,
    /// Frontal plane `s_cx = [theta_x, phi_x, theta_dot_x, phi_dot_x]`.
    pub frontal: WipState<T>,
    /// Spin `s_cz = [theta_z, theta_dot_z]` (heading, yaw rate).
    pub spin: SpinState<T>,
}

/// One step of shaped command.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let garbled = Command::Velocity(VelocityCommand { vx_m_per_s: f64::NAN, ..Default::default() });
/// // A non-finite command is flagged and replaced by a stop.
/// let shaped = shaper.step(&garbled, 0.0025);
/// assert!(!shaped.command_finite);
/// assert_eq!(shaped.velocity.vx_m_per_s, 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapedCommand<T: nalgebra::Scalar> {
    /// Shaped body velocity (m/s, m/s, rad/s).
    pub velocity: BodyVelocity<T>,
    /// Its acceleration (m/s^2, m/s^2, rad/s^2); with the reference filter on, that of the
    /// filtered speed (see [`CommandShaperParams::reference_filter_secs`]).
    pub acceleration: BodyMotion<T>,
    /// The planar command states.
    pub planar: PlanarCommands<T>,
    /// Commanded tilt accelerations `[theta_ddot_x, theta_ddot_y]` of the frontal and
    /// sagittal planes (rad/s^2): for a trajectory, the slope of its linearly interpolated tilt
    /// rate, along its heading (zero where the tilt-rate command is clamped); zero for the
    /// other commands, whose lean command is the equilibrium lean.
    pub tilt_accel_rad_per_s2: [T; 2],
    /// Whether the command was finite; a non-finite command is replaced by [`Command::Stop`].
    pub command_finite: bool,
    /// With [`CommandShaper::step_within`]: the acceleration limit along the direction the
    /// command wanted to accelerate in (m/s^2), `None` when it did not ask to accelerate or
    /// without a limit.
    pub accel_limit_m_per_s2: Option<T>,
    /// Whether that limit held the command back in this step: it was below the
    /// translation limit and the shaped acceleration rides on it.
    pub limited: bool,
}

/// A shaped velocity with named fields (m/s, m/s, rad/s).
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{BodyVelocity, CommandShaper, CommandShaperParams};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// assert_eq!(shaper.velocity(), BodyVelocity::default()); // starts at rest
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyVelocity<T> {
    /// Along body x (m/s).
    pub vx_m_per_s: T,
    /// Along body y (m/s).
    pub vy_m_per_s: T,
    /// About body z (rad/s).
    pub yaw_rate_rad_per_s: T,
}

/// Per-plane constants of the lean feedforward.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlaneShaping<T> {
    /// `1 / r` (1/m).
    inv_radius_per_m: T,
    /// Tilt per unit ball acceleration `(b + c0) / (r m_U g l)` (rad per m/s^2).
    lean_rad_per_m_per_s2: T,
}

impl<T: RealField + Copy> PlaneShaping<T> {
    fn new(p: &WipParams<T>) -> Self {
        let r = p.ball_radius_m;
        Self {
            inv_radius_per_m: T::one() / r,
            lean_rad_per_m_per_s2: p.lean_per_ball_accel_s2() / r,
        }
    }
}

/// Shapes any [`Command`] into smooth, feasible planar command states.
///
/// Holds three [`JerkLimiter`]s (body x speed, body y speed, yaw rate), the integrated heading
/// command and the integrated ball-angle commands. Allocation-free and O(1) per step.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
/// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 2.0, ..VelocityCommand::zero() });
/// // Mid-ramp, accelerating at the 1 m/s^2 limit: the sagittal command leans forward by the
/// // equilibrium lean theta_ff = (b + c0) a / (r m_U g l), 7.3 deg for MiaPURE with 60 kg.
/// let mut shaped = shaper.step(&go, 0.0025);
/// for _ in 0..400 {
///     shaped = shaper.step(&go, 0.0025);
/// }
/// let p = &robot.sagittal;
/// let (r, l, m) = (p.ball_radius_m, p.com_height_m, p.body_mass_kg);
/// let b = p.ball_inertia_kg_m2 + (p.ball_mass_kg + m) * r * r;
/// let lean_rad_per_m_per_s2 = (b + m * r * l) / (r * m * p.gravity_m_per_s2 * l);
/// assert_eq!(shaped.acceleration.x, 1.0);
/// approx::assert_relative_eq!(shaped.planar.sagittal[0], lean_rad_per_m_per_s2, epsilon = 1e-12);
/// assert!((shaped.planar.sagittal[0].to_degrees() - 7.3).abs() < 0.1);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandShaper<T> {
    pub(super) params: CommandShaperParams<T>,
    lean: LeanToDrive<T>,
    sagittal: PlaneShaping<T>,
    frontal: PlaneShaping<T>,
    pub(super) vx: JerkLimiter<T>,
    pub(super) vy: JerkLimiter<T>,
    pub(super) yaw_rate: JerkLimiter<T>,
    heading_rad: T,
    phi_x_rad: T,
    phi_y_rad: T,
    /// The filtered speeds `v_f` (m/s, body x and y; equal to the shaped speeds when the
    /// reference filter is off or a trajectory runs).
    pub(super) filtered_m_per_s: (T, T),
}

impl<T: RealField + Copy> CommandShaper<T> {
    /// Validates `params` and `robot` and starts at rest with heading 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// assert!(shaper.is_at_rest());
    /// let mut bad = CommandShaperParams::miapure();
    /// bad.yaw.max_rate_per_s = f64::NAN;
    /// assert!(CommandShaper::new(bad, &robot).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: CommandShaperParams<T>, robot: &BallbotParams<T>) -> Result<Self, Error> {
        params.validate()?;
        robot.validate()?;
        Ok(Self {
            params,
            lean: LeanToDrive::new(params.lean_to_drive)?,
            sagittal: PlaneShaping::new(&robot.sagittal),
            frontal: PlaneShaping::new(&robot.frontal),
            vx: JerkLimiter::at(T::zero()),
            vy: JerkLimiter::at(T::zero()),
            yaw_rate: JerkLimiter::at(T::zero()),
            heading_rad: T::zero(),
            phi_x_rad: T::zero(),
            phi_y_rad: T::zero(),
            filtered_m_per_s: (T::zero(), T::zero()),
        })
    }

    /// The settings.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// assert_eq!(shaper.params(), &CommandShaperParams::miapure());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &CommandShaperParams<T> {
        &self.params
    }

    /// Restarts at rest with heading command `heading_rad` (use the measured heading when
    /// arming) and ball-angle commands `phi_x_rad`, `phi_y_rad`. Non-finite values become 0.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// // Arming while the robot faces 1.2 rad: hold that heading, not 0.
    /// shaper.reset(1.2, 0.0, 0.0);
    /// let shaped = shaper.step(&Command::Stop, 0.0025);
    /// assert_eq!(shaped.planar.spin[0], 1.2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self, heading_rad: T, phi_x_rad: T, phi_y_rad: T) {
        let or_zero = |x: T| if x.is_finite() { x } else { T::zero() };
        self.vx = JerkLimiter::at(T::zero());
        self.vy = JerkLimiter::at(T::zero());
        self.yaw_rate = JerkLimiter::at(T::zero());
        self.heading_rad = or_zero(heading_rad);
        self.phi_x_rad = or_zero(phi_x_rad);
        self.phi_y_rad = or_zero(phi_y_rad);
        self.filtered_m_per_s = (T::zero(), T::zero());
    }

    /// The shaped velocity now.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
    /// let shaped = shaper.step(&go, 0.0025);
    /// assert_eq!(shaper.velocity(), shaped.velocity);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn velocity(&self) -> BodyVelocity<T> {
        BodyVelocity {
            vx_m_per_s: self.vx.value(),
            vy_m_per_s: self.vy.value(),
            yaw_rate_rad_per_s: self.yaw_rate.value(),
        }
    }

    /// Whether the shaped command is at rest (speeds and accelerations exactly 0).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, ..VelocityCommand::zero() });
    /// for _ in 0..800 {
    ///     shaper.step(&go, 0.0025);
    /// }
    /// // A controlled stop: Stop until the shaped command is at rest, exactly.
    /// let mut steps = 0;
    /// while !shaper.is_at_rest() && steps < 4000 {
    ///     shaper.step(&Command::Stop, 0.0025);
    ///     steps += 1;
    /// }
    /// assert!(shaper.is_at_rest() && steps < 4000);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn is_at_rest(&self) -> bool {
        let z = T::zero();
        self.vx.value() == z
            && self.vy.value() == z
            && self.yaw_rate.value() == z
            && self.vx.rate_per_s() == z
            && self.vy.rate_per_s() == z
            && self.yaw_rate.rate_per_s() == z
            && self.filtered_m_per_s == (z, z)
    }

    /// Advances one step of `dt_secs` (non-finite or non-positive: no motion) towards
    /// `command`. A non-finite command is treated as [`Command::Stop`] and flagged in the
    /// output.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::ballbot::BallbotControllerConfig;
    /// use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, Trajectory};
    /// use nalgebra::Vector4;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let limits = BallbotControllerConfig::design(&robot)?.trajectory_limits()?;
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// // A trajectory driven towards body +y (heading pi/2): it lands in the frontal plane with
    /// // the opposite sign (y = -r phi_x), and its own tilt is passed through.
    /// let samples = [Vector4::new(0.05, 0.0, 0.0, 0.0), Vector4::zeros()];
    /// let trajectory = Trajectory::new(&samples, 0.1, core::f64::consts::FRAC_PI_2, &limits)?;
    /// let shaped = shaper.step(&Command::Trajectory { trajectory, time_secs: 0.0 }, 0.0025);
    /// approx::assert_relative_eq!(shaped.planar.frontal[0], -0.05, epsilon = 1e-12);
    /// approx::assert_relative_eq!(shaped.planar.sagittal[0], 0.0, epsilon = 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(&mut self, command: &Command<'_, T>, dt_secs: T) -> ShapedCommand<T> {
        self.step_inner::<NoLimit>(command, dt_secs, None)
    }

    /// [`Self::step`] within a direction-dependent acceleration limit (e.g. the traction
    /// envelope, [`crate::traction`]).
    ///
    /// The direction is that of the velocity error (target minus shaped velocity, body x and
    /// y). The two axes share the smaller of `limit` in that direction and the translation
    /// limit in proportion to the direction's components, so the *vector* acceleration stays
    /// within it (without a limit each axis has the full translation limit). A limit below
    /// the present acceleration is reached within the translation's jerk limit (at once
    /// without one): the lean of the acceleration goes with it, and righting the body in one
    /// step makes the ball accelerate harder first, which is the traction a slip reaction
    /// means to spare (in the 3D world a one-step cut lifted the least-loaded wheel off on
    /// 10 of 16 diagonal ramps). A trajectory held back by the limit gets the equilibrium lean of its
    /// shaped acceleration instead of its own tilt. Yaw is not limited.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::command::{AccelLimit, Command, CommandShaper, CommandShaperParams, VelocityCommand};
    /// struct Half;
    /// impl AccelLimit<f64> for Half {
    ///     fn accel_limit_m_per_s2(&self, _x: f64, _y: f64, _braking: bool) -> f64 { 0.5 }
    /// }
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
    /// // Diagonally: the vector acceleration is at most 0.5 m/s^2, not 0.5 per axis.
    /// let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, vy_m_per_s: 1.0, ..Default::default() });
    /// let mut shaped = shaper.step_within(&go, 0.0025, &Half);
    /// for _ in 0..400 {
    ///     shaped = shaper.step_within(&go, 0.0025, &Half);
    /// }
    /// let a = shaped.acceleration;
    /// approx::assert_relative_eq!((a.x * a.x + a.y * a.y).sqrt(), 0.5, epsilon = 1e-9);
    /// assert!(shaped.limited && shaped.accel_limit_m_per_s2 == Some(0.5));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step_within<L: AccelLimit<T>>(
        &mut self,
        command: &Command<'_, T>,
        dt_secs: T,
        limit: &L,
    ) -> ShapedCommand<T> {
        self.step_inner(command, dt_secs, Some(limit))
    }

    /// The step, monomorphised per limit type: with `None` for [`NoLimit`] the limit's code
    /// is compiled out of [`Self::step`]. Its phases: the targets the command asks for, the
    /// traction envelope on them, the rate limiters, the reference filter, the wheel angles'
    /// integration and the planar reference.
    fn step_inner<L: AccelLimit<T>>(
        &mut self,
        command: &Command<'_, T>,
        dt_secs: T,
        limit: Option<&L>,
    ) -> ShapedCommand<T> {
        let command_finite = command.is_finite();
        let command = if command_finite {
            *command
        } else {
            Command::Stop
        };
        let is_trajectory = matches!(command, Command::Trajectory { .. });
        let target = self.targets(&command);
        let dt_ok = dt_is_valid(dt_secs);
        let envelope = match limit {
            Some(limit) => envelope(&target, limit, (&self.vx, &self.vy), dt_secs),
            None => Envelope::open(&target.translation),
        };
        let (vx, vy, wz) = if dt_ok {
            self.advance_limiters(&target, &envelope, dt_secs)
        } else {
            (self.vx.value(), self.vy.value(), self.yaw_rate.value())
        };
        let limited = held_back(&target.translation, &envelope, (&self.vx, &self.vy));
        // Held back: the trajectory's own lean belongs to an acceleration it no longer has.
        let trajectory_tilt = if limited {
            None
        } else {
            target.trajectory_tilt
        };
        let reference = self.reference_filter(vx, vy, is_trajectory, dt_ok, dt_secs);
        if dt_ok {
            self.integrate(wz, reference.0, dt_secs);
        }
        let (planar, tilt_accel_rad_per_s2) =
            self.planar_reference(trajectory_tilt, &reference, wz);
        ShapedCommand {
            velocity: BodyVelocity {
                vx_m_per_s: vx,
                vy_m_per_s: vy,
                yaw_rate_rad_per_s: wz,
            },
            acceleration: BodyMotion {
                x: (reference.1).0,
                y: (reference.1).1,
                yaw: self.yaw_rate.rate_per_s(),
            },
            planar,
            tilt_accel_rad_per_s2,
            command_finite,
            accel_limit_m_per_s2: envelope.accel_limit_m_per_s2,
            limited,
        }
    }

    /// Phase 1: the targets (vx, vy, yaw rate) the command asks for, their own rates and, for a
    /// trajectory, its tilt and tilt rate along the heading with the heading's (sin, cos).
    #[inline(always)]
    fn targets(&self, command: &Command<'_, T>) -> Targets<T> {
        let zero = T::zero();
        let mut translation = self.params.translation;
        let mut trajectory_tilt = None;
        // Each target's own rate (nonzero only for a trajectory).
        let mut feed = (zero, zero);
        let (x, y, yaw) = match *command {
            Command::Stop => (zero, zero, zero),
            Command::Velocity(v) => {
                let (vx, vy) = clamp_norm(v.vx_m_per_s, v.vy_m_per_s, translation.max_value);
                (vx, vy, v.yaw_rate_rad_per_s)
            }
            Command::Lean(lean) => {
                let v = self.lean.velocity(&lean);
                translation.max_rate_per_s = translation
                    .max_rate_per_s
                    .min(self.params.lean_to_drive.max_accel_m_per_s2);
                let (vx, vy) = clamp_norm(v.vx_m_per_s, v.vy_m_per_s, translation.max_value);
                (vx, vy, v.yaw_rate_rad_per_s)
            }
            Command::Trajectory {
                trajectory,
                time_secs,
            } => {
                let (s, rate) = trajectory.sample_with_rate(time_secs);
                let (sin_h, cos_h) = trajectory.heading_rad().sin_cos();
                // Ball rate along the heading in m/s (one ball: the sagittal radius).
                let radius = T::one() / self.sagittal.inv_radius_per_m;
                let speed = s[BALL_RATE] * radius;
                let accel = rate[BALL_RATE] * radius;
                trajectory_tilt = Some((s[TILT], s[TILT_RATE], rate[TILT_RATE], sin_h, cos_h));
                feed = (accel * cos_h, accel * sin_h);
                let (vx, vy) = clamp_norm(speed * cos_h, speed * sin_h, translation.max_value);
                (vx, vy, trajectory.yaw_rate_rad_per_s())
            }
        };
        Targets {
            x,
            y,
            yaw,
            feed,
            trajectory_tilt,
            translation,
        }
    }

    /// Phase 3: the three rate limiters one step towards their targets.
    #[inline(always)]
    fn advance_limiters(
        &mut self,
        target: &Targets<T>,
        envelope: &Envelope<T>,
        dt_secs: T,
    ) -> (T, T, T) {
        (
            self.vx
                .advance(target.x, target.feed.0, &envelope.x, dt_secs),
            self.vy
                .advance(target.y, target.feed.1, &envelope.y, dt_secs),
            self.yaw_rate
                .advance(target.yaw, T::zero(), &self.params.yaw, dt_secs),
        )
    }

    /// Phase 4, the reference filter (see `CommandShaperParams::reference_filter_secs`): the
    /// speeds, accelerations and jerks the planar reference is built from.
    #[inline(always)]
    fn reference_filter(
        &mut self,
        vx: T,
        vy: T,
        is_trajectory: bool,
        dt_ok: bool,
        dt_secs: T,
    ) -> Reference<T> {
        let zero = T::zero();
        let tau = self.params.reference_filter_secs;
        let (ax, ay) = (self.vx.rate_per_s(), self.vy.rate_per_s());
        if tau > zero && !is_trajectory {
            let (fx, fy) = self.filtered_m_per_s;
            let (afx, afy) = ((vx - fx) / tau, (vy - fy) / tau);
            if dt_ok {
                // Exact for a held input up to first order, stable for any `dt_secs / tau`.
                let gain = min(dt_secs / tau, T::one());
                let settle = |f: T, v: T| {
                    let next = f + (v - f) * gain;
                    // Within 0.1 mm/s the filter is settled: snap (an exponential never is).
                    if (v - next).abs() <= lit(1e-4) {
                        v
                    } else {
                        next
                    }
                };
                self.filtered_m_per_s = (settle(fx, vx), settle(fy, vy));
            }
            ((fx, fy), (afx, afy), ((ax - afx) / tau, (ay - afy) / tau))
        } else {
            self.filtered_m_per_s = (vx, vy);
            ((vx, vy), (ax, ay), (zero, zero))
        }
    }

    /// Phase 5: the heading and the reference's wheel angles, one step on.
    #[inline(always)]
    fn integrate(&mut self, wz: T, (rvx, rvy): (T, T), dt_secs: T) {
        self.heading_rad += wz * dt_secs;
        self.phi_y_rad += rvx * self.sagittal.inv_radius_per_m * dt_secs;
        self.phi_x_rad -= rvy * self.frontal.inv_radius_per_m * dt_secs;
    }

    /// Phase 6: the planar reference states and the tilt accelerations `[x, y]` they imply.
    #[inline(always)]
    fn planar_reference(
        &self,
        trajectory_tilt: Option<(T, T, T, T, T)>,
        &((rvx, rvy), (rax, ray), (rjx, rjy)): &Reference<T>,
        wz: T,
    ) -> (PlanarCommands<T>, [T; 2]) {
        let zero = T::zero();
        let ky = self.sagittal.lean_rad_per_m_per_s2;
        let kx = self.frontal.lean_rad_per_m_per_s2;
        // Velocity and lean commands: the equilibrium lean of the shaped acceleration, and no
        // tilt-rate command. (Feeding the lean's rate, `k j`, forward makes the LQR's tilt-rate
        // term step by `k2 k dj` wherever the jerk switches: on MiaPURE braking from 1.5 m/s
        // that raised the peak ball acceleration from 1.7 to 6.7 m/s^2 for a 0.04 m/s smaller
        // speed error.) Trajectories bring their own tilt and tilt rate.
        let max_tilt = self.params.max_tilt_command_rad;
        let max_rate = self.params.max_tilt_rate_command_rad_per_s;
        // A clamped tilt-rate command does not change: no tilt acceleration then.
        let unless_clamped = |rate: T, accel: T| if rate.abs() > max_rate { zero } else { accel };
        let (tilt_y, rate_y, tilt_x, rate_x, accel_y, accel_x) = match trajectory_tilt {
            Some((tilt, rate, accel, sin_h, cos_h)) => (
                cos_h * tilt,
                cos_h * rate,
                -sin_h * tilt,
                -sin_h * rate,
                unless_clamped(cos_h * rate, cos_h * accel),
                unless_clamped(sin_h * rate, -sin_h * accel),
            ),
            None => (ky * rax, ky * rjx, -kx * ray, -kx * rjy, zero, zero),
        };
        let clamp = clamp_sym::<T>;
        let planar = PlanarCommands {
            sagittal: WipState::new(
                clamp(tilt_y, max_tilt),
                self.phi_y_rad,
                clamp(rate_y, max_rate),
                rvx * self.sagittal.inv_radius_per_m,
            ),
            frontal: WipState::new(
                clamp(tilt_x, max_tilt),
                self.phi_x_rad,
                clamp(rate_x, max_rate),
                -rvy * self.frontal.inv_radius_per_m,
            ),
            spin: SpinState::new(self.heading_rad, wz),
        };
        (planar, [accel_x, accel_y])
    }
}

/// The reference filter's output: speeds (m/s), accelerations (m/s^2) and jerks (m/s^3), each
/// as (x, y).
type Reference<T> = ((T, T), (T, T), (T, T));

/// Scales `(x, y)` down to length `max` if longer, keeping its direction for every finite
/// input (the direction is taken from the scaled components, [`direction`]: the plain `x^2 +
/// y^2` overflowed from `1.3e154` in `f64`, `1.8e19` in `f32`, and the command then passed
/// unclamped).
fn clamp_norm<T: RealField + Copy>(x: T, y: T, max: T) -> (T, T) {
    match direction(x, y) {
        Some(((ux, uy), norm)) if norm > max => (ux * max, uy * max),
        _ => (x, y),
    }
}
