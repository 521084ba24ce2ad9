//! Integration tests of ballbot-sim, one module per area.

// Tests may unwrap and panic: a failure is a test failure.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod export;
mod gym;
mod log;
mod motor_health;
mod piptb;
mod piptb_stop;
mod planar_plant;
mod planar_sim;
mod plot;
mod rig;
mod robustness_faults;
mod robustness_fuzz;
mod robustness_monte_carlo;
mod rollout;
mod scenario;
mod trajopt;
mod trajopt_margin;
mod world;
mod world_brake;
mod world_contact;
mod world_controllers_3d;
mod world_crossing;
mod world_driver;
mod world_floor;
mod world_load_transfer;
mod world_max_speed;
mod world_mechanisms;
mod world_multirate;
mod world_paper_ablation;
mod world_sensing;
mod world_setters;
mod world_traction;
mod world_yaw;
