//! The spin (yaw) model `I_z theta_z_ddot + D_z theta_z_dot = tau_z`.
//!
//! State `[theta_z (rad), theta_z_dot (rad/s)]`; `tau_z` is the yaw torque on the body.
//!
//! ```
//! use ballbot_core::{Spin, SpinParams};
//! use nalgebra::Vector2;
//! let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
//! assert_eq!(spin.derivative(&Vector2::new(0.0, 0.0), 1.8), Vector2::new(0.0, 1.0));
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use crate::{Error, SpinParams};
use nalgebra::{Matrix2, RealField, Vector2};

/// Spin state `[theta_z (rad), theta_z_dot (rad/s)]`.
pub type SpinState<T> = Vector2<T>;

/// A validated spin model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spin<T> {
    params: SpinParams<T>,
}

impl<T: RealField + Copy> Spin<T> {
    /// Validates `params`.
    pub fn new(params: SpinParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self { params })
    }

    /// The parameters this model was built from.
    pub fn params(&self) -> &SpinParams<T> {
        &self.params
    }

    /// Yaw acceleration `(tau_z - D_z theta_z_dot) / I_z` (rad/s^2).
    pub fn acceleration(&self, s: &SpinState<T>, torque_nm: T) -> T {
        (torque_nm - self.params.damping_nm_s_per_rad * s[1]) / self.params.inertia_kg_m2
    }

    /// State derivative `[theta_z_dot, theta_z_ddot]`.
    pub fn derivative(&self, s: &SpinState<T>, torque_nm: T) -> SpinState<T> {
        Vector2::new(s[1], self.acceleration(s, torque_nm))
    }

    /// The (exact, linear) state space `s_dot = A s + B tau_z`.
    pub fn state_space(&self) -> (Matrix2<T>, Vector2<T>) {
        let p = &self.params;
        let a = Matrix2::new(
            T::zero(),
            T::one(),
            T::zero(),
            -p.damping_nm_s_per_rad / p.inertia_kg_m2,
        );
        let b = Vector2::new(T::zero(), T::one() / p.inertia_kg_m2);
        (a, b)
    }
}
