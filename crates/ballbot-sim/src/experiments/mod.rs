//! The paper's experiments, reproduced in simulation.
//!
//! - [`piptb`]: the PIPTB controller comparison (paper Sec. IV-C): LQR, cascaded PI-PD and
//!   cascaded LQR-PI braking from 1 m/s to rest in 1.4 s on a testbed with transmission
//!   stiction.
//! - [`braking`]: the braking reference those controllers track.

pub mod braking;
pub mod piptb;

pub use braking::{BrakingSource, BrakingTrajectory};
pub use piptb::{ExperimentError, PiptbReport, PiptbSettings};
