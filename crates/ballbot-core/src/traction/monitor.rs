//! [`SlipMonitor`]: wheel-slip and lift-off detection and the traction-control reaction.

use super::TractionParams;
use crate::estimation::{PlanarStates, ball_body_z_rate_per_ball_rate_sin_cos};
use crate::num::{max, min};
use crate::wip::{BALL_RATE, TILT};
use crate::{OmniKinematics, WHEEL_COUNT, Wip};
use nalgebra::{RealField, Vector3};

/// What the slip monitor found in one step, and the traction state it keeps.
///
/// ```
/// use ballbot_core::traction::SlipStatus;
/// let quiet = SlipStatus::<f64>::quiet(0.6);
/// assert!(!quiet.any_slipping() && quiet.accel_scale == 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlipStatus<T: nalgebra::Scalar> {
    /// Estimated slip speed of each omniwheel (m/s at the rim, the encoders' reading minus the
    /// rolling the ball's motion allows; see [`SlipMonitor`]).
    pub slip_speed_m_per_s: Vector3<T>,
    /// Which wheels slip: `|slip speed|` above the threshold.
    pub slipping: [bool; WHEEL_COUNT],
    /// The normal forces the contact model predicts for the measured state and the last
    /// reference torque (N).
    pub predicted_normal_force_n: Vector3<T>,
    /// Whether a predicted normal force is below the envelope's minimum.
    pub lift_off_imminent: bool,
    /// How long the present slip has lasted (s; 0 without slip).
    pub slip_secs: T,
    /// The factor on the envelope now: 1, or less after a slip or an imminent lift-off.
    pub accel_scale: T,
    /// The wheel-ball friction the envelope uses now (the parameter's `mu`, or less after a
    /// slip).
    pub friction_estimate: T,
    /// Slip events so far (rising edges of "any wheel slips"), saturating.
    pub slip_events: u32,
}

impl<T: RealField + Copy> SlipStatus<T> {
    /// No slip, no lift-off, full envelope, friction `mu`.
    ///
    /// ```
    /// use ballbot_core::traction::SlipStatus;
    /// let s = SlipStatus::quiet(0.6);
    /// assert_eq!((s.friction_estimate, s.slip_events), (0.6, 0));
    /// ```
    pub fn quiet(mu: T) -> Self {
        Self {
            slip_speed_m_per_s: Vector3::zeros(),
            slipping: [false; WHEEL_COUNT],
            predicted_normal_force_n: Vector3::zeros(),
            lift_off_imminent: false,
            slip_secs: T::zero(),
            accel_scale: T::one(),
            friction_estimate: mu,
            slip_events: 0,
        }
    }

    /// Whether any wheel slips.
    ///
    /// ```
    /// use ballbot_core::traction::SlipStatus;
    /// let mut s = SlipStatus::quiet(0.6);
    /// s.slipping[2] = true;
    /// assert!(s.any_slipping());
    /// ```
    pub fn any_slipping(&self) -> bool {
        self.slipping.iter().any(|&s| s)
    }
}

/// Wheel-slip and lift-off detection from the redundancy of the sensors, and the reaction.
///
/// **Three residuals.** The encoders give the ball's rates relative to the body, three
/// numbers for three degrees of freedom; the model adds what they cannot:
/// - in each WIP plane the generalised momentum `p` (see [`Wip::momentum`]) changes only by
///   gravity, whatever torque the wheels transmit. An observer integrates
///   `p_hat' = dp/dt(s) + L (p - p_hat)` and the residual `p - p_hat`, divided by
///   [`Wip::momentum_per_ball_rate`], is the ball-rate error the encoders report;
/// - about the body's z axis, the ball does not spin about the vertical (MODEL.md section 3),
///   so the wheels' relative z rate must equal `k . [phi_dot_x, phi_dot_y] - omega_z` with the
///   IMU's yaw rate ([`crate::estimation::ball_body_z_rate_per_ball_rate`]).
///
/// The three errors form a relative-rate error `e_rel`; the wheel speed map turns it into
/// each wheel's slip, `r_W J e_rel` (m/s at the rim). While any wheel slips the observers
/// coast (`L = 0`): the residual then holds the whole slip instead of forgetting it, and falls
/// back to zero by itself when the wheel grips again.
///
/// **Lift-off.** The contact model ([`OmniKinematics::decoupled_contact_forces`]) predicts the
/// normal forces for the measured state and the last reference torque.
///
/// **Reaction** (the controller applies it when [`TractionParams::enabled`]): while a wheel
/// slips or a lift-off is imminent the envelope is scaled by
/// [`TractionParams::slip_accel_scale`], and afterwards restored over
/// [`TractionParams::recovery_secs`]; a slip lasting [`TractionParams::slip_fault_secs`] asks
/// for a controlled stop ([`Self::update`] returns `true`). At each slip's onset the friction
/// estimate drops to `mu` times the predicted friction-cone use of the slipping wheel (the
/// friction the wheel actually had, as far as the model knows), if that is lower and the
/// prediction sound (no predicted lift-off); it climbs back to `mu` over
/// [`TractionParams::friction_recovery_secs`].
///
/// Allocation-free, O(1) per step.
///
/// ```
/// use ballbot_core::BallbotParams;
/// use ballbot_core::estimation::PlanarStates;
/// use ballbot_core::traction::{SlipMonitor, TractionParams};
/// use ballbot_core::OmniKinematics;
/// use nalgebra::Vector3;
/// let robot = BallbotParams::<f64>::miapure_60kg();
/// let kin = OmniKinematics::from_ballbot(&robot)?;
/// let mut monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
/// let still = PlanarStates::zeros();
/// let (status, stop) = monitor.update(&kin, &still, &Vector3::zeros(), 0.0025);
/// assert!(!status.any_slipping() && !stop);
/// // OW1 suddenly reports 2 rad/s (0.125 m/s at the rim) that the ball does not have.
/// let spinning = Vector3::new(2.0, 0.0, 0.0);
/// let mut states = still;
/// let rel = kin.relative_rate_rad_per_s(&spinning);
/// states.frontal[3] = rel[0];
/// states.sagittal[3] = rel[1];
/// let (status, _) = monitor.update(&kin, &states, &rel, 0.0025);
/// assert_eq!(status.slipping, [true, false, false]);
/// approx::assert_relative_eq!(status.slip_speed_m_per_s[0], 0.125, epsilon = 1e-9);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlipMonitor<T: RealField + Copy> {
    params: TractionParams<T>,
    frontal: Wip<T>,
    sagittal: Wip<T>,
    mu: T,
    /// Observed momenta `[frontal, sagittal]` (kg m^2/s); `None` until the first update.
    momentum_estimate: Option<[T; 2]>,
    /// The last reference planar torque (N m), for the normal-force prediction.
    last_torque_nm: Vector3<T>,
    status: SlipStatus<T>,
}

impl<T: RealField + Copy> SlipMonitor<T> {
    /// Validates `params` and builds the monitor for `robot`.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
    /// assert_eq!(monitor.status().friction_estimate, 0.6); // the robot's mu
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(
        robot: &crate::BallbotParams<T>,
        params: TractionParams<T>,
    ) -> Result<Self, crate::Error> {
        params.validate()?;
        let mu = robot.drivetrain.wheel_ball_friction;
        Ok(Self {
            params,
            frontal: Wip::new(robot.frontal)?,
            sagittal: Wip::new(robot.sagittal)?,
            mu,
            momentum_estimate: None,
            last_torque_nm: Vector3::zeros(),
            status: SlipStatus::quiet(mu),
        })
    }

    /// The status of the last update.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
    /// assert!(!monitor.status().any_slipping());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn status(&self) -> &SlipStatus<T> {
        &self.status
    }

    /// Restarts the observers (after the motors were off); keeps the counters and the
    /// friction estimate.
    ///
    /// ```
    /// use ballbot_core::estimation::PlanarStates;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let kin = OmniKinematics::from_ballbot(&robot)?;
    /// let mut monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
    /// let mut spinning = PlanarStates::zeros();
    /// spinning.sagittal[3] = 3.0; // the wheels say the ball rolls; the momentum says no
    /// monitor.update(&kin, &PlanarStates::zeros(), &Vector3::zeros(), 0.0025);
    /// monitor.update(&kin, &spinning, &Vector3::new(0.0, 3.0, 0.0), 0.0025);
    /// assert!(monitor.status().any_slipping());
    /// monitor.reset();
    /// assert!(!monitor.status().any_slipping() && monitor.status().slip_events == 1);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.momentum_estimate = None;
        self.last_torque_nm = Vector3::zeros();
        self.status.slip_speed_m_per_s = Vector3::zeros();
        self.status.slipping = [false; WHEEL_COUNT];
        self.status.slip_secs = T::zero();
        self.status.accel_scale = T::one();
        self.status.lift_off_imminent = false;
    }

    /// Records the reference planar torque `[tau_x, tau_y, tau_z]` (N m) the controller sent,
    /// for the next step's normal-force prediction.
    ///
    /// ```
    /// use ballbot_core::estimation::PlanarStates;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let kin = OmniKinematics::from_ballbot(&robot)?;
    /// let mut monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
    /// // 50 N m forward from upright would need tension at OW2 and OW3: lift-off predicted.
    /// monitor.record_torque(&Vector3::new(0.0, 50.0, 0.0));
    /// let (status, _) = monitor.update(&kin, &PlanarStates::zeros(), &Vector3::zeros(), 0.0025);
    /// assert!(status.lift_off_imminent && status.accel_scale < 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn record_torque(&mut self, planar_torque_nm: &Vector3<T>) {
        if planar_torque_nm.iter().all(|t| t.is_finite()) {
            self.last_torque_nm = *planar_torque_nm;
        }
    }

    /// One step: `states` from the estimator, `relative_rate_rad_per_s` the encoders' relative
    /// rate `J^-1 psi_dot` of this step ([`OmniKinematics::relative_rate_rad_per_s`]; its z
    /// part the estimator does not use), `dt_secs` the period. Returns the status and whether
    /// a slip has lasted long enough to ask for a controlled stop. Non-finite inputs (or a
    /// step without a valid encoder or IMU sample, which the caller skips) leave everything
    /// unchanged.
    ///
    /// ```
    /// use ballbot_core::estimation::PlanarStates;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let kin = OmniKinematics::from_ballbot(&robot)?;
    /// let params = TractionParams::recommended(&robot);
    /// let mut monitor = SlipMonitor::new(&robot, params)?;
    /// // The wheels report the ball spinning about the vertical at 1 rad/s: all three slip
    /// // alike, and after 0.3 s of it the monitor asks for a controlled stop.
    /// let spin = Vector3::new(0.0, 0.0, 1.0);
    /// let mut asked = None;
    /// for k in 0..200 {
    ///     let (_, stop) = monitor.update(&kin, &PlanarStates::zeros(), &spin, 0.0025);
    ///     if stop && asked.is_none() {
    ///         asked = Some(k);
    ///     }
    /// }
    /// assert!(monitor.status().slipping.iter().all(|&s| s));
    /// assert_eq!(asked, Some(119)); // the 120th update: 0.3 s at 400 Hz
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn update(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        relative_rate_rad_per_s: &Vector3<T>,
        dt_secs: T,
    ) -> (SlipStatus<T>, bool) {
        let p = &self.params;
        let fro = &states.frontal;
        let sag = &states.sagittal;
        let sin_cos_x = fro[TILT].sin_cos();
        let sin_cos_y = sag[TILT].sin_cos();
        let measured = [
            self.frontal.momentum(fro, sin_cos_x.1),
            self.sagittal.momentum(sag, sin_cos_y.1),
        ];
        let usable = states.is_finite()
            && relative_rate_rad_per_s.iter().all(|x| x.is_finite())
            && dt_secs.is_finite()
            && dt_secs > T::zero();
        if !usable {
            return (self.status, false);
        }
        let estimate = self.momentum_estimate.unwrap_or(measured);
        let residual = [measured[0] - estimate[0], measured[1] - estimate[1]];
        // Coast while slipping: the residual keeps the slip.
        let gain = if self.status.any_slipping() {
            T::zero()
        } else {
            p.observer_gain_per_s
        };
        let rates = [
            self.frontal.momentum_rate(fro, sin_cos_x.0),
            self.sagittal.momentum_rate(sag, sin_cos_y.0),
        ];
        self.momentum_estimate = Some([
            estimate[0] + (rates[0] + gain * residual[0]) * dt_secs,
            estimate[1] + (rates[1] + gain * residual[1]) * dt_secs,
        ]);
        let k = ball_body_z_rate_per_ball_rate_sin_cos(sin_cos_x, sin_cos_y);
        let expected_z = k[0] * fro[BALL_RATE] + k[1] * sag[BALL_RATE] - states.spin[1];
        let rate_error = Vector3::new(
            residual[0] / self.frontal.momentum_per_ball_rate(sin_cos_x.1),
            residual[1] / self.sagittal.momentum_per_ball_rate(sin_cos_y.1),
            relative_rate_rad_per_s[2] - expected_z,
        );
        let rim_m = kinematics.drivetrain().wheel_radius_m;
        let slip = kinematics.wheel_speeds_rad_per_s(&rate_error) * rim_m;
        let threshold = p.slip_speed_threshold_m_per_s;
        let slipping = core::array::from_fn(|i| slip[i].abs() > threshold);
        let contacts = kinematics.decoupled_contact_forces(
            (&self.sagittal, sag),
            (&self.frontal, fro),
            &self.last_torque_nm,
        );
        let normal = contacts.normal_forces_n();
        let lift_off_imminent = normal.iter().any(|&n| n < p.min_normal_force_n);
        let any = slipping.iter().any(|&s| s);
        let onset = any && !self.status.any_slipping();
        let mut status = self.status;
        let mu = self.mu;
        if onset {
            status.slip_events = status.slip_events.saturating_add(1);
            // The friction the slipping wheel had, as far as the model knows.
            let worst = (0..WHEEL_COUNT)
                .filter(|&i| slipping[i])
                .fold(T::zero(), |acc, i| {
                    max(acc, contacts.wheels[i].friction_utilisation)
                });
            if p.estimate_friction && !contacts.any_lifted_off() && worst.is_finite() {
                let seen = max(mu * worst, p.min_friction);
                status.friction_estimate = min(status.friction_estimate, seen);
            }
        } else if !any {
            let climb = mu * dt_secs / p.friction_recovery_secs;
            status.friction_estimate = min(status.friction_estimate + climb, mu);
        }
        status.slip_secs = if any {
            status.slip_secs + dt_secs
        } else {
            T::zero()
        };
        status.accel_scale = if any || lift_off_imminent {
            p.slip_accel_scale
        } else {
            let back = (T::one() - p.slip_accel_scale) * dt_secs / p.recovery_secs;
            min(status.accel_scale + back, T::one())
        };
        status.slip_speed_m_per_s = slip;
        status.slipping = slipping;
        status.predicted_normal_force_n = normal;
        status.lift_off_imminent = lift_off_imminent;
        self.status = status;
        let stop = status.slip_secs > p.slip_fault_secs;
        (status, stop)
    }

    /// The factor on the envelope's friction part: `accel_scale * friction_estimate / mu`.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_core::traction::{SlipMonitor, TractionParams};
    /// let robot = BallbotParams::<f64>::miapure_60kg();
    /// let monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
    /// assert_eq!(monitor.envelope_scale(), 1.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn envelope_scale(&self) -> T {
        self.status.accel_scale * self.status.friction_estimate / self.mu
    }

    /// The braking floor of the settings (m/s^2).
    pub(crate) fn min_braking_decel_m_per_s2(&self) -> T {
        self.params.min_braking_decel_m_per_s2
    }
}
