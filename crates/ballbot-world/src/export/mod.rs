//! The world's robot in other simulators' formats: MJCF (MuJoCo) and URDF (Drake, Isaac, ROS
//! tools), written from the same [`WorldParams`] the 3D world runs on.
//!
//! Both writers take one [`RobotModel`]: the ball, and the world's body split into a chassis,
//! three motor-driven omniwheel hubs and their passive rollers, such that chassis, hubs and
//! rollers together have exactly the world body's mass, centre of mass and inertia
//! ([`model`] documents the split, the frames and the estimates it needs). The files are
//! plain XML strings; nothing is written to disk here.
//!
//! What each format carries:
//!
//! * **MJCF**: a floor; the ball and the body on free joints (the body rests on the ball
//!   through the rollers only); the hubs on hinge joints with the rotor's reflected inertia
//!   as armature and the world's wheel damping; rollers on hinge joints along the rim's
//!   tangent, as barrels (an inline convex mesh) whose profile lies on the rim circle; one
//!   `motor` per wheel with the gear ratio (its control is the rotor torque, limited to the
//!   peak wheel torque over the gear ratio); elliptic friction cones with the world's
//!   coefficients (roller-ball, ball-floor, and the ball-floor torsional and rolling friction
//!   with `condim` 6); contact time constants from the world's ball contact frequency
//!   ([`RobotModel::roller_contact_timeconst_secs`]); gravity and the world's rigid step as the
//!   time step. The contact law itself (MuJoCo's soft contacts, not the world's
//!   spring-damper with its stick-slip bristle) and the motor's torque-speed line do not map
//!   onto MJCF.
//! * **URDF**: the body as the root link (the chassis), the hubs on `continuous` joints with
//!   the peak torque and no-load speed as limits and the wheel damping, the rollers on
//!   `continuous` joints, the ball on a `floating` joint, a transmission per wheel with the
//!   gear ratio. URDF has no armature (the reflected rotor inertia is written as a comment),
//!   no capsule or inline mesh (the rollers collide as cylinders of their mid radius) and no
//!   friction.
//!
//! ```
//! use ballbot_world::export::{ExportFormat, export};
//! use ballbot_world::world::WorldParams;
//! let mjcf = export(&WorldParams::miapure_60kg(), ExportFormat::Mjcf)?;
//! assert!(mjcf.starts_with("<mujoco model=\"ballbot\">"));
//! let urdf = export(&WorldParams::miapure_60kg(), ExportFormat::Urdf)?;
//! assert!(urdf.contains("<joint name=\"ow1\" type=\"continuous\">"));
//! # Ok::<(), ballbot_world::export::ExportError>(())
//! ```

mod mjcf;
pub mod model;
mod urdf;
mod xml;

pub use model::{Inertial, Pose, RobotModel};

use crate::world::{WorldError, WorldParams};
use std::fmt;
use std::str::FromStr;

/// The formats [`export`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ExportFormat {
    /// MuJoCo's MJCF.
    Mjcf,
    /// The Unified Robot Description Format.
    Urdf,
}

impl ExportFormat {
    /// Every format.
    pub const ALL: [Self; 2] = [Self::Mjcf, Self::Urdf];

    /// The canonical name: `mjcf`, `urdf`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mjcf => "mjcf",
            Self::Urdf => "urdf",
        }
    }

    /// The usual file extension: `xml` for MJCF, `urdf`.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Mjcf => "xml",
            Self::Urdf => "urdf",
        }
    }
}

impl fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ExportFormat {
    type Err = ExportError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|f| f.as_str() == s)
            .ok_or_else(|| ExportError::UnknownFormat(s.to_owned()))
    }
}

/// What can go wrong exporting the robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The world rejects its parameters.
    #[error(transparent)]
    World(#[from] WorldError),
    /// The body cannot be split into a chassis and the omniwheels ([`model`]).
    #[error("cannot export `{field}`: {requirement}")]
    Split {
        /// The (dotted) world parameter at fault.
        field: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// Not `mjcf` or `urdf`.
    #[error("unknown export format `{0}` (expected mjcf or urdf)")]
    UnknownFormat(String),
}

/// The robot of the world `params` in `format`, as an XML document.
///
/// Errors: [`ExportError::World`] for parameters the world rejects, [`ExportError::Split`]
/// for a body lighter than its wheels ([`RobotModel::new`]).
pub fn export(params: &WorldParams, format: ExportFormat) -> Result<String, ExportError> {
    let model = RobotModel::new(params)?;
    Ok(match format {
        ExportFormat::Mjcf => mjcf::write(&model),
        ExportFormat::Urdf => urdf::write(&model),
    })
}
