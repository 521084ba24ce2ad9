//! Reports of the studies: the summary's JSON, plain-text comparison tables, and figures
//! (`report::plot`, behind the cargo feature `plot`, which pulls in plotters).
//!
//! Layer rule: reports import [`crate::studies`] (and the physics types the studies return);
//! the studies and the physics never import reports.
//!
//! - [`reproduce`](mod@reproduce): `ballbot reproduce` as a library call: every study, its table, figures,
//!   logs and `summary.json`.
//! - [`piptb`], [`brake`], [`max_speed`], [`mechanisms`], [`world_suite`], [`traction`],
//!   [`crossing`], [`controllers_3d`]: one study's JSON and tables each;
//!   the `*_figures` modules draw its figures.
//! - [`robustness`](mod@robustness): `ballbot robustness` as a library call: the reliability
//!   campaign (fuzzing, fault-injection matrix, Monte Carlo) and `robustness.json`.

pub mod brake;
pub mod controllers_3d;
pub mod crossing;
mod error;
pub mod max_speed;
#[cfg(feature = "plot")]
pub mod max_speed_figures;
pub mod mechanisms;
#[cfg(feature = "plot")]
pub mod mechanisms_figures;
pub mod piptb;
#[cfg(feature = "plot")]
pub mod piptb_figures;
#[cfg(feature = "plot")]
pub mod plot;
pub mod reproduce;
pub mod robustness;
#[cfg(feature = "plot")]
pub mod robustness_figures;
pub mod traction;
#[cfg(feature = "plot")]
pub mod traction_figures;
pub mod world_suite;
#[cfg(feature = "plot")]
pub mod world_suite_figures;

pub use error::ReportError;
pub use reproduce::{ReproduceObserver, ReproduceOptions, reproduce};
pub use robustness::{RobustnessOptions, robustness};
