//! The scripted demonstration run by `cargo run -p ballbot-examples --example robot_loop` and
//! checked by the package's tests: start-up, driving, a lost command link (controlled stop),
//! resuming, shutdown.
//!
//! | time (s) | operator | expected |
//! |---|---|---|
//! | 0 | remote connected, "stop" | upright and still for 0.25 s, then armed |
//! | 0.5 | 0.8 m/s forward | accelerates (jerk-limited), cruises |
//! | 2.5 | 0.4 m/s forward, 0.5 rad/s yaw | curves |
//! | 3.5 | the remote goes silent | 0.25 s later `CommandLinkLost`: controlled stop, keeps balancing, comes to rest |
//! | 6.0 | remote back, "resume" | balancing again |
//! | 6.5 | shutdown | controlled stop, disarm at rest, motors off |

use crate::sim::{SimError, SimPlant, devices, run_until};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::ModeRequest;
use ballbot_core::{BallbotParams, Error};
use ballbot_runtime::{LoopConfig, OperatorInput, OuterReport, RobotLoop};
use core::cell::RefCell;

/// When each scripted event happens (us).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timeline {
    /// Start driving straight.
    pub drive_us: u64,
    /// Curve.
    pub curve_us: u64,
    /// The remote goes silent.
    pub link_lost_us: u64,
    /// The remote is back and asks to resume.
    pub link_back_us: u64,
    /// Shutdown starts.
    pub shutdown_us: u64,
    /// The run ends.
    pub end_us: u64,
}

impl Timeline {
    /// The script in the module docs.
    pub const DEFAULT: Self = Self {
        drive_us: 500_000,
        curve_us: 2_500_000,
        link_lost_us: 3_500_000,
        link_back_us: 6_000_000,
        shutdown_us: 6_500_000,
        end_us: 7_000_000,
    };

    /// The operator's velocity command at `now_us` (zero again once the link is back).
    pub fn velocity(&self, now_us: u64) -> VelocityCommand<f64> {
        if now_us < self.drive_us || now_us >= self.link_back_us {
            VelocityCommand::zero()
        } else if now_us < self.curve_us {
            VelocityCommand {
                vx_m_per_s: 0.8,
                vy_m_per_s: 0.0,
                yaw_rate_rad_per_s: 0.0,
            }
        } else {
            VelocityCommand {
                vx_m_per_s: 0.4,
                vy_m_per_s: 0.0,
                yaw_rate_rad_per_s: 0.5,
            }
        }
    }
}

/// Why the demonstration could not run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DemoError {
    /// Building the controller failed.
    Design(Error),
    /// The simulation failed.
    Sim(SimError),
}

impl From<Error> for DemoError {
    fn from(e: Error) -> Self {
        Self::Design(e)
    }
}

impl From<SimError> for DemoError {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}

/// Runs the script on a simulated `robot`, calling `on_outer` with every outer report and the
/// plant after it.
pub fn run(
    robot: &BallbotParams<f64>,
    timeline: &Timeline,
    on_outer: impl FnMut(&OuterReport<f64>, &SimPlant),
) -> Result<(), DemoError> {
    let plant = RefCell::new(SimPlant::new(robot)?);
    let (imu, encoders, motors, clock) = devices(&plant);
    let config = LoopConfig::miapure();
    let controller = BallbotControllerConfig::design(robot)?;
    let mut robot_loop = RobotLoop::new(controller, config, imu, encoders, motors, clock)?;
    let mut last_command_us = None;
    let mut shutdown_started = false;
    let t = *timeline;
    run_until(
        &plant,
        &mut robot_loop,
        &config,
        t.end_us,
        |now_us, _plant, robot_loop| {
            let link_up = now_us < t.link_lost_us || now_us >= t.link_back_us;
            if link_up {
                last_command_us = Some(now_us);
            }
            if now_us >= t.shutdown_us && !shutdown_started {
                shutdown_started = true;
                robot_loop.shutdown();
            }
            let request = if now_us == t.link_back_us {
                ModeRequest::Resume
            } else {
                ModeRequest::None
            };
            OperatorInput {
                command: Command::Velocity(t.velocity(now_us)),
                command_timestamp_us: last_command_us,
                request,
            }
        },
        on_outer,
    )?;
    Ok(())
}
