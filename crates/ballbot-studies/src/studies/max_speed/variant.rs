//! The robot variants of the sensitivity study: the nominal robot, another roller-ball
//! friction, another COM height.

use ballbot_world::world::WorldParams;

/// Which parameter a sensitivity row varies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Variant {
    /// The robot as given.
    Nominal,
    /// Roller-ball friction coefficient `mu` (dimensionless).
    WheelBallFriction(f64),
    /// COM height `l` of the body above the ball centre (m), in both planes.
    ComHeight(f64),
}

impl Variant {
    /// The world parameters of this variant.
    pub fn apply(&self, params: WorldParams) -> WorldParams {
        let mut p = params;
        match *self {
            Self::Nominal => {}
            Self::WheelBallFriction(mu) => p.robot.drivetrain.wheel_ball_friction = mu,
            Self::ComHeight(l) => {
                p.robot.sagittal.com_height_m = l;
                p.robot.frontal.com_height_m = l;
            }
        }
        p
    }
}
