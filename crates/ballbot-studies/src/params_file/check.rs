//! [`ParamsFile`]: a parameter file read into its Rust type and checked by its `validate()`,
//! every error naming the dotted key.

use super::{FileKind, ParamsFileError};
use crate::studies::scenario::{Scenario, ScenarioError};
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::{BalancingLaw, BallbotController, BallbotControllerConfig};
use ballbot_world::world::{WorldError, WorldParams};
use serde::de::DeserializeOwned;

/// A parameter file of one of the [`FileKind`]s, read into its type.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamsFile {
    /// A robot.
    Robot(Box<BallbotParams<f64>>),
    /// A planar scenario.
    Scenario(Box<Scenario>),
    /// The 3D world and its robot.
    World(Box<WorldParams>),
    /// The 3D robot's controller.
    Controller(Box<BallbotControllerConfig<f64>>),
}

impl ParamsFile {
    /// The file's kind.
    pub fn kind(&self) -> FileKind {
        match self {
            Self::Robot(_) => FileKind::Robot,
            Self::Scenario(_) => FileKind::Scenario,
            Self::World(_) => FileKind::World,
            Self::Controller(_) => FileKind::Controller,
        }
    }

    /// Reads `text` as a file of `kind`: unknown keys, missing keys and values of the wrong
    /// type are errors naming the key; values are not range-checked ([`Self::validate`]).
    pub fn parse(text: &str, kind: FileKind) -> Result<Self, ParamsFileError> {
        Ok(match kind {
            FileKind::Robot => Self::Robot(Box::new(parse_typed(text)?)),
            FileKind::Scenario => Self::Scenario(Box::new(parse_typed(text)?)),
            FileKind::World => Self::World(Box::new(parse_typed(text)?)),
            FileKind::Controller => Self::Controller(Box::new(parse_typed(text)?)),
        })
    }

    /// [`Self::parse`], then [`Self::validate`].
    pub fn check(text: &str, kind: FileKind) -> Result<Self, ParamsFileError> {
        let file = Self::parse(text, kind)?;
        file.validate()?;
        Ok(file)
    }

    /// Checks every value with the type's own `validate()`; the error names the dotted key
    /// of the first value out of range and the bound it violates.
    pub fn validate(&self) -> Result<(), ParamsFileError> {
        match self {
            Self::Robot(robot) => validate_robot(robot, ""),
            Self::Scenario(scenario) => scenario.validate().map_err(|e| match e {
                ScenarioError::Invalid { key, requirement } => {
                    ParamsFileError::Invalid { key, requirement }
                }
                other => ParamsFileError::Invalid {
                    key: String::new(),
                    requirement: other.to_string(),
                },
            }),
            Self::World(world) => {
                // The robot first, so that its errors carry the whole path; every error
                // left is then one of the world's own (already dotted) fields.
                validate_robot(&world.robot, "robot.")?;
                world.validate().map_err(|e| match e {
                    WorldError::InvalidParameter { field, requirement } => {
                        invalid(field, requirement)
                    }
                    other => ParamsFileError::Invalid {
                        key: "robot".to_owned(),
                        requirement: other.to_string(),
                    },
                })
            }
            Self::Controller(config) => validate_controller(config),
        }
    }

    /// The file as TOML, every field written (the serializer's key order: the types' field
    /// order).
    pub fn to_toml(&self) -> Result<String, ParamsFileError> {
        let text = match self {
            Self::Robot(robot) => toml::to_string(robot.as_ref()),
            Self::Scenario(scenario) => toml::to_string(scenario.as_ref()),
            Self::World(world) => toml::to_string(world.as_ref()),
            Self::Controller(config) => toml::to_string(config.as_ref()),
        };
        text.map_err(|e| ParamsFileError::Write(e.to_string()))
    }
}

fn invalid(key: &str, requirement: &str) -> ParamsFileError {
    ParamsFileError::Invalid {
        key: key.to_owned(),
        requirement: requirement.to_owned(),
    }
}

/// Deserializes `text` into `T`, naming the key path of the first error.
fn parse_typed<T: DeserializeOwned>(text: &str) -> Result<T, ParamsFileError> {
    let de = toml::Deserializer::parse(text).map_err(|e| ParamsFileError::Toml {
        message: e.to_string(),
    })?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let mut key = e
            .path()
            .iter()
            .map(|segment| match segment {
                serde_path_to_error::Segment::Seq { index } => format!("[{index}]"),
                serde_path_to_error::Segment::Map { key } => key.clone(),
                serde_path_to_error::Segment::Enum { variant } => variant.clone(),
                serde_path_to_error::Segment::Unknown => "?".to_owned(),
            })
            .collect::<Vec<_>>()
            .join(".")
            .replace(".[", "[");
        let inner = e.inner();
        let message = inner.message().trim().to_owned();
        // A missing or unknown key is named by the message, not always by the path.
        for prefix in ["missing field `", "unknown field `"] {
            if let Some(name) = message
                .strip_prefix(prefix)
                .and_then(|rest| rest.split('`').next())
                && !key.ends_with(name)
            {
                key = if key.is_empty() {
                    name.to_owned()
                } else {
                    format!("{key}.{name}")
                };
            }
        }
        ParamsFileError::Key {
            key,
            message,
            line: inner.span().map(|span| line_column(text, span.start)),
        }
    })
}

/// The 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before
        .rsplit('\n')
        .next()
        .map_or(1, |last| last.chars().count() + 1);
    (line, column)
}

/// The robot's own `validate()`, part by part, so that every error names the whole key
/// (`prefix` + `sagittal.ball_mass_kg`; the core's errors name the field alone).
fn validate_robot(robot: &BallbotParams<f64>, prefix: &str) -> Result<(), ParamsFileError> {
    let at = |part: &str, e: ballbot_core::Error| named(&format!("{prefix}{part}"), e);
    robot.sagittal.validate().map_err(|e| at("sagittal.", e))?;
    robot.frontal.validate().map_err(|e| at("frontal.", e))?;
    robot.spin.validate().map_err(|e| at("spin.", e))?;
    robot
        .drivetrain
        .actuator
        .validate()
        .map_err(|e| at("drivetrain.actuator.", e))?;
    robot
        .drivetrain
        .validate()
        .map_err(|e| at("drivetrain.", e))?;
    // What is left is across parts (one ball for both planes); its field is already whole.
    robot.validate().map_err(|e| at("", e))
}

/// A core error as a file error whose key is `prefix` + the field the core names.
fn named(prefix: &str, e: ballbot_core::Error) -> ParamsFileError {
    match e {
        ballbot_core::Error::InvalidParameter { field, requirement } => ParamsFileError::Invalid {
            key: format!("{prefix}{field}"),
            requirement: requirement.to_owned(),
        },
        other => ParamsFileError::Invalid {
            key: prefix.trim_end_matches('.').to_owned(),
            requirement: other.to_string(),
        },
    }
}

/// The controller configuration part by part (each part's own `validate()`, the error named
/// by its whole key), then what only the whole controller can check
/// ([`BallbotController::new`]: the parts against the robot).
fn validate_controller(c: &BallbotControllerConfig<f64>) -> Result<(), ParamsFileError> {
    validate_robot(&c.robot, "robot.")?;
    for (plane, outer) in [("frontal.", &c.frontal), ("sagittal.", &c.sagittal)] {
        outer
            .lqr
            .validate()
            .map_err(|e| named(&format!("{plane}lqr."), e))?;
        outer.validate().map_err(|e| named(plane, e))?;
    }
    c.spin.validate().map_err(|e| match e {
        ballbot_core::Error::InvalidParameter { field, .. }
            if field != "max_rate_error_rad_per_s" =>
        {
            named("spin.gains.", e)
        }
        _ => named("spin.", e),
    })?;
    c.motor.validate().map_err(|e| named("motor.", e))?;
    let shaping = &c.shaping;
    shaping
        .translation
        .validate()
        .map_err(|e| named("shaping.translation.", e))?;
    shaping
        .yaw
        .validate()
        .map_err(|e| named("shaping.yaw.", e))?;
    shaping
        .lean_to_drive
        .validate()
        .map_err(|e| named("shaping.lean_to_drive.", e))?;
    shaping.validate().map_err(|e| named("shaping.", e))?;
    c.safety.validate().map_err(|e| named("safety.", e))?;
    if !(c.outer_dt_secs.is_finite() && c.outer_dt_secs > 0.0) {
        return Err(invalid("outer_dt_secs", "must be finite and > 0"));
    }
    c.traction.validate().map_err(|e| named("traction.", e))?;
    // These two name their fields with the part already (`balance_point.max_offset_rad`).
    c.balance_point.validate().map_err(|e| named("", e))?;
    c.imu_lean.validate().map_err(|e| named("", e))?;
    if let BalancingLaw::PiPd { frontal, sagittal } = &c.balancing {
        frontal
            .validate()
            .map_err(|e| named("balancing.pi_pd.frontal.", e))?;
        sagittal
            .validate()
            .map_err(|e| named("balancing.pi_pd.sagittal.", e))?;
    }
    BallbotController::new(*c)
        .map(|_| ())
        .map_err(|e| named("", e))
}
