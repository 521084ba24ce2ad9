//! Obstacles on the floor: a bump (a circular-arc bar) and a step (a plateau with a rounded
//! edge), added to a running world by `BallbotWorld::add_floor_bump` and `add_floor_step`.

use super::super::WorldError;
use super::super::check::positive;

/// A rigid bump across the robot's path with a circular-arc profile of chord `width_m` and
/// rise `height_m`: a rounded door threshold or a cable protector. The ball's coating rolls
/// over it ([`crate::world::floor`]); the wheels above may lose contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorBump {
    /// Where the bar's centre line crosses the path, on the floor (m).
    pub centre_m: [f64; 2],
    /// The path's direction (deg from world x); the bar lies across it.
    pub heading_deg: f64,
    /// Height: the arc's rise above the floor (m).
    pub height_m: f64,
    /// Width along the path: the chord of the arc at the floor (m).
    pub width_m: f64,
    /// Length across the path (m).
    pub length_m: f64,
}

impl FloorBump {
    /// Checks every field (finite; height, width and length > 0).
    ///
    /// ```
    /// use ballbot_world::world::FloorBump;
    /// let bump = FloorBump { centre_m: [1.0, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        width_m: 0.04, length_m: 2.0 };
    /// assert!(bump.validate().is_ok());
    /// let err = FloorBump { height_m: -0.01, ..bump }.validate().unwrap_err();
    /// assert!(err.to_string().contains("height_m"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        finite(self.centre_m[0], "centre_m")?;
        finite(self.centre_m[1], "centre_m")?;
        finite(self.heading_deg, "heading_deg")?;
        positive(self.height_m, "height_m")?;
        positive(self.width_m, "width_m")?;
        positive(self.length_m, "length_m")
    }
}

/// A step up across the robot's path: from the edge line on, the floor is `height_m` higher,
/// and the edge is rounded with `edge_radius_m`. Driven the other way, from a plateau the
/// robot starts on (`BallbotWorld::translate_robot` lifts it there), it is a step down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorStep {
    /// A point of the edge line on the floor (m).
    pub edge_m: [f64; 2],
    /// The climbing direction (deg from world x); the edge lies across it, infinitely long.
    pub heading_deg: f64,
    /// The plateau's height above the floor (m), > 0.
    pub height_m: f64,
    /// The edge's radius (m), in (0, `height_m`].
    pub edge_radius_m: f64,
}

impl FloorStep {
    /// Checks every field (finite; height > 0; edge radius in (0, height]).
    ///
    /// ```
    /// use ballbot_world::world::FloorStep;
    /// let step = FloorStep { edge_m: [0.5, 0.0], heading_deg: 0.0, height_m: 0.01,
    ///                        edge_radius_m: 0.002 };
    /// assert!(step.validate().is_ok());
    /// let err = FloorStep { edge_radius_m: 0.02, ..step }.validate().unwrap_err();
    /// assert!(err.to_string().contains("edge_radius_m"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        finite(self.edge_m[0], "edge_m")?;
        finite(self.edge_m[1], "edge_m")?;
        finite(self.heading_deg, "heading_deg")?;
        positive(self.height_m, "height_m")?;
        positive(self.edge_radius_m, "edge_radius_m")?;
        if self.edge_radius_m > self.height_m {
            return Err(WorldError::InvalidParameter {
                field: "edge_radius_m",
                requirement: "must be <= height_m",
            });
        }
        Ok(())
    }
}

fn finite(v: f64, field: &'static str) -> Result<(), WorldError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(WorldError::InvalidParameter {
            field,
            requirement: "must be finite",
        })
    }
}
