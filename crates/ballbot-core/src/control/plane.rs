//! [`PlaneController`]: one balancing plane's controller, whatever its law, so that what steps
//! a plane (a log replay, a rollout, a binding's `step_many`) is written once.

use super::{
    LqrController, LqrOutput, LqrPiOuter, LqrPiOuterOutput, PiPdController, PiPdOutput, StepStatus,
    Terms,
};
use crate::wip::WipState;
use nalgebra::RealField;

/// A step's output of a [`PlaneController`]: its terms ([`Terms`]) and its status.
///
/// ```
/// use ballbot_core::control::{LqrController, LqrGains, LqrOutput, PlaneOutput, StepStatus, Terms};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut lqr = LqrController::new(LqrGains::for_wip(&wip, 83.9)?)?;
/// let upright = lqr.step(&Vector4::zeros(), &Vector4::zeros(), 0.0025);
/// // Upright and at rest: a nominal step that asks for no torque.
/// assert_eq!(PlaneOutput::status(&upright), StepStatus::Nominal);
/// assert_eq!(PlaneOutput::torque_nm(&upright), upright.torque_nm);
/// assert_eq!(upright.term(<LqrOutput<f64> as Terms<f64>>::TERM_NAMES[0]), Some(0.0));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub trait PlaneOutput<T: Copy>: Terms<T> + Copy {
    /// Whether the step was nominal, saturated or rejected.
    fn status(&self) -> StepStatus;

    /// The torque the step asks of the plane's drive (N m): the LQR's and the PI-PD's motor
    /// torque, the LQR-PI outer loop's reference torque (its speed PI's feedforward).
    fn torque_nm(&self) -> T;
}

/// One balancing plane's controller: from the measured and commanded WIP states
/// `[theta, phi, theta_dot, phi_dot]` to an output with named terms. Implemented by the LQR
/// ([`LqrController`]), the PI-PD ([`PiPdController`]) and the LQR-PI's outer loop
/// ([`LqrPiOuter`]); each keeps its own inherent `step` and `reset`, which these call.
///
/// ```
/// use ballbot_core::control::{
///     LqrController, LqrGains, PiPdController, PiPdGains, PlaneController, PlaneOutput, StepStatus,
///     Terms,
/// };
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// // One replay for every law: the torque of each step and how many were saturated.
/// fn replay<C: PlaneController<f64>>(c: &mut C, tilts_rad: &[f64]) -> (Vec<f64>, usize) {
///     c.reset();
///     let outs: Vec<C::Output> = tilts_rad
///         .iter()
///         .map(|&tilt| c.step(&Vector4::new(tilt, 0.0, 0.0, 0.0), &Vector4::zeros(), 0.0025))
///         .collect();
///     let torque = outs.iter().map(|o| o.term(C::Output::TERM_NAMES[0]).unwrap()).collect();
///     (torque, outs.iter().filter(|o| o.status() == StepStatus::Saturated).count())
/// }
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut lqr = LqrController::new(LqrGains::for_wip(&wip, 83.9)?)?;
/// let mut pi_pd = PiPdController::new(PiPdGains::for_wip(&wip, 83.9)?)?;
/// let tilts = [0.0, 0.05, 0.5];
/// let (lqr_torque, lqr_saturated) = replay(&mut lqr, &tilts);
/// let (pi_pd_torque, _) = replay(&mut pi_pd, &tilts);
/// // Leaning forward drives the ball forward under both laws; half a radian saturates.
/// assert!(lqr_torque[1] > 0.0 && pi_pd_torque[1] > 0.0 && lqr_saturated == 1);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub trait PlaneController<T: RealField + Copy> {
    /// What a step returns.
    type Output: PlaneOutput<T>;

    /// One step of `dt_secs` (s).
    fn step(&mut self, measured: &WipState<T>, command: &WipState<T>, dt_secs: T) -> Self::Output;

    /// Clears every internal state (integrals, references).
    fn reset(&mut self);
}

/// [`PlaneOutput`] for outputs with a `status` field and the named torque field.
macro_rules! impl_plane_output {
    ($($output:ident => $torque:ident),+) => {$(
        impl<T: RealField + Copy> PlaneOutput<T> for $output<T> {
            #[inline]
            fn status(&self) -> StepStatus {
                self.status
            }

            #[inline]
            fn torque_nm(&self) -> T {
                self.$torque
            }
        }
    )+};
}
impl_plane_output!(
    LqrOutput => torque_nm,
    PiPdOutput => torque_nm,
    LqrPiOuterOutput => reference_torque_nm
);

/// [`PlaneController`] through the controller's inherent `step` and `reset`.
macro_rules! impl_plane_controller {
    ($($controller:ident => $output:ident),+) => {$(
        impl<T: RealField + Copy> PlaneController<T> for $controller<T> {
            type Output = $output<T>;

            #[inline]
            fn step(&mut self, measured: &WipState<T>, command: &WipState<T>, dt_secs: T)
            -> $output<T> {
                $controller::step(self, measured, command, dt_secs)
            }

            #[inline]
            fn reset(&mut self) {
                $controller::reset(self);
            }
        }
    )+};
}
impl_plane_controller!(
    LqrController => LqrOutput,
    PiPdController => PiPdOutput,
    LqrPiOuter => LqrPiOuterOutput
);
