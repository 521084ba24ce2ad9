//! Planar scenarios as data: a TOML file with the robot, its friction and sensors, the
//! simulator's rates, the controller, the command profile, the seed and the duration.
//!
//! Every section but `[controller]` is optional and defaults to the PIPTB preset, no
//! friction, ideal sensors, the paper's rates (8 kHz plant and drive, 400 Hz controller, one
//! period of computation delay), and the PIPTB braking profile. Unknown keys are errors, and
//! every error names the key (TOML's own errors quote the offending line).
//!
//! ```
//! use ballbot_studies::studies::scenario::Scenario;
//! let scenario = Scenario::from_toml_str(r#"
//!     seed = 7
//!     duration_secs = 6.4
//!     [friction]
//!     stiction_torque_nm = 0.5
//!     coulomb_torque_nm = 0.35
//!     [controller]
//!     kind = "lqr_pi"
//!     [command]
//!     kind = "piptb"
//! "#)?;
//! assert_eq!(scenario.seed, 7);
//! let err = Scenario::from_toml_str("[controller]\nkind = \"lqr\"\n[friction]\nstiction_nm = 1.0")
//!     .unwrap_err();
//! assert!(err.to_string().contains("stiction_nm"));
//! # Ok::<(), ballbot_studies::studies::scenario::ScenarioError>(())
//! ```

use super::piptb::{PiptbProfile, PiptbSettings, braking_reference};
use ballbot_core::{ActuatorParams, PlanarRobotParams, WipParams, WipState};
use ballbot_world::planar::{
    CommandProfile, ControllerSettings, PlanarCommand, PlanarError, PlanarSim, SensorParams,
    SimConfig, TransmissionFriction,
};
use std::path::{Path, PathBuf};

/// What is wrong with a scenario.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario {path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The TOML does not parse or does not fit the schema (the message names the key).
    #[error("invalid scenario{}: {message}", path.as_ref().map(|p| format!(" {}", p.display())).unwrap_or_default())]
    Parse {
        /// The file, if read from one.
        path: Option<PathBuf>,
        /// TOML's message, with the line and the key.
        message: String,
    },
    /// A value is out of range.
    #[error("invalid scenario: `{key}` {requirement}")]
    Invalid {
        /// The key, e.g. `friction.coulomb_torque_nm`.
        key: String,
        /// What it must satisfy.
        requirement: String,
    },
}

impl From<PlanarError> for ScenarioError {
    fn from(e: PlanarError) -> Self {
        match e {
            PlanarError::Invalid { key, requirement } => Self::Invalid { key, requirement },
            PlanarError::Model(ballbot_core::Error::InvalidParameter { field, requirement }) => {
                Self::Invalid {
                    key: format!("robot.{field}"),
                    requirement: requirement.to_owned(),
                }
            }
            other => Self::Invalid {
                key: "robot".to_owned(),
                requirement: other.to_string(),
            },
        }
    }
}

/// A robot preset.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum RobotPreset {
    /// The planar testbed ([`PlanarRobotParams::piptb`]).
    #[default]
    Piptb,
}

/// `[robot]`: a preset, optionally with its plane or actuator replaced entirely.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// The preset. Default `piptb`.
    #[serde(default)]
    pub preset: RobotPreset,
    /// Replaces the preset's WIP plane (every field of [`WipParams`]).
    #[serde(default)]
    pub plane: Option<WipParams<f64>>,
    /// Replaces the preset's actuator (every field of [`ActuatorParams`]).
    #[serde(default)]
    pub actuator: Option<ActuatorParams<f64>>,
}

impl RobotSpec {
    /// The robot's parameters, validated; errors name `robot.plane.<field>` or
    /// `robot.actuator.<field>`.
    pub fn params(&self) -> Result<PlanarRobotParams<f64>, ScenarioError> {
        let mut robot = match self.preset {
            RobotPreset::Piptb => PlanarRobotParams::piptb(),
        };
        if let Some(plane) = self.plane {
            robot.plane = plane;
        }
        if let Some(actuator) = self.actuator {
            robot.actuator = actuator;
        }
        let named = |section: &str, e: ballbot_core::Error| match e {
            ballbot_core::Error::InvalidParameter { field, requirement } => {
                ScenarioError::Invalid {
                    key: format!("robot.{section}.{field}"),
                    requirement: requirement.to_owned(),
                }
            }
            other => ScenarioError::Invalid {
                key: format!("robot.{section}"),
                requirement: other.to_string(),
            },
        };
        robot.plane.validate().map_err(|e| named("plane", e))?;
        ballbot_core::Wip::new(robot.plane).map_err(|e| named("plane", e))?;
        robot
            .actuator
            .validate()
            .map_err(|e| named("actuator", e))?;
        Ok(robot)
    }
}

fn default_cruise() -> f64 {
    1.0
}
fn default_accel() -> f64 {
    2.0
}
fn default_hold() -> f64 {
    2.0
}
fn default_brake() -> f64 {
    1.4
}

/// `[command]`: the command profile.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum CommandSpec {
    /// The PIPTB protocol: ramp to `cruise_speed_m_per_s` in `accel_secs`, hold for
    /// `hold_secs`, brake along the braking reference in `brake_secs`, then rest.
    Piptb {
        /// Cruise speed (m/s). Default 1.
        #[serde(default = "default_cruise")]
        cruise_speed_m_per_s: f64,
        /// Ramp time (s). Default 2.
        #[serde(default = "default_accel")]
        #[schemars(extend("exclusiveMinimum" = 0))]
        accel_secs: f64,
        /// Hold time (s). Default 2.
        #[serde(default = "default_hold")]
        #[schemars(range(min = 0))]
        hold_secs: f64,
        /// Braking time (s). Default 1.4.
        #[serde(default = "default_brake")]
        #[schemars(extend("exclusiveMinimum" = 0))]
        brake_secs: f64,
    },
    /// A speed trapezoid: ramp to `speed_m_per_s` in `ramp_secs`, hold `hold_secs`, ramp
    /// back to 0 in `ramp_secs`, then rest. Upright tilt command throughout.
    Trapezoid {
        /// Peak speed (m/s).
        speed_m_per_s: f64,
        /// Each ramp's duration (s).
        #[schemars(extend("exclusiveMinimum" = 0))]
        ramp_secs: f64,
        /// Hold at the peak (s).
        #[schemars(range(min = 0))]
        hold_secs: f64,
    },
    /// Balance in place (all commands zero).
    Balance,
}

impl Default for CommandSpec {
    fn default() -> Self {
        Self::Piptb {
            cruise_speed_m_per_s: default_cruise(),
            accel_secs: default_accel(),
            hold_secs: default_hold(),
            brake_secs: default_brake(),
        }
    }
}

/// `[initial]`: the initial state (default at rest upright).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct InitialState {
    /// Tilt (rad).
    pub tilt_rad: f64,
    /// Tilt rate (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// Ball rate (rad/s).
    pub ball_rate_rad_per_s: f64,
}

fn default_duration() -> f64 {
    6.4
}

/// A complete planar scenario.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Noise seed. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// Simulated time (s). Default 6.4 (the PIPTB protocol plus one second at rest).
    #[serde(default = "default_duration")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub duration_secs: f64,
    /// The robot.
    #[serde(default)]
    pub robot: RobotSpec,
    /// Transmission friction. Default none.
    #[serde(default)]
    pub friction: TransmissionFriction,
    /// Sensors. Default ideal.
    #[serde(default)]
    pub sensors: SensorParams,
    /// Rates and delay.
    #[serde(default)]
    pub sim: SimConfig,
    /// The controller (required: `kind = "lqr" | "pi_pd" | "lqr_pi"`).
    pub controller: ControllerSettings,
    /// The command profile. Default the PIPTB protocol.
    #[serde(default)]
    pub command: CommandSpec,
    /// The initial state.
    #[serde(default)]
    pub initial: InitialState,
}

/// A scenario's command profile, built.
#[derive(Clone, Debug)]
pub enum BuiltCommand {
    /// The PIPTB protocol.
    Piptb(Box<PiptbProfile>),
    /// A speed trapezoid `(peak rate rad/s, ramp s, hold s)`.
    Trapezoid(f64, f64, f64),
    /// Zero.
    Balance,
}

impl CommandProfile for BuiltCommand {
    fn command(&self, t: f64) -> PlanarCommand {
        match self {
            Self::Piptb(p) => p.command(t),
            Self::Trapezoid(rate, ramp, hold) => {
                let scale = if t < *ramp {
                    t / ramp
                } else if t < ramp + hold {
                    1.0
                } else if t < 2.0 * ramp + hold {
                    (2.0 * ramp + hold - t) / ramp
                } else {
                    0.0
                };
                PlanarCommand {
                    ball_rate_rad_per_s: rate * scale,
                    ..PlanarCommand::default()
                }
            }
            Self::Balance => PlanarCommand::default(),
        }
    }
}

fn positive(value: f64, key: &str) -> Result<(), ScenarioError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ScenarioError::Invalid {
            key: key.to_owned(),
            requirement: "must be finite and > 0".to_owned(),
        })
    }
}

fn non_negative(value: f64, key: &str) -> Result<(), ScenarioError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ScenarioError::Invalid {
            key: key.to_owned(),
            requirement: "must be finite and >= 0".to_owned(),
        })
    }
}

impl Scenario {
    /// Parses and validates a scenario.
    pub fn from_toml_str(text: &str) -> Result<Self, ScenarioError> {
        let scenario: Self = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            path: None,
            message: e.to_string(),
        })?;
        scenario.validate()?;
        Ok(scenario)
    }

    /// Reads, parses and validates a scenario file.
    pub fn from_path(path: &Path) -> Result<Self, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::from_toml_str(&text).map_err(|e| match e {
            ScenarioError::Parse { message, .. } => ScenarioError::Parse {
                path: Some(path.to_owned()),
                message,
            },
            other => other,
        })
    }

    /// Checks every value; the error names the key.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        positive(self.duration_secs, "duration_secs")?;
        self.robot.params()?;
        self.friction.validate()?;
        self.sensors.validate()?;
        self.sim.dividers()?;
        match self.command {
            CommandSpec::Piptb {
                cruise_speed_m_per_s,
                accel_secs,
                hold_secs,
                brake_secs,
            } => {
                if !cruise_speed_m_per_s.is_finite() {
                    return Err(ScenarioError::Invalid {
                        key: "command.cruise_speed_m_per_s".to_owned(),
                        requirement: "must be finite".to_owned(),
                    });
                }
                positive(accel_secs, "command.accel_secs")?;
                non_negative(hold_secs, "command.hold_secs")?;
                positive(brake_secs, "command.brake_secs")?;
            }
            CommandSpec::Trapezoid {
                speed_m_per_s,
                ramp_secs,
                hold_secs,
            } => {
                if !speed_m_per_s.is_finite() {
                    return Err(ScenarioError::Invalid {
                        key: "command.speed_m_per_s".to_owned(),
                        requirement: "must be finite".to_owned(),
                    });
                }
                positive(ramp_secs, "command.ramp_secs")?;
                non_negative(hold_secs, "command.hold_secs")?;
            }
            CommandSpec::Balance => {}
        }
        for (v, key) in [
            (self.initial.tilt_rad, "initial.tilt_rad"),
            (
                self.initial.tilt_rate_rad_per_s,
                "initial.tilt_rate_rad_per_s",
            ),
            (
                self.initial.ball_rate_rad_per_s,
                "initial.ball_rate_rad_per_s",
            ),
        ] {
            if !v.is_finite() {
                return Err(ScenarioError::Invalid {
                    key: key.to_owned(),
                    requirement: "must be finite".to_owned(),
                });
            }
        }
        Ok(())
    }

    /// The simulator this scenario describes, reset to its initial state.
    pub fn simulator(&self) -> Result<PlanarSim, ScenarioError> {
        let mut sim = PlanarSim::new(
            self.robot.params()?,
            self.friction,
            self.sensors,
            self.sim,
            self.seed,
        )?;
        sim.reset(WipState::new(
            self.initial.tilt_rad,
            0.0,
            self.initial.tilt_rate_rad_per_s,
            self.initial.ball_rate_rad_per_s,
        ));
        Ok(sim)
    }

    /// The command profile.
    pub fn command_profile(&self) -> Result<BuiltCommand, ScenarioError> {
        let robot = self.robot.params()?;
        Ok(match self.command {
            CommandSpec::Piptb {
                cruise_speed_m_per_s,
                accel_secs,
                hold_secs,
                brake_secs,
            } => {
                let settings = PiptbSettings {
                    robot,
                    cruise_speed_m_per_s,
                    accel_secs,
                    hold_secs,
                    brake_secs,
                    ..PiptbSettings::paper()
                };
                let brake = braking_reference(&settings).map_err(|e| ScenarioError::Invalid {
                    key: "command".to_owned(),
                    requirement: e.to_string(),
                })?;
                BuiltCommand::Piptb(Box::new(PiptbProfile::new(&settings, brake)))
            }
            CommandSpec::Trapezoid {
                speed_m_per_s,
                ramp_secs,
                hold_secs,
            } => BuiltCommand::Trapezoid(
                speed_m_per_s / robot.plane.ball_radius_m,
                ramp_secs,
                hold_secs,
            ),
            CommandSpec::Balance => BuiltCommand::Balance,
        })
    }
}
