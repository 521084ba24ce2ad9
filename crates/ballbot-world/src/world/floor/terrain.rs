//! The floor's height map as rigid primitives, and where the ball touches each.
//!
//! * The **plane** through the origin with unit normal `n_p`: penetration `R - n_p . c`.
//! * A **bump** ([`FloorBump`]): a circular arc of chord `w` and rise `h`, i.e. a cylinder of
//!   radius `rho = (w^2/4 + h^2) / (2 h)` with its axis `h - rho` above the plane, lying across
//!   the path and `length_m` long; only the part above the plane is there (where the closest
//!   point lies below the plane, the plane carries the ball).
//! * A **step** ([`FloorStep`]): the plateau `s >= 0, z <= H` (with `s` the distance along
//!   `u`, the climbing direction, from the edge line) whose edge is rounded with radius `rho`:
//!   the set of points within `rho` of the inner corner region `s >= rho, z <= H - rho`. One
//!   distance gives the riser, the rounded edge and the top face, continuous in the ball's
//!   position. The coating's law is the flat one (`R_e = R`) over the whole step: a small
//!   edge radius would make it 5-25 times softer at the edge itself, but the ball's 47 mm patch
//!   straddles an edge of a few millimetres and meets the faces beside it, which a single
//!   curvature cannot say; the flat law is the stiffer, harsher side.
//!
//! Heights of bumps and steps are measured from the plane below the ball (module
//! [`super`]).

use super::super::rubber::{CoatingLaw, RubberLayer};
use super::law_on_cylinder;
use super::obstacle::{FloorBump, FloorStep};
use rapier3d_f64::glamx::DVec3;

/// Where the ball touches one primitive.
#[derive(Clone, Copy, Debug)]
pub(in crate::world) struct Patch {
    /// Unit normal from the surface towards the ball's centre.
    pub normal: DVec3,
    /// Penetration of the ball's undeformed surface into the primitive (m), > 0.
    pub penetration_m: f64,
    /// The coating's law there.
    pub law: CoatingLaw,
}

#[derive(Clone, Copy, Debug)]
enum Obstacle {
    Bump {
        /// A point on the cylinder's axis, at the bar's centre (m), its height above the plane.
        centre: [f64; 2],
        axis_height_m: f64,
        /// Unit vector along the bar.
        along: DVec3,
        half_length_m: f64,
        radius_m: f64,
        law: CoatingLaw,
    },
    Step {
        edge: [f64; 2],
        /// Unit climbing direction (horizontal).
        up: DVec3,
        height_m: f64,
        edge_radius_m: f64,
        law: CoatingLaw,
    },
}

/// The plane and the obstacles on it.
#[derive(Clone, Debug)]
pub(in crate::world) struct Terrain {
    normal: DVec3,
    plane_law: CoatingLaw,
    obstacles: Vec<Obstacle>,
}

impl Terrain {
    pub(in crate::world) fn new(normal: DVec3, layer: &RubberLayer, ball_radius_m: f64) -> Self {
        Self {
            normal,
            plane_law: CoatingLaw::new(layer, ball_radius_m),
            obstacles: Vec::new(),
        }
    }

    /// Number of primitives (the plane and the obstacles).
    pub(in crate::world) fn len(&self) -> usize {
        1 + self.obstacles.len()
    }

    pub(in crate::world) fn plane_law(&self) -> &CoatingLaw {
        &self.plane_law
    }

    pub(in crate::world) fn plane_normal(&self) -> DVec3 {
        self.normal
    }

    pub(in crate::world) fn add_bump(
        &mut self,
        bump: &FloorBump,
        layer: &RubberLayer,
        ball_radius_m: f64,
    ) {
        let (w, h) = (bump.width_m, bump.height_m);
        let rho = (0.25 * w * w + h * h) / (2.0 * h);
        let heading = bump.heading_deg.to_radians();
        self.obstacles.push(Obstacle::Bump {
            centre: bump.centre_m,
            axis_height_m: h - rho,
            along: DVec3::new(-heading.sin(), heading.cos(), 0.0),
            half_length_m: 0.5 * bump.length_m,
            radius_m: rho,
            law: law_on_cylinder(layer, rho, ball_radius_m),
        });
    }

    /// A step uses the flat law (module documentation).
    pub(in crate::world) fn add_step(&mut self, step: &FloorStep) {
        let heading = step.heading_deg.to_radians();
        self.obstacles.push(Obstacle::Step {
            edge: step.edge_m,
            up: DVec3::new(heading.cos(), heading.sin(), 0.0),
            height_m: step.height_m,
            edge_radius_m: step.edge_radius_m,
            law: self.plane_law,
        });
    }

    /// The plane's height at `(x, y)` (m).
    fn plane_height_m(&self, x: f64, y: f64) -> f64 {
        -(self.normal.x * x + self.normal.y * y) / self.normal.z
    }

    /// The floor's height at `(x, y)`: the plane plus the highest obstacle there (m).
    pub(in crate::world) fn height_m(&self, x: f64, y: f64) -> f64 {
        let base = self.plane_height_m(x, y);
        let p = DVec3::new(x, y, 0.0);
        let mut top: f64 = 0.0;
        for o in &self.obstacles {
            let h = match *o {
                Obstacle::Bump {
                    centre,
                    axis_height_m,
                    along,
                    half_length_m,
                    radius_m,
                    ..
                } => {
                    let d = p - DVec3::new(centre[0], centre[1], 0.0);
                    let across = (d - along * d.dot(along)).length();
                    if d.dot(along).abs() <= half_length_m && across < radius_m {
                        axis_height_m + (radius_m * radius_m - across * across).sqrt()
                    } else {
                        0.0
                    }
                }
                Obstacle::Step {
                    edge, up, height_m, ..
                } => {
                    let s = (p - DVec3::new(edge[0], edge[1], 0.0)).dot(up);
                    if s >= 0.0 { height_m } else { 0.0 }
                }
            };
            top = top.max(h);
        }
        base + top
    }

    /// Where the ball (centre `c`, radius `r`) touches primitive `index` (0: the plane), if it
    /// does.
    #[inline]
    pub(in crate::world) fn patch(&self, index: usize, c: DVec3, r: f64) -> Option<Patch> {
        if index == 0 {
            let penetration_m = r - self.normal.dot(c);
            return (penetration_m > 0.0).then_some(Patch {
                normal: self.normal,
                penetration_m,
                law: self.plane_law,
            });
        }
        // Heights above the plane below the ball.
        let z = c.z - self.plane_height_m(c.x, c.y);
        let local = DVec3::new(c.x, c.y, z);
        match self.obstacles[index - 1] {
            Obstacle::Bump {
                centre,
                axis_height_m,
                along,
                half_length_m,
                radius_m,
                law,
            } => {
                let axis = DVec3::new(centre[0], centre[1], axis_height_m);
                let t = (local - axis)
                    .dot(along)
                    .clamp(-half_length_m, half_length_m);
                let diff = local - (axis + along * t);
                let dist = diff.length();
                let penetration_m = r + radius_m - dist;
                if penetration_m <= 0.0 || dist <= 0.0 {
                    return None;
                }
                let normal = diff / dist;
                // The arc exists only above the plane.
                if axis_height_m + radius_m * normal.z < 0.0 {
                    return None;
                }
                Some(Patch {
                    normal,
                    penetration_m,
                    law,
                })
            }
            Obstacle::Step {
                edge,
                up,
                height_m,
                edge_radius_m,
                law,
            } => {
                let rho = edge_radius_m;
                let s = (local - DVec3::new(edge[0], edge[1], 0.0)).dot(up);
                let dx = (rho - s).max(0.0);
                let dz = (z - (height_m - rho)).max(0.0);
                let dist = (dx * dx + dz * dz).sqrt();
                let penetration_m = r + rho - dist;
                if penetration_m <= 0.0 {
                    return None;
                }
                let normal = if dist > 0.0 {
                    (DVec3::Z * dz - up * dx) / dist
                } else {
                    DVec3::Z
                };
                Some(Patch {
                    normal,
                    penetration_m: penetration_m.min(r),
                    law,
                })
            }
        }
    }
}
