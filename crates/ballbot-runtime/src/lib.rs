// The crate documentation is the crate's README (crates.io shows the same text), so its first
// example (the loop on mock devices) is compiled and run as a doctest and cannot rot.
#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

mod robot_loop;

pub use robot_loop::{
    DeviceErrorCounts, InnerReport, LoopConfig, OperatorInput, OuterReport, Phase, RobotLoop,
};
