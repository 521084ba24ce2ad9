//! The range of WIP torques a planar motion at a given heading can use: actuator limits
//! (torque-speed line of each wheel) and contact limits (friction cones, no lift-off).
//!
//! For a planar WIP motion at heading `h` in state `s`, every wheel torque, wheel traction
//! and normal force is affine in the WIP torque `tau` (the accelerations of the WIP are affine
//! in `tau`, and everything downstream is linear). Each limit is therefore an interval of
//! `tau`, computed exactly in closed form: no search, bounded time. The paper's heading
//! dependence of the maximum speed (Sec. V) is the asymmetry of the contact interval.
//!
//! ```
//! use ballbot_core::{BallbotParams, OmniKinematics, Wip};
//! use nalgebra::Vector4;
//! let params = BallbotParams::<f64>::miapure_60kg();
//! let kin = OmniKinematics::from_ballbot(&params)?;
//! let wip = Wip::new(params.sagittal)?;
//! let upright = Vector4::zeros();
//! // Towards OW1 (heading 0) the contacts allow less forward torque than backward torque.
//! let range = kin
//!     .wip_contact_torque_interval_nm(&wip, 0.0, &upright)
//!     .unwrap();
//! assert!(range.max_nm < -range.min_nm);
//! # Ok::<(), ballbot_core::Error>(())
//! ```

use super::{OmniKinematics, planar_torque_at_heading, relative_rate_at_heading};
use crate::wip::{BALL_RATE, TILT_RATE};
use crate::{Wip, WipState};
use nalgebra::RealField;

/// A closed interval `[min_nm, max_nm]` of WIP torques (N m); the ends may be infinite.
///
/// ```
/// use ballbot_core::TorqueInterval;
/// let range = TorqueInterval {
///     min_nm: -20.9,
///     max_nm: 17.1,
/// };
/// assert!(range.contains(0.0) && !range.contains(18.0));
/// assert_eq!(range.clamp(30.0), 17.1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueInterval<T> {
    /// Lower end (N m).
    pub min_nm: T,
    /// Upper end (N m), `>= min_nm`.
    pub max_nm: T,
}

impl<T: RealField + Copy> TorqueInterval<T> {
    /// The whole real line.
    ///
    /// ```
    /// use ballbot_core::TorqueInterval;
    /// let all = TorqueInterval::<f64>::unbounded();
    /// assert!(all.contains(1e300) && all.contains(-1e300));
    /// // The neutral element of intersection.
    /// let range = TorqueInterval {
    ///     min_nm: -1.0,
    ///     max_nm: 2.0,
    /// };
    /// assert_eq!(all.intersect(&range), Some(range));
    /// ```
    pub fn unbounded() -> Self {
        let infinity: T = nalgebra::convert(f64::INFINITY);
        Self {
            min_nm: -infinity,
            max_nm: infinity,
        }
    }

    /// Whether `torque_nm` lies in the interval.
    ///
    /// ```
    /// use ballbot_core::TorqueInterval;
    /// let range = TorqueInterval {
    ///     min_nm: -5.0,
    ///     max_nm: 5.0,
    /// };
    /// // Closed at both ends; NaN is never inside.
    /// assert!(range.contains(5.0) && range.contains(-5.0));
    /// assert!(!range.contains(f64::NAN));
    /// ```
    pub fn contains(&self, torque_nm: T) -> bool {
        self.min_nm <= torque_nm && torque_nm <= self.max_nm
    }

    /// `torque_nm` clamped into the interval; a non-finite request gives the point of the
    /// interval closest to zero.
    ///
    /// ```
    /// use ballbot_core::TorqueInterval;
    /// let range = TorqueInterval {
    ///     min_nm: -5.0,
    ///     max_nm: 8.0,
    /// };
    /// assert_eq!(
    ///     (range.clamp(10.0), range.clamp(-7.0), range.clamp(3.0)),
    ///     (8.0, -5.0, 3.0)
    /// );
    /// // A non-finite request gives the torque closest to zero: 0 here, 2 for [2, 8].
    /// assert_eq!(range.clamp(f64::NAN), 0.0);
    /// assert_eq!(
    ///     TorqueInterval {
    ///         min_nm: 2.0,
    ///         max_nm: 8.0
    ///     }
    ///     .clamp(f64::INFINITY),
    ///     2.0
    /// );
    /// ```
    pub fn clamp(&self, torque_nm: T) -> T {
        let t = if torque_nm.is_finite() {
            torque_nm
        } else {
            T::zero()
        };
        t.max(self.min_nm).min(self.max_nm)
    }

    /// The intersection with `other`, `None` if it is empty.
    ///
    /// ```
    /// use ballbot_core::TorqueInterval;
    /// let actuator = TorqueInterval {
    ///     min_nm: -96.9,
    ///     max_nm: 79.4,
    /// };
    /// let contact = TorqueInterval {
    ///     min_nm: -20.9,
    ///     max_nm: 17.1,
    /// };
    /// assert_eq!(actuator.intersect(&contact), Some(contact));
    /// // Disjoint intervals: no torque satisfies both.
    /// let high = TorqueInterval {
    ///     min_nm: 30.0,
    ///     max_nm: 40.0,
    /// };
    /// assert_eq!(contact.intersect(&high), None);
    /// ```
    pub fn intersect(&self, other: &Self) -> Option<Self> {
        Self::new(self.min_nm.max(other.min_nm), self.max_nm.min(other.max_nm))
    }

    fn new(min_nm: T, max_nm: T) -> Option<Self> {
        (min_nm <= max_nm).then_some(Self { min_nm, max_nm })
    }

    /// Narrows the interval to the `tau` with `offset + slope tau <= 0`; `None` if empty.
    fn with_affine_le_zero(self, offset: T, slope: T) -> Option<Self> {
        if !(offset.is_finite() && slope.is_finite()) {
            return None;
        }
        if slope > T::zero() {
            Self::new(self.min_nm, self.max_nm.min(-offset / slope))
        } else if slope < T::zero() {
            Self::new(self.min_nm.max(-offset / slope), self.max_nm)
        } else if offset <= T::zero() {
            Some(self)
        } else {
            None
        }
    }
}

impl<T: RealField + Copy> OmniKinematics<T> {
    /// The WIP torques (N m) that keep every omniwheel within its actuator limits
    /// ([`ActuatorParams::torque_bounds_nm`](crate::ActuatorParams::torque_bounds_nm) at its
    /// current speed) for a planar motion at heading `heading_rad` in WIP state `s`. It always
    /// contains 0. Non-finite inputs give `[0, 0]`.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector4;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// // At rest, towards omniwheel 1 (heading 0): the sagittal capacity, +-96.9 N m.
    /// let at_rest = kin.wip_actuator_torque_interval_nm(0.0, &Vector4::zeros());
    /// approx::assert_relative_eq!(at_rest.max_nm, 96.93, epsilon = 0.01);
    /// approx::assert_relative_eq!(at_rest.min_nm, -96.93, epsilon = 0.01);
    /// // Rolling forward at 10 rad/s (1.1 m/s), less is left to accelerate, all of it to brake.
    /// let rolling = kin.wip_actuator_torque_interval_nm(0.0, &Vector4::new(0.0, 0.0, 0.0, 10.0));
    /// approx::assert_relative_eq!(rolling.max_nm, 79.39, epsilon = 0.01);
    /// assert_eq!(rolling.min_nm, at_rest.min_nm);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wip_actuator_torque_interval_nm(
        &self,
        heading_rad: T,
        s: &WipState<T>,
    ) -> TorqueInterval<T> {
        let zero = TorqueInterval {
            min_nm: T::zero(),
            max_nm: T::zero(),
        };
        let per_unit = self.wheel_torques_nm(&planar_torque_at_heading(heading_rad, T::one()));
        let speeds = self.wheel_speeds_rad_per_s(&relative_rate_at_heading(
            heading_rad,
            s[BALL_RATE],
            s[TILT_RATE],
        ));
        let mut range = TorqueInterval::unbounded();
        for (&w, &speed) in per_unit.iter().zip(speeds.iter()) {
            if !(w.is_finite() && speed.is_finite()) {
                return zero;
            }
            let (lo, hi) = self.drivetrain.actuator.torque_bounds_nm(speed);
            // lo <= tau w <= hi, as two affine constraints.
            range = match range
                .with_affine_le_zero(-hi, w)
                .and_then(|r| r.with_affine_le_zero(lo, -w))
            {
                Some(r) => r,
                None => return zero,
            };
        }
        range
    }

    /// The WIP torques (N m) for which every omniwheel contact holds (inside its friction cone
    /// `|F_i| <= mu N_i`, which implies `N_i >= 0`: no lift-off) for a planar motion of `wip`
    /// at heading `heading_rad` in state `s`, with the forces of
    /// [`Self::wip_contact_forces`]. `None` when no torque keeps all contacts (e.g. a lean
    /// or spin so large that a wheel lifts off whatever the torque).
    ///
    /// At an end of the interval one contact is exactly at its friction limit.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, OmniKinematics, TorqueInterval, Wip};
    /// use nalgebra::Vector4;
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// let (kin, wip) = (
    ///     OmniKinematics::from_ballbot(&params)?,
    ///     Wip::new(params.sagittal)?,
    /// );
    /// let upright = Vector4::zeros();
    /// let deg = |d: f64| d.to_radians();
    /// // From rest, the contacts allow [-20.9, 17.1] N m at heading 0 and the mirror image at
    /// // 180 deg; about +-16.3 N m at 90 deg. Far below the actuators' 97 N m.
    /// let h0 = kin
    ///     .wip_contact_torque_interval_nm(&wip, deg(0.0), &upright)
    ///     .unwrap_or(TorqueInterval::unbounded());
    /// let h180 = kin
    ///     .wip_contact_torque_interval_nm(&wip, deg(180.0), &upright)
    ///     .unwrap_or(TorqueInterval::unbounded());
    /// let h90 = kin
    ///     .wip_contact_torque_interval_nm(&wip, deg(90.0), &upright)
    ///     .unwrap_or(TorqueInterval::unbounded());
    /// approx::assert_relative_eq!(h0.min_nm, -20.92, epsilon = 0.01);
    /// approx::assert_relative_eq!(h0.max_nm, 17.10, epsilon = 0.01);
    /// approx::assert_relative_eq!(h180.max_nm, -h0.min_nm, epsilon = 1e-9);
    /// approx::assert_relative_eq!(h90.max_nm, 16.30, epsilon = 0.01);
    /// // At an end, one contact is exactly at its friction limit.
    /// let edge = kin.wip_contact_forces(&wip, 0.0, &upright, h0.max_nm);
    /// approx::assert_relative_eq!(edge.max_friction_utilisation(), 1.0, epsilon = 1e-9);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn wip_contact_torque_interval_nm(
        &self,
        wip: &Wip<T>,
        heading_rad: T,
        s: &WipState<T>,
    ) -> Option<TorqueInterval<T>> {
        let mu = self.drivetrain.wheel_ball_friction;
        let at_zero = self.wip_contact_forces(wip, heading_rad, s, T::zero());
        let at_one = self.wip_contact_forces(wip, heading_rad, s, T::one());
        let mut range = TorqueInterval::unbounded();
        for (c0, c1) in at_zero.wheels.iter().zip(at_one.wheels.iter()) {
            let (n0, dn) = (c0.normal_force_n, c1.normal_force_n - c0.normal_force_n);
            let (f0, df) = (c0.traction_n, c1.traction_n - c0.traction_n);
            // F - mu N <= 0 and -F - mu N <= 0.
            range = range
                .with_affine_le_zero(f0 - mu * n0, df - mu * dn)?
                .with_affine_le_zero(-f0 - mu * n0, -df - mu * dn)?;
        }
        Some(range)
    }
}
