//! The Foxglove 3D scene of a world run: frames of ball, body and spinning wheels; floor,
//! robot, contact-force arrows and wheel labels.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::foxglove::{
    BallbotScene, Color, CubePrimitive, CylinderPrimitive, FrameTransforms, JointState,
    JointStates, LinePrimitive, LineType, Pose, SceneEntity, SceneUpdate, TextPrimitive, arrow,
    entity, frame_transform, point3, pose_at, rgba, size, timestamp,
};
use ballbot_world::world::failure::wheel_name;
use ballbot_world::world::params::WorldParams;
use ballbot_world::world::telemetry::{StepTelemetry, WheelTelemetry};

/// The 3D scene of a world run: the robot's dimensions and frames, and the entities drawn.
///
/// Frames: `world` (fixed, z up), `ball` (ball centre, rotating with the ball), `body` (the
/// body frame of [`BallbotWorld`](ballbot_world::world::BallbotWorld): origin at the nominal ball
/// centre, x towards OW1), and
/// `ow1`, `ow2`, `ow3` (each omniwheel's centre, z along its axle `a_i = d_i x n_i`, rotated by
/// the wheel's angle, so the wheels turn in the 3D panel).
#[derive(Clone, Debug, PartialEq)]
pub struct WorldScene {
    /// Ball, body and wheel dimensions and poses in the body frame.
    pub robot: BallbotScene,
    /// Names of the wheel frames, `ow1`, `ow2`, `ow3` (the [`wheel_name`]s in lower case).
    pub wheel_frames: [String; 3],
    /// Length of a contact-force arrow per newton (m/N).
    pub metres_per_newton: f64,
    /// Side of the square floor drawn around the origin (m). Default 20.
    pub floor_size_m: f64,
}

impl WorldScene {
    /// The scene of the robot in `params`.
    pub fn new(params: &WorldParams, metres_per_newton: f64) -> Self {
        Self {
            robot: BallbotScene::from_params(&params.robot),
            wheel_frames: std::array::from_fn(|i| wheel_name(i).to_ascii_lowercase()),
            metres_per_newton,
            floor_size_m: 20.0,
        }
    }

    /// The transforms `world -> ball`, `world -> body` and `body -> ow_i` of one step.
    pub fn frames(&self, t: &StepTelemetry) -> FrameTransforms {
        let world_from_ball =
            Isometry3::from_parts(Translation3::from(t.ball_position_m), t.ball_orientation);
        let world_from_body =
            Isometry3::from_parts(Translation3::from(t.body_position_m), t.body_orientation);
        let mut frames = self
            .robot
            .frames(t.time_secs, &world_from_ball, &world_from_body);
        for ((name, body_from_wheel), wheel) in self
            .wheel_frames
            .iter()
            .zip(&self.robot.body_from_wheels)
            .zip(&t.wheels)
        {
            let spin = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), wheel.angle_rad);
            let body_from_spinning_wheel = body_from_wheel * spin;
            frames.transforms.push(frame_transform(
                t.time_secs,
                &self.robot.body_frame,
                name,
                &body_from_spinning_wheel,
            ));
        }
        frames
    }

    /// The omniwheel joints `ow1`..`ow3` of one step: angle (rad), speed (rad/s) and the
    /// motor torque (N m) as the effort.
    pub fn joints(&self, t: &StepTelemetry) -> JointStates {
        JointStates {
            timestamp: Some(timestamp(t.time_secs)),
            joints: self
                .wheel_frames
                .iter()
                .zip(&t.wheels)
                .map(|(name, wheel)| JointState {
                    name: name.clone(),
                    position: Some(wheel.angle_rad),
                    velocity: Some(wheel.speed_rad_per_s),
                    acceleration: None,
                    effort: Some(wheel.motor_torque_nm),
                })
                .collect(),
        }
    }

    /// The entities of one step: `floor`, `ball`, `body`, `ow1`..`ow3`, `contact_forces` and
    /// `labels` (the wheel names).
    pub fn scene(&self, t: &StepTelemetry) -> SceneUpdate {
        let time_secs = t.time_secs;
        let mut update = self.robot.scene(time_secs);
        // The robot's own wheels are drawn in the spinning wheel frames instead.
        update.entities.retain(|e| e.id != "wheels");
        update.entities.insert(0, self.floor(time_secs));
        for name in &self.wheel_frames {
            update.entities.push(self.wheel(time_secs, name));
        }
        update
            .entities
            .push(self.contact_forces(time_secs, &t.wheels));
        update.entities.push(self.labels(time_secs));
        update
    }

    /// The wheel names `OW1`..`OW3` just outside each wheel, in the body frame, facing the
    /// camera.
    fn labels(&self, time_secs: f64) -> SceneEntity {
        let mut labels = entity(time_secs, &self.robot.body_frame, "labels");
        for (i, body_from_wheel) in self.robot.body_from_wheels.iter().enumerate() {
            let centre = body_from_wheel.translation.vector;
            let outward = Vector3::new(centre.x, centre.y, 0.0)
                .try_normalize(1e-12)
                .unwrap_or_else(Vector3::x);
            let at = centre + outward * (2.0 * self.robot.wheel_radius_m);
            labels.texts.push(TextPrimitive {
                pose: Some(pose_at(at.x, at.y, at.z)),
                billboard: true,
                font_size: 14.0,
                scale_invariant: true,
                color: Some(rgba(1.0, 1.0, 1.0, 1.0)),
                text: wheel_name(i).to_owned(),
            });
        }
        labels
    }

    /// A grey floor slab just below z = 0 with lines every metre, in the world frame.
    fn floor(&self, time_secs: f64) -> SceneEntity {
        let mut floor = entity(time_secs, &self.robot.world_frame, "floor");
        let size_m = self.floor_size_m;
        floor.cubes.push(CubePrimitive {
            pose: Some(pose_at(0.0, 0.0, -0.006)),
            size: Some(size(size_m, size_m, 0.01)),
            color: Some(rgba(0.55, 0.55, 0.55, 1.0)),
        });
        let half_m = 0.5 * size_m;
        let lines = size_m.floor() as i32;
        let mut points = Vec::with_capacity(4 * (lines as usize + 1));
        for k in 0..=lines {
            let at_m = -half_m + f64::from(k);
            let z_m = 0.0005;
            points.push(point3(&nalgebra::Point3::new(at_m, -half_m, z_m)));
            points.push(point3(&nalgebra::Point3::new(at_m, half_m, z_m)));
            points.push(point3(&nalgebra::Point3::new(-half_m, at_m, z_m)));
            points.push(point3(&nalgebra::Point3::new(half_m, at_m, z_m)));
        }
        floor.lines.push(LinePrimitive {
            r#type: LineType::LineList as i32,
            pose: Some(Pose::default()),
            thickness: 0.01,
            scale_invariant: false,
            points,
            color: Some(rgba(0.25, 0.25, 0.25, 1.0)),
            colors: Vec::new(),
            indices: Vec::new(),
        });
        floor
    }

    /// One omniwheel in its own (spinning) frame: a disc about the axle (z) with a light spoke
    /// along its x axis, so its rotation shows.
    fn wheel(&self, time_secs: f64, frame: &str) -> SceneEntity {
        let mut wheel = entity(time_secs, frame, frame);
        let r_m = self.robot.wheel_radius_m;
        let width_m = self.robot.wheel_width_m;
        wheel.cylinders.push(CylinderPrimitive {
            pose: Some(Pose::default()),
            size: Some(size(2.0 * r_m, 2.0 * r_m, width_m)),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Some(rgba(0.2, 0.2, 0.2, 1.0)),
        });
        wheel.cubes.push(CubePrimitive {
            pose: Some(pose_at(0.5 * r_m, 0.0, 0.0)),
            size: Some(size(r_m, 0.2 * r_m, 1.1 * width_m)),
            color: Some(rgba(0.95, 0.85, 0.2, 1.0)),
        });
        wheel
    }

    /// The contact force of each wheel on the ball, `N_i (-n_i) + F_i d_i`, as an arrow
    /// ending at the wheel's (nominal) contact point, in the body frame, coloured by
    /// [`cone_colour`].
    fn contact_forces(&self, time_secs: f64, wheels: &[WheelTelemetry; 3]) -> SceneEntity {
        let mut forces = entity(time_secs, &self.robot.body_frame, "contact_forces");
        for (body_from_wheel, w) in self.robot.body_from_wheels.iter().zip(wheels) {
            let centre = body_from_wheel.translation.vector;
            let Some(inward) = (-centre).try_normalize(1e-12) else {
                continue;
            };
            let axle = body_from_wheel.rotation * Vector3::z();
            let rolling = axle.cross(&inward);
            let contact = centre + inward * self.robot.wheel_radius_m;
            let force = inward * w.normal_force_n + rolling * w.traction_n;
            let tail = contact - force * self.metres_per_newton;
            forces.arrows.push(arrow(
                nalgebra::Point3::from(tail),
                force,
                self.metres_per_newton,
                cone_colour(w.cone_utilisation, w.slipping),
            ));
        }
        forces
    }
}

/// The colour of a contact-force arrow: green at no traction through yellow (half the cone)
/// to orange at the cone's edge; red while the contact slips.
pub fn cone_colour(cone_utilisation: f64, slipping: bool) -> Color {
    if slipping {
        return rgba(0.9, 0.05, 0.05, 1.0);
    }
    let u = if cone_utilisation.is_finite() {
        cone_utilisation.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let green = (0.1, 0.75, 0.2);
    let yellow = (0.95, 0.85, 0.1);
    let orange = (1.0, 0.45, 0.0);
    let mix = |a: (f64, f64, f64), b: (f64, f64, f64), s: f64| {
        rgba(
            a.0 + (b.0 - a.0) * s,
            a.1 + (b.1 - a.1) * s,
            a.2 + (b.2 - a.2) * s,
            1.0,
        )
    };
    if u <= 0.5 {
        mix(green, yellow, 2.0 * u)
    } else {
        mix(yellow, orange, 2.0 * u - 1.0)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn cone_colour_goes_from_green_to_orange_and_red_when_slipping() {
        let green = cone_colour(0.0, false);
        assert!(green.g > green.r);
        let orange = cone_colour(1.0, false);
        assert!(orange.r > orange.g && orange.b < 0.1);
        let red = cone_colour(0.3, true);
        assert!(red.r > 0.8 && red.g < 0.1);
        assert_eq!(cone_colour(f64::NAN, false), cone_colour(1.0, false));
        assert_eq!(cone_colour(2.0, false), cone_colour(1.0, false));
    }
}
