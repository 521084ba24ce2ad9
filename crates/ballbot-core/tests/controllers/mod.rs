//! Closed-loop tests of the planar controllers on the nonlinear WIP.
//!
//! The plant is the core's nonlinear WIP integrated with `rk4_step` at 8 kHz (torque held
//! between controller updates, as a motor driver holds it); the controllers run at their own
//! rates: LQR, PI-PD and the LQR-PI outer part at 400 Hz, the LQR-PI inner speed PI at 8 kHz.
//! An optional friction torque on the relative (motor) joint stands in for the PIPTB's
//! transmission stiction (MODEL.md section 7).
#![allow(clippy::unwrap_used)]

mod hostile;
mod recovery;
mod rig;
mod tracking;
mod windup;
