//! [`SceneRenderer`]: one frame of the world's robot over its floor.
//!
//! The camera ([`crate::camera`]) follows the ball at a fixed azimuth and elevation, so the
//! floor's tiles and grid, fixed to the world, slide past as the robot moves. The robot is
//! the export model's ([`RobotModel`], from [`WorldParams`]): the ball, the body (a deck over
//! the wheels, a mast, a top plate as high as the chassis, with a bracket to each wheel),
//! and the three omniwheels at their azimuths and contact angle, each a rim as wide as its
//! rollers with every roller marked on it (turning with the wheel angle). Parts are drawn far
//! to near (painter's algorithm). On top: per wheel an arrow of the force the wheel applies
//! to the ball (normal force, traction and axle force), ending at the contact point and
//! coloured by the contact's friction-cone use (green 0, yellow 0.5, red 1); a wheel without
//! normal force (below the world's lift-off threshold) is painted [`palette::LIFT_OFF`] with a ring and a "lift-off" label, a
//! sliding one labelled "slip". A state before the world's first step (time 0, no contact
//! computed yet) is drawn without arrows or lift-off marks.

use crate::camera::{Camera, CameraView};
use crate::palette::{self, Rgb};
use crate::text::{Anchor, Text};
use ballbot_world::export::{ExportError, RobotModel};
use ballbot_world::world::{StepTelemetry, WheelTelemetry, WorldParams};
use nalgebra::{Point2, Vector3};
use tiny_skia::{
    Color, FillRule, GradientStop, LineCap, LinearGradient, Paint, PathBuilder, Pixmap, Point,
    RadialGradient, Rect, Shader, SpreadMode, Stroke, Transform,
};

/// Default frame width (px).
pub const DEFAULT_WIDTH: u32 = 480;
/// Default frame height (px).
pub const DEFAULT_HEIGHT: u32 = 360;
/// Side of a floor tile (m); grid lines run along every tile edge.
pub const TILE_M: f64 = 0.5;
/// Length of a force arrow per newton (m/N): the robot's weight on three wheels (about
/// 280 N each at rest) draws arrows about 0.13 m long.
pub const ARROW_M_PER_N: f64 = 0.13 / 280.0;
/// Floor drawn around the camera's target (m, half side).
const FLOOR_HALF_M: f64 = 7.0;
/// Half the drawn rim's width, in roller mid radii: a little wider than one row of rollers, so
/// that a wheel seen edge-on still shows.
const RIM_WIDTH_ROLLERS: f64 = 1.6;

/// Why a renderer cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The world's parameters give no robot model.
    #[error("the world's robot cannot be drawn: {0}")]
    Model(#[from] ExportError),
    /// A frame must be between 16 x 16 and 4096 x 4096 pixels.
    #[error("frame size {width} x {height} must be between 16 and 4096 pixels a side")]
    Size {
        /// Requested width (px).
        width: u32,
        /// Requested height (px).
        height: u32,
    },
    /// The embedded font did not parse (a build error).
    #[error("the embedded font cannot be read")]
    Font,
    /// PNG encoding failed.
    #[error("cannot encode the frame as PNG: {0}")]
    Png(String),
}

/// One frame: `height` rows of `width` RGB pixels, row-major, 3 bytes a pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// `height * width * 3` bytes.
    pub rgb: Vec<u8>,
}

impl Frame {
    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// How many pixels are exactly `rgb`.
    pub fn count(&self, rgb: Rgb) -> usize {
        self.rgb.chunks_exact(3).filter(|p| *p == rgb).count()
    }
}

/// A wheel's frame in the body frame: centre, direction from the ball to it, rolling
/// direction, axle.
#[derive(Clone, Copy, Debug)]
struct WheelFrame {
    centre: Vector3<f64>,
    out: Vector3<f64>,
    rolling: Vector3<f64>,
    axle: Vector3<f64>,
}

/// Draws frames of one world's robot (module documentation).
pub struct SceneRenderer {
    model: RobotModel,
    wheels: [WheelFrame; 3],
    roller_count: usize,
    lift_off_force_n: f64,
    contacts_known: bool,
    view: CameraView,
    pixmap: Pixmap,
    text: Text,
}

/// What a frame's parts are, for the far-to-near sort.
#[derive(Clone, Copy, Debug)]
enum Part {
    Ball,
    Wheel(usize),
    Bracket(usize),
    Deck,
    Mast,
    Top,
}

/// A view of one step: where the body is, and the camera.
struct Pose<'a> {
    t: &'a StepTelemetry,
    cam: Camera,
}

impl Pose<'_> {
    /// A body-frame point in the world.
    fn world(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.t.body_position_m + self.t.body_orientation * p
    }

    /// A body-frame direction in the world.
    fn dir(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.t.body_orientation * v
    }
}

fn colour(rgb: Rgb, alpha: f32) -> Color {
    let a = (alpha.clamp(0.0, 1.0) * 255.0).round() as u8;
    Color::from_rgba8(rgb[0], rgb[1], rgb[2], a)
}

fn paint(rgb: Rgb, alpha: f32) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(colour(rgb, alpha));
    p.anti_alias = true;
    p
}

fn polygon(builder: &mut PathBuilder, points: &[Point2<f64>]) {
    let Some((first, rest)) = points.split_first() else {
        return;
    };
    builder.move_to(first.x as f32, first.y as f32);
    for p in rest {
        builder.line_to(p.x as f32, p.y as f32);
    }
    builder.close();
}

fn fill(pixmap: &mut Pixmap, points: &[Point2<f64>], rgb: Rgb, alpha: f32) {
    if points.len() < 3 {
        return;
    }
    let mut b = PathBuilder::new();
    polygon(&mut b, points);
    if let Some(path) = b.finish() {
        pixmap.fill_path(
            &path,
            &paint(rgb, alpha),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

fn stroke_polyline(
    pixmap: &mut Pixmap,
    points: &[Point2<f64>],
    closed: bool,
    rgb: Rgb,
    alpha: f32,
    width: f32,
) {
    let mut b = PathBuilder::new();
    let Some((first, rest)) = points.split_first() else {
        return;
    };
    b.move_to(first.x as f32, first.y as f32);
    for p in rest {
        b.line_to(p.x as f32, p.y as f32);
    }
    if closed {
        b.close();
    }
    if let Some(path) = b.finish() {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        pixmap.stroke_path(
            &path,
            &paint(rgb, alpha),
            &stroke,
            Transform::identity(),
            None,
        );
    }
}

fn circle(pixmap: &mut Pixmap, c: &Point2<f64>, radius: f64, rgb: Rgb, alpha: f32) {
    if let Some(path) = PathBuilder::from_circle(c.x as f32, c.y as f32, radius.max(0.5) as f32) {
        pixmap.fill_path(
            &path,
            &paint(rgb, alpha),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

/// The convex hull of `points` (Andrew's monotone chain), counter-clockwise.
fn convex_hull(mut points: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    if points.len() < 3 {
        return points;
    }
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(points.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull
}

/// Whether wheel telemetry `w` has the wheel off the ball: its normal force below
/// `lift_off_force_n` (the world's `failure.lift_off_force_n`, 1 N by default, as the world's
/// lift-off events and stop rule judge it).
pub fn lifted(w: &WheelTelemetry, lift_off_force_n: f64) -> bool {
    w.normal_force_n.is_nan() || w.normal_force_n < lift_off_force_n
}

impl SceneRenderer {
    /// A renderer of frames `width` x `height` pixels of the robot of `params`.
    ///
    /// Errors: [`RenderError::Model`] for parameters the world or the export model rejects,
    /// [`RenderError::Size`] for a side outside 16..=4096 pixels.
    ///
    /// ```
    /// use ballbot_render::SceneRenderer;
    /// use ballbot_world::world::{BallbotWorld, WorldParams};
    /// let params = WorldParams::miapure_60kg();
    /// let world = BallbotWorld::new(params)?;
    /// let mut renderer = SceneRenderer::new(&params, 480, 360)?;
    /// let frame = renderer.render(world.telemetry());
    /// assert_eq!(frame.rgb.len(), 480 * 360 * 3);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(params: &WorldParams, width: u32, height: u32) -> Result<Self, RenderError> {
        if !(16..=4096).contains(&width) || !(16..=4096).contains(&height) {
            return Err(RenderError::Size { width, height });
        }
        let model = RobotModel::new(params)?;
        let frame = |i: usize| {
            let pose = &model.wheels[i].pose;
            let m = pose.rotation.matrix();
            WheelFrame {
                centre: pose.position_m,
                out: -m.column(0).into_owned(),
                rolling: m.column(1).into_owned(),
                axle: m.column(2).into_owned(),
            }
        };
        let wheels = [frame(0), frame(1), frame(2)];
        let roller_count = model.wheels[0].rollers.len();
        let pixmap = Pixmap::new(width, height).ok_or(RenderError::Size { width, height })?;
        Ok(Self {
            model,
            wheels,
            roller_count,
            lift_off_force_n: params.failure.lift_off_force_n,
            contacts_known: true,
            view: CameraView::default(),
            pixmap,
            text: Text::new().ok_or(RenderError::Font)?,
        })
    }

    /// The camera's placement (the default: [`CameraView::default`]).
    pub fn set_view(&mut self, view: CameraView) {
        self.view = view;
    }

    /// Frame width (px).
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// Frame height (px).
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// Draws the state `t` and returns the frame.
    pub fn render(&mut self, t: &StepTelemetry) -> Frame {
        self.draw(t);
        let mut rgb = Vec::new();
        self.rgb_into(&mut rgb);
        Frame {
            width: self.width(),
            height: self.height(),
            rgb,
        }
    }

    /// The last frame drawn as RGB bytes, written into `out` (resized).
    pub fn rgb_into(&self, out: &mut Vec<u8>) {
        out.clear();
        out.reserve(self.pixmap.data().len() / 4 * 3);
        // Every pixel is opaque (the sky is), so the premultiplied colour is the colour.
        for p in self.pixmap.data().chunks_exact(4) {
            out.extend_from_slice(&p[..3]);
        }
    }

    /// The last frame drawn, as a PNG file's bytes.
    pub fn png(&self) -> Result<Vec<u8>, RenderError> {
        self.pixmap
            .encode_png()
            .map_err(|e| RenderError::Png(e.to_string()))
    }

    /// Draws the state `t` into the renderer's pixmap.
    pub fn draw(&mut self, t: &StepTelemetry) {
        // Before the world's first step (a reset's state) no contact has been computed yet:
        // its zero normal forces are not lift-offs.
        self.contacts_known = t.time_secs > 0.0;
        let r = self.model.ball_radius_m;
        let target = Vector3::new(
            t.ball_position_m.x,
            t.ball_position_m.y,
            r + 0.45 * self.model.chassis_height_m,
        );
        let cam = Camera::new(&self.view, target, self.width(), self.height());
        let pose = Pose { t, cam };
        self.sky(&pose);
        self.floor(&pose, &target);
        self.shadow(&pose);
        let mut parts: Vec<(f64, Part)> = [Part::Ball, Part::Deck, Part::Mast, Part::Top]
            .into_iter()
            .chain((0..3).flat_map(|i| [Part::Wheel(i), Part::Bracket(i)]))
            .map(|p| (self.depth(&pose, p), p))
            .collect();
        parts.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (_, part) in parts {
            match part {
                Part::Ball => self.ball(&pose),
                Part::Wheel(i) => self.wheel(&pose, i),
                Part::Bracket(i) => self.bracket(&pose, i),
                Part::Deck => self.deck(&pose),
                Part::Mast => self.mast(&pose),
                Part::Top => self.top(&pose),
            }
        }
        for i in 0..3 {
            self.arrow(&pose, i);
        }
        for i in 0..3 {
            self.wheel_label(&pose, i);
        }
        self.header(t);
        self.legend();
    }

    fn deck_height(&self) -> f64 {
        let w = &self.wheels[0];
        w.centre.z + 0.9 * self.model.roller.rim_radius_m
    }

    fn part_centre(&self, part: Part) -> Vector3<f64> {
        let h = self.model.chassis_height_m;
        match part {
            Part::Ball => Vector3::zeros(),
            Part::Wheel(i) => self.wheels[i].centre,
            Part::Bracket(i) => 0.5 * (self.wheels[i].centre + Vector3::z() * self.deck_height()),
            Part::Deck => Vector3::z() * self.deck_height(),
            Part::Mast => Vector3::z() * 0.5 * (self.deck_height() + h),
            Part::Top => Vector3::z() * h,
        }
    }

    fn depth(&self, pose: &Pose<'_>, part: Part) -> f64 {
        let p = match part {
            Part::Ball => pose.t.ball_position_m,
            _ => pose.world(&self.part_centre(part)),
        };
        // A bracket is drawn just before its wheel, which it must not hide.
        let behind = match part {
            Part::Bracket(i) => {
                return pose.cam.depth(&pose.world(&self.wheels[i].centre)) + 1e-6;
            }
            _ => 0.0,
        };
        pose.cam.depth(&p) + behind
    }

    fn sky(&mut self, pose: &Pose<'_>) {
        let h = self.height() as f32;
        // The horizon: where a far point on the floor ahead projects.
        let ahead = pose.cam.eye()
            + (Vector3::new(pose.t.ball_position_m.x, pose.t.ball_position_m.y, 0.0)
                - pose.cam.eye())
            .component_mul(&Vector3::new(1.0, 1.0, 0.0))
                * 50.0;
        let horizon = pose.cam.project(&ahead).map_or(0.5 * h, |p| p.y as f32);
        let stops = vec![
            GradientStop::new(0.0, colour(palette::SKY_TOP, 1.0)),
            GradientStop::new(1.0, colour(palette::SKY_HORIZON, 1.0)),
        ];
        let shader = LinearGradient::new(
            Point::from_xy(0.0, 0.0),
            Point::from_xy(0.0, horizon.max(1.0)),
            stops,
            SpreadMode::Pad,
            Transform::identity(),
        )
        .unwrap_or(Shader::SolidColor(colour(palette::SKY_HORIZON, 1.0)));
        let paint = Paint {
            shader,
            ..Paint::default()
        };
        if let Some(rect) = Rect::from_xywh(0.0, 0.0, self.width() as f32, h) {
            self.pixmap
                .fill_rect(rect, &paint, Transform::identity(), None);
        }
    }

    fn floor(&mut self, pose: &Pose<'_>, target: &Vector3<f64>) {
        let cam = &pose.cam;
        let (i0, i1) = (
            ((target.x - FLOOR_HALF_M) / TILE_M).floor() as i64,
            ((target.x + FLOOR_HALF_M) / TILE_M).ceil() as i64,
        );
        let (j0, j1) = (
            ((target.y - FLOOR_HALF_M) / TILE_M).floor() as i64,
            ((target.y + FLOOR_HALF_M) / TILE_M).ceil() as i64,
        );
        let at = |i: i64, j: i64| Vector3::new(i as f64 * TILE_M, j as f64 * TILE_M, 0.0);
        let base = cam.project_polygon(&[at(i0, j0), at(i1, j0), at(i1, j1), at(i0, j1)]);
        fill(&mut self.pixmap, &base, palette::FLOOR, 1.0);
        let mut tiles = PathBuilder::new();
        for i in i0..i1 {
            for j in j0..j1 {
                if (i + j).rem_euclid(2) == 0 {
                    continue;
                }
                let quad = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                polygon(&mut tiles, &cam.project_polygon(&quad));
            }
        }
        if let Some(path) = tiles.finish() {
            self.pixmap.fill_path(
                &path,
                &paint(palette::FLOOR_TILE, 1.0),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
        let mut lines = PathBuilder::new();
        let mut segment = |a: Vector3<f64>, b: Vector3<f64>| {
            if let Some((p, q)) = cam.project_segment(&a, &b) {
                lines.move_to(p.x as f32, p.y as f32);
                lines.line_to(q.x as f32, q.y as f32);
            }
        };
        for i in i0..=i1 {
            segment(at(i, j0), at(i, j1));
        }
        for j in j0..=j1 {
            segment(at(i0, j), at(i1, j));
        }
        if let Some(path) = lines.finish() {
            let stroke = Stroke {
                width: 1.0,
                ..Stroke::default()
            };
            self.pixmap.stroke_path(
                &path,
                &paint(palette::GRID_LINE, 0.8),
                &stroke,
                Transform::identity(),
                None,
            );
        }
    }

    fn shadow(&mut self, pose: &Pose<'_>) {
        let r = self.model.ball_radius_m;
        let c = pose.t.ball_position_m;
        let ring: Vec<Vector3<f64>> = (0..32)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 32.0;
                Vector3::new(c.x + 1.1 * r * a.cos(), c.y + 1.1 * r * a.sin(), 0.0)
            })
            .collect();
        let pts = pose.cam.project_polygon(&ring);
        fill(&mut self.pixmap, &pts, [0, 0, 0], 0.22);
    }

    fn ball(&mut self, pose: &Pose<'_>) {
        let r = self.model.ball_radius_m;
        let c = pose.t.ball_position_m;
        let Some(centre) = pose.cam.project(&c) else {
            return;
        };
        let radius = r * pose.cam.scale_at(pose.cam.depth(&c));
        let (cx, cy, rad) = (centre.x as f32, centre.y as f32, radius as f32);
        let stops = vec![
            GradientStop::new(0.0, colour(palette::BALL_LIGHT, 1.0)),
            GradientStop::new(1.0, colour(palette::BALL_DARK, 1.0)),
        ];
        let shader = RadialGradient::new(
            Point::from_xy(cx - 0.35 * rad, cy - 0.45 * rad),
            0.0,
            Point::from_xy(cx, cy),
            rad * 1.05,
            stops,
            SpreadMode::Pad,
            Transform::identity(),
        )
        .unwrap_or(Shader::SolidColor(colour(palette::BALL_DARK, 1.0)));
        let paint = Paint {
            shader,
            anti_alias: true,
            ..Paint::default()
        };
        if let Some(path) = PathBuilder::from_circle(cx, cy, rad) {
            self.pixmap.fill_path(
                &path,
                &paint,
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
        // Marks at the ball's six axis points show it rolling.
        let eye = pose.cam.eye();
        for axis in [Vector3::x(), Vector3::y(), Vector3::z()] {
            for s in [1.0, -1.0] {
                let n = pose.t.ball_orientation * (axis * s);
                let p = c + n * r;
                let facing = n.dot(&(eye - p).normalize());
                if facing <= 0.05 {
                    continue;
                }
                if let Some(q) = pose.cam.project(&p) {
                    let k = facing.sqrt();
                    circle(
                        &mut self.pixmap,
                        &q,
                        0.16 * radius * k,
                        palette::BALL_MARK,
                        0.9,
                    );
                }
            }
        }
    }

    /// A box centred at `centre` (body frame) with body-frame axes and half sides `half`.
    fn cuboid(&mut self, pose: &Pose<'_>, centre: Vector3<f64>, half: [f64; 3], rgb: Rgb) {
        let c = pose.world(&centre);
        let axes = [Vector3::x(), Vector3::y(), Vector3::z()].map(|a| pose.dir(&a));
        let eye = pose.cam.eye();
        let light = Vector3::new(0.35, -0.55, 0.76).normalize();
        for k in 0..3 {
            for s in [1.0, -1.0] {
                let n = axes[k] * s;
                let fc = c + n * half[k];
                if n.dot(&(eye - fc)) <= 0.0 {
                    continue;
                }
                let (u, v) = (
                    axes[(k + 1) % 3] * half[(k + 1) % 3],
                    axes[(k + 2) % 3] * half[(k + 2) % 3],
                );
                let quad = [fc + u + v, fc - u + v, fc - u - v, fc + u - v];
                let pts = pose.cam.project_polygon(&quad);
                let lit = 0.62 + 0.38 * n.dot(&light).max(0.0);
                fill(&mut self.pixmap, &pts, palette::shade(rgb, lit), 1.0);
                stroke_polyline(&mut self.pixmap, &pts, true, palette::INK, 0.5, 0.8);
            }
        }
    }

    fn deck(&mut self, pose: &Pose<'_>) {
        let w = 0.32 * self.wheels[0].centre.xy().norm();
        let centre = Vector3::z() * self.deck_height();
        self.cuboid(pose, centre, [w, w, 0.012], palette::BODY);
    }

    fn mast(&mut self, pose: &Pose<'_>) {
        let (z0, z1) = (self.deck_height(), self.model.chassis_height_m);
        let centre = Vector3::z() * 0.5 * (z0 + z1);
        self.cuboid(pose, centre, [0.025, 0.025, 0.5 * (z1 - z0)], palette::BODY);
    }

    fn top(&mut self, pose: &Pose<'_>) {
        let w = 0.5 * self.model.chassis_half_width_m;
        let centre = Vector3::z() * self.model.chassis_height_m;
        self.cuboid(pose, centre, [w, w, 0.02], palette::BODY);
        // A mark towards OW1 (body +x) shows the heading.
        let tip = pose.world(&Vector3::new(w, 0.0, self.model.chassis_height_m + 0.021));
        let root = pose.world(&Vector3::new(
            0.3 * w,
            0.0,
            self.model.chassis_height_m + 0.021,
        ));
        if let Some((a, b)) = pose.cam.project_segment(&root, &tip) {
            stroke_polyline(&mut self.pixmap, &[a, b], false, palette::INK, 0.8, 2.5);
        }
    }

    fn bracket(&mut self, pose: &Pose<'_>, i: usize) {
        let w = self.wheels[i];
        let a = pose.world(&(w.centre - w.axle * 0.0));
        let inner = Vector3::new(w.centre.x * 0.3, w.centre.y * 0.3, self.deck_height());
        let b = pose.world(&inner);
        if let Some((p, q)) = pose.cam.project_segment(&a, &b) {
            let width = (0.016 * pose.cam.scale_at(pose.cam.depth(&a))) as f32;
            stroke_polyline(
                &mut self.pixmap,
                &[p, q],
                false,
                palette::INK,
                1.0,
                width + 1.5,
            );
            stroke_polyline(
                &mut self.pixmap,
                &[p, q],
                false,
                palette::shade(palette::BODY, 0.8),
                1.0,
                width,
            );
        }
    }

    fn wheel(&mut self, pose: &Pose<'_>, i: usize) {
        let w = self.wheels[i];
        let telemetry = &pose.t.wheels[i];
        let r_w = self.model.roller.rim_radius_m;
        let half_width = RIM_WIDTH_ROLLERS * self.model.roller.mid_radius_m;
        let c = pose.world(&w.centre);
        let (u, v, a) = (pose.dir(&w.out), pose.dir(&w.rolling), pose.dir(&w.axle));
        let cam = &pose.cam;
        let eye = cam.eye();
        let rim = |g: f64| u * (r_w * g.cos()) + v * (r_w * g.sin());
        let mut pts = Vec::with_capacity(64);
        for k in 0..32 {
            let g = std::f64::consts::TAU * f64::from(k) / 32.0;
            for s in [1.0, -1.0] {
                if let Some(p) = cam.project(&(c + rim(g) + a * (s * half_width))) {
                    pts.push(p);
                }
            }
        }
        let is_lifted = self.contacts_known && lifted(telemetry, self.lift_off_force_n);
        let body = if is_lifted {
            palette::LIFT_OFF
        } else {
            palette::WHEELS[i]
        };
        let hull = convex_hull(pts);
        fill(&mut self.pixmap, &hull, body, 1.0);
        stroke_polyline(&mut self.pixmap, &hull, true, palette::INK, 0.9, 1.0);
        // The face towards the camera, and its hub.
        let side = if a.dot(&(eye - c)) >= 0.0 { 1.0 } else { -1.0 };
        let face_c = c + a * (side * half_width);
        let face: Vec<Point2<f64>> = (0..32)
            .filter_map(|k| {
                let g = std::f64::consts::TAU * f64::from(k) / 32.0;
                cam.project(&(face_c + rim(g) * 0.72))
            })
            .collect();
        stroke_polyline(
            &mut self.pixmap,
            &face,
            true,
            palette::shade(body, 1.6),
            1.0,
            1.0,
        );
        let hub: Vec<Point2<f64>> = (0..16)
            .filter_map(|k| {
                let g = std::f64::consts::TAU * f64::from(k) / 16.0;
                cam.project(&(face_c + rim(g) * 0.3))
            })
            .collect();
        fill(&mut self.pixmap, &hub, palette::BODY, 1.0);
        // The rollers, turning with the wheel.
        let scale = cam.scale_at(cam.depth(&c));
        let roller_px = (0.9 * half_width * scale).max(1.5) as f32;
        let half_len = 0.75 * self.model.roller.half_length_m;
        let count = self.roller_count.max(1);
        for j in 0..count {
            let g = std::f64::consts::TAU * j as f64 / count as f64 + telemetry.angle_rad;
            let radial = u * g.cos() + v * g.sin();
            let p = c + radial * r_w;
            if radial.dot(&(eye - p).normalize()) < -0.15 {
                continue;
            }
            let tangent = v * g.cos() - u * g.sin();
            if let Some((p0, p1)) =
                cam.project_segment(&(p - tangent * half_len), &(p + tangent * half_len))
            {
                stroke_polyline(
                    &mut self.pixmap,
                    &[p0, p1],
                    false,
                    palette::ROLLER,
                    1.0,
                    roller_px,
                );
            }
        }
        if is_lifted && let Some(centre) = cam.project(&c) {
            let ring: Vec<Point2<f64>> = (0..32)
                .map(|k| {
                    let g = std::f64::consts::TAU * f64::from(k) / 32.0;
                    let rr = 1.7 * r_w * scale;
                    Point2::new(centre.x + rr * g.cos(), centre.y + rr * g.sin())
                })
                .collect();
            stroke_polyline(&mut self.pixmap, &ring, true, palette::LIFT_OFF, 1.0, 3.0);
        }
    }

    fn arrow(&mut self, pose: &Pose<'_>, i: usize) {
        let w = self.wheels[i];
        let tel = &pose.t.wheels[i];
        if !self.contacts_known || lifted(tel, self.lift_off_force_n) {
            return;
        }
        let r = self.model.ball_radius_m;
        let contact = pose.world(&(w.out * r));
        // The force on the ball: the normal force into it, traction along the rolling
        // direction, the axle force along the axle.
        let force = pose.dir(
            &(-w.out * tel.normal_force_n + w.rolling * tel.traction_n + w.axle * tel.axle_force_n),
        );
        let tail = contact - force * ARROW_M_PER_N;
        let cam = &pose.cam;
        let (Some(p), Some(q)) = (cam.project(&tail), cam.project(&contact)) else {
            return;
        };
        let d = q - p;
        let len = d.norm();
        if len < 2.0 {
            return;
        }
        let dir = d / len;
        let normal = nalgebra::Vector2::new(-dir.y, dir.x);
        let head = 9.0_f64.min(0.6 * len);
        let base = q - dir * head;
        let rgb = palette::cone_colour(tel.cone_utilisation);
        let tri = [
            q,
            base + normal * (0.5 * head),
            base - normal * (0.5 * head),
        ];
        stroke_polyline(&mut self.pixmap, &[p, base], false, palette::INK, 1.0, 5.0);
        stroke_polyline(&mut self.pixmap, &tri, true, palette::INK, 1.0, 2.0);
        stroke_polyline(&mut self.pixmap, &[p, base], false, rgb, 1.0, 3.0);
        fill(&mut self.pixmap, &tri, rgb, 1.0);
    }

    fn wheel_label(&mut self, pose: &Pose<'_>, i: usize) {
        let w = self.wheels[i];
        let tel = &pose.t.wheels[i];
        let r_w = self.model.roller.rim_radius_m;
        let out = Vector3::new(w.out.x, w.out.y, 0.0).normalize();
        let anchor = pose.world(&(w.centre + out * (1.3 * r_w)));
        let Some(p) = pose.cam.project(&anchor) else {
            return;
        };
        let name = format!("OW{}", i + 1);
        let (text, rgb) = if self.contacts_known && lifted(tel, self.lift_off_force_n) {
            (format!("{name} lift-off"), palette::LIFT_OFF)
        } else if tel.slipping {
            (
                format!("{name} slip {:.2}", tel.cone_utilisation),
                palette::SLIP,
            )
        } else {
            (format!("{name} {:.2}", tel.cone_utilisation), palette::INK)
        };
        let size = 13;
        let width = self.text.width(&text, size);
        let x = (p.x as f32).clamp(4.0, (self.width() as f32 - width - 6.0).max(4.0));
        let y = (p.y as f32).min(self.height() as f32 - 40.0).max(10.0);
        self.text.draw(
            &mut self.pixmap,
            &text,
            (x, y),
            Anchor::MiddleLeft,
            size,
            rgb,
            true,
        );
    }

    fn header(&mut self, t: &StepTelemetry) {
        let speed = t.ball_velocity_m_per_s.xy().norm();
        let up = t.body_orientation * Vector3::z();
        let tilt = up.z.clamp(-1.0, 1.0).acos().to_degrees();
        let line = format!(
            "t {:.2} s   speed {:.2} m/s   tilt {:.1}\u{b0}",
            t.time_secs, speed, tilt
        );
        self.text.draw(
            &mut self.pixmap,
            &line,
            (8.0, 6.0),
            Anchor::TopLeft,
            14,
            palette::INK,
            true,
        );
        let lifted: Vec<String> = (0..3)
            .filter(|&i| self.contacts_known && lifted(&t.wheels[i], self.lift_off_force_n))
            .map(|i| format!("OW{}", i + 1))
            .collect();
        if !lifted.is_empty() {
            let line = format!("LIFT-OFF {}", lifted.join(" "));
            self.text.draw(
                &mut self.pixmap,
                &line,
                (8.0, 26.0),
                Anchor::TopLeft,
                14,
                palette::LIFT_OFF,
                true,
            );
        }
    }

    fn legend(&mut self) {
        let (w, h) = (self.width() as f32, self.height() as f32);
        let y = h - 22.0;
        let x = self.text.draw(
            &mut self.pixmap,
            "wheel force on ball; friction-cone use 0",
            (8.0, y),
            Anchor::TopLeft,
            12,
            palette::INK,
            true,
        );
        let bar = (x + 6.0, y + 3.0, (w - x - 40.0).clamp(20.0, 90.0), 10.0);
        let stops = palette::CONE_RAMP
            .iter()
            .enumerate()
            .map(|(k, c)| GradientStop::new(k as f32 / 2.0, colour(*c, 1.0)))
            .collect();
        if let (Some(shader), Some(rect)) = (
            LinearGradient::new(
                Point::from_xy(bar.0, 0.0),
                Point::from_xy(bar.0 + bar.2, 0.0),
                stops,
                SpreadMode::Pad,
                Transform::identity(),
            ),
            Rect::from_xywh(bar.0, bar.1, bar.2, bar.3),
        ) {
            let paint = Paint {
                shader,
                ..Paint::default()
            };
            self.pixmap
                .fill_rect(rect, &paint, Transform::identity(), None);
        }
        self.text.draw(
            &mut self.pixmap,
            "1",
            (bar.0 + bar.2 + 5.0, y),
            Anchor::TopLeft,
            12,
            palette::INK,
            true,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_of_a_square_and_its_centre_is_the_square() {
        let p = |x: f64, y: f64| Point2::new(x, y);
        let hull = convex_hull(vec![
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(0.5, 0.5),
            p(1.0, 1.0),
            p(0.0, 1.0),
        ]);
        assert_eq!(hull.len(), 4, "{hull:?}");
    }
}
