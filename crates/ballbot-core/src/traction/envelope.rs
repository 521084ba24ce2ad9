//! [`TractionEnvelope`]: the largest acceleration in each body-frame direction that keeps every
//! omniwheel inside a margin of its friction cone and above a minimum normal force, built once
//! at configuration time; plus the actuators' speed-dependent limit, evaluated every step.

use super::TractionParams;
use crate::check::lit;
use crate::num::{hypot, min};
use crate::{BallbotParams, Error, OmniKinematics, Wip, WipState};
use nalgebra::{RealField, Vector3};

/// Number of directions in the envelope's table: 24 per quadrant of the diamond angle (see
/// [`TractionEnvelope`]), the largest gap between neighbours 5.3 deg.
///
/// ```
/// use ballbot_core::traction::ENVELOPE_DIRECTIONS;
/// assert_eq!(ENVELOPE_DIRECTIONS % 4, 0); // whole quadrants: the axes are table entries
/// ```
pub const ENVELOPE_DIRECTIONS: usize = 96;

/// Largest lean the quasi-static search considers (deg): beyond it the envelope is capped.
const MAX_LEAN_DEG: f64 = 30.0;
/// Step of the search's scan over the lean (deg); bisection refines the last step.
const LEAN_STEP_DEG: f64 = 0.25;

/// The acceleration limits of a ballbot by direction, from the contact model of
/// [`OmniKinematics::wip_contact_forces`] at the quasi-static accelerating equilibrium.
///
/// **Friction and lift-off.** For a direction `h` (body frame, 0 = towards OW1) the robot
/// accelerating steadily at `a` leans by the `theta` at which the body's lean is held
/// (`theta_ddot = 0`, `theta_dot = 0`, ball at rest: the torque `tau(theta)` and
/// `a = r phi_ddot(theta, tau)` follow from the WIP). The envelope is the largest such `a` at
/// which every wheel keeps `|F_i| <= (mu / s) N_i` and `N_i >= N_min` (`s` the
/// [`TractionParams::friction_safety_factor`], `N_min` the
/// [`TractionParams::min_normal_force_n`]), found by a scan over the lean in 0.25 deg steps and
/// bisection. Deceleration while travelling towards `h` is acceleration towards `h + 180 deg`.
///
/// **The table.** [`ENVELOPE_DIRECTIONS`] directions, uniform in the *diamond angle*
/// `d(x, y)`: a piecewise-rational function of the direction that increases with its angle
/// like the angle does (quadrant `q` plus `|y| / (|x| + |y|)` or `|x| / (|x| + |y|)`), so
/// that a lookup needs one division and no arctangent. Between entries it interpolates
/// linearly. Built at construction without allocation (about 10^4 contact evaluations).
///
/// **Actuators.** [`Self::actuator_limit_m_per_s2`] divides the torque each actuator has left at
/// its present speed ([`crate::ActuatorParams::torque_bounds_nm`]) by the wheel torque one m/s^2
/// needs in that direction (`b / r` of WIP torque, mapped to the wheels): this is the part of
/// the envelope that depends on speed.
///
/// The payload is the robot's: a different payload is a different [`BallbotParams`] and a new
/// envelope.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::traction::{TractionEnvelope, TractionParams};
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let exact = TractionParams { friction_safety_factor: 1.0, ..TractionParams::recommended(&robot) };
/// let envelope = TractionEnvelope::new(&robot, &exact)?;
/// let towards_ow1 = envelope.friction_limit_m_per_s2(1.0, 0.0);
/// let away = envelope.friction_limit_m_per_s2(-1.0, 0.0);
/// // Accelerating towards OW1 unloads the two driving wheels: far less than away from it.
/// assert!(towards_ow1 < 0.8 * away, "{towards_ow1} {away}");
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TractionEnvelope<T> {
    /// Friction and lift-off limit per table direction (m/s^2).
    friction_accel_m_per_s2: [T; ENVELOPE_DIRECTIONS],
    /// Omniwheel torques per m/s^2 along body x and along body y (N m per m/s^2).
    wheel_torque_per_accel: [Vector3<T>; 2],
    /// Actuator peak torque (N m at the omniwheel) and no-load speed (rad/s).
    peak_torque_nm: T,
    no_load_speed_rad_per_s: T,
}

impl<T: RealField + Copy> TractionEnvelope<T> {
    /// Builds the table for `robot` with the margins of `params` (validated, also when
    /// `params.enabled` is false).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionEnvelope, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let p = TractionParams::recommended(&robot);
    /// let planned = TractionEnvelope::new(&robot, &p)?;
    /// let exact = TractionEnvelope::new(&robot, &TractionParams { friction_safety_factor: 1.0, ..p })?;
    /// // The safety factor lowers every direction's limit.
    /// assert!((0..96).all(|k| planned.table_m_per_s2()[k] < exact.table_m_per_s2()[k]));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(robot: &BallbotParams<T>, params: &TractionParams<T>) -> Result<Self, Error> {
        params.validate()?;
        let kin = OmniKinematics::from_ballbot(robot)?;
        let wip = Wip::new(robot.sagittal)?;
        let mu = robot.drivetrain.wheel_ball_friction / params.friction_safety_factor;
        let n_min = params.min_normal_force_n;
        let friction_accel_m_per_s2 = core::array::from_fn(|k| {
            let (x, y) = table_direction::<T>(k);
            quasi_static_limit(&kin, &wip, y.atan2(x), mu, n_min)
        });
        // Quasi-static: b phi_ddot = tau, a = r phi_ddot, so tau per m/s^2 is b / r.
        let p = &robot.sagittal;
        let r = p.ball_radius_m;
        let b = p.ball_inertia_kg_m2
            + (p.ball_mass_kg + p.body_mass_kg) * r * r
            + p.wheel_inertia_kg_m2;
        let per_accel = b / r;
        // Along body x the sagittal plane drives (tau_y > 0); along body y the frontal plane,
        // which travels along -y (tau_x < 0).
        let wheel_torque_per_accel = [
            kin.wheel_torques_nm(&Vector3::new(T::zero(), per_accel, T::zero())),
            kin.wheel_torques_nm(&Vector3::new(-per_accel, T::zero(), T::zero())),
        ];
        let actuator = robot.drivetrain.actuator;
        Ok(Self {
            friction_accel_m_per_s2,
            wheel_torque_per_accel,
            peak_torque_nm: actuator.peak_torque_nm,
            no_load_speed_rad_per_s: actuator.no_load_speed_rad_per_s,
        })
    }

    /// The table: friction and lift-off limit (m/s^2) at each of the
    /// [`ENVELOPE_DIRECTIONS`] directions of [`Self::table_heading_rad`].
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionEnvelope, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let e = TractionEnvelope::new(&robot, &TractionParams::recommended(&robot))?;
    /// // Entry 0 is towards OW1, entry 48 away from it: the weak and a strong direction.
    /// let t = e.table_m_per_s2();
    /// assert_eq!(e.table_heading_rad(48), core::f64::consts::PI);
    /// assert!(t[0] < t[48]);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn table_m_per_s2(&self) -> &[T; ENVELOPE_DIRECTIONS] {
        &self.friction_accel_m_per_s2
    }

    /// The heading (rad, in (-pi, pi], body frame, 0 = towards OW1) of table entry `index`
    /// (taken modulo [`ENVELOPE_DIRECTIONS`]).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionEnvelope, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let e = TractionEnvelope::new(&robot, &TractionParams::recommended(&robot))?;
    /// // Entry 24 of 96 is the first of the second quadrant: body +y.
    /// approx::assert_relative_eq!(e.table_heading_rad(24), core::f64::consts::FRAC_PI_2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn table_heading_rad(&self, index: usize) -> T {
        let (x, y) = table_direction::<T>(index % ENVELOPE_DIRECTIONS);
        let heading = y.atan2(x);
        // -pi (y = -0) is +pi.
        if heading <= -T::pi() {
            T::pi()
        } else {
            heading
        }
    }

    /// The friction and lift-off limit (m/s^2) for an acceleration along `(dir_x, dir_y)`
    /// (body frame, any length > 0), interpolated in the table. A zero or non-finite direction
    /// gives the smallest entry.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionEnvelope, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let e = TractionEnvelope::new(&robot, &TractionParams::recommended(&robot))?;
    /// // The direction's length does not matter; a table direction returns its entry.
    /// assert_eq!(e.friction_limit_m_per_s2(2.0, 0.0), e.table_m_per_s2()[0]);
    /// approx::assert_relative_eq!(
    ///     e.friction_limit_m_per_s2(-0.3, 0.3),
    ///     e.table_m_per_s2()[36],
    ///     epsilon = 1e-12
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn friction_limit_m_per_s2(&self, dir_x: T, dir_y: T) -> T {
        let table = &self.friction_accel_m_per_s2;
        let Some(d) = diamond_angle(dir_x, dir_y) else {
            return table.iter().fold(table[0], |acc, &a| min(acc, a));
        };
        let u = d * lit::<T>(ENVELOPE_DIRECTIONS as f64 / 4.0);
        let index_f = u.floor();
        let k = nalgebra::try_convert::<T, f64>(index_f).unwrap_or(0.0) as usize;
        let k = k.min(ENVELOPE_DIRECTIONS - 1);
        let next = (k + 1) % ENVELOPE_DIRECTIONS;
        let frac = u - index_f;
        table[k] + (table[next] - table[k]) * frac
    }

    /// The actuators' limit (m/s^2) for an acceleration along `(dir_x, dir_y)` (body frame, any
    /// length > 0) with the omniwheels at `wheel_speeds_rad_per_s`: the torque each actuator
    /// has left at its speed over the torque one m/s^2 needs from it. Infinite when no wheel
    /// is needed; 0 for non-finite inputs.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{TractionEnvelope, TractionParams};
    /// use nalgebra::Vector3;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let e = TractionEnvelope::new(&robot, &TractionParams::recommended(&robot))?;
    /// let still = e.actuator_limit_m_per_s2(1.0, 0.0, &Vector3::zeros());
    /// // Rolling towards OW1 at 2 m/s the driving wheels have less torque left (back-EMF).
    /// let rolling = Vector3::new(0.0, -17.8, 17.8);
    /// let moving = e.actuator_limit_m_per_s2(1.0, 0.0, &rolling);
    /// assert!(still > 5.0 && moving < still);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn actuator_limit_m_per_s2(
        &self,
        dir_x: T,
        dir_y: T,
        wheel_speeds_rad_per_s: &Vector3<T>,
    ) -> T {
        let norm = hypot(dir_x, dir_y);
        if !(norm > T::zero() && norm.is_finite()) {
            return T::zero();
        }
        let [along_x, along_y] = &self.wheel_torque_per_accel;
        let per_accel = (along_x * dir_x + along_y * dir_y) / norm;
        let peak = self.peak_torque_nm;
        let mut limit: T = lit(f64::INFINITY);
        for (&w, &speed) in per_accel.iter().zip(wheel_speeds_rad_per_s.iter()) {
            if !speed.is_finite() {
                return T::zero();
            }
            // The torque left in w's sign: motoring against the back-EMF line, or braking.
            let motoring = w * speed > T::zero();
            let left = if motoring {
                (peak * (T::one() - speed.abs() / self.no_load_speed_rad_per_s)).max(T::zero())
            } else {
                peak
            };
            if w != T::zero() {
                limit = min(limit, left / w.abs());
            }
        }
        limit
    }
}

/// The quasi-static acceleration limit along `heading_rad` (see [`TractionEnvelope`]).
fn quasi_static_limit<T: RealField + Copy>(
    kin: &OmniKinematics<T>,
    wip: &Wip<T>,
    heading_rad: T,
    mu: T,
    n_min: T,
) -> T {
    let r = wip.params().ball_radius_m;
    // (acceleration, whether every contact keeps its margin) at lean `theta`.
    let at = |theta: T| {
        let s = WipState::new(theta, T::zero(), T::zero(), T::zero());
        // theta_ddot is affine in the torque: the torque that holds the lean.
        let free = wip.accelerations(&s, T::zero())[0];
        let slope = wip.accelerations(&s, T::one())[0] - free;
        let torque = -free / slope;
        let contacts = kin.wip_contact_forces(wip, heading_rad, &s, torque);
        let holds = contacts
            .wheels
            .iter()
            .all(|w| w.normal_force_n >= n_min && w.traction_n.abs() <= mu * w.normal_force_n);
        (wip.accelerations(&s, torque)[1] * r, holds)
    };
    let (_, upright_holds) = at(T::zero());
    if !upright_holds {
        return T::zero();
    }
    let step: T = lit(LEAN_STEP_DEG.to_radians());
    let steps = (MAX_LEAN_DEG / LEAN_STEP_DEG) as usize;
    let mut good = T::zero();
    for k in 1..=steps {
        let theta = step * lit(k as f64);
        if !at(theta).1 {
            let mut bad = theta;
            for _ in 0..30 {
                let mid = (good + bad) * lit(0.5);
                if at(mid).1 {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            return at(good).0.max(T::zero());
        }
        good = theta;
    }
    at(good).0.max(T::zero())
}

/// The diamond angle of `(x, y)` in `[0, 4)`: quadrant plus `|y| / (|x| + |y|)` (quadrants
/// I and III) or `|x| / (|x| + |y|)` (II and IV), continuous and increasing with the angle.
/// `None` for a zero or non-finite direction.
fn diamond_angle<T: RealField + Copy>(x: T, y: T) -> Option<T> {
    let sum = x.abs() + y.abs();
    if !(sum > T::zero() && sum.is_finite()) {
        return None;
    }
    let zero = T::zero();
    let d = if y >= zero {
        if x >= zero {
            y / sum
        } else {
            T::one() - x / sum
        }
    } else if x < zero {
        lit::<T>(2.0) - y / sum
    } else {
        lit::<T>(3.0) + x / sum
    };
    // y = -0.0 with x > 0 lands on 4: the same direction as 0.
    Some(if d >= lit(4.0) { zero } else { d })
}

/// The direction `(x, y)` (`|x| + |y| = 1`) of table entry `index`.
fn table_direction<T: RealField + Copy>(index: usize) -> (T, T) {
    let per_quadrant = ENVELOPE_DIRECTIONS / 4;
    let quadrant = index / per_quadrant;
    let t: T = lit((index % per_quadrant) as f64 / per_quadrant as f64);
    let one = T::one();
    match quadrant {
        0 => (one - t, t),
        1 => (-t, one - t),
        2 => (t - one, -t),
        _ => (t, t - one),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn envelope(safety: f64) -> TractionEnvelope<f64> {
        let robot = BallbotParams::miapure_60kg();
        let p = TractionParams {
            friction_safety_factor: safety,
            ..TractionParams::recommended(&robot)
        };
        TractionEnvelope::new(&robot, &p).unwrap()
    }

    #[test]
    fn table_directions_round_trip_through_the_diamond_angle() {
        for k in 0..ENVELOPE_DIRECTIONS {
            let (x, y) = table_direction::<f64>(k);
            let d = diamond_angle(x, y).unwrap();
            approx::assert_relative_eq!(d, 4.0 * k as f64 / 96.0, epsilon = 1e-12);
        }
    }

    proptest! {
        /// The diamond angle increases with the true angle (so the table interpolates between
        /// its two true neighbours), and ignores the direction's length.
        #[test]
        fn diamond_angle_is_monotone(a in 0.0f64..6.0, b in 0.0f64..6.0, scale in 0.01f64..100.0) {
            let d = |t: f64| diamond_angle(t.cos(), t.sin()).unwrap();
            if a < b {
                prop_assert!(d(a) <= d(b) + 1e-12);
            }
            let scaled = diamond_angle(scale * a.cos(), scale * a.sin()).unwrap();
            prop_assert!((scaled - d(a)).abs() < 1e-9);
        }
    }

    /// At its limit, one contact is exactly at the margin of its friction cone or at the
    /// minimum normal force, and every contact keeps the margin (checked by mutation: a sign
    /// error in the held torque or the search's step breaks it).
    #[test]
    fn the_limit_is_where_the_first_contact_reaches_its_margin() {
        let robot = BallbotParams::<f64>::miapure_60kg();
        let p = TractionParams::recommended(&robot);
        let kin = OmniKinematics::from_ballbot(&robot).unwrap();
        let wip = Wip::new(robot.sagittal).unwrap();
        let mu = 0.6 / p.friction_safety_factor;
        for deg in [0.0f64, 37.0, 90.0, 150.0, 180.0, 265.0] {
            let h = deg.to_radians();
            let a = quasi_static_limit(&kin, &wip, h, mu, p.min_normal_force_n);
            // Recover the lean of that acceleration and check the contacts there.
            let theta = (0..500_000)
                .map(|k| k as f64 * 1e-6)
                .find(|&th| {
                    let s = WipState::new(th, 0.0, 0.0, 0.0);
                    let free = wip.accelerations(&s, 0.0)[0];
                    let slope = wip.accelerations(&s, 1.0)[0] - free;
                    wip.accelerations(&s, -free / slope)[1] * 0.1145 >= a
                })
                .unwrap();
            let s = WipState::new(theta, 0.0, 0.0, 0.0);
            let free = wip.accelerations(&s, 0.0)[0];
            let slope = wip.accelerations(&s, 1.0)[0] - free;
            let c = kin.wip_contact_forces(&wip, h, &s, -free / slope);
            let worst = c
                .wheels
                .iter()
                .map(|w| {
                    (w.traction_n.abs() / (mu * w.normal_force_n))
                        .max(p.min_normal_force_n / w.normal_force_n)
                })
                .fold(0.0, f64::max);
            assert!(
                (worst - 1.0).abs() < 2e-3,
                "{deg} deg: a {a}, worst {worst}"
            );
        }
    }

    /// Between table entries the interpolated envelope never exceeds the exact limit by more
    /// than 0.5 %, and is at most 5 % below it (at the envelope's peaks, where linear
    /// interpolation cuts the corner), at 0.25 deg steps all round.
    #[test]
    fn interpolation_error_is_small() {
        let robot = BallbotParams::<f64>::miapure_60kg();
        let p = TractionParams::recommended(&robot);
        let e = TractionEnvelope::new(&robot, &p).unwrap();
        let kin = OmniKinematics::from_ballbot(&robot).unwrap();
        let wip = Wip::new(robot.sagittal).unwrap();
        let mu = 0.6 / p.friction_safety_factor;
        for quarter in 0..1440 {
            let h = f64::from(quarter).to_radians() / 4.0;
            let exact = quasi_static_limit(&kin, &wip, h, mu, p.min_normal_force_n);
            let table = e.friction_limit_m_per_s2(h.cos(), h.sin());
            assert!(
                table <= 1.005 * exact && table >= 0.95 * exact,
                "{} deg: table {table}, exact {exact}",
                f64::from(quarter) / 4.0
            );
        }
    }

    #[test]
    fn the_safety_factor_and_mu_order_the_limits() {
        let (exact, planned) = (envelope(1.0), envelope(1.5));
        for k in 0..ENVELOPE_DIRECTIONS {
            assert!(planned.table_m_per_s2()[k] < exact.table_m_per_s2()[k]);
        }
        // Towards OW1 (0 deg) the weakest direction of the sagittal line, as the paper found.
        let toward = exact.friction_limit_m_per_s2(1.0, 0.0);
        let away = exact.friction_limit_m_per_s2(-1.0, 0.0);
        assert!(toward < away);
    }

    #[test]
    fn actuator_limit_falls_with_speed_along_the_motoring_direction() {
        let e = envelope(1.5);
        let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg()).unwrap();
        let at = |v: f64| {
            let rel = Vector3::new(0.0, v / 0.1145, 0.0);
            e.actuator_limit_m_per_s2(1.0, 0.0, &kin.wheel_speeds_rad_per_s(&rel))
        };
        assert!(at(1.0) < at(0.0) && at(3.0) < at(1.0));
        // Braking (acceleration against the motion) keeps the full peak torque.
        let rel = Vector3::new(0.0, 3.0 / 0.1145, 0.0);
        let braking = e.actuator_limit_m_per_s2(-1.0, 0.0, &kin.wheel_speeds_rad_per_s(&rel));
        approx::assert_relative_eq!(braking, at(0.0), epsilon = 1e-9);
        assert_eq!(
            e.actuator_limit_m_per_s2(f64::NAN, 0.0, &Vector3::zeros()),
            0.0
        );
    }
}
