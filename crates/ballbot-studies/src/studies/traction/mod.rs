//! Traction-aware control in the 3D world: MiaPURE with 60 kg, the default world,
//! the designed controller with its shaper caps lifted, traction-aware control on and off.
//!
//! - **Failing acceleration per heading**: off, the failing-acceleration search
//!   ([`crate::studies::max_speed::failing_acceleration`]); on, the same protocol's ramp at
//!   the search's top request and at the acceleration that failed off.
//! - **Stop from 1.4 m/s** at 0, 90, 180 deg: on, off, and the shipped controller.
//! - **A friction patch** 0.5 m long crossed at 1.4 m/s towards OW1: the floor at mu 0.3
//!   (cruising), and a wet patch that also takes the wheel-ball friction to 0.3 (crossed while
//!   accelerating): detection latency, and whether the robot stays up.
//! - **A rider** leaning back (towards OW1, 0 deg) as hard as forward (180 deg).
//!
//! * [`probe`]: what a run measures; [`runs`]: the runs; [`settings`]: what the study runs;
//!   [`experiment`]: the study as a type on the experiment driver ([`TractionExperiment`]);
//!   [`study`]: the whole study, assembled from the driver's records. JSON, tables and
//!   figures: [`crate::report::traction`].

pub mod experiment;
pub mod probe;
pub mod runs;
pub mod settings;
pub mod study;

pub use experiment::{
    TractionExperiment, TractionJob, TractionRun, TractionTrial, runs_estimate, search_result,
    single_run,
};
pub use probe::{Probe, RunRecord, TractionSample};
pub use runs::{Control, FrictionPatch, PatchCrossing, SAMPLE_PERIOD_SECS};
pub use settings::{PatchVariant, TractionStudySettings};
pub use study::{
    HeadingResult, PatchResult, RiderResult, StopResult, TractionStudy, job_count, run_study,
};
