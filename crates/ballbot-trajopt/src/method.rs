//! The collocation scheme.

/// The collocation scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Hermite-Simpson (compressed form, with a midpoint torque per interval): cubic states,
    /// quadratic torque, error O(h^4). The default.
    #[default]
    HermiteSimpson,
    /// Trapezoidal: quadratic states, linear torque, error O(h^2).
    Trapezoidal,
}
