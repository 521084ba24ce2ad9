//! Integration tests of ballbot-core, one module per area.

mod balance_point;
mod ballbot3d;
mod controllers;
mod doc_examples;
mod fast_paths;
mod kinematics;
mod load_transfer;
mod lqr;
mod names;
mod safety;
mod spin;
mod terms;
mod traction;
mod trajectories;
