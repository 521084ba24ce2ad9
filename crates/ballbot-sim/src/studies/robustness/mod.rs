//! The reliability campaign (issue 15, `ballbot robustness`): what the controller survives.
//!
//! - fuzzing the core and the parsers: seeded hostile inputs, invariants checked on every step;
//! - a fault-injection matrix in the 3D world: each fault while standing, cruising and braking;
//! - Monte Carlo robustness: pushes on robots that differ from the controller's model.
