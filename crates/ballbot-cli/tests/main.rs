//! Integration tests of the `ballbot` command, one module per subcommand.

// Tests may unwrap and panic: a failure is a test failure.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod brake;
mod controller_file;
mod export;
mod float_flags;
mod params;
mod simulate;
mod sweep;
mod world_live;
mod world_log;
mod world_outcome;
mod world_video;
