//! What the traction study runs ([`TractionStudySettings`]) and its friction patches
//! ([`PatchVariant`]).

use super::runs::{Control, FrictionPatch};
use crate::studies::max_speed::MaxSpeedProtocol;
use ballbot_core::command::LeanToDriveParams;

/// What the study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionStudySettings {
    /// The failing-acceleration protocol and the shaper caps every `on`/`off` run uses
    /// ([`MaxSpeedProtocol::default`]: ramps to 3 m/s, search in [0.5, 3] m/s^2 on a
    /// 0.05 m/s^2 grid, caps 8 m/s and 20 m/s^2).
    pub protocol: MaxSpeedProtocol,
    /// Headings of the failing-acceleration comparison (deg). Default 0 to 345 every 15.
    pub headings_deg: Vec<f64>,
    /// Seed of the sensor noise of every run. Default 1.
    pub seed: u64,
    /// More seeds for the traction-on ramps at the search's top request (`failed_on` if any
    /// fails). Default 2, 3; none in the quick variant.
    pub extra_on_seeds: Vec<u64>,
    /// Headings of the stop from 1.4 m/s (deg). Default 0, 90, 180.
    pub stop_headings_deg: Vec<f64>,
    /// Controllers of the stop. Default on, off, shipped.
    pub stop_controls: Vec<Control>,
    /// Patch variants. Default floor and wet.
    pub patch_variants: Vec<PatchVariant>,
    /// Controllers of the patch crossings and the rider runs. Default on, off.
    pub controls: Vec<Control>,
    /// Directions the rider leans (deg). Default 0 (back, towards OW1) and 180 (forward).
    pub rider_headings_deg: Vec<f64>,
    /// The rider's lean-to-drive settings. Default a sporty rider: the rider defaults with
    /// 2 m/s (the paper's design target) and 2 m/s^2 (an acceleration the strong direction
    /// carries: the 3D world's failing acceleration away from OW1 is above 3 m/s^2).
    pub rider: LeanToDriveParams<f64>,
    /// The rider's lean (rad). Default 0.3 (17 deg, far beyond the 3 deg deadband: full speed).
    pub rider_lean_rad: f64,
    /// Worker threads; 0 uses every available core. Default 0.
    pub threads: usize,
}

impl TractionStudySettings {
    /// The full study.
    pub fn paper() -> Self {
        Self {
            protocol: MaxSpeedProtocol::default(),
            headings_deg: (0..24).map(|k| f64::from(k) * 15.0).collect(),
            seed: 1,
            extra_on_seeds: vec![2, 3],
            stop_headings_deg: vec![0.0, 90.0, 180.0],
            stop_controls: vec![Control::TractionOn, Control::TractionOff, Control::Shipped],
            patch_variants: PatchVariant::ALL.to_vec(),
            controls: vec![Control::TractionOn, Control::TractionOff],
            rider_headings_deg: vec![0.0, 180.0],
            rider: LeanToDriveParams {
                max_speed_m_per_s: 2.0,
                max_accel_m_per_s2: 2.0,
                ..LeanToDriveParams::rider()
            },
            rider_lean_rad: 0.3,
            threads: 0,
        }
    }

    /// The CI smoke variant: 0 and 180 deg on a 0.25 m/s^2 search grid, the stop with
    /// traction control on at 0 and 180 deg, the wet patch and the rider leaning back, on and
    /// off.
    pub fn quick() -> Self {
        let paper = Self::paper();
        Self {
            protocol: MaxSpeedProtocol {
                accel_resolution_m_per_s2: 0.25,
                ..paper.protocol
            },
            headings_deg: vec![0.0, 180.0],
            extra_on_seeds: Vec::new(),
            stop_headings_deg: vec![0.0, 180.0],
            stop_controls: vec![Control::TractionOn],
            patch_variants: vec![PatchVariant::Wet],
            rider_headings_deg: vec![0.0],
            ..paper
        }
    }
}

/// Which friction patch, and how it is crossed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchVariant {
    /// The floor at mu 0.3 (the case), crossed cruising at 1.4 m/s.
    Floor,
    /// A wet patch (the floor at mu 0.3 and the wheel-ball friction at 0.3 while the ball is
    /// on it: the water wets the ball), crossed cruising at 1.4 m/s.
    WetCruise,
    /// The wet patch crossed while the ball still accelerates towards 2 m/s at the envelope's
    /// acceleration towards OW1 (1.30 m/s^2, planned for mu 0.6) and passes 1.4 m/s: more than
    /// the wet contacts carry, and the wheels slip.
    Wet,
}

impl PatchVariant {
    /// All three.
    pub const ALL: [Self; 3] = [Self::Floor, Self::WetCruise, Self::Wet];

    /// The name in JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Floor => "floor_mu_0.3",
            Self::WetCruise => "wet_mu_0.3_cruise",
            Self::Wet => "wet_mu_0.3",
        }
    }

    /// The patch itself: 0.5 m at mu 0.3, wet or not.
    pub fn patch(self) -> FrictionPatch {
        FrictionPatch {
            length_m: 0.5,
            floor_friction: 0.3,
            wheel_ball_friction: (self != Self::Floor).then_some(0.3),
        }
    }

    /// Whether the patch is crossed cruising (at 1.4 m/s), not accelerating.
    pub fn cruising(self) -> bool {
        self != Self::Wet
    }
}
