//! LQR synthesis without allocation: Riccati solvers (discrete and continuous) and gain
//! design for the WIP's reduced state and the spin model.
//!
//! - [`solve_dare`], [`solve_care`]: generic fixed-size algebraic Riccati solvers by
//!   structured doubling, returning a [`RiccatiSolution`] with a [`RiccatiStatus`].
//! - [`wip_lqr`], [`wip_lqr_discrete`]: the paper's LQR on `[theta, theta_dot, phi_dot]`
//!   (`phi` is not fed back; MODEL.md section 2), gains `[k1, k2, k3]` and the paper's
//!   `[k1, 0, k2, k3]`, for `tau = k . (s_c - s)`.
//! - [`spin_lqr`], [`spin_lqr_discrete`]: LQR on the spin state `[theta_z, theta_z_dot]`.
//!
//! Zero-order-hold discretisation and the matrix exponential live in [`crate::linalg`].
//!
//! ```
//! use ballbot_core::lqr::{WipLqrWeights, wip_lqr};
//! use ballbot_core::{Wip, WipParams};
//! let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
//! let lqr = wip_lqr(&wip, &WipLqrWeights::model_default())?;
//! // Leaning forward by 0.01 rad (reference upright) asks for a forward ball torque.
//! let tau_nm = lqr.control(
//!     &nalgebra::Vector3::zeros(),
//!     &nalgebra::Vector3::new(0.01, 0.0, 0.0),
//! );
//! assert!(tau_nm > 0.0);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

mod design;
mod riccati;

pub use design::{
    Lqr, LqrWeights, SpinLqr, SpinLqrWeights, WipLqr, WipLqrWeights, outer_loop_dt_secs, spin_lqr,
    spin_lqr_discrete, wip_lqr, wip_lqr_discrete,
};
pub use riccati::{
    RiccatiSettings, RiccatiSolution, RiccatiStatus, solve_care, solve_dare, validate_weights,
};
