//! Transmission friction on the relative joint (wheel against body): stiction, Coulomb and
//! viscous, with the Karnopp stick-slip model.
//!
//! The joint is the one the motor drives: its rate is `v = phi_dot - theta_dot`. The friction
//! torque `tau_f` enters the WIP exactly like the motor torque (it is a torque between body and
//! ball), so the plant integrates `M q_ddot + ... = [-1, 1]^T (tau_m + tau_f)`.
//!
//! # Karnopp model
//!
//! Outside a small velocity window `|v| >= w` the joint slips and
//! `tau_f = -(T_c sign(v) + b_v v)` (Coulomb plus viscous).
//!
//! Inside the window the joint is treated as stuck: `tau_f` is the torque that holds it, i.e.
//! that makes the relative acceleration `v_dot` equal to `-v / t_secs` (zero, plus a first-order
//! pull of the residual window velocity to zero with time constant `t_secs`, so a stuck joint does
//! not creep). Because `q_ddot` is affine in the joint torque,
//! `v_dot(tau) = v_dot(tau_m) + k (tau - tau_m)` with `k = [-1, 1] M^-1 [-1, 1]^T > 0`, so
//!
//! ```text
//! tau_hold = -(v_dot(tau_m) + v / t_secs) / k
//! ```
//!
//! If `|tau_hold| <= T_s` (the breakaway or stiction torque) the joint sticks with
//! `tau_f = tau_hold`; otherwise it breaks away against `tau_f = T_s sign(tau_hold)`.
//!
//! The window must be wide enough that a joint that should stick cannot jump across it in one
//! integration step; [`TransmissionFriction::min_stick_window_rad_per_s`] gives the bound
//! (`w >= k (T_s + T_c) dt`), and the simulator rejects a narrower window.

use super::PlanarError;

/// Friction of the transmission between body and wheel (PIPTB) or ball (one ballbot plane),
/// acting on the relative joint rate `phi_dot - theta_dot`. All torques at the wheel.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields, default)]
pub struct TransmissionFriction {
    /// Breakaway (static) torque `T_s` (N m): the largest torque a stuck joint holds.
    #[schemars(range(min = 0))]
    pub stiction_torque_nm: f64,
    /// Coulomb (sliding) torque `T_c` (N m), `<= T_s`.
    #[schemars(range(min = 0))]
    pub coulomb_torque_nm: f64,
    /// Viscous coefficient `b_v` (N m s/rad) while slipping.
    #[schemars(range(min = 0))]
    pub viscous_nm_s_per_rad: f64,
    /// Half-width `w` of the Karnopp stick window on the joint rate (rad/s).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub stick_window_rad_per_s: f64,
    /// Time constant `t_secs` with which a stuck joint's residual rate is pulled to zero (s).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub stick_settle_time_secs: f64,
}

impl Default for TransmissionFriction {
    /// No friction (see [`TransmissionFriction::none`]).
    fn default() -> Self {
        Self::none()
    }
}

/// Which branch of the Karnopp model produced a friction torque.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionMode {
    /// The model has no friction at all.
    Free,
    /// Outside the window: Coulomb plus viscous.
    Slipping,
    /// Inside the window, held by friction.
    Stuck,
    /// Inside the window, the holding torque would exceed stiction: breaking away.
    BreakingAway,
}

impl FrictionMode {
    /// A small integer code for logs and plots: 0 free, 1 slipping, 2 stuck, 3 breaking away.
    pub fn code(self) -> u8 {
        match self {
            Self::Free => 0,
            Self::Slipping => 1,
            Self::Stuck => 2,
            Self::BreakingAway => 3,
        }
    }

    /// The mode's canonical name (snake_case, as serde writes it): `free`, `slipping`, `stuck`,
    /// `breaking_away`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Free => "free",
            Self::Slipping => "slipping",
            Self::Stuck => "stuck",
            Self::BreakingAway => "breaking_away",
        }
    }
}

impl TransmissionFriction {
    /// No friction: the ideal transmission of the controller's design model.
    pub fn none() -> Self {
        Self {
            stiction_torque_nm: 0.0,
            coulomb_torque_nm: 0.0,
            viscous_nm_s_per_rad: 0.0,
            stick_window_rad_per_s: 0.02,
            stick_settle_time_secs: 1e-3,
        }
    }

    /// The PIPTB's transmission (all values estimates; see `docs/piptb.md`).
    ///
    /// A 7.5:1 planetary quasi-direct-drive actuator: breakaway 0.5 N m (about 1.2 % of its
    /// 43.2 N m peak, the order of back-drive torques reported for such actuators), Coulomb
    /// 0.35 N m, viscous 0.01 N m s/rad (0.17 N m at the 17.5 rad/s of 1 m/s on a 57 mm
    /// wheel). The Karnopp window 0.02 rad/s is 1.1 mm/s at the wheel rim.
    pub fn piptb() -> Self {
        Self {
            stiction_torque_nm: 0.5,
            coulomb_torque_nm: 0.35,
            viscous_nm_s_per_rad: 0.01,
            stick_window_rad_per_s: 0.02,
            stick_settle_time_secs: 1e-3,
        }
    }

    /// `true` when every friction torque is zero (the plant then skips the model entirely).
    pub fn is_none(&self) -> bool {
        self.stiction_torque_nm == 0.0
            && self.coulomb_torque_nm == 0.0
            && self.viscous_nm_s_per_rad == 0.0
    }

    /// Checks every field; the error names the field (as in a scenario file's `[friction]`).
    pub fn validate(&self) -> Result<(), PlanarError> {
        let check = |v: f64, key: &'static str| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(PlanarError::invalid(key, "must be finite and >= 0"))
            }
        };
        check(self.stiction_torque_nm, "friction.stiction_torque_nm")?;
        check(self.coulomb_torque_nm, "friction.coulomb_torque_nm")?;
        check(self.viscous_nm_s_per_rad, "friction.viscous_nm_s_per_rad")?;
        if self.coulomb_torque_nm > self.stiction_torque_nm {
            return Err(PlanarError::invalid(
                "friction.coulomb_torque_nm",
                "must not exceed friction.stiction_torque_nm",
            ));
        }
        if !(self.stick_window_rad_per_s.is_finite() && self.stick_window_rad_per_s > 0.0) {
            return Err(PlanarError::invalid(
                "friction.stick_window_rad_per_s",
                "must be finite and > 0",
            ));
        }
        if !(self.stick_settle_time_secs.is_finite() && self.stick_settle_time_secs > 0.0) {
            return Err(PlanarError::invalid(
                "friction.stick_settle_time_secs",
                "must be finite and > 0",
            ));
        }
        Ok(())
    }

    /// The narrowest stick window (rad/s) a step of `dt_secs` tolerates: a joint decelerating
    /// under at most `T_s + T_c` of net torque changes its rate by `k (T_s + T_c) dt` per step
    /// and must not jump across the window. `joint_gain` is `k` (rad/s^2 per N m), largest
    /// upright.
    pub fn min_stick_window_rad_per_s(&self, joint_gain: f64, dt_secs: f64) -> f64 {
        joint_gain * (self.stiction_torque_nm + self.coulomb_torque_nm) * dt_secs
    }

    /// The friction torque (N m) and its branch, at joint rate `joint_rate_rad_per_s`, given the
    /// relative acceleration `free_joint_accel` (rad/s^2) the motor torque alone would produce
    /// and `joint_gain` `k` (rad/s^2 per N m of joint torque).
    #[inline]
    pub fn torque_nm(
        &self,
        joint_rate_rad_per_s: f64,
        free_joint_accel: f64,
        joint_gain: f64,
    ) -> (f64, FrictionMode) {
        let v = joint_rate_rad_per_s;
        if v.abs() >= self.stick_window_rad_per_s {
            let torque = -(self.coulomb_torque_nm * v.signum() + self.viscous_nm_s_per_rad * v);
            return (torque, FrictionMode::Slipping);
        }
        let hold = -(free_joint_accel + v / self.stick_settle_time_secs) / joint_gain;
        if hold.abs() <= self.stiction_torque_nm {
            (hold, FrictionMode::Stuck)
        } else {
            (
                self.stiction_torque_nm * hold.signum(),
                FrictionMode::BreakingAway,
            )
        }
    }

    /// `true` when [`Self::torque_nm`] needs the free acceleration (the rate is in the window).
    #[inline]
    pub fn in_window(&self, joint_rate_rad_per_s: f64) -> bool {
        joint_rate_rad_per_s.abs() < self.stick_window_rad_per_s
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn slipping_friction_opposes_motion() {
        let f = TransmissionFriction::piptb();
        let (t, m) = f.torque_nm(2.0, 0.0, 100.0);
        assert_eq!(m, FrictionMode::Slipping);
        assert!((t + 0.35 + 0.02).abs() < 1e-12);
        let (t, _) = f.torque_nm(-2.0, 0.0, 100.0);
        assert!((t - 0.35 - 0.02).abs() < 1e-12);
    }

    #[test]
    fn stuck_joint_holds_up_to_stiction_then_breaks_away() {
        let f = TransmissionFriction::piptb();
        let k = 100.0;
        // A motor torque of 0.3 N m alone would accelerate the joint at 30 rad/s^2.
        let (t, m) = f.torque_nm(0.0, 30.0, k);
        assert_eq!(m, FrictionMode::Stuck);
        assert!((t + 0.3).abs() < 1e-12);
        // 0.8 N m exceeds the 0.5 N m breakaway torque.
        let (t, m) = f.torque_nm(0.0, 80.0, k);
        assert_eq!(m, FrictionMode::BreakingAway);
        assert!((t + 0.5).abs() < 1e-12);
    }

    #[test]
    fn validation_names_the_key() {
        let mut f = TransmissionFriction::piptb();
        f.coulomb_torque_nm = 1.0;
        let err = f.validate().unwrap_err().to_string();
        assert!(err.contains("friction.coulomb_torque_nm"), "{err}");
        f = TransmissionFriction::piptb();
        f.stick_window_rad_per_s = 0.0;
        let err = f.validate().unwrap_err().to_string();
        assert!(err.contains("friction.stick_window_rad_per_s"), "{err}");
    }
}
