//! Parameter files as data: the three kinds of TOML file the project reads ([`FileKind`]),
//! their JSON Schemas generated from the Rust types ([`schema_json`]), checking a file against
//! the types and their `validate()` with errors that name the dotted key ([`ParamsFile::check`]),
//! the presets as commented files ([`commented_toml`]) and the keys two files differ in
//! ([`diff`]). `ballbot params` is this module on the command line; `docs/params.md` explains
//! the files and the editor setup.
//!
//! ```
//! use ballbot_studies::params_file::{FileKind, ParamsFile};
//! let text = "[controller]\nkind = \"lqr\"\n[friction]\ncoulomb_torque_nm = -1.0";
//! assert_eq!(FileKind::infer(text)?, FileKind::Scenario);
//! let err = ParamsFile::check(text, FileKind::Scenario).unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "`friction.coulomb_torque_nm` must be finite and >= 0"
//! );
//! # Ok::<(), ballbot_studies::params_file::ParamsFileError>(())
//! ```
//!
//! Layer: reads the parameter types of the core, the world and the planar scenario; only the
//! command line imports it.

mod check;
mod diff;
mod error;
mod kind;
mod preset;
mod schema;
mod show;

pub use check::ParamsFile;
pub use diff::{KeyDiff, diff};
pub use error::ParamsFileError;
pub use kind::FileKind;
pub use preset::{PRESETS, Preset, preset};
pub use schema::{schema_json, schema_text};
pub use show::commented_toml;
