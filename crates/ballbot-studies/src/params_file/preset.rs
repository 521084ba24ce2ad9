//! The presets that `ballbot params show` writes: the robots, worlds, scenario and controllers
//! the code constructs by name.

use super::{FileKind, ParamsFile, ParamsFileError};
use crate::studies::scenario::{CommandSpec, InitialState, RobotSpec, Scenario};
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_world::planar::{
    ControllerKind, ControllerSettings, SensorParams, SimConfig, TransmissionFriction,
};
use ballbot_world::world::WorldParams;

/// A named preset of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset {
    /// The kind of file it is.
    pub kind: FileKind,
    /// Its name (`miapure_60kg`).
    pub name: &'static str,
    /// Where it comes from, one line.
    pub about: &'static str,
}

/// Every preset, in the order `--kind`-less look-ups try them (a robot before the world of the
/// same name). `miapure` is short for `miapure_60kg`.
pub const PRESETS: [Preset; 8] = [
    Preset {
        kind: FileKind::Robot,
        name: "miapure_60kg",
        about: "MiaPURE carrying 60 kg (BallbotParams::miapure_60kg)",
    },
    Preset {
        kind: FileKind::Robot,
        name: "miapure_unloaded",
        about: "MiaPURE without payload (BallbotParams::miapure_unloaded)",
    },
    Preset {
        kind: FileKind::Scenario,
        name: "piptb",
        about: "the PIPTB braking trial with LQR-PI, its friction and sensors \
                (scenarios/piptb_lqr_pi.toml)",
    },
    Preset {
        kind: FileKind::World,
        name: "miapure_60kg",
        about: "MiaPURE carrying 60 kg in the default (realistic) world (WorldParams::miapure_60kg)",
    },
    Preset {
        kind: FileKind::World,
        name: "miapure_unloaded",
        about: "MiaPURE without payload in the default (realistic) world",
    },
    Preset {
        kind: FileKind::World,
        name: "ideal",
        about: "MiaPURE carrying 60 kg in the ideal world (WorldParams::ideal)",
    },
    Preset {
        kind: FileKind::Controller,
        name: "design",
        about: "the shipped controller of MiaPURE carrying 60 kg, traction-aware \
                (BallbotControllerConfig::design)",
    },
    Preset {
        kind: FileKind::Controller,
        name: "paper",
        about: "the paper's LQR-PI for MiaPURE carrying 60 kg (BallbotControllerConfig::paper)",
    },
];

/// The preset `name` (`miapure` for `miapure_60kg`) of `kind`, or of the first kind that has
/// one of that name.
///
/// ```
/// use ballbot_studies::params_file::{FileKind, preset};
/// let (found, file) = preset("miapure", None)?;
/// assert_eq!((found.kind, found.name), (FileKind::Robot, "miapure_60kg"));
/// file.validate()?;
/// assert!(preset("piptb", Some(FileKind::World)).is_err());
/// # Ok::<(), ballbot_studies::params_file::ParamsFileError>(())
/// ```
pub fn preset(name: &str, kind: Option<FileKind>) -> Result<(Preset, ParamsFile), ParamsFileError> {
    let name = if name == "miapure" {
        "miapure_60kg"
    } else {
        name
    };
    let found = PRESETS
        .into_iter()
        .find(|p| p.name == name && kind.is_none_or(|k| k == p.kind))
        .ok_or_else(|| ParamsFileError::UnknownPreset {
            name: name.to_owned(),
            kind: kind.map(FileKind::as_str),
            known: PRESETS
                .iter()
                .map(|p| format!("{}/{}", p.kind, p.name))
                .collect::<Vec<_>>()
                .join(", "),
        })?;
    let file = match (found.kind, found.name) {
        (FileKind::Robot, "miapure_unloaded") => {
            ParamsFile::Robot(Box::new(BallbotParams::miapure_unloaded()))
        }
        (FileKind::Robot, _) => ParamsFile::Robot(Box::new(BallbotParams::miapure_60kg())),
        (FileKind::Scenario, _) => ParamsFile::Scenario(Box::new(piptb_scenario())),
        (FileKind::World, "miapure_unloaded") => ParamsFile::World(Box::new(
            WorldParams::with_robot(BallbotParams::miapure_unloaded()),
        )),
        (FileKind::World, "ideal") => {
            ParamsFile::World(Box::new(WorldParams::ideal(BallbotParams::miapure_60kg())))
        }
        (FileKind::World, _) => ParamsFile::World(Box::new(WorldParams::miapure_60kg())),
        (FileKind::Controller, name) => {
            let robot = BallbotParams::miapure_60kg();
            let designed = if name == "paper" {
                BallbotControllerConfig::paper(&robot)
            } else {
                BallbotControllerConfig::design(&robot)
            };
            let config = designed.map_err(|e| ParamsFileError::Invalid {
                key: String::new(),
                requirement: e.to_string(),
            })?;
            ParamsFile::Controller(Box::new(config))
        }
    };
    Ok((found, file))
}

/// The PIPTB braking trial of the paper (Sec. IV-C) with the cascaded LQR-PI: the testbed's
/// friction and sensors, the paper's rates, seed 1 (`scenarios/piptb_lqr_pi.toml`).
fn piptb_scenario() -> Scenario {
    Scenario {
        seed: 1,
        duration_secs: 6.4,
        robot: RobotSpec::default(),
        friction: TransmissionFriction::piptb(),
        sensors: SensorParams::piptb(),
        sim: SimConfig::default(),
        controller: ControllerSettings::new(ControllerKind::LqrPi),
        command: CommandSpec::default(),
        initial: InitialState::default(),
    }
}
