//! The paper's experiments, planar and 3D, as studies: protocols, seeded trials, searches and
//! their results (plain data; [`crate::report`] turns them into JSON, tables and figures).
//!
//! Layer rule: studies import the physics ([`ballbot_world::world`], [`ballbot_world::planar`]), the robot
//! loop, [`ballbot_trajopt`] and [`ballbot_log`]; never [`crate::report`] or the command line.
//!
//! - [`runner`]: the one job runner: independent jobs on every core, results in job order.
//! - [`driver`]: the one experiment driver: a study is a type ([`driver::Study`]: jobs, a
//!   trial or a bisection per job, what passes), run on the runner with progress and replay.
//! - [`crossing`]: the highest floor bump and step crossed per speed and heading (a
//!   [`driver::Study`]).
//! - [`controllers_3d`]: the paper's LQR, PI-PD and LQR-PI compared in the 3D world (a
//!   [`driver::Study`]).
//! - [`piptb`]: the PIPTB controller comparison (paper Sec. IV-C) and [`planar_braking`], the
//!   braking reference its controllers track.
//! - [`ramp`]: a velocity ramp in the 3D world until failure (the maximum-speed protocol's run).
//! - [`max_speed`]: MiaPURE's maximum speed and failing acceleration per heading (Sec. V).
//! - [`world_braking`]: optimal braking to rest in the 3D world (Sec. V).
//! - [`push`]: push recovery in the 3D world.
//! - [`world_suite`]: the world braking and push studies of `ballbot reproduce`, run together.
//! - [`traction`]: traction-aware control against the same controller without it.
//! - [`robustness`]: the reliability campaign: fuzzing, fault injection, Monte Carlo.
//! - [`scenario`]: the TOML scenario files of `ballbot simulate`; [`scenario_run`]: one planar
//!   run from such a file.
//! - [`world_run`]: one logged world run with a ramp and a push (`ballbot world`).
//! - [`replay`]: a run replayed with an MCAP logger, checked against the study's run.

pub mod controllers_3d;
pub mod crossing;
pub mod driver;
pub mod max_speed;
pub mod mechanisms;
pub mod piptb;
pub mod planar_braking;
pub mod push;
pub mod ramp;
pub mod replay;
pub mod robustness;
pub use ballbot_world::runner;
pub mod scenario;
pub mod scenario_run;
pub mod sweep;
pub mod traction;
pub mod world_braking;
pub mod world_run;
pub mod world_suite;

pub use piptb::{ExperimentError, PiptbReport, PiptbSettings};
pub use planar_braking::{BrakingSource, BrakingTrajectory};
pub use runner::run_jobs;
