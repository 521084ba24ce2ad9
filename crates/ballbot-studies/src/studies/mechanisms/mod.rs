//! What limited MiaPURE on the paper's slow ramps: the mechanism study.
//!
//! The paper's robot failed below 0.6 m/s towards OW1 (0 deg) and at 2.3 m/s away from it
//! (180 deg) on slow velocity ramps. The study runs the maximum-speed protocol
//! ([`crate::studies::max_speed::MaxSpeedProtocol`]'s slow ramp) at 0, 90 and 180 deg in the
//! ideal world, with each realistic mechanism of the world added one at a time, and with all
//! of them (the default world), for the shipped controller and for the paper's
//! ([`ControllerVariant`]); then a ramp-acceleration sweep of the default world (failure speed
//! against `a / (mu g)`), and the spectrum of the contact-load ripple against speed.
//!
//! * [`variant`]: the world and controller variants.
//! * [`ripple`]: one cruise's normal-force spectra.
//! * [`study`]: the whole study on the experiment driver ([`MechanismExperiment`]).
//!
//! JSON, tables and figures are in [`crate::report::mechanisms`].

pub mod ripple;
pub mod study;
pub mod variant;

pub use ripple::{
    Cruise, RippleProtocol, RippleSpectrum, WheelRipple, cruise_spectrum, cruise_spectrum_observed,
};
pub use study::{
    MechanismExperiment, MechanismJob, MechanismRun, MechanismStudy, MechanismStudySettings,
    MechanismTrial, SweepPoint, job_count, run_study,
};
pub use variant::{ControllerVariant, Mechanism};
