//! Roller gaps of a single-plate omniwheel: the wheel's effective radius at the contact dips
//! once per roller pitch.
//!
//! # Geometry
//!
//! A single-plate omniwheel carries `N_r` barrel rollers in one plane; their profiles in the
//! wheel plane lie on the rim circle of radius `r_W`, and between two roller ends a lug of the
//! plate holds the pins, leaving a gap of width `g` (a chord of the rim) with no roller
//! material. Let `u` be the angle between the contact normal (the line of wheel and ball
//! centres) and the centre of the nearest gap, measured about the axle. While `|u| < h`, with
//! the gap half-angle `h = g / (2 r_W)`, the ball (outer radius `R`) cannot touch the rim on
//! the line of centres; it rests on the nearer roller end, at the angle `theta_e = h - |u|`
//! from that line. A ball of radius `R` touching the rim point at angle `theta_e` has its
//! centre at distance `r_W cos theta_e + sqrt(R^2 - r_W^2 sin^2 theta_e)` from the wheel
//! centre, so the wheel's effective radius (centre distance minus `R`) is
//!
//! ```text
//! r_eff = r_W - dip,   dip(theta_e) = r_W + R - r_W cos theta_e - sqrt(R^2 - r_W^2 sin^2 theta_e)
//!       ~ (1/r_W + 1/R) (r_W theta_e)^2 / 2,     peak (u = 0): dip_max ~ (1/r_W + 1/R) g^2 / 8
//! ```
//!
//! i.e. the sag of the two convex profiles (relative curvature `1/r_W + 1/R`) over half the
//! gap. The profile repeats with the roller pitch `2 pi / N_r` in the wheel angle `psi`; the
//! gaps are centred at `psi = (k + 1/2) 2 pi / N_r`, so a wheel at `psi = 0` touches mid-roller.
//!
//! The contact point moves to the roller end, which changes two more things:
//!
//! * the rim speed along the rolling direction is `r_rim psi_dot` with `r_rim = r_W cos theta_e`
//!   (the roller end moves partly along the normal), and the traction's lever arm on the wheel
//!   is the same `r_rim`;
//! * the normal force acts off the line of centres and exerts `N d(dip)/d(psi)` on the wheel
//!   about its axle: the generalised force of the normal spring `k delta` whose penetration
//!   `delta = r + r_eff(psi) - |w - c|` depends on `psi`. Its rate carries the term
//!   `-d(dip)/d(psi) psi_dot`.
//!
//! The force's direction still follows the line of centres: its true tilt, about
//! `r_W theta_e / R` (0.02 rad at the MiaPURE gap), is neglected, so the ball does not feel the
//! tangential part of it (about `N r_W theta_e / R`, up to 6 N); the wheel's torque is
//! reacted by the body through the hub, which keeps energy and angular momentum. Roller ends
//! are modelled sharp; chamfered ends widen the effective gap.
//!
//! # Excitation frequency
//!
//! The dip repeats `N_r` times per wheel turn: `f = N_r |psi_dot| / (2 pi)`. Rolling the ball at
//! `v` (m/s) along the heading `phi` under a body that translates with it gives wheel `i`
//! (azimuth `beta_i`, contact angle `alpha`) the speed `|psi_dot_i| = v cos(alpha)
//! |sin(phi - beta_i)| / r_W`, so
//!
//! ```text
//! f_i = N_r v cos(alpha) |sin(phi - beta_i)| / (2 pi r_W).
//! ```
//!
//! For MiaPURE (`alpha` = 45 deg, `r_W` = 62.5 mm) this is `1.80 N_r v |sin(phi - beta_i)|` Hz:
//! `1.56 N_r v` Hz for the two driving wheels when the robot heads towards the third wheel
//! (`|phi - beta_i|` = 120 deg), `1.80 N_r v` Hz for a wheel driving straight across its axle.

use super::WorldError;
use super::check::non_negative;
use super::num::floor;

/// Roller radius at mid-roller of the MiaPURE omniwheel (m): 11 mm. Estimate (no datasheet):
/// a 125 mm single-plate wheel with ten rollers has about 39 mm of rim per roller, and barrel
/// rollers of such wheels are about 22 mm across. Used by the axle-loss and rubber-contact
/// presets.
pub const MIAPURE_ROLLER_RADIUS_M: f64 = 0.011;

/// The rollers of each omniwheel (see the module documentation for the geometry).
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct RollerParams {
    /// Rollers per wheel `N_r` (0: a continuous ideal rim, no gaps). Default 0 (the ideal
    /// world); [`RollerParams::miapure`] has 10.
    pub count: u32,
    /// Gap between the ends of neighbouring rollers along the rim `g` (m), a chord of the rim
    /// circle. Default 0.004 in [`RollerParams::miapure`] (ignored while `count` is 0).
    #[schemars(range(min = 0))]
    pub gap_width_m: f64,
}

impl Default for RollerParams {
    fn default() -> Self {
        Self::none()
    }
}

impl RollerParams {
    /// A continuous rim: no gaps, the ideal world.
    pub fn none() -> Self {
        Self {
            count: 0,
            gap_width_m: 0.0,
        }
    }

    /// The MiaPURE omniwheel, 125 mm single-plate with TPU rollers (SeCure Inc.; the paper
    /// gives neither roller count nor gap). Assumptions, stated as such:
    ///
    /// * `count` 10: generic single-plate omniwheels of 100-150 mm carry 8 to 12 rollers; 10
    ///   is the middle of that range, not a datasheet value.
    /// * `gap_width_m` 4 mm: the plate's lug between two roller ends (3 mm of aluminium plate
    ///   to carry the pin under a 600 N wheel load) plus 0.5 mm running clearance each side.
    ///
    /// With the 114.5 mm ball this gives a peak dip of `(1/r_W + 1/R) g^2 / 8` = 49 um.
    pub fn miapure() -> Self {
        Self {
            count: 10,
            gap_width_m: 0.004,
        }
    }

    /// Checks the fields against a wheel of radius `wheel_radius_m`: the gaps must fit on the
    /// rim (`count g < 2 pi r_W`).
    pub fn validate(&self, wheel_radius_m: f64) -> Result<(), WorldError> {
        non_negative(self.gap_width_m, "contact.rollers.gap_width_m")?;
        if self.count > 0 && self.gap_width_m <= 0.0 {
            return Err(WorldError::InvalidParameter {
                field: "contact.rollers.gap_width_m",
                requirement: "must be > 0 when contact.rollers.count > 0",
            });
        }
        if f64::from(self.count) * self.gap_width_m >= std::f64::consts::TAU * wheel_radius_m {
            return Err(WorldError::InvalidParameter {
                field: "contact.rollers.count",
                requirement: "count * gap_width_m must be < the rim circumference 2 pi r_W",
            });
        }
        Ok(())
    }
}

/// Where the ball touches a wheel at one wheel angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RimContact {
    /// How far the effective radius dips below `r_W` (m), >= 0.
    pub dip_m: f64,
    /// `d(dip)/d(psi)` (m/rad).
    pub dip_slope_m_per_rad: f64,
    /// Lever arm of the traction and rim speed per wheel speed, `r_W cos theta_e` (m).
    pub rim_radius_m: f64,
}

/// [`RollerParams`] resolved against the wheel and ball radii for fast evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollerProfile {
    count: u32,
    pitch_rad: f64,
    half_gap_rad: f64,
    wheel_radius_m: f64,
    ball_radius_m: f64,
}

impl RollerProfile {
    /// The profile of `rollers` on a wheel of radius `wheel_radius_m` against a ball of radius
    /// `ball_radius_m`.
    pub fn new(rollers: &RollerParams, wheel_radius_m: f64, ball_radius_m: f64) -> Self {
        let count = rollers.count;
        Self {
            count,
            pitch_rad: if count > 0 {
                std::f64::consts::TAU / f64::from(count)
            } else {
                0.0
            },
            half_gap_rad: rollers.gap_width_m / (2.0 * wheel_radius_m),
            wheel_radius_m,
            ball_radius_m,
        }
    }

    /// Whether the rim has gaps at all.
    pub fn has_gaps(&self) -> bool {
        self.count > 0
    }

    /// The contact at wheel angle `psi_rad` (see the module documentation).
    pub fn at(&self, psi_rad: f64) -> RimContact {
        let r_w = self.wheel_radius_m;
        if self.count == 0 {
            return RimContact {
                dip_m: 0.0,
                dip_slope_m_per_rad: 0.0,
                rim_radius_m: r_w,
            };
        }
        // psi mod pitch, by floor rather than rem_euclid: libm's fmod was a tenth of the world
        // step's own instructions. The remainder can round to the pitch itself, which only
        // moves u to the other end of the same gap-free zone.
        let turns = floor(psi_rad / self.pitch_rad);
        let u = (psi_rad - turns * self.pitch_rad) - 0.5 * self.pitch_rad;
        let theta_e = self.half_gap_rad - u.abs();
        if theta_e <= 0.0 {
            return RimContact {
                dip_m: 0.0,
                dip_slope_m_per_rad: 0.0,
                rim_radius_m: r_w,
            };
        }
        let big_r = self.ball_radius_m;
        let (s, c) = theta_e.sin_cos();
        let root = (big_r * big_r - r_w * r_w * s * s).sqrt();
        let dip_m = r_w + big_r - r_w * c - root;
        // d(dip)/d(theta_e), and d(theta_e)/d(psi) = -sign(u).
        let d_dip_d_theta = r_w * s + r_w * r_w * s * c / root;
        RimContact {
            dip_m,
            dip_slope_m_per_rad: -u.signum() * d_dip_d_theta,
            rim_radius_m: r_w * c,
        }
    }

    /// The largest dip, at the gap centre (m): 0 without gaps.
    pub fn peak_dip_m(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.at(0.5 * self.pitch_rad).dip_m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile() -> RollerProfile {
        RollerProfile::new(&RollerParams::miapure(), 0.0625, 0.1145)
    }

    #[test]
    fn peak_dip_matches_the_relative_curvature_sag() {
        // (1/r_W + 1/R) g^2 / 8 = (16 + 8.734) * 16e-6 / 8 = 49.5 um.
        let p = profile();
        let sag = (1.0 / 0.0625 + 1.0 / 0.1145) * 0.004_f64.powi(2) / 8.0;
        assert!(
            (p.peak_dip_m() - sag).abs() < 0.01 * sag,
            "{}",
            p.peak_dip_m()
        );
        assert!((p.peak_dip_m() - 49.5e-6).abs() < 0.5e-6);
    }

    #[test]
    fn dip_is_periodic_and_zero_on_the_rollers() {
        let p = profile();
        let pitch = std::f64::consts::TAU / 10.0;
        assert_eq!(p.at(0.0).dip_m, 0.0);
        assert_eq!(p.at(0.0).rim_radius_m, 0.0625);
        for psi in [0.31, 0.3142, 0.32] {
            let a = p.at(psi);
            let b = p.at(psi + 3.0 * pitch);
            let c = p.at(psi - 7.0 * pitch);
            assert!((a.dip_m - b.dip_m).abs() < 1e-12 && (a.dip_m - c.dip_m).abs() < 1e-12);
            assert!(a.dip_m > 0.0);
            assert!(a.rim_radius_m < 0.0625);
        }
    }

    #[test]
    fn dip_slope_is_the_derivative_of_the_dip() {
        let p = profile();
        let centre = std::f64::consts::PI / 10.0;
        for offset in [-0.02, -0.01, 0.005, 0.02] {
            let psi = centre + offset;
            let h = 1e-7;
            let numeric = (p.at(psi + h).dip_m - p.at(psi - h).dip_m) / (2.0 * h);
            let slope = p.at(psi).dip_slope_m_per_rad;
            assert!(
                (slope - numeric).abs() < 1e-6 * numeric.abs().max(1e-9),
                "{slope} {numeric}"
            );
            // Approaching the gap centre the dip grows.
            assert_eq!(slope > 0.0, offset < 0.0);
        }
    }

    #[test]
    fn rejects_gaps_that_do_not_fit_naming_the_field() {
        let too_many = RollerParams {
            count: 200,
            gap_width_m: 0.004,
        };
        match too_many.validate(0.0625) {
            Err(WorldError::InvalidParameter { field, .. }) => {
                assert_eq!(field, "contact.rollers.count");
            }
            other => panic!("{other:?}"),
        }
        let no_gap = RollerParams {
            count: 10,
            gap_width_m: 0.0,
        };
        assert!(matches!(
            no_gap.validate(0.0625),
            Err(WorldError::InvalidParameter {
                field: "contact.rollers.gap_width_m",
                ..
            })
        ));
        assert!(RollerParams::miapure().validate(0.0625).is_ok());
        assert!(RollerParams::none().validate(0.0625).is_ok());
    }
}
