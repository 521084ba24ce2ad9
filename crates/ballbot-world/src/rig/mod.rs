//! The simulated robot: the shipped robot loop ([`ballbot_runtime::RobotLoop`], the code a robot
//! binary runs) driving the rapier3d world through the core's hardware traits
//! ([`ballbot_core::hal`]).
//!
//! * [`devices`]: the world's IMU, encoders, motor drivers and clock behind the `hal` traits.
//! * [`inject`]: fault injection between the world and the loop ([`Injector`]).
//! * [`world_robot`]: [`WorldRobot`], the world and the robot loop stepped together (outer task
//!   at 400 Hz on a fresh sensor sample, inner task at every 8 kHz physics step).
//!
//! Every closed-loop experiment on the world (the studies, the `ballbot world` command, the
//! Python `WorldLoop`, the benchmarks) runs through [`WorldRobot`], so the loop that the
//! experiments test is the loop that ships.
//!
//! Layer: imports the physics (`world`), the core and the runtime; nothing above it.

pub mod devices;
pub mod events;
pub mod inject;
pub mod outcome;
pub mod world_robot;

pub use devices::{WorldClock, WorldEncoders, WorldImu, WorldMotors};
pub use events::{Event, EventKind, EventLog};
pub use inject::{Injector, NoFaults, Tick};
pub use outcome::{Happened, Outcome, OutcomeTracker};
pub use world_robot::WorldRobot;
