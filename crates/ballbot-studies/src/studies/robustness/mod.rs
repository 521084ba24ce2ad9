//! The reliability campaign (`ballbot robustness`): what the controller survives.
//!
//! - fuzzing the core and the parsers: seeded hostile inputs, invariants checked on every step;
//! - a fault-injection matrix in the 3D world: each fault while standing, cruising and braking;
//! - Monte Carlo robustness: pushes on robots that differ from the controller's model.

pub mod fault_run;
pub mod faults;
pub mod injector;

pub use fault_run::{
    Cell, CellError, CellLog, CellProtocol, CellResult, ControllerVariant, run_cell,
    run_cell_observed,
};
pub use faults::{Condition, FaultClass, FaultMagnitudes, SafeState};
pub use injector::FaultInjector;
pub mod fault_matrix;
pub use fault_matrix::{
    FaultMatrix, FaultMatrixSettings, FaultMatrixStudy, FaultMatrixSummary, run_fault_matrix,
};
pub mod mismatch;
pub mod monte_carlo;
pub use mismatch::{Mismatch, SensorBias};
pub use monte_carlo::{
    LimitQuantiles, MonteCarlo, MonteCarloCount, MonteCarloRun, MonteCarloSettings,
    MonteCarloStudy, Throughput, run_monte_carlo, run_one, run_one_observed, run_seed,
    wilson_interval_95,
};
pub mod fuzz;
pub use fuzz::{FuzzResult, FuzzSettings, run_fuzz};
