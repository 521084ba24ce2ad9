//! # ballbot-studies
//!
//! The paper's experiments on the simulated world, and what they produce (see
//! `ARCHITECTURE.md`):
//!
//! - [`studies`]: the experiments as plain data, run by one experiment driver
//!   ([`studies::driver`]) on the job runner;
//! - [`report`]: their JSON, tables and figures (figures behind the `plot` feature), and
//!   `ballbot reproduce` as a library call;
//! - [`params_file`]: every parameter file's schema, checks naming the dotted key, presets
//!   and differences (`ballbot params`).
//!
//! Layer rule: imports the physics (`ballbot-world`), `ballbot-trajopt` and `ballbot-log`,
//! never the command line.

pub mod params_file;
pub mod report;
pub mod studies;
