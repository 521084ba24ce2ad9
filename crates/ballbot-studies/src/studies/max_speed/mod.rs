//! The paper's maximum-speed benchmark (Sec. V) as a study in the 3D world: seeded slow-ramp
//! trials per heading, the failing ramp acceleration per heading (bisection), a capability
//! map over headings, and the sensitivity to the roller-ball friction `mu` and the COM height
//! `l`.
//!
//! Two metrics, because the world separates what the paper's protocol mixes:
//!
//! * **Maximum speed** (the paper's protocol as we read it): a slow velocity ramp at
//!   [`MaxSpeedProtocol::slow_ramp`] (0.25 m/s^2 to 6 m/s, then 1 s hold) until failure;
//!   the highest ball speed along the heading before the failure. A run that reaches the end
//!   of the ramp without failing is *censored*: its maximum speed is only a lower bound
//!   (`>= X m/s`), never a failure speed.
//! * **Failing acceleration**: the largest constant ramp acceleration (on a grid of
//!   [`MaxSpeedProtocol::accel_resolution_m_per_s2`]) with which a ramp to
//!   [`MaxSpeedProtocol::fast_top_m_per_s`] and a 1 s hold survives. Traction demand in this
//!   world comes from acceleration, so this is where the paper's direction dependence shows.
//!
//! The command shaper of the core caps speed and acceleration by default (2 m/s, 1 m/s^2); the
//! study lifts those caps with [`ShaperLimits`] (documented defaults) and keeps the core's jerk
//! limit (2 m/s^3). Trials differ only by the seed of the sensor noise
//! ([`ballbot_world::world::SensorParams::seed`]); the simulation is otherwise deterministic, so a trial
//! is reproducible bit for bit from its seed. Jobs run in parallel on the shared runner
//! ([`ballbot_world::runner`]); results do not depend on the number of threads.

//!
//! * [`protocol`]: the ramps, the search's bracket and grid, the shaper limits, the settings.
//! * [`trial`]: one seeded slow-ramp trial and its outcome.
//! * [`bisection`]: the failing-acceleration search's result.
//! * [`experiment`]: the study as a type on the experiment driver ([`MaxSpeedExperiment`]):
//!   slow ramps, and the failing-acceleration search as a grid bisection.
//! * [`study`]: the whole study, assembled from the driver's records.
//!
//! JSON, tables and figures of a study are in [`crate::report::max_speed`].

pub mod bisection;
pub mod experiment;
mod jobs;
pub mod protocol;
pub mod study;
pub mod trial;
pub mod variant;

pub use bisection::FailingAccel;
pub use experiment::{MaxSpeedExperiment, RampTrial, failing_acceleration, runs_estimate};
pub use jobs::{MaxSpeedJob, job_count};
pub use protocol::{
    MaxSpeedProtocol, MaxSpeedStudySettings, PAPER_MAX_SPEED, PaperMaxSpeed, ShaperLimits,
};
pub use study::{MapPoint, MaxSpeedStudy, SensitivityRow, run_study};
pub use trial::{
    HeadingTrials, TrialOutcome, controller, quasi_static_failing_accel_m_per_s2, slow_ramp_trial,
    slow_ramp_trial_observed, slow_ramp_trial_with_config,
};
pub use variant::Variant;
