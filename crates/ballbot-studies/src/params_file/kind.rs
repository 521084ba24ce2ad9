//! [`FileKind`]: which parameter file a text is, named or inferred from its keys.

use super::ParamsFileError;
use std::fmt;
use std::str::FromStr;

/// The kinds of parameter file, each one Rust type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FileKind {
    /// A robot: [`ballbot_core::BallbotParams`] (`examples/params/miapure_60kg.toml`).
    Robot,
    /// A planar scenario for `ballbot simulate`: [`crate::studies::scenario::Scenario`] (`scenarios/`).
    Scenario,
    /// The 3D world with its robot: [`ballbot_world::world::WorldParams`] (`params = "world.toml"` of
    /// a sweep).
    World,
    /// The 3D robot's controller: [`ballbot_core::ballbot::BallbotControllerConfig`]
    /// (`--controller FILE` of the commands that run it).
    Controller,
}

impl FileKind {
    /// Every kind.
    pub const ALL: [Self; 4] = [Self::Robot, Self::Scenario, Self::World, Self::Controller];

    /// The canonical name: `robot`, `scenario`, `world`, `controller`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Robot => "robot",
            Self::Scenario => "scenario",
            Self::World => "world",
            Self::Controller => "controller",
        }
    }

    /// The Rust type a file of this kind is.
    pub const fn type_name(self) -> &'static str {
        match self {
            Self::Robot => "BallbotParams",
            Self::Scenario => "Scenario",
            Self::World => "WorldParams",
            Self::Controller => "BallbotControllerConfig",
        }
    }

    /// The file name of this kind's JSON Schema in `schemas/`.
    pub const fn schema_file_name(self) -> &'static str {
        match self {
            Self::Robot => "ballbot-params.schema.json",
            Self::Scenario => "scenario.schema.json",
            Self::World => "world-params.schema.json",
            Self::Controller => "controller.schema.json",
        }
    }

    /// The kind of a file's text: the schema its `#:schema` line names (a path ending in one
    /// of [`Self::schema_file_name`]) if it has one among its leading comments, else its
    /// top-level keys: `shaping` or `traction` makes a controller; `controller` a scenario;
    /// `contact`, or a `robot` table with a `sagittal` key, a world; `sagittal`, `frontal`,
    /// `spin` or `drivetrain` a robot.
    ///
    /// ```
    /// use ballbot_studies::params_file::FileKind;
    /// assert_eq!(FileKind::infer("[sagittal]\nball_mass_kg = 3.6")?, FileKind::Robot);
    /// assert_eq!(FileKind::infer("[traction]\nenabled = true")?, FileKind::Controller);
    /// assert_eq!(FileKind::infer("[robot.sagittal]\nball_mass_kg = 3.6")?, FileKind::World);
    /// let directive = "#:schema ../schemas/world-params.schema.json\n";
    /// assert_eq!(FileKind::infer(directive)?, FileKind::World);
    /// assert!(FileKind::infer("seed = 1").is_err());
    /// # Ok::<(), ballbot_studies::params_file::ParamsFileError>(())
    /// ```
    pub fn infer(text: &str) -> Result<Self, ParamsFileError> {
        if let Some(kind) = Self::from_schema_directive(text) {
            return Ok(kind);
        }
        let table: toml::Table =
            text.parse()
                .map_err(|e: toml::de::Error| ParamsFileError::Toml {
                    message: e.to_string(),
                })?;
        let has = |key: &str| table.contains_key(key);
        let robot_has_planes = table
            .get("robot")
            .and_then(toml::Value::as_table)
            .is_some_and(|robot| robot.contains_key("sagittal"));
        if has("shaping") || has("traction") {
            Ok(Self::Controller)
        } else if has("controller") {
            Ok(Self::Scenario)
        } else if has("contact") || robot_has_planes {
            Ok(Self::World)
        } else if ["sagittal", "frontal", "spin", "drivetrain"]
            .into_iter()
            .any(has)
        {
            Ok(Self::Robot)
        } else {
            Err(ParamsFileError::UnknownKind)
        }
    }

    /// The kind whose schema a `#:schema PATH` line among the leading comments names.
    fn from_schema_directive(text: &str) -> Option<Self> {
        text.lines()
            .map(str::trim)
            .take_while(|line| line.is_empty() || line.starts_with('#'))
            .filter_map(|line| line.strip_prefix("#:schema"))
            .find_map(|path| {
                let path = path.trim().trim_matches('"');
                Self::ALL
                    .into_iter()
                    .find(|kind| path.ends_with(kind.schema_file_name()))
            })
    }
}

impl fmt::Display for FileKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for FileKind {
    type Err = ParamsFileError;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|kind| kind.as_str() == name)
            .ok_or_else(|| ParamsFileError::KindName(name.to_owned()))
    }
}
