//! Trajectory optimisation: minimum-effort braking of a wheeled inverted pendulum by direct
//! collocation, solved by SQP with clarabel (the paper's Sec. III-D, MODEL.md section 7).
//!
//! ```text
//! min  integral_0^T tau^2 dt
//! s.t. s_dot = f(s, tau)                      (nonlinear WIP, ballbot_core::Wip)
//!      s(0) = [0, 0, 0, v0 / r],  theta(T) = theta_dot(T) = phi_dot(T) = 0,  phi(T) free
//!      optional tau(0) = tau(T) = 0, tilt / tilt-rate / ball-speed / torque bounds,
//!      motor-side limits (peak torque, torque-speed line, no-load speed per actuator),
//!      traction |F_i| <= mu N_i at every omniwheel (linearised per iteration)
//! ```
//!
//! Hermite-Simpson (default) or trapezoidal collocation on `N` intervals; SQP with exact
//! Jacobians, an L1 merit line search and a KKT-residual stop; warm starts from a previous
//! [`Trajectory`] or the closed-form [`LqBraking`] optimum. [`min_braking_time`] bisects the
//! duration under given limits.
//!
//! ```
//! use ballbot_trajopt::{BrakingProblem, SolveStatus};
//! let sol = BrakingProblem::miapure().solve()?;
//! assert_eq!(sol.status, SolveStatus::Solved);
//! // The body leans back while braking, and the command state is available at any time.
//! assert!(sol.trajectory.state_at(0.5)[0] < 0.0);
//! # Ok::<(), ballbot_trajopt::TrajoptError>(())
//! ```

mod drive;
mod error;
mod interp;
mod lq;
mod method;
mod mintime;
mod problem;
mod qp;
mod sqp;
mod transcription;

pub use drive::Drive;
pub use error::TrajoptError;
pub use interp::Trajectory;
pub use lq::LqBraking;
pub use method::Method;
pub use mintime::{MinTimeOptions, MinTimeResult, min_braking_time};
pub use problem::{BrakingProblem, InitialGuess, Limits, SolveOptions};
pub use sqp::{BrakingSolution, KnotContact, SolveStatus, solve};
