//! Integration tests of ballbot-core, one module per area.

mod controllers;
mod kinematics;
mod lqr;
