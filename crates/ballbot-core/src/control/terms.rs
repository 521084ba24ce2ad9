//! One way to list a controller output's per-term contributions: the [`Terms`] trait.
//!
//! Logs, the simulator and the Python bindings read the terms through it instead of spelling
//! the names again: a term's name is its output field's name (units in the name), in the
//! field's declaration order. The [`StepStatus`](super::StepStatus) is not a term: it has its
//! own name ([`StepStatus::as_str`](super::StepStatus::as_str)).

/// A controller output whose numeric fields are named terms (applied value, feedforward, P, I,
/// D, saturation, references...), listed without allocation.
///
/// Every scalar field of the output but its `status` is a term, named as the field and
/// visited in declaration order. Implemented by [`LqrOutput`](super::LqrOutput),
/// [`PiPdOutput`](super::PiPdOutput), [`LqrPiOuterOutput`](super::LqrPiOuterOutput),
/// [`SpeedPiOutput`](super::SpeedPiOutput) and
/// [`SpinOuterOutput`](crate::ballbot::SpinOuterOutput).
///
/// ```
/// use ballbot_core::control::{LqrController, LqrGains, LqrOutput, Terms};
/// use nalgebra::Vector4;
/// let mut lqr = LqrController::new(LqrGains::from_reduced([-234.8, -45.70, -3.162], 83.9))?;
/// let out = lqr.step(&Vector4::new(0.1, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025);
/// // The names, known without an output (e.g. for a log's header) ...
/// assert_eq!(LqrOutput::<f64>::TERM_NAMES[1], "tilt_term_nm");
/// // ... and the values, visited in that order.
/// let mut sum_nm = 0.0;
/// out.for_each_term(|name, value| {
///     if name.ends_with("_term_nm") {
///         sum_nm += value;
///     }
/// });
/// approx::assert_relative_eq!(sum_nm, out.torque_nm, epsilon = 1e-12); // not saturated
/// assert_eq!(out.term("tilt_term_nm"), Some(out.tilt_term_nm));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub trait Terms<T: Copy> {
    /// The terms' names, in the order [`Terms::for_each_term`] visits them.
    const TERM_NAMES: &'static [&'static str];

    /// Calls `f(name, value)` for every term, in [`Terms::TERM_NAMES`] order.
    fn for_each_term<F: FnMut(&'static str, T)>(&self, f: F);

    /// The value of the term called `name`, if the output has one.
    fn term(&self, name: &str) -> Option<T> {
        let mut found = None;
        self.for_each_term(|n, v| {
            if found.is_none() && n == name {
                found = Some(v);
            }
        });
        found
    }
}

/// Implements [`Terms`] for an output struct generic over `T` from the list of its term
/// fields: each name is spelled once, as the field.
macro_rules! impl_terms {
    ($output:ident { $($field:ident),+ $(,)? }) => {
        impl<T: nalgebra::RealField + Copy> $crate::control::Terms<T> for $output<T> {
            const TERM_NAMES: &'static [&'static str] = &[$(stringify!($field)),+];

            #[inline]
            fn for_each_term<F: FnMut(&'static str, T)>(&self, mut f: F) {
                $(f(stringify!($field), self.$field);)+
            }
        }
    };
}
pub(crate) use impl_terms;
