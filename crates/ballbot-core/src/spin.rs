//! The spin (yaw) model `I_z theta_z_ddot + D_z theta_z_dot = tau_z`.
//!
//! State `[theta_z (rad), theta_z_dot (rad/s)]`; `tau_z` is the yaw torque on the body.
//!
//! ```
//! use ballbot_core::{Spin, SpinParams};
//! use nalgebra::Vector2;
//! let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
//! assert_eq!(
//!     spin.derivative(&Vector2::new(0.0, 0.0), 1.8),
//!     Vector2::new(0.0, 1.0)
//! );
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use crate::{Error, SpinParams};
use nalgebra::{Matrix2, RealField, Vector2};

/// Spin state `[theta_z (rad), theta_z_dot (rad/s)]`.
///
/// ```
/// use ballbot_core::SpinState;
/// // Heading 0.5 rad, turning at 1 rad/s.
/// let s: SpinState<f64> = SpinState::new(0.5, 1.0);
/// assert_eq!(s[1], 1.0);
/// ```
pub type SpinState<T> = Vector2<T>;

/// A validated spin model.
///
/// ```
/// use ballbot_core::{Error, Spin, SpinParams};
/// let spin = Spin::new(SpinParams::<f32>::miapure_unloaded())?;
/// assert_eq!(spin.params().inertia_kg_m2, 0.35);
/// // A zero inertia is rejected once, at construction.
/// let bad = SpinParams {
///     inertia_kg_m2: 0.0,
///     ..SpinParams::<f32>::miapure_60kg()
/// };
/// assert!(matches!(
///     Spin::new(bad),
///     Err(Error::InvalidParameter {
///         field: "inertia_kg_m2",
///         ..
///     })
/// ));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spin<T> {
    params: SpinParams<T>,
}

impl<T: RealField + Copy> Spin<T> {
    /// Validates `params`.
    ///
    /// ```
    /// use ballbot_core::{Spin, SpinParams};
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// assert_eq!(spin.params().damping_nm_s_per_rad, 1.0);
    /// let negative = SpinParams {
    ///     damping_nm_s_per_rad: -1.0,
    ///     ..SpinParams::<f64>::miapure_60kg()
    /// };
    /// assert!(Spin::new(negative).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(params: SpinParams<T>) -> Result<Self, Error> {
        params.validate()?;
        Ok(Self { params })
    }

    /// The parameters this model was built from.
    ///
    /// ```
    /// use ballbot_core::{Spin, SpinParams};
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// assert_eq!(*spin.params(), SpinParams::miapure_60kg());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn params(&self) -> &SpinParams<T> {
        &self.params
    }

    /// Yaw acceleration `(tau_z - D_z theta_z_dot) / I_z` (rad/s^2).
    ///
    /// ```
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// // MiaPURE with 60 kg (I_z = 1.8 kg m^2, D_z = 1 N m s/rad) turning at 1 rad/s:
    /// // 2.8 N m gives (2.8 - 1) / 1.8 = 1 rad/s^2, and 1 N m just holds the rate.
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// approx::assert_relative_eq!(
    ///     spin.acceleration(&Vector2::new(0.0, 1.0), 2.8),
    ///     1.0,
    ///     epsilon = 1e-12
    /// );
    /// assert_eq!(spin.acceleration(&Vector2::new(0.0, 1.0), 1.0), 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn acceleration(&self, s: &SpinState<T>, torque_nm: T) -> T {
        (torque_nm - self.params.damping_nm_s_per_rad * s[1]) / self.params.inertia_kg_m2
    }

    /// State derivative `[theta_z_dot, theta_z_ddot]`.
    ///
    /// ```
    /// use ballbot_core::{Spin, SpinParams, rk4_step};
    /// use nalgebra::Vector2;
    /// // Coasting from 1 rad/s, the yaw rate decays with time constant I_z / D_z = 1.8 s.
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let mut s = Vector2::new(0.0, 1.0);
    /// for _ in 0..1800 {
    ///     s = rk4_step(|x| spin.derivative(x, 0.0), &s, 0.001);
    /// }
    /// approx::assert_relative_eq!(s[1], (-1.0f64).exp(), epsilon = 1e-9);
    /// // The heading reached is 1.8 (1 - e^-1) rad.
    /// approx::assert_relative_eq!(s[0], 1.8 * (1.0 - (-1.0f64).exp()), epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn derivative(&self, s: &SpinState<T>, torque_nm: T) -> SpinState<T> {
        Vector2::new(s[1], self.acceleration(s, torque_nm))
    }

    /// The (exact, linear) state space `s_dot = A s + B tau_z`.
    ///
    /// ```
    /// use ballbot_core::{Spin, SpinParams};
    /// use nalgebra::Vector2;
    /// let spin = Spin::new(SpinParams::<f64>::miapure_60kg())?;
    /// let (a, b) = spin.state_space();
    /// // The model is linear: A s + B tau equals the nonlinear-form derivative exactly.
    /// let s = Vector2::new(0.3, -2.0);
    /// approx::assert_relative_eq!(a * s + b * 4.0, spin.derivative(&s, 4.0), epsilon = 1e-12);
    /// // Poles 0 and -D_z / I_z = -0.556 rad/s.
    /// approx::assert_relative_eq!(a[(1, 1)], -1.0 / 1.8, epsilon = 1e-12);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
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
