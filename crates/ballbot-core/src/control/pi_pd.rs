//! The cascaded PI-PD controller of the CMU ballbot (paper Fig. "controller" b): an outer PI on
//! the ball rate gives a reference tilt, an inner PD on the tilt gives the torque. Both run at
//! the same rate (400 Hz on the PIPTB).
//!
//! ```text
//! e_v      = phi_dot_c - phi_dot,     z = int e_v dt                 (rad)
//! theta_r  = clamp(theta_c + kp_v e_v + ki_v z, +-max_tilt)          outer PI
//! tau      = sat(kp_t (theta_r - theta) + kd_t (theta_dot_c - theta_dot))   inner PD
//! ```
//!
//! Signs follow the paper's `tau = k (s_c - s)`: the balancing tilt gains `kp_t`, `kd_t` are
//! negative (like the LQR's `k1`, `k2`); the speed gains `kp_v`, `ki_v` are positive (to go
//! faster, lean forward).
//!
//! **Anti-windup**: conditional integration. The speed integral `z` is not advanced in a step
//! where the reference tilt is clipped or the torque saturated *and* advancing it would push
//! further into that limit; it is committed only when finite.
//!
//! **Default gains** ([`PiPdGains::design`]): without limits the law is a state feedback
//! `tau = -K x` on `x = [theta, theta_dot, phi_dot, z]` with
//! `K = [kp_t, kd_t, kp_t kp_v, -kp_t ki_v]`, so the four gains are found by pole placement
//! (Ackermann's formula) on the model's upright linearisation, augmented with `z_dot = -phi_dot`.
//! [`PiPdGains::for_wip`] places the poles at fixed multiples of the open-loop unstable pole
//! `p0 = sqrt(m_U g l b / Delta0)`, which scales the design to each robot.

use super::terms::impl_terms;
use super::{StepStatus, check_gain, check_limit, dt_is_valid, saturate, state_is_finite};
use crate::check::lit;
use crate::wip::{BALL_RATE, TILT, TILT_RATE};
use crate::{Error, Wip, WipState};
use nalgebra::{Matrix4, RealField, RowVector4, Vector4};

/// Closed-loop poles of [`PiPdGains::for_wip`], as multiples of the open-loop unstable pole
/// `p0`: two fast balance poles and two slower speed poles, all real. The fastest is kept at
/// 1.6 `p0` so that a 10 deg tilt asks for less than MiaPURE's 83.9 N m (the tilt gain is
/// -377 N m/rad for MiaPURE with 60 kg; the pole set `[-2, -1.2, ...]` would need -492).
///
/// ```
/// assert!(ballbot_core::control::PI_PD_DEFAULT_POLES_PER_P0.iter().all(|m| *m < 0.0));
/// ```
pub const PI_PD_DEFAULT_POLES_PER_P0: [f64; 4] = [-1.6, -1.0, -0.4, -0.25];

/// Default reference-tilt limit of [`PiPdGains::for_wip`] (rad): 0.2 rad, about 11.5 deg.
///
/// ```
/// assert!((ballbot_core::control::PI_PD_DEFAULT_MAX_TILT_RAD.to_degrees() - 11.46).abs() < 0.01);
/// ```
pub const PI_PD_DEFAULT_MAX_TILT_RAD: f64 = 0.2;

/// Gains and limits of [`PiPdController`].
///
/// ```
/// use ballbot_core::control::{PiPdController, PiPdGains};
/// // Hand-set gains in the paper's signs: balancing tilt gains negative, speed gains positive.
/// let gains = PiPdGains {
///     speed_p_secs: 0.05,
///     speed_i_rad_per_rad: 0.01,
///     tilt_p_nm_per_rad: -300.0,
///     tilt_d_nm_s_per_rad: -50.0,
///     max_tilt_rad: 0.2,
///     max_torque_nm: 83.9,
/// };
/// let controller = PiPdController::new(gains)?;
/// assert_eq!(controller.gains().max_tilt_rad, 0.2);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
pub struct PiPdGains<T> {
    /// Outer proportional gain `kp_v`: reference tilt per ball-rate error (rad per rad/s, i.e. s).
    pub speed_p_secs: T,
    /// Outer integral gain `ki_v`: reference tilt per integrated ball-rate error (rad/rad).
    pub speed_i_rad_per_rad: T,
    /// Inner proportional gain `kp_t` on `theta_r - theta` (N m/rad; negative to balance).
    pub tilt_p_nm_per_rad: T,
    /// Inner derivative gain `kd_t` on `theta_dot_c - theta_dot` (N m s/rad; negative to
    /// balance).
    pub tilt_d_nm_s_per_rad: T,
    /// Reference-tilt limit (rad, > 0).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_tilt_rad: T,
    /// Torque saturation, symmetric (N m, > 0).
    #[cfg_attr(feature = "schema", schemars(extend("exclusiveMinimum" = 0)))]
    pub max_torque_nm: T,
}

impl<T: RealField + Copy> PiPdGains<T> {
    /// Checks every field; the error names the first one out of range.
    ///
    /// ```
    /// use ballbot_core::Error;
    /// use ballbot_core::control::PiPdGains;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let gains = PiPdGains::for_wip(&wip, 83.9)?;
    /// assert!(gains.validate().is_ok());
    /// // Without a tilt gain the PD cannot balance: refused.
    /// let no_tilt_gain = PiPdGains { tilt_p_nm_per_rad: 0.0, ..gains };
    /// assert!(matches!(
    ///     no_tilt_gain.validate(),
    ///     Err(Error::InvalidParameter { field: "tilt_p_nm_per_rad", .. })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        check_gain(self.speed_p_secs, "speed_p_secs")?;
        check_gain(self.speed_i_rad_per_rad, "speed_i_rad_per_rad")?;
        check_gain(self.tilt_p_nm_per_rad, "tilt_p_nm_per_rad")?;
        check_gain(self.tilt_d_nm_s_per_rad, "tilt_d_nm_s_per_rad")?;
        if self.tilt_p_nm_per_rad == T::zero() {
            return Err(Error::invalid("tilt_p_nm_per_rad", "must not be 0"));
        }
        check_limit(self.max_tilt_rad, "max_tilt_rad")?;
        check_limit(self.max_torque_nm, "max_torque_nm")
    }

    /// Gains by pole placement on `wip`'s upright linearisation (see the module docs).
    /// `poles_rad_per_s` are the four closed-loop poles, real and negative.
    ///
    /// Errors: `poles_rad_per_s` when a pole is not finite and negative or the design fails
    /// numerically; `max_tilt_rad` / `max_torque_nm` when not finite and positive.
    ///
    /// ```
    /// use ballbot_core::control::PiPdGains;
    /// use ballbot_core::linalg::eigenvalues;
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::{Matrix4, RowVector4, Vector4};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let poles = [-12.0, -8.0, -3.0, -2.0];
    /// let g = PiPdGains::design(&wip, poles, 0.2, 83.9)?;
    /// // Without limits the law is tau = -K x on x = [theta, theta_dot, phi_dot, z]:
    /// // the closed loop A - B K of the augmented linearisation has exactly the requested poles.
    /// let (a, b) = wip.linearize_upright().reduced();
    /// let mut a_aug = Matrix4::zeros();
    /// a_aug.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    /// a_aug[(3, 2)] = -1.0; // z_dot = -phi_dot
    /// let b_aug = Vector4::new(b[0], b[1], b[2], 0.0);
    /// let (kp, kd) = (g.tilt_p_nm_per_rad, g.tilt_d_nm_s_per_rad);
    /// let k = RowVector4::new(kp, kd, kp * g.speed_p_secs, -kp * g.speed_i_rad_per_rad);
    /// let eig = eigenvalues(&(a_aug - b_aug * k)).ok_or("no eigenvalues")?;
    /// let mut re: Vec<f64> = eig.iter().map(|z| z.re).collect();
    /// re.sort_by(f64::total_cmp);
    /// for (got, want) in re.iter().zip(poles) {
    ///     approx::assert_relative_eq!(*got, want, max_relative = 1e-6);
    /// }
    /// assert!(eig.iter().all(|z| z.im.abs() < 1e-6));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    #[allow(non_snake_case)]
    pub fn design(
        wip: &Wip<T>,
        poles_rad_per_s: [T; 4],
        max_tilt_rad: T,
        max_torque_nm: T,
    ) -> Result<Self, Error> {
        const POLES: &str = "poles_rad_per_s";
        for p in poles_rad_per_s {
            if !(p.is_finite() && p < T::zero()) {
                return Err(Error::invalid(POLES, "every pole must be finite and < 0"));
            }
        }
        let lin = wip.linearize_upright();
        // Augmented state [theta, theta_dot, phi_dot, z], z_dot = -phi_dot.
        let keep = [TILT, TILT_RATE, BALL_RATE];
        let mut A = Matrix4::<T>::zeros();
        let mut B = Vector4::<T>::zeros();
        for (i, &ri) in keep.iter().enumerate() {
            for (j, &cj) in keep.iter().enumerate() {
                A[(i, j)] = lin.A[(ri, cj)];
            }
            B[i] = lin.B[ri];
        }
        A[(3, 2)] = -T::one();
        // Characteristic polynomial prod (s - p_i) = s^4 + c3 s^3 + c2 s^2 + c1 s + c0.
        let mut coeffs = [T::one(), T::zero(), T::zero(), T::zero(), T::zero()];
        for (n, p) in poles_rad_per_s.iter().enumerate() {
            // Multiply the degree-n polynomial (highest power first) by (s - p).
            for k in (1..=n + 1).rev() {
                let lower = coeffs[k - 1];
                coeffs[k] -= *p * lower;
            }
        }
        let I = Matrix4::<T>::identity();
        let A2 = A * A;
        let A3 = A2 * A;
        let phi = A3 * A + A3 * coeffs[1] + A2 * coeffs[2] + A * coeffs[3] + I * coeffs[4];
        let C = Matrix4::from_columns(&[B, A * B, A2 * B, A3 * B]);
        let C_inv = C.try_inverse().ok_or(Error::invalid(
            POLES,
            "the linearisation is not controllable",
        ))?;
        let K: RowVector4<T> = C_inv.row(3) * phi;
        let kp_t = K[0];
        if kp_t == T::zero() {
            return Err(Error::invalid(POLES, "give a zero tilt gain: move them"));
        }
        let gains = Self {
            speed_p_secs: K[2] / kp_t,
            speed_i_rad_per_rad: -K[3] / kp_t,
            tilt_p_nm_per_rad: kp_t,
            tilt_d_nm_s_per_rad: K[1],
            max_tilt_rad,
            max_torque_nm,
        };
        if !(gains.speed_p_secs.is_finite()
            && gains.speed_i_rad_per_rad.is_finite()
            && gains.tilt_p_nm_per_rad.is_finite()
            && gains.tilt_d_nm_s_per_rad.is_finite())
        {
            return Err(Error::invalid(POLES, "the design is numerically singular"));
        }
        gains.validate()?;
        Ok(gains)
    }

    /// The documented default for `wip`: [`Self::design`] with the poles
    /// [`PI_PD_DEFAULT_POLES_PER_P0`] times the open-loop unstable pole `p0`, and the tilt limit
    /// [`PI_PD_DEFAULT_MAX_TILT_RAD`]. Tested to recover every preset from a 10 deg tilt.
    ///
    /// ```
    /// use ballbot_core::control::PiPdGains;
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let g = PiPdGains::for_wip(&wip, 83.9)?;
    /// assert!(g.tilt_p_nm_per_rad < 0.0 && g.tilt_d_nm_s_per_rad < 0.0);
    /// assert!(g.speed_p_secs > 0.0 && g.speed_i_rad_per_rad > 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn for_wip(wip: &Wip<T>, max_torque_nm: T) -> Result<Self, Error> {
        let p0 = wip.upright_unstable_pole_rad_per_s();
        let poles = PI_PD_DEFAULT_POLES_PER_P0.map(|m| lit::<T>(m) * p0);
        Self::design(wip, poles, lit(PI_PD_DEFAULT_MAX_TILT_RAD), max_torque_nm)
    }
}

/// One PI-PD step's result, with each term for logging.
///
/// ```
/// use ballbot_core::control::{PiPdController, PiPdGains, StepStatus};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
/// let mut c = PiPdController::new(PiPdGains::for_wip(&wip, 83.9)?)?;
/// // A 10 m/s command asks for a reference tilt far beyond 0.2 rad: the tilt limit acts.
/// let r = wip.params().ball_radius_m;
/// let out = c.step(&Vector4::zeros(), &Vector4::new(0.0, 0.0, 0.0, 10.0 / r), 0.0025);
/// assert_eq!((out.reference_tilt_rad, out.status), (0.2, StepStatus::Saturated));
/// let requested = out.tilt_feedforward_rad + out.speed_p_term_rad + out.speed_i_term_rad;
/// approx::assert_relative_eq!(out.tilt_limit_rad, 0.2 - requested, epsilon = 1e-12);
/// approx::assert_relative_eq!(out.torque_nm, out.tilt_p_term_nm + out.tilt_d_term_nm);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiPdOutput<T> {
    /// The torque to apply, after saturation (N m). Always finite and within the limit.
    pub torque_nm: T,
    /// The reference tilt after the limit (rad).
    pub reference_tilt_rad: T,
    /// Outer feedforward: the command tilt `theta_c` (rad).
    pub tilt_feedforward_rad: T,
    /// Outer `kp_v e_v` (rad).
    pub speed_p_term_rad: T,
    /// Outer `ki_v z` (rad).
    pub speed_i_term_rad: T,
    /// Limited minus requested reference tilt (rad): zero unless the tilt limit acted.
    pub tilt_limit_rad: T,
    /// Inner `kp_t (theta_r - theta)` (N m).
    pub tilt_p_term_nm: T,
    /// Inner `kd_t (theta_dot_c - theta_dot)` (N m).
    pub tilt_d_term_nm: T,
    /// Applied minus requested torque (N m): zero unless saturated.
    pub saturation_nm: T,
    /// Whether the step was nominal, saturated (torque or tilt) or rejected.
    pub status: StepStatus,
}

impl_terms!(PiPdOutput {
    torque_nm,
    reference_tilt_rad,
    tilt_feedforward_rad,
    speed_p_term_rad,
    speed_i_term_rad,
    tilt_limit_rad,
    tilt_p_term_nm,
    tilt_d_term_nm,
    saturation_nm,
});

impl<T: RealField + Copy> PiPdOutput<T> {
    fn rejected() -> Self {
        let z = T::zero();
        Self {
            torque_nm: z,
            reference_tilt_rad: z,
            tilt_feedforward_rad: z,
            speed_p_term_rad: z,
            speed_i_term_rad: z,
            tilt_limit_rad: z,
            tilt_p_term_nm: z,
            tilt_d_term_nm: z,
            saturation_nm: z,
            status: StepStatus::InvalidInput,
        }
    }
}

/// The cascaded PI-PD controller (see the module docs).
///
/// ```
/// use ballbot_core::control::{PiPdController, PiPdGains};
/// use ballbot_core::{Wip, WipParams};
/// use nalgebra::Vector4;
/// let wip = Wip::new(WipParams::<f64>::piptb())?;
/// let mut c = PiPdController::new(PiPdGains::for_wip(&wip, 43.2)?)?;
/// // Commanded forward while at rest: the reference tilt leans forward, and the first torque
/// // rolls the ball back to tip the body forward (non-minimum phase).
/// let out = c.step(&Vector4::zeros(), &Vector4::new(0.0, 0.0, 0.0, 5.0), 1.0 / 400.0);
/// assert!(out.reference_tilt_rad > 0.0 && out.torque_nm < 0.0);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiPdController<T> {
    gains: PiPdGains<T>,
    /// Integrated ball-rate error `z` (rad).
    speed_error_integral_rad: T,
}

impl<T: RealField + Copy> PiPdController<T> {
    /// Validates `gains`; the integral starts at zero.
    ///
    /// ```
    /// use ballbot_core::control::{PiPdController, PiPdGains};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// let gains = PiPdGains::for_wip(&wip, 43.2)?;
    /// assert_eq!(PiPdController::new(gains)?.speed_error_integral_rad(), 0.0);
    /// assert!(PiPdController::new(PiPdGains { max_tilt_rad: -0.2, ..gains }).is_err());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(gains: PiPdGains<T>) -> Result<Self, Error> {
        gains.validate()?;
        Ok(Self {
            gains,
            speed_error_integral_rad: T::zero(),
        })
    }

    /// The gains in use.
    ///
    /// ```
    /// use ballbot_core::control::{PiPdController, PiPdGains};
    /// use ballbot_core::{Wip, WipParams};
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// let c = PiPdController::new(PiPdGains::for_wip(&wip, 43.2)?)?;
    /// assert_eq!(c.gains().max_torque_nm, 43.2);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn gains(&self) -> &PiPdGains<T> {
        &self.gains
    }

    /// The integrated ball-rate error `z` (rad).
    ///
    /// ```
    /// use ballbot_core::control::{PiPdController, PiPdGains};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// let mut c = PiPdController::new(PiPdGains::for_wip(&wip, 43.2)?)?;
    /// // 1 rad/s short of the command for one 2.5 ms step: z = 1 * 0.0025 rad.
    /// c.step(&Vector4::zeros(), &Vector4::new(0.0, 0.0, 0.0, 1.0), 0.0025);
    /// approx::assert_relative_eq!(c.speed_error_integral_rad(), 0.0025);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn speed_error_integral_rad(&self) -> T {
        self.speed_error_integral_rad
    }

    /// Clears the speed integral.
    ///
    /// ```
    /// use ballbot_core::control::{PiPdController, PiPdGains};
    /// use ballbot_core::{Wip, WipParams};
    /// use nalgebra::Vector4;
    /// let wip = Wip::new(WipParams::<f64>::piptb())?;
    /// let mut c = PiPdController::new(PiPdGains::for_wip(&wip, 43.2)?)?;
    /// c.step(&Vector4::zeros(), &Vector4::new(0.0, 0.0, 0.0, 1.0), 0.0025);
    /// c.reset();
    /// assert_eq!(c.speed_error_integral_rad(), 0.0);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.speed_error_integral_rad = T::zero();
    }

    /// One step. `measured` and `command` are full WIP states (`phi` ignored; the command's
    /// tilt is a feedforward on the reference tilt, its tilt rate the PD's rate reference),
    /// `dt_secs` the step (s). A non-finite input or `dt_secs <= 0` gives zero torque with
    /// [`StepStatus::InvalidInput`] and leaves the integral unchanged.
    ///
    /// ```
    /// use ballbot_core::control::{PiPdController, PiPdGains, StepStatus};
    /// use ballbot_core::{Wip, WipParams, rk4_step};
    /// use nalgebra::Vector4;
    /// // MiaPURE with 60 kg at 400 Hz, from a 10 deg forward lean to a 1 m/s command.
    /// let wip = Wip::new(WipParams::<f64>::miapure_60kg())?;
    /// let mut c = PiPdController::new(PiPdGains::for_wip(&wip, 83.9)?)?;
    /// let speed_rad_per_s = 1.0 / wip.params().ball_radius_m;
    /// let command = Vector4::new(0.0, 0.0, 0.0, speed_rad_per_s);
    /// let mut s = Vector4::new(10f64.to_radians(), 0.0, 0.0, 0.0);
    /// for _ in 0..20 * 400 {
    ///     let out = c.step(&s, &command, 0.0025);
    ///     assert_ne!(out.status, StepStatus::InvalidInput);
    ///     s = rk4_step(|x| wip.derivative(x, out.torque_nm), &s, 0.0025);
    /// }
    /// // Upright, and the speed integral has removed the speed error.
    /// assert!(s[0].abs() < 1e-3 && (s[3] - speed_rad_per_s).abs() < 1e-2 * speed_rad_per_s);
    /// // A NaN measurement: zero torque, flagged, the integral untouched.
    /// let z = c.speed_error_integral_rad();
    /// let out = c.step(&Vector4::new(f64::NAN, 0.0, 0.0, 0.0), &command, 0.0025);
    /// assert_eq!((out.torque_nm, out.status), (0.0, StepStatus::InvalidInput));
    /// assert_eq!(c.speed_error_integral_rad(), z);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn step(
        &mut self,
        measured: &WipState<T>,
        command: &WipState<T>,
        dt_secs: T,
    ) -> PiPdOutput<T> {
        if !(state_is_finite(measured) && state_is_finite(command) && dt_is_valid(dt_secs)) {
            return PiPdOutput::rejected();
        }
        let g = &self.gains;
        let speed_error = command[BALL_RATE] - measured[BALL_RATE];
        let speed_p = g.speed_p_secs * speed_error;
        let speed_i = g.speed_i_rad_per_rad * self.speed_error_integral_rad;
        let tilt_requested = command[TILT] + speed_p + speed_i;
        let (tilt_ref, tilt_status) = saturate(tilt_requested, g.max_tilt_rad);
        let tilt_p = g.tilt_p_nm_per_rad * (tilt_ref - measured[TILT]);
        let tilt_d = g.tilt_d_nm_s_per_rad * (command[TILT_RATE] - measured[TILT_RATE]);
        let requested = tilt_p + tilt_d;
        if !(requested.is_finite() && tilt_requested.is_finite()) {
            return PiPdOutput::rejected();
        }
        let (torque, torque_status) = saturate(requested, g.max_torque_nm);

        // Conditional integration: skip when advancing would push further into a limit.
        let tilt_push = g.speed_i_rad_per_rad * speed_error;
        let torque_push = g.tilt_p_nm_per_rad * tilt_push;
        let zero = T::zero();
        let tilt_blocked = (tilt_requested > g.max_tilt_rad && tilt_push > zero)
            || (tilt_requested < -g.max_tilt_rad && tilt_push < zero);
        let torque_blocked = (requested > g.max_torque_nm && torque_push > zero)
            || (requested < -g.max_torque_nm && torque_push < zero);
        if !(tilt_blocked || torque_blocked) {
            let next = self.speed_error_integral_rad + speed_error * dt_secs;
            if next.is_finite() {
                self.speed_error_integral_rad = next;
            }
        }
        let status = if torque_status == StepStatus::Saturated {
            torque_status
        } else {
            tilt_status
        };
        PiPdOutput {
            torque_nm: torque,
            reference_tilt_rad: tilt_ref,
            tilt_feedforward_rad: command[TILT],
            speed_p_term_rad: speed_p,
            speed_i_term_rad: speed_i,
            tilt_limit_rad: tilt_ref - tilt_requested,
            tilt_p_term_nm: tilt_p,
            tilt_d_term_nm: tilt_d,
            saturation_nm: torque - requested,
            status,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::WipParams;

    fn wip(p: WipParams<f64>) -> Wip<f64> {
        Wip::new(p).unwrap()
    }

    /// Eigenvalues of the augmented closed loop A - B K, via its characteristic polynomial
    /// evaluated at the design poles (det(pI - (A - BK)) = 0).
    #[test]
    #[allow(non_snake_case)]
    fn design_places_the_requested_poles() {
        for params in [
            WipParams::miapure_60kg(),
            WipParams::miapure_unloaded(),
            WipParams::piptb(),
        ] {
            let w = wip(params);
            let poles = [-12.0, -7.0, -3.0, -1.5];
            let g = PiPdGains::design(&w, poles, 0.2, 100.0).unwrap();
            let lin = w.linearize_upright();
            let keep = [TILT, TILT_RATE, BALL_RATE];
            let mut A = Matrix4::zeros();
            let mut B = Vector4::zeros();
            for i in 0..3 {
                for j in 0..3 {
                    A[(i, j)] = lin.A[(keep[i], keep[j])];
                }
                B[i] = lin.B[keep[i]];
            }
            A[(3, 2)] = -1.0;
            let kp = g.tilt_p_nm_per_rad;
            let K = RowVector4::new(
                kp,
                g.tilt_d_nm_s_per_rad,
                kp * g.speed_p_secs,
                -kp * g.speed_i_rad_per_rad,
            );
            let Acl = A - B * K;
            for p in poles {
                let det = (Matrix4::identity() * p - Acl).determinant();
                // Scale: the product of distances to the other poles.
                let scale: f64 = poles
                    .iter()
                    .filter(|&&q| q != p)
                    .map(|q| (p - q).abs())
                    .product();
                assert!(det.abs() < 1e-8 * scale, "pole {p}: det {det}");
            }
        }
    }

    #[test]
    fn validation_names_the_field() {
        let w = wip(WipParams::piptb());
        let mut g = PiPdGains::for_wip(&w, 43.2).unwrap();
        g.max_tilt_rad = -1.0;
        assert!(matches!(
            PiPdController::new(g),
            Err(Error::InvalidParameter {
                field: "max_tilt_rad",
                ..
            })
        ));
        assert!(matches!(
            PiPdGains::design(&w, [-1.0, -2.0, 0.5, -3.0], 0.2, 43.2),
            Err(Error::InvalidParameter {
                field: "poles_rad_per_s",
                ..
            })
        ));
    }

    #[test]
    fn tilt_limit_stops_the_integral() {
        let w = wip(WipParams::piptb());
        let mut c = PiPdController::new(PiPdGains::for_wip(&w, 43.2).unwrap()).unwrap();
        // A huge speed error: the reference tilt clips at the limit; the integral must not
        // grow while it does.
        let sc = Vector4::new(0.0, 0.0, 0.0, 1000.0);
        let out = c.step(&Vector4::zeros(), &sc, 0.0025);
        assert_eq!(out.reference_tilt_rad, 0.2);
        assert!(out.tilt_limit_rad < 0.0);
        assert_eq!(c.speed_error_integral_rad(), 0.0);
        // A non-finite step is rejected and holds the integral.
        let out = c.step(
            &Vector4::zeros(),
            &Vector4::new(0.0, 0.0, f64::NAN, 0.0),
            0.0025,
        );
        assert_eq!((out.torque_nm, out.status), (0.0, StepStatus::InvalidInput));
    }
}
