//! [`SlipMonitor`]: wheel-slip and lift-off detection and the traction-control reaction.

use super::TractionParams;
use crate::check::lit;
use crate::estimation::{PlanarStates, ball_body_z_rate_per_ball_rate_sin_cos};
use crate::num::{max, min};
use crate::wip::{BALL_RATE, TILT};
use crate::{OmniKinematics, WHEEL_COUNT, Wip};
use nalgebra::{RealField, Vector2, Vector3};

/// The smallest predicted friction-cone use at a slip's onset from which the monitor infers
/// the friction (see [`SlipMonitor`]).
const MIN_USE_FOR_ESTIMATE: f64 = 0.25;

/// `(sin, cos)` of the frontal and the sagittal tilt, and the ball's body-z rate per ball
/// rate `k` ([`crate::estimation::ball_body_z_rate_per_ball_rate`]): what the 3D controller
/// has computed already and hands to the monitor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TiltTerms<T> {
    pub(crate) frontal_sin_cos: (T, T),
    pub(crate) sagittal_sin_cos: (T, T),
    pub(crate) k: [T; 2],
}

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
/// each wheel's slip evidence, `r_W J e_rel` (m/s at the rim).
///
/// **A push is not a slip** (docs/traction.md section 3). `L (p - p_hat)` is the observers'
/// estimate of an external torque: a push moves the momentum residuals, never the no-spin
/// part, and its wheel slips sum to zero. Evidence above the threshold flags a wheel only
/// where a slip is supported: kinematically (the slips' sum, the no-spin part, above the
/// threshold with the wheel's sign) or dynamically (before the evidence came, the wheel's
/// predicted friction-cone use was at least a quarter and its torque drove it the way it now
/// slips: a slip follows a demand, the torque a push brings follows the push); otherwise it is
/// an external force, which the observers follow. A flag needs supported evidence in two updates running
/// (one outlier sample sets none), and stays while its wheel's evidence lasts; the observers
/// coast (`L = 0`) meanwhile, and on the first update of any evidence: the residual then holds
/// the whole slip instead of forgetting it, and falls back to zero by itself when the wheel
/// grips again. They coast for at most [`TractionParams::max_coast_secs`], then take the
/// measured momentum again: on consistent data every flag falls within that bound.
///
/// **Lift-off.** The contact model ([`OmniKinematics::decoupled_contact_forces`]) predicts the
/// normal forces for the measured state and the reference torque (in the 3D controller from
/// its planes' reference-model accelerations, after they ran; standalone, in [`Self::update`],
/// from the torque given to [`Self::record_torque`]); the next update acts on it.
///
/// **Reaction** (the controller applies it when [`TractionParams::enabled`]): while a wheel
/// slips the controller takes the flagged wheels' ball-rate error off its estimate (the
/// encoders of a spinning wheel report a ball that is not there; the rest of the residual,
/// an external force's, is real motion), and while a wheel slips or a lift-off is
/// imminent the envelope is scaled by
/// [`TractionParams::slip_accel_scale`], and afterwards restored over
/// [`TractionParams::recovery_secs`]; a slip lasting [`TractionParams::slip_fault_secs`] asks
/// for a controlled stop ([`Self::update`] returns `true`). At each slip's onset the friction
/// estimate drops to `mu` times the predicted friction-cone use of the slipping wheel (the
/// friction the wheel actually had, as far as the model knows), if that is lower and the
/// inference sound: no predicted lift-off, and a predicted use of at least a quarter (a slip
/// of a lightly loaded wheel has another cause: a bump, a glitch, a model error). It climbs
/// back to `mu` over
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
/// // One sample proves nothing; the second confirms it, on OW1 alone.
/// let (status, _) = monitor.update(&kin, &states, &rel, 0.0025);
/// assert!(!status.any_slipping());
/// let (status, _) = monitor.update(&kin, &states, &rel, 0.0025);
/// assert_eq!(status.slipping, [true, false, false]);
/// approx::assert_relative_eq!(status.slip_speed_m_per_s[0], 0.125, epsilon = 1e-9);
/// // The same ball-rate change on all wheels alike (as a push would make it, the ball rolling
/// // at 3 rad/s) with no wheel working hard: an external force, no slip.
/// let mut monitor = SlipMonitor::new(&robot, TractionParams::recommended(&robot))?;
/// let mut rolling = still;
/// rolling.sagittal[3] = 3.0;
/// monitor.update(&kin, &still, &Vector3::zeros(), 0.0025);
/// for _ in 0..10 {
///     let (status, _) = monitor.update(&kin, &rolling, &Vector3::new(0.0, 3.0, 0.0), 0.0025);
///     assert!(!status.any_slipping());
/// }
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
    /// The last reference planar torque (N m), for [`Self::update`]'s normal-force prediction.
    last_torque_nm: Vector3<T>,
    /// The omniwheel torques of the last prediction (N m), for the friction estimate.
    predicted_wheel_torques_nm: Vector3<T>,
    /// How long the present slip has lasted (s; 0 without slip).
    slip_secs: T,
    /// How long the observers have coasted on the present flags (s; 0 without slip).
    coast_secs: T,
    /// Which wheels had supported slip evidence in the last update (see [`Self::support`]).
    previous_support: [bool; WHEEL_COUNT],
    /// Whether any wheel's slip estimate was above the threshold in the last update.
    previous_evidence: bool,
    /// Which wheels were working hard before the present episode of evidence
    /// ([`Self::worked_hard`]).
    hard_before: [bool; WHEEL_COUNT],
    /// While a wheel slips: the ball-rate error the encoders report, `[frontal, sagittal]`
    /// (rad/s; the momentum residuals), to take off the estimate; 0 otherwise.
    ball_rate_correction_rad_per_s: [T; 2],
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
            predicted_wheel_torques_nm: Vector3::zeros(),
            slip_secs: T::zero(),
            coast_secs: T::zero(),
            previous_support: [false; WHEEL_COUNT],
            previous_evidence: false,
            hard_before: [false; WHEEL_COUNT],
            ball_rate_correction_rad_per_s: [T::zero(); 2],
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
    /// // OW1 spins at 2 rad/s that the ball does not have, for two samples: a slip.
    /// let rel = kin.relative_rate_rad_per_s(&Vector3::new(2.0, 0.0, 0.0));
    /// let mut spinning = PlanarStates::zeros();
    /// spinning.frontal[3] = rel[0];
    /// spinning.sagittal[3] = rel[1];
    /// monitor.update(&kin, &PlanarStates::zeros(), &Vector3::zeros(), 0.0025);
    /// monitor.update(&kin, &spinning, &rel, 0.0025);
    /// monitor.update(&kin, &spinning, &rel, 0.0025);
    /// assert!(monitor.status().any_slipping());
    /// monitor.reset();
    /// assert!(!monitor.status().any_slipping() && monitor.status().slip_events == 1);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.momentum_estimate = None;
        self.last_torque_nm = Vector3::zeros();
        self.predicted_wheel_torques_nm = Vector3::zeros();
        self.status.predicted_normal_force_n = Vector3::zeros();
        self.status.slip_speed_m_per_s = Vector3::zeros();
        self.status.slipping = [false; WHEEL_COUNT];
        self.slip_secs = T::zero();
        self.coast_secs = T::zero();
        self.previous_support = [false; WHEEL_COUNT];
        self.previous_evidence = false;
        self.hard_before = [false; WHEEL_COUNT];
        self.ball_rate_correction_rad_per_s = [T::zero(); 2];
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
    /// // Confirmed at the second update, then 0.3 s at 400 Hz.
    /// assert_eq!(asked, Some(120));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn update(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        relative_rate_rad_per_s: &Vector3<T>,
        dt_secs: T,
    ) -> (SlipStatus<T>, bool) {
        let tilts = (
            states.frontal[TILT].sin_cos(),
            states.sagittal[TILT].sin_cos(),
        );
        if states.is_finite() {
            let (normal, wheel) = kinematics.decoupled_normal_forces_sin_cos_n(
                (&self.sagittal, &states.sagittal, tilts.1),
                (&self.frontal, &states.frontal, tilts.0),
                &self.last_torque_nm,
            );
            self.set_prediction(&normal, &wheel);
        }
        let rel_z = relative_rate_rad_per_s[2];
        let terms = TiltTerms {
            frontal_sin_cos: tilts.0,
            sagittal_sin_cos: tilts.1,
            k: ball_body_z_rate_per_ball_rate_sin_cos(tilts.0, tilts.1),
        };
        let stop = self.update_with_sin_cos(kinematics, states, rel_z, &terms, dt_secs);
        (self.status, stop)
    }

    /// The normal forces for the measured `states` (with `(sin, cos)` of the frontal and the
    /// sagittal tilt) under the reference planar torque `planar_torque_nm`, from the planes'
    /// accelerations `[theta_ddot, phi_ddot]` under it (frontal, sagittal), which the
    /// controller's reference models computed: [`SlipStatus::predicted_normal_force_n`] and
    /// [`SlipStatus::lift_off_imminent`], acted on in the next update.
    pub(crate) fn predict_with_accelerations(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        (sin_cos_x, sin_cos_y): ((T, T), (T, T)),
        [acc_x, acc_y]: [Vector2<T>; 2],
        planar_torque_nm: &Vector3<T>,
    ) {
        let (normal, wheel) = kinematics.decoupled_normal_forces_with_accelerations_n(
            (&self.sagittal, &states.sagittal, &acc_y, sin_cos_y),
            (&self.frontal, &states.frontal, &acc_x, sin_cos_x),
            planar_torque_nm,
        );
        self.set_prediction(&normal, &wheel);
    }

    fn set_prediction(&mut self, normal: &Vector3<T>, wheel_torques_nm: &Vector3<T>) {
        if normal
            .iter()
            .chain(wheel_torques_nm.iter())
            .all(|x| x.is_finite())
        {
            self.status.predicted_normal_force_n = *normal;
            self.status.lift_off_imminent =
                normal.iter().any(|&n| n < self.params.min_normal_force_n);
            self.predicted_wheel_torques_nm = *wheel_torques_nm;
        }
    }

    /// [`Self::update`] with only the z part of the relative rate, and `(sin, cos)` of the
    /// frontal and the sagittal tilt and the ball's body-z rate per ball rate `k` given (the
    /// controller has them already); returns only whether to stop (the status stays in
    /// [`Self::status`]).
    pub(crate) fn update_with_sin_cos(
        &mut self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        relative_z_rate_rad_per_s: T,
        terms: &TiltTerms<T>,
        dt_secs: T,
    ) -> bool {
        let momentum = self.momentum(states, terms);
        let slip = self.slip_m_per_s(
            kinematics,
            states,
            relative_z_rate_rad_per_s,
            terms,
            &momentum,
        );
        let flags = self.flag(kinematics, &slip);
        let next = self.observe(&momentum, flags.hold, dt_secs);
        // Non-finite inputs (or a non-positive period) change nothing: NaN anywhere reaches
        // the slip or the next estimate (and a NaN slip is no evidence).
        let finite = slip.iter().chain(next.iter()).all(|x| x.is_finite());
        if !(finite && dt_secs > T::zero()) {
            return false;
        }
        let (next, slipping) = self.coast(&momentum, next, flags.slipping, dt_secs);
        self.momentum_estimate = Some(next);
        self.previous_support = flags.support;
        self.previous_evidence = flags.any_evidence;
        self.hard_before = flags.hard_before;
        let any = slipping.iter().any(|&s| s);
        self.learn_friction(kinematics, &slipping, dt_secs);
        self.slip_secs = if any {
            self.slip_secs + dt_secs
        } else {
            T::zero()
        };
        self.ball_rate_correction_rad_per_s = ball_rate_correction(kinematics, &slip, &slipping);
        self.adapt_accel_scale(any, dt_secs);
        self.status.slip_speed_m_per_s = slip;
        self.status.slipping = slipping;
        self.slip_secs > self.params.slip_fault_secs
    }

    /// The planes' momenta from the measured states, the observers' estimate of them (the
    /// measured value before the first update) and the model's rates of change.
    #[inline(always)]
    fn momentum(&self, states: &PlanarStates<T>, terms: &TiltTerms<T>) -> Momentum<T> {
        let (fro, sag) = (&states.frontal, &states.sagittal);
        let (sin_cos_x, sin_cos_y) = (terms.frontal_sin_cos, terms.sagittal_sin_cos);
        let measured = [
            self.frontal.momentum(fro, sin_cos_x.1),
            self.sagittal.momentum(sag, sin_cos_y.1),
        ];
        Momentum {
            measured,
            estimate: self.momentum_estimate.unwrap_or(measured),
            rates: [
                self.frontal.momentum_rate(fro, sin_cos_x.0),
                self.sagittal.momentum_rate(sag, sin_cos_y.0),
            ],
        }
    }

    /// Each wheel's slip speed at the rim (m/s): the momentum residuals as ball-rate errors,
    /// and the measured z rate against the rolling ball's, through the wheel mapping.
    #[inline(always)]
    fn slip_m_per_s(
        &self,
        kinematics: &OmniKinematics<T>,
        states: &PlanarStates<T>,
        relative_z_rate_rad_per_s: T,
        terms: &TiltTerms<T>,
        momentum: &Momentum<T>,
    ) -> Vector3<T> {
        let (fro, sag, k) = (&states.frontal, &states.sagittal, terms.k);
        let residual = momentum.residual();
        let expected_z = k[0] * fro[BALL_RATE] + k[1] * sag[BALL_RATE] - states.spin[1];
        let rate_error = Vector3::new(
            residual[0] / self.frontal.momentum_per_ball_rate(terms.frontal_sin_cos.1),
            residual[1]
                / self
                    .sagittal
                    .momentum_per_ball_rate(terms.sagittal_sin_cos.1),
            relative_z_rate_rad_per_s - expected_z,
        );
        kinematics.wheel_speeds_rad_per_s(&rate_error) * kinematics.drivetrain().wheel_radius_m
    }

    /// Which wheels the slip speeds flag. Without evidence nothing is flagged and the observers
    /// follow (the quiet path).
    #[inline(always)]
    fn flag(&self, kinematics: &OmniKinematics<T>, slip: &Vector3<T>) -> Flags {
        let threshold = self.params.slip_speed_threshold_m_per_s;
        let evidence: [bool; WHEEL_COUNT] = core::array::from_fn(|i| slip[i].abs() > threshold);
        let any_evidence = evidence.iter().any(|&e| e);
        let mut flags = Flags {
            any_evidence,
            slipping: [false; WHEEL_COUNT],
            support: [false; WHEEL_COUNT],
            hard_before: self.hard_before,
            hold: false,
        };
        if !any_evidence {
            return flags;
        }
        if !self.previous_evidence {
            flags.hard_before = self.worked_hard(kinematics, slip);
        }
        let support = support_of(slip, threshold, flags.hard_before);
        // A flag needs supported evidence in two updates running (one sample proves nothing),
        // and stays while the wheel's evidence lasts.
        let (was, previous) = (self.status.slipping, self.previous_support);
        flags.slipping =
            core::array::from_fn(|i| evidence[i] && (was[i] || (support[i] && previous[i])));
        // The observers coast while a wheel slips (the residual keeps the slip), while the
        // evidence is supported and waits for its confirmation, and on the first update of any
        // evidence (an outlier must not be learnt); unsupported evidence that lasts is an
        // external force, which they follow.
        flags.hold = flags.slipping.iter().any(|&s| s)
            || !self.previous_evidence
            || support.iter().any(|&s| s);
        flags.support = support;
        flags
    }

    /// The observers' next momentum estimate: the model's rate, plus the residual's
    /// correction unless they hold.
    #[inline(always)]
    fn observe(&self, momentum: &Momentum<T>, hold: bool, dt_secs: T) -> [T; 2] {
        let gain = if hold {
            T::zero()
        } else {
            self.params.observer_gain_per_s
        };
        let (estimate, rates, residual) = (momentum.estimate, momentum.rates, momentum.residual());
        [
            estimate[0] + (rates[0] + gain * residual[0]) * dt_secs,
            estimate[1] + (rates[1] + gain * residual[1]) * dt_secs,
        ]
    }

    /// Counts how long the flags have held the observers; past
    /// [`TractionParams::max_coast_secs`], whatever the residual holds now, the observers take
    /// the measured momentum again and the flags fall. Returns the estimate and the flags.
    #[inline(always)]
    fn coast(
        &mut self,
        momentum: &Momentum<T>,
        next: [T; 2],
        slipping: [bool; WHEEL_COUNT],
        dt_secs: T,
    ) -> ([T; 2], [bool; WHEEL_COUNT]) {
        if !slipping.iter().any(|&s| s) {
            self.coast_secs = T::zero();
            return (next, slipping);
        }
        self.coast_secs += dt_secs;
        if self.coast_secs > self.params.max_coast_secs {
            self.coast_secs = T::zero();
            let (measured, rates) = (momentum.measured, momentum.rates);
            let taken = [
                measured[0] + rates[0] * dt_secs,
                measured[1] + rates[1] * dt_secs,
            ];
            return (taken, [false; WHEEL_COUNT]);
        }
        (next, slipping)
    }

    /// The friction estimate: at a slip's onset, lowered to what the slipping wheel had as far
    /// as the model knows (only where the model says it was working hard: a slip at low
    /// predicted use has another cause, a bump, a glitch, a model error); without a slip, back
    /// towards the nominal over [`TractionParams::friction_recovery_secs`].
    #[inline(always)]
    fn learn_friction(
        &mut self,
        kinematics: &OmniKinematics<T>,
        slipping: &[bool; WHEEL_COUNT],
        dt_secs: T,
    ) {
        let any = slipping.iter().any(|&s| s);
        let onset = any && !self.status.any_slipping();
        let (p, mu) = (&self.params, self.mu);
        let status = &mut self.status;
        if onset {
            status.slip_events = status.slip_events.saturating_add(1);
            let normal = &status.predicted_normal_force_n;
            let wheel_torques = &self.predicted_wheel_torques_nm;
            let worst = (0..WHEEL_COUNT)
                .filter(|&i| slipping[i])
                .fold(T::zero(), |acc, i| {
                    let contact = kinematics.wheel_contact(normal[i], wheel_torques[i]);
                    max(acc, contact.friction_utilisation)
                });
            let lifted_off = normal.iter().any(|&n| n <= T::zero());
            let sound = worst.is_finite() && worst >= lit(MIN_USE_FOR_ESTIMATE);
            if p.estimate_friction && !lifted_off && sound {
                let seen = max(mu * worst, p.min_friction);
                status.friction_estimate = min(status.friction_estimate, seen);
            }
        } else if !any && status.friction_estimate < mu {
            let climb = mu * dt_secs / p.friction_recovery_secs;
            status.friction_estimate = min(status.friction_estimate + climb, mu);
        }
    }

    /// The acceleration scale: [`TractionParams::slip_accel_scale`] while a wheel slips or a
    /// lift-off is imminent, then back to 1 over [`TractionParams::recovery_secs`].
    #[inline(always)]
    fn adapt_accel_scale(&mut self, any_slipping: bool, dt_secs: T) {
        let p = &self.params;
        let status = &mut self.status;
        if any_slipping || status.lift_off_imminent {
            status.accel_scale = p.slip_accel_scale;
        } else if status.accel_scale < T::one() {
            let back = (T::one() - p.slip_accel_scale) * dt_secs / p.recovery_secs;
            status.accel_scale = min(status.accel_scale + back, T::one());
        }
    }

    /// At the first update of an episode of evidence, which wheels were working hard before it
    /// the way they now slip: the prediction of the update before (made before the evidence
    /// came), a friction-cone use of at least [`MIN_USE_FOR_ESTIMATE`] and the wheel's torque
    /// driving it the way it slips (a rim slides the way its torque pushes it, driving or
    /// braking). See [`support_of`].
    fn worked_hard(
        &self,
        kinematics: &OmniKinematics<T>,
        slip: &Vector3<T>,
    ) -> [bool; WHEEL_COUNT] {
        let normal = &self.status.predicted_normal_force_n;
        let torques = &self.predicted_wheel_torques_nm;
        core::array::from_fn(|i| {
            let cone_use = kinematics
                .wheel_contact(normal[i], torques[i])
                .friction_utilisation;
            cone_use >= lit(MIN_USE_FOR_ESTIMATE) && slip[i] * torques[i] > T::zero()
        })
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

    /// While a wheel slips, the ball-rate error `[frontal, sagittal]` (rad/s) the encoders
    /// report (the momentum residuals): the controller takes it off its estimate, so that a
    /// spinning wheel does not make it see a ball that is not there; 0 without slip.
    pub(crate) fn ball_rate_correction_rad_per_s(&self) -> [T; 2] {
        self.ball_rate_correction_rad_per_s
    }

    /// The braking floor of the settings (m/s^2).
    pub(crate) fn min_braking_decel_m_per_s2(&self) -> T {
        self.params.min_braking_decel_m_per_s2
    }
}

/// The planes' momenta in one update (frontal, sagittal; see
/// [`SlipMonitor::update_with_sin_cos`]).
struct Momentum<T> {
    /// From the measured states.
    measured: [T; 2],
    /// The observers' estimate (the measured value before the first update).
    estimate: [T; 2],
    /// The model's rates of change.
    rates: [T; 2],
}

impl<T: RealField + Copy> Momentum<T> {
    /// Measured minus estimated: what the observers have not explained.
    #[inline(always)]
    fn residual(&self) -> [T; 2] {
        [
            self.measured[0] - self.estimate[0],
            self.measured[1] - self.estimate[1],
        ]
    }
}

/// What the slip speeds say in one update.
struct Flags {
    /// Some wheel's slip speed is over the threshold.
    any_evidence: bool,
    /// The wheels flagged as slipping.
    slipping: [bool; WHEEL_COUNT],
    /// The wheels whose evidence the model supports (see `support_of`).
    support: [bool; WHEEL_COUNT],
    /// The wheels that worked hard before this episode of evidence.
    hard_before: [bool; WHEEL_COUNT],
    /// Whether the observers hold (coast) in this update.
    hold: bool,
}

/// While a wheel is flagged: the ball-rate error (`[frontal, sagittal]`, rad/s) that the
/// flagged wheels' slip reports, to take off the estimate (what the residual holds besides, an
/// external force's momentum or the other wheels' ripple, is real ball motion); 0 otherwise.
#[inline(always)]
fn ball_rate_correction<T: RealField + Copy>(
    kinematics: &OmniKinematics<T>,
    slip: &Vector3<T>,
    slipping: &[bool; WHEEL_COUNT],
) -> [T; 2] {
    if !slipping.iter().any(|&s| s) {
        return [T::zero(); 2];
    }
    let rim_m = kinematics.drivetrain().wheel_radius_m;
    let flagged = Vector3::from_fn(|i, _| if slipping[i] { slip[i] } else { T::zero() });
    let error = kinematics.relative_rate_rad_per_s(&(flagged / rim_m));
    [error.x, error.y]
}

/// Which wheels' slip evidence `slip` (m/s at the rim) a slip can explain and an external force
/// cannot, its *support* (see [`SlipMonitor`] and docs/traction.md section 3):
///
/// - **kinematically**: an external force on the body or the ball changes the ball's rolling
///   and the body's motion alike, never the relation of the wheels to a ball that does not spin
///   about the vertical. It moves the momentum residuals only, whose wheel slips
///   `r_W J [e_x, e_y, 0]` sum to zero (the wheels' `u_i` sum to a vertical vector). The sum
///   of the three slips is the no-spin part alone; one wheel slipping by `s` makes it `s`.
///   Evidence with the sign of a sum above the threshold is supported;
/// - **dynamically** (`hard_before`, [`SlipMonitor::worked_hard`] at the episode's start): a
///   slip that the wheels share so that the sum stays zero (OW2 and OW3 spinning alike
///   towards OW1) is, for the IMU and the encoders, the same as a push near the centre of
///   mass. It is supported only on a wheel that was working hard the way it slips before the
///   evidence came: a slip follows a demand, while the torque a push brings follows the push.
fn support_of<T: RealField + Copy>(
    slip: &Vector3<T>,
    threshold: T,
    hard_before: [bool; WHEEL_COUNT],
) -> [bool; WHEEL_COUNT] {
    let sum = slip.x + slip.y + slip.z;
    let kinematic = sum.abs() > threshold;
    core::array::from_fn(|i| (kinematic && slip[i] * sum > T::zero()) || hard_before[i])
}
