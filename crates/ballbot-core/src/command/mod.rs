//! Command shaping: what the robot is asked to do, made smooth and feasible.
//!
//! Three kinds of command reach a ballbot (see [`Command`]):
//! - **velocity** ([`VelocityCommand`]): remote control, `vx`, `vy` (m/s, body frame: x towards
//!   omniwheel 1, y to its left, z up) and a yaw rate (rad/s, counter-clockwise from above);
//! - **lean-to-drive** ([`LeanInput`], [`LeanToDrive`]): a rider's torso lean becomes a velocity
//!   command through a deadband, a gain and a speed limit;
//! - **trajectory** ([`Trajectory`]): a sampled planar command state `s_c(t) = [theta, phi,
//!   theta_dot, phi_dot]` (e.g. the optimal braking trajectory) borrowed from a slice, sampled
//!   every `sample_period_secs`, linearly interpolated, and driven along a heading; checked
//!   once when built against the [`TrajectoryLimits`] of the controller that will follow it.
//!
//! Every kind passes through the same per-axis [`JerkLimiter`]: speed, acceleration and jerk are
//! bounded, so a step in the command (a dropped remote, a rider jerking forward) becomes a smooth
//! ramp. The [`CommandShaper`] turns the shaped motion into the three planar command states the
//! plane controllers consume ([`PlanarCommands`]):
//!
//! ```text
//! sagittal (travel along x):  s_cy = [theta_ff(a_x),  phi_y, 0,  v_x / r]
//! frontal  (travel along -y): s_cx = [-theta_ff(a_y), phi_x, 0, -v_y / r]
//! spin:                       s_cz = [heading, yaw_rate]
//! ```
//!
//! (MODEL.md section 1: ball position `x = r phi_y`, `y = -r phi_x`.) The lean feedforward
//! `theta_ff` is the constant tilt at which the nominal WIP accelerates its ball at `a` without
//! tipping: with `theta_dot = theta_ddot = 0` the model gives `c phi_ddot = m_U g l theta - tau`
//! and `b phi_ddot = tau`, so, to first order, `theta_ff = (b + c0) a / (r m_U g l)`. Jerk
//! limiting is what makes that lean command continuous. (Trajectory commands carry their own
//! tilt and tilt rate.)
//!
//! ```
//! use ballbot_core::command::{Command, CommandShaper, CommandShaperParams, VelocityCommand};
//! use ballbot_core::BallbotParams;
//! let robot = BallbotParams::<f64>::miapure_60kg();
//! let mut shaper = CommandShaper::new(CommandShaperParams::miapure(), &robot)?;
//! let go = Command::Velocity(VelocityCommand { vx_m_per_s: 1.0, vy_m_per_s: 0.0, yaw_rate_rad_per_s: 0.0 });
//! // A 1 m/s step becomes a ramp: after one 400 Hz step the command has barely moved.
//! let shaped = shaper.step(&go, 0.0025);
//! assert!(shaped.velocity.vx_m_per_s > 0.0 && shaped.velocity.vx_m_per_s < 1e-3);
//! // Three seconds later it has arrived, and the sagittal plane is asked for v / r.
//! for _ in 0..1200 { shaper.step(&go, 0.0025); }
//! let shaped = shaper.step(&go, 0.0025);
//! approx::assert_relative_eq!(shaped.velocity.vx_m_per_s, 1.0, epsilon = 1e-9);
//! approx::assert_relative_eq!(shaped.planar.sagittal[3], 1.0 / 0.1145, epsilon = 1e-6);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

mod envelope;
mod jerk;
mod lean;
mod limit;
mod pending;
#[cfg(test)]
mod proptests;
mod shaper;
#[cfg(test)]
mod tests;
mod trajectory;
mod trajectory_limits;

pub use jerk::{AxisLimits, JerkLimiter};
pub use lean::{LeanInput, LeanToDrive, LeanToDriveParams};
pub use limit::AccelLimit;
pub use shaper::{
    BodyMotion, BodyVelocity, CommandShaper, CommandShaperParams, PlanarCommands, ShapedCommand,
};
pub use trajectory::Trajectory;
pub use trajectory_limits::TrajectoryLimits;

use nalgebra::RealField;

/// A remote-control velocity command in the body frame.
///
/// ```
/// use ballbot_core::command::VelocityCommand;
/// // Forward and to the left at 0.5 m/s each, turning clockwise at 0.2 rad/s.
/// let v = VelocityCommand { vx_m_per_s: 0.5, vy_m_per_s: 0.5, yaw_rate_rad_per_s: -0.2 };
/// assert!(v.is_finite());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityCommand<T> {
    /// Forward speed, towards omniwheel 1 (body x) (m/s).
    pub vx_m_per_s: T,
    /// Sideways speed, to the left (body y) (m/s).
    pub vy_m_per_s: T,
    /// Yaw rate, counter-clockwise seen from above (rad/s).
    pub yaw_rate_rad_per_s: T,
}

impl<T: RealField + Copy> VelocityCommand<T> {
    /// Standing still.
    ///
    /// ```
    /// use ballbot_core::command::VelocityCommand;
    /// assert_eq!(VelocityCommand::<f64>::zero(), VelocityCommand::default());
    /// ```
    pub fn zero() -> Self {
        Self {
            vx_m_per_s: T::zero(),
            vy_m_per_s: T::zero(),
            yaw_rate_rad_per_s: T::zero(),
        }
    }

    /// Whether every component is finite.
    ///
    /// ```
    /// use ballbot_core::command::VelocityCommand;
    /// let v = VelocityCommand { vx_m_per_s: f64::NAN, ..VelocityCommand::zero() };
    /// assert!(!v.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        self.vx_m_per_s.is_finite()
            && self.vy_m_per_s.is_finite()
            && self.yaw_rate_rad_per_s.is_finite()
    }
}

/// What the robot is asked to do this step.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::ballbot::BallbotControllerConfig;
/// use ballbot_core::command::{Command, LeanInput, Trajectory, VelocityCommand};
/// use nalgebra::Vector4;
/// let limits = BallbotControllerConfig::design(&BallbotParams::<f64>::miapure_60kg())?
///     .trajectory_limits()?;
/// let samples = [Vector4::new(0.0, 0.0, 0.0, 5.0)];
/// let trajectory = Trajectory::new(&samples, 0.01, 0.0, &limits)?;
/// let commands = [
///     Command::Stop,
///     Command::Velocity(VelocityCommand { vx_m_per_s: 0.5, ..VelocityCommand::zero() }),
///     Command::Lean(LeanInput { towards_x_rad: 0.1, ..LeanInput::default() }),
///     Command::Trajectory { trajectory, time_secs: 0.0 },
/// ];
/// assert!(commands.iter().all(|c| c.is_finite()));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command<'a, T: nalgebra::Scalar> {
    /// Come to rest and hold upright (the controlled stop uses this).
    Stop,
    /// Remote-control velocity.
    Velocity(VelocityCommand<T>),
    /// A rider's lean.
    Lean(LeanInput<T>),
    /// Follow a trajectory, `time_secs` after its start.
    Trajectory {
        /// The trajectory.
        trajectory: Trajectory<'a, T>,
        /// Time since its start (s).
        time_secs: T,
    },
}

impl<T: RealField + Copy> Command<'_, T> {
    /// Whether every number in the command is finite (a trajectory's samples were checked when
    /// it was built).
    ///
    /// ```
    /// use ballbot_core::command::{Command, VelocityCommand};
    /// let garbled = VelocityCommand { yaw_rate_rad_per_s: f64::INFINITY, ..Default::default() };
    /// assert!(!Command::Velocity(garbled).is_finite());
    /// assert!(Command::<f64>::Stop.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        match self {
            Self::Stop => true,
            Self::Velocity(v) => v.is_finite(),
            Self::Lean(l) => {
                l.towards_x_rad.is_finite()
                    && l.towards_y_rad.is_finite()
                    && l.yaw_rate_rad_per_s.is_finite()
            }
            Self::Trajectory { time_secs, .. } => time_secs.is_finite(),
        }
    }
}
