//! Losses along an omniwheel's axle: the rollers' rolling resistance and their pin friction,
//! as a real force that opposes the axle-direction slip.
//!
//! # Model
//!
//! When the ball's surface moves along the axle `a` of a wheel relative to the rim,
//! `s_a = a . (v_ball(p) - v_rim(p))`, the roller under the contact turns about its pin. Two
//! losses resist it, both proportional to the normal force `N`:
//!
//! * rolling resistance of the roller on the rubber-covered ball, `C_rr N`;
//! * friction of the roller's bore on its pin (a plain bushing): the friction torque
//!   `mu_b N r_pin` divided by the roller's radius at the contact, `mu_b (r_pin / r_roller) N`.
//!
//! Together `F_a = -C_a N s_a / max(|s_a|, s_eps)` with `C_a = C_rr + mu_b r_pin / r_roller`:
//! Coulomb-like (constant magnitude `C_a N` once `|s_a| >= s_eps`), linear through zero slip
//! so that a contact at rest is not chattered by the sign. The force always opposes `s_a`, so
//! it never does positive work on the relative motion. It has no moment about the wheel's
//! axle (it is parallel to it), so the wheel's spin does not see it; ball and body do.
//!
//! The friction cone bounds the vector sum of this force and the traction along the rolling
//! direction (see [`crate::world::contact`]).
//!
//! # Step size
//!
//! The linear part is a damper `C_a N / s_eps` (N s/m) on the ball-surface-against-rim motion
//! (effective mass about 1 kg, see [`crate::world::contact`]); the explicit step needs
//! `C_a N dt / (s_eps m_eff) < 1`. With the MiaPURE values (`C_a` 0.042, `N` up to 1000 N,
//! `s_eps` 0.01 m/s, `dt` 125 us) it is 0.5.

use super::WorldError;
use super::check::non_negative;
use super::rollers::MIAPURE_ROLLER_RADIUS_M;

/// Rolling resistance and pin friction of the rollers, along each wheel's axle.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct AxleLossParams {
    /// Rolling resistance coefficient of a roller on the ball `C_rr` (force over load).
    /// Default 0 (the ideal world); [`AxleLossParams::miapure`] has 0.015.
    #[schemars(range(min = 0))]
    pub rolling_resistance: f64,
    /// Friction coefficient of the roller's bore on its pin `mu_b`. Default 0;
    /// [`AxleLossParams::miapure`] has 0.15.
    #[schemars(range(min = 0))]
    pub pin_friction: f64,
    /// Radius of the roller's pin `r_pin` (m). Default 0.002.
    #[schemars(range(min = 0))]
    pub pin_radius_m: f64,
    /// Radius of the roller at the contact `r_roller` (m), > `pin_radius_m`. Default 0.011
    /// ([`MIAPURE_ROLLER_RADIUS_M`]).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub roller_radius_m: f64,
    /// Axle slip speed `s_eps` below which the force is linear in the slip (m/s). Default
    /// 0.01: small against driving speeds (0.1 to 2 m/s) and keeping the explicit step stable
    /// (module documentation).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub regularisation_speed_m_per_s: f64,
}

impl Default for AxleLossParams {
    fn default() -> Self {
        Self::none()
    }
}

impl AxleLossParams {
    /// No losses along the axle: the ideal world.
    pub fn none() -> Self {
        Self {
            rolling_resistance: 0.0,
            pin_friction: 0.0,
            ..Self::miapure()
        }
    }

    /// Estimates for the MiaPURE omniwheels (TPU rollers on 60A SBR, pins in plain bores):
    ///
    /// * `rolling_resistance` 0.015: rubber tyres on hard surfaces roll at 0.010-0.015 of the
    ///   load (T. D. Gillespie, *Fundamentals of Vehicle Dynamics*, SAE 1992, ch. 4); the
    ///   soft 60A layer is the deforming body here, so the upper end.
    /// * `pin_friction` 0.15 with a 2 mm pin: dry polymer bushings on steel run at 0.1-0.25
    ///   (igus iglidur design data; POM on steel about 0.2); the 2 mm pin radius is an
    ///   estimate for a 125 mm wheel's roller pins (M4).
    /// * `roller_radius_m` 11 mm ([`MIAPURE_ROLLER_RADIUS_M`], estimate).
    ///
    /// `C_a` = 0.015 + 0.15 * 2 / 11 = 0.042 of the load, inside the 0.005-0.048 that
    /// S. Duda, G. Gembalczyk, T. Machoczek, Z. Kowalik measured for omniwheels (Sensors 25,
    /// 5026, 2025: 1.04-10.34 N at 215.8 N).
    pub fn miapure() -> Self {
        Self {
            rolling_resistance: 0.015,
            pin_friction: 0.15,
            pin_radius_m: 0.002,
            roller_radius_m: MIAPURE_ROLLER_RADIUS_M,
            regularisation_speed_m_per_s: 0.01,
        }
    }

    /// The force per unit load once the axle slip exceeds the regularisation speed,
    /// `C_a = C_rr + mu_b r_pin / r_roller`.
    pub fn coefficient(&self) -> f64 {
        self.rolling_resistance + self.pin_friction * self.pin_radius_m / self.roller_radius_m
    }

    /// Checks every field; the error names it (`contact.axle_loss.pin_friction`).
    pub fn validate(&self) -> Result<(), WorldError> {
        non_negative(
            self.rolling_resistance,
            "contact.axle_loss.rolling_resistance",
        )?;
        non_negative(self.pin_friction, "contact.axle_loss.pin_friction")?;
        non_negative(self.pin_radius_m, "contact.axle_loss.pin_radius_m")?;
        if !(self.roller_radius_m.is_finite() && self.roller_radius_m > self.pin_radius_m) {
            return Err(WorldError::InvalidParameter {
                field: "contact.axle_loss.roller_radius_m",
                requirement: "must be finite and > contact.axle_loss.pin_radius_m",
            });
        }
        if !(self.regularisation_speed_m_per_s.is_finite()
            && self.regularisation_speed_m_per_s > 0.0)
        {
            return Err(WorldError::InvalidParameter {
                field: "contact.axle_loss.regularisation_speed_m_per_s",
                requirement: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn miapure_coefficient_adds_rolling_and_pin_losses() {
        let c = AxleLossParams::miapure().coefficient();
        assert!((c - (0.015 + 0.15 * 2.0 / 11.0)).abs() < 1e-15);
        assert!(c > 0.005 && c < 0.048, "inside Duda et al.'s range: {c}");
        assert_eq!(AxleLossParams::none().coefficient(), 0.0);
    }

    #[test]
    fn rejects_bad_fields_naming_them() {
        let mut p = AxleLossParams::miapure();
        p.roller_radius_m = 0.001;
        assert!(matches!(
            p.validate(),
            Err(WorldError::InvalidParameter {
                field: "contact.axle_loss.roller_radius_m",
                ..
            })
        ));
        let mut p = AxleLossParams::miapure();
        p.pin_friction = -0.1;
        assert!(matches!(
            p.validate(),
            Err(WorldError::InvalidParameter {
                field: "contact.axle_loss.pin_friction",
                ..
            })
        ));
        let mut p = AxleLossParams::miapure();
        p.regularisation_speed_m_per_s = 0.0;
        assert!(matches!(
            p.validate(),
            Err(WorldError::InvalidParameter {
                field: "contact.axle_loss.regularisation_speed_m_per_s",
                ..
            })
        ));
    }
}
