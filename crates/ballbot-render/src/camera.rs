//! The camera: a fixed 3/4 perspective view (azimuth and elevation fixed in the world) that
//! follows a target point, and the projection of world points to pixels.

use nalgebra::{Point2, Vector3};

/// Points closer to the camera than this along its view axis are clipped (m).
const NEAR_M: f64 = 0.05;

/// A pinhole camera looking at a target from a fixed direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    eye: Vector3<f64>,
    right: Vector3<f64>,
    up: Vector3<f64>,
    forward: Vector3<f64>,
    focal_px: f64,
    centre_px: (f64, f64),
}

/// Where the camera sits relative to what it looks at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Direction from the target to the camera, seen from above (deg, counter-clockwise from
    /// world +x).
    pub azimuth_deg: f64,
    /// Height of the camera above the target's horizon (deg).
    pub elevation_deg: f64,
    /// Distance from the camera to the target (m).
    pub distance_m: f64,
    /// Vertical field of view (deg).
    pub fov_deg: f64,
}

impl Default for CameraView {
    /// A 3/4 view from the front right, 38 deg above the horizon, 1.6 m away.
    fn default() -> Self {
        Self {
            azimuth_deg: -60.0,
            elevation_deg: 38.0,
            distance_m: 1.6,
            fov_deg: 32.0,
        }
    }
}

impl Camera {
    /// The camera of `view` looking at `target`, for an image `width` x `height` pixels.
    pub fn new(view: &CameraView, target: Vector3<f64>, width: u32, height: u32) -> Self {
        let (sa, ca) = view.azimuth_deg.to_radians().sin_cos();
        let (se, ce) = view.elevation_deg.to_radians().sin_cos();
        let back = Vector3::new(ce * ca, ce * sa, se);
        let eye = target + back * view.distance_m;
        let forward = -back;
        let right = forward.cross(&Vector3::z()).normalize();
        let up = right.cross(&forward);
        let focal_px = 0.5 * f64::from(height) / (0.5 * view.fov_deg.to_radians()).tan();
        Self {
            eye,
            right,
            up,
            forward,
            focal_px,
            centre_px: (0.5 * f64::from(width), 0.5 * f64::from(height)),
        }
    }

    /// The camera's position (m).
    pub fn eye(&self) -> Vector3<f64> {
        self.eye
    }

    /// Distance of `p` in front of the camera along its view axis (m): larger is farther.
    pub fn depth(&self, p: &Vector3<f64>) -> f64 {
        (p - self.eye).dot(&self.forward)
    }

    /// Pixels per metre at the depth `depth_m`.
    pub fn scale_at(&self, depth_m: f64) -> f64 {
        self.focal_px / depth_m.max(NEAR_M)
    }

    /// The pixel of `p`, `None` behind the near plane.
    pub fn project(&self, p: &Vector3<f64>) -> Option<Point2<f64>> {
        let d = p - self.eye;
        let z = d.dot(&self.forward);
        (z >= NEAR_M).then(|| self.pixel_of(&d, z))
    }

    fn pixel_of(&self, d: &Vector3<f64>, z: f64) -> Point2<f64> {
        Point2::new(
            self.centre_px.0 + self.focal_px * d.dot(&self.right) / z,
            self.centre_px.1 - self.focal_px * d.dot(&self.up) / z,
        )
    }

    /// A world polygon's pixels, clipped at the near plane (empty when wholly behind it).
    pub fn project_polygon(&self, points: &[Vector3<f64>]) -> Vec<Point2<f64>> {
        let mut out = Vec::with_capacity(points.len() + 2);
        let n = points.len();
        for i in 0..n {
            let (a, b) = (points[i], points[(i + 1) % n]);
            let (da, db) = (self.depth(&a), self.depth(&b));
            if da >= NEAR_M {
                out.push(self.pixel_of(&(a - self.eye), da));
            }
            if (da >= NEAR_M) != (db >= NEAR_M) {
                let s = (NEAR_M - da) / (db - da);
                let p = a + (b - a) * s;
                out.push(self.pixel_of(&(p - self.eye), NEAR_M));
            }
        }
        out
    }

    /// A world segment's pixels, clipped at the near plane.
    pub fn project_segment(
        &self,
        a: &Vector3<f64>,
        b: &Vector3<f64>,
    ) -> Option<(Point2<f64>, Point2<f64>)> {
        let (da, db) = (self.depth(a), self.depth(b));
        if da < NEAR_M && db < NEAR_M {
            return None;
        }
        let cut = |p: &Vector3<f64>, q: &Vector3<f64>, dp: f64, dq: f64| {
            if dp >= NEAR_M {
                *p
            } else {
                p + (q - p) * ((NEAR_M - dp) / (dq - dp))
            }
        };
        let (a2, b2) = (cut(a, b, da, db), cut(b, a, db, da));
        Some((self.project(&a2)?, self.project(&b2)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_is_the_image_centre_and_up_is_up() {
        let target = Vector3::new(1.0, 2.0, 0.3);
        let cam = Camera::new(&CameraView::default(), target, 480, 360);
        let c = cam.project(&target).unwrap_or(Point2::origin());
        assert!((c.x - 240.0).abs() < 1e-9 && (c.y - 180.0).abs() < 1e-9);
        let above = cam.project(&(target + Vector3::z() * 0.1));
        assert!(above.is_some_and(|p| p.y < 180.0));
        assert!((cam.depth(&target) - 1.6).abs() < 1e-9);
    }

    #[test]
    fn a_polygon_behind_the_camera_is_clipped_away() {
        let cam = Camera::new(&CameraView::default(), Vector3::zeros(), 480, 360);
        let behind = cam.eye() - (Vector3::zeros() - cam.eye()) * 2.0;
        let poly = [behind, behind + Vector3::x(), behind + Vector3::y()];
        assert!(cam.project_polygon(&poly).is_empty());
    }
}
