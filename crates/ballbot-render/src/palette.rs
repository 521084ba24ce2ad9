//! The frame's colours. Some are exact on purpose: a filled shape's inside is painted with
//! exactly its colour, so tests (and a viewer) can find a lifted wheel or the wheels by it.

/// An opaque colour.
pub type Rgb = [u8; 3];

/// Sky at the top of the frame.
pub const SKY_TOP: Rgb = [222, 230, 240];
/// Sky at the horizon.
pub const SKY_HORIZON: Rgb = [245, 247, 250];
/// The floor.
pub const FLOOR: Rgb = [206, 200, 188];
/// Every other floor tile.
pub const FLOOR_TILE: Rgb = [188, 181, 168];
/// The floor grid's lines.
pub const GRID_LINE: Rgb = [150, 143, 130];
/// The ball (lit side).
pub const BALL_LIGHT: Rgb = [150, 185, 230];
/// The ball (shaded side).
pub const BALL_DARK: Rgb = [35, 62, 120];
/// The marks on the ball that show it rolling.
pub const BALL_MARK: Rgb = [245, 245, 240];
/// The body's plates and mast.
pub const BODY: Rgb = [172, 176, 186];
/// The omniwheels OW1, OW2, OW3 in contact, each its own dark tint: the inside of a wheel is
/// exactly its colour.
pub const WHEELS: [Rgb; 3] = [[40, 52, 96], [34, 82, 56], [92, 44, 78]];
/// The rollers on a wheel's rim.
pub const ROLLER: Rgb = [228, 190, 80];
/// A lifted-off wheel and its label: exactly this, and nothing else is.
pub const LIFT_OFF: Rgb = [222, 28, 40];
/// A slipping wheel's label.
pub const SLIP: Rgb = [225, 110, 10];
/// Outlines and text.
pub const INK: Rgb = [28, 30, 36];
/// Friction-cone use 0 (green), 0.5 (yellow), 1 and beyond (red) of the force arrows.
pub const CONE_RAMP: [Rgb; 3] = [[40, 170, 70], [235, 200, 30], [205, 45, 45]];

/// The force arrow's colour for a friction-cone utilisation `u` (0 green, 1 red).
pub fn cone_colour(u: f64) -> Rgb {
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let (a, b, s) = if u < 0.5 {
        (CONE_RAMP[0], CONE_RAMP[1], 2.0 * u)
    } else {
        (CONE_RAMP[1], CONE_RAMP[2], 2.0 * u - 1.0)
    };
    let mix = |k: usize| (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * s).round() as u8;
    [mix(0), mix(1), mix(2)]
}

/// `rgb` scaled by `k` (shading), saturated.
pub fn shade(rgb: Rgb, k: f64) -> Rgb {
    rgb.map(|c| (f64::from(c) * k).round().clamp(0.0, 255.0) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cone_ramp_runs_green_to_red_and_never_gives_the_lift_off_colour() {
        assert_eq!(cone_colour(0.0), CONE_RAMP[0]);
        assert_eq!(cone_colour(1.7), CONE_RAMP[2]);
        assert_eq!(cone_colour(f64::NAN), CONE_RAMP[2]);
        assert!((0..=100).all(|i| cone_colour(f64::from(i) / 100.0) != LIFT_OFF));
    }
}
