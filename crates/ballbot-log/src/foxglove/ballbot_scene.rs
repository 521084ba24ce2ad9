//! [`BallbotScene`]: a ballbot (ball, body, omniwheels) and its contact forces drawn with
//! the scene primitives, locked to the `world`, `ball` and `body` frames.

use ballbot_core::BallbotParams;
use nalgebra::{Isometry3, UnitQuaternion};

use super::convert::{arrow, entity, frame_transform, pose, pose_at, rgba, size};
use ::foxglove::schemas::{
    CylinderPrimitive, FrameTransforms, Pose, SceneEntity, SceneUpdate, SpherePrimitive,
};

/// Dimensions and frames for drawing a ballbot in Foxglove's 3D panel.
///
/// [`frames`](Self::frames) gives the transforms `world -> ball` and `world -> body` (log them
/// every step); [`scene`](Self::scene) draws, locked to those frames, the ball as a sphere with
/// a marker dot (so its rolling shows), the body as a cylinder whose axis is the body's z axis,
/// and the omniwheels as thin cylinders at the poses in `body_from_wheels` (each wheel's axle
/// along its z axis). Entities are frame-locked, so the scene only needs logging when it
/// changes, but logging it at a modest rate (e.g. 10 Hz) keeps it visible after seeking.
#[derive(Debug, Clone, PartialEq)]
pub struct BallbotScene {
    /// Ball radius (m).
    pub ball_radius_m: f64,
    /// Body cylinder radius (m).
    pub body_radius_m: f64,
    /// Height of the body cylinder's bottom face above the body frame origin (m).
    pub body_bottom_m: f64,
    /// Body cylinder height (m).
    pub body_height_m: f64,
    /// Omniwheel radius (m).
    pub wheel_radius_m: f64,
    /// Omniwheel width along its axle (m).
    pub wheel_width_m: f64,
    /// Each omniwheel's pose in the body frame, axle along the wheel's z axis.
    pub body_from_wheels: Vec<Isometry3<f64>>,
    /// Name of the fixed frame. Default `world`.
    pub world_frame: String,
    /// Name of the ball frame (origin at the ball centre). Default `ball`.
    pub ball_frame: String,
    /// Name of the body frame (origin at the ball centre, z up the body axis). Default `body`.
    pub body_frame: String,
}

impl BallbotScene {
    /// The MiaPURE with a 60 kg payload, from [`BallbotParams::miapure_60kg`].
    pub fn miapure_like() -> Self {
        Self::from_params(&BallbotParams::miapure_60kg())
    }

    /// The robot described by a parameter set: the ball radius of the sagittal plane, the
    /// omniwheels at their azimuths and contact angle with their radius (each wheel's centre on
    /// the line from the ball centre through its contact, axle `a_i = d_i x n_i` so that it
    /// rolls along the horizontal tangent `d_i`), and a body cylinder of 0.25 m radius from just above the wheels, centred on the
    /// COM height (at least 0.2 m tall). Change the public fields for another look.
    pub fn from_params(robot: &BallbotParams<f64>) -> Self {
        let ball_radius_m = robot.sagittal.ball_radius_m;
        let drivetrain = &robot.drivetrain;
        let wheel_radius_m = drivetrain.wheel_radius_m;
        let zenith_rad = drivetrain.contact_angle_rad;
        let body_from_wheels = drivetrain
            .wheel_azimuths_rad
            .iter()
            .map(|&azimuth_rad| {
                // Contact direction from the ball centre, then the wheel centre just outside it.
                let direction = nalgebra::Vector3::new(
                    zenith_rad.sin() * azimuth_rad.cos(),
                    zenith_rad.sin() * azimuth_rad.sin(),
                    zenith_rad.cos(),
                );
                let centre = direction * (ball_radius_m + wheel_radius_m);
                // The wheel drives the ball along the horizontal tangent d_i (MODEL.md section
                // 1): its axle is a_i = d_i x n_i, perpendicular to d_i and to the contact
                // normal, as in the world (`ballbot_world::world::contact`).
                let rolling = nalgebra::Vector3::new(-azimuth_rad.sin(), azimuth_rad.cos(), 0.0);
                let axle = rolling.cross(&direction);
                let rotation = UnitQuaternion::rotation_between(&nalgebra::Vector3::z(), &axle)
                    .unwrap_or_else(UnitQuaternion::identity);
                Isometry3::from_parts(centre.into(), rotation)
            })
            .collect();
        let body_bottom_m = (ball_radius_m + 2.0 * wheel_radius_m) * zenith_rad.cos() + 0.02;
        let body_height_m = (2.0 * (robot.sagittal.com_height_m - body_bottom_m)).max(0.2);
        Self {
            ball_radius_m,
            body_radius_m: 0.25,
            body_bottom_m,
            body_height_m,
            wheel_radius_m,
            wheel_width_m: 0.04,
            body_from_wheels,
            world_frame: "world".to_owned(),
            ball_frame: "ball".to_owned(),
            body_frame: "body".to_owned(),
        }
    }

    /// The transforms `world -> ball` and `world -> body` at a simulated time.
    pub fn frames(
        &self,
        time_secs: f64,
        world_from_ball: &Isometry3<f64>,
        world_from_body: &Isometry3<f64>,
    ) -> FrameTransforms {
        FrameTransforms {
            transforms: vec![
                frame_transform(
                    time_secs,
                    &self.world_frame,
                    &self.ball_frame,
                    world_from_ball,
                ),
                frame_transform(
                    time_secs,
                    &self.world_frame,
                    &self.body_frame,
                    world_from_body,
                ),
            ],
        }
    }

    /// The entities `ball`, `body` and `wheels` at a simulated time.
    pub fn scene(&self, time_secs: f64) -> SceneUpdate {
        let ball_diameter_m = 2.0 * self.ball_radius_m;
        let mut ball = entity(time_secs, &self.ball_frame, "ball");
        ball.spheres.push(SpherePrimitive {
            pose: Some(Pose::default()),
            size: Some(size(ball_diameter_m, ball_diameter_m, ball_diameter_m)),
            color: Some(rgba(0.85, 0.33, 0.10, 1.0)),
        });
        let dot_m = 0.25 * self.ball_radius_m;
        ball.spheres.push(SpherePrimitive {
            pose: Some(pose_at(self.ball_radius_m, 0.0, 0.0)),
            size: Some(size(dot_m, dot_m, dot_m)),
            color: Some(rgba(1.0, 1.0, 1.0, 1.0)),
        });

        let mut body = entity(time_secs, &self.body_frame, "body");
        let body_diameter_m = 2.0 * self.body_radius_m;
        body.cylinders.push(CylinderPrimitive {
            pose: Some(pose_at(
                0.0,
                0.0,
                self.body_bottom_m + 0.5 * self.body_height_m,
            )),
            size: Some(size(body_diameter_m, body_diameter_m, self.body_height_m)),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Some(rgba(0.0, 0.45, 0.74, 0.6)),
        });

        let mut wheels = entity(time_secs, &self.body_frame, "wheels");
        let wheel_diameter_m = 2.0 * self.wheel_radius_m;
        for body_from_wheel in &self.body_from_wheels {
            wheels.cylinders.push(CylinderPrimitive {
                pose: Some(pose(body_from_wheel)),
                size: Some(size(wheel_diameter_m, wheel_diameter_m, self.wheel_width_m)),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: Some(rgba(0.2, 0.2, 0.2, 1.0)),
            });
        }
        SceneUpdate {
            deletions: Vec::new(),
            entities: vec![ball, body, wheels],
        }
    }

    /// The entity `contact_forces`: at each omniwheel's contact with the ball, an arrow of the
    /// normal force the wheel presses on the ball (towards the ball centre) and one of its
    /// traction (along `axle x normal`, the wheel's rolling direction, signed), scaled by
    /// `metres_per_newton`. Traction arrows are green while the contact sticks and red when
    /// `slipping`. `contacts` holds one entry per wheel, in the order of `body_from_wheels`.
    pub fn contact_forces(
        &self,
        time_secs: f64,
        contacts: &[WheelContact],
        metres_per_newton: f64,
    ) -> SceneEntity {
        let mut forces = entity(time_secs, &self.body_frame, "contact_forces");
        for (body_from_wheel, contact) in self.body_from_wheels.iter().zip(contacts) {
            let centre = body_from_wheel.translation.vector;
            let Some(inward) = (-centre).try_normalize(1e-12) else {
                continue;
            };
            let axle = body_from_wheel.rotation * nalgebra::Vector3::z();
            let rolling = axle.cross(&inward);
            let point = nalgebra::Point3::from(centre + inward * self.wheel_radius_m);
            forces.arrows.push(arrow(
                point - inward * (contact.normal_force_n * metres_per_newton),
                inward * contact.normal_force_n,
                metres_per_newton,
                rgba(0.0, 0.3, 0.9, 1.0),
            ));
            let traction_color = if contact.slipping {
                rgba(0.9, 0.1, 0.1, 1.0)
            } else {
                rgba(0.1, 0.7, 0.2, 1.0)
            };
            forces.arrows.push(arrow(
                point,
                rolling * contact.traction_n,
                metres_per_newton,
                traction_color,
            ));
        }
        forces
    }
}

/// The contact state of one omniwheel, for [`BallbotScene::contact_forces`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelContact {
    /// Normal force the wheel presses on the ball (N), >= 0.
    pub normal_force_n: f64,
    /// Traction the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// Whether the contact slides (traction at the friction-cone limit).
    pub slipping: bool,
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::foxglove::{ArrowPrimitive, position_of, rotation_of};

    #[test]
    fn contact_arrows_start_at_the_contacts_and_point_as_the_forces() {
        let robot = BallbotScene::miapure_like();
        let contacts = [
            WheelContact {
                normal_force_n: 200.0,
                traction_n: 50.0,
                slipping: false,
            },
            WheelContact {
                normal_force_n: 100.0,
                traction_n: -20.0,
                slipping: true,
            },
            WheelContact::default(),
        ];
        let entity = robot.contact_forces(1.0, &contacts, 0.001);
        assert_eq!(entity.frame_id, "body");
        assert_eq!(entity.arrows.len(), 6);
        let direction =
            |arrow: &ArrowPrimitive| rotation_of(arrow.pose.as_ref()) * nalgebra::Vector3::x();
        let tip = |arrow: &ArrowPrimitive| {
            position_of(arrow.pose.as_ref())
                + direction(arrow) * (arrow.shaft_length + arrow.head_length)
        };
        // The normal-force arrow of wheel 0 ends on the ball surface, pointing at the centre.
        let normal = &entity.arrows[0];
        assert!((tip(normal).norm() - robot.ball_radius_m).abs() < 1e-12);
        let inward = -tip(normal).normalize();
        assert!((direction(normal) - inward).norm() < 1e-12);
        assert!((normal.shaft_length + normal.head_length - 0.2).abs() < 1e-12);
        // Traction is tangent to the ball, starts at the contact, and red only when slipping.
        let traction = &entity.arrows[1];
        assert!(direction(traction).dot(&inward).abs() < 1e-12);
        assert!((position_of(traction.pose.as_ref()) - tip(normal)).norm() < 1e-12);
        let colour = |a: &ArrowPrimitive| a.color.unwrap_or_default();
        assert!(colour(traction).g > colour(traction).r);
        assert!(colour(&entity.arrows[3]).r > colour(&entity.arrows[3]).g);
        // A negative traction points the other way.
        let axle = robot.body_from_wheels[1].rotation * nalgebra::Vector3::z();
        let inward_1 = -robot.body_from_wheels[1].translation.vector.normalize();
        assert!((direction(&entity.arrows[3]) + axle.cross(&inward_1)).norm() < 1e-9);
    }

    #[test]
    fn miapure_wheels_touch_the_ball_and_roll_along_the_horizontal_tangent() {
        let robot = BallbotScene::miapure_like();
        let params = BallbotParams::<f64>::miapure_60kg();
        assert_eq!(robot.ball_radius_m, params.sagittal.ball_radius_m);
        assert_eq!(robot.body_from_wheels.len(), 3);
        // The first wheel sits at azimuth 0: in the x-z plane, on the +x side, 45 deg up.
        let first = robot.body_from_wheels[0].translation.vector;
        assert!(first.y.abs() < 1e-12 && first.x > 0.0);
        assert!((first.z.atan2(first.x) - (90_f64 - 45.0).to_radians()).abs() < 1e-12);
        assert!(robot.body_bottom_m > first.z + robot.wheel_radius_m);
        for wheel in &robot.body_from_wheels {
            let centre_distance_m = wheel.translation.vector.norm();
            assert!((centre_distance_m - robot.ball_radius_m - robot.wheel_radius_m).abs() < 1e-12);
            let axle = wheel.rotation * nalgebra::Vector3::z();
            assert!(axle.dot(&wheel.translation.vector).abs() < 1e-12);
            // Rolling direction at the contact: axle x inward normal, horizontal (d_i).
            let inward = -wheel.translation.vector.normalize();
            let rolling = axle.cross(&inward);
            assert!(rolling.z.abs() < 1e-12, "{rolling}");
            assert!((rolling.norm() - 1.0).abs() < 1e-12);
        }
        // OW1 at azimuth 0 drives the ball along +y (d_1 = [0, 1, 0]).
        let axle = robot.body_from_wheels[0].rotation * nalgebra::Vector3::z();
        let inward = -robot.body_from_wheels[0].translation.vector.normalize();
        assert!((axle.cross(&inward) - nalgebra::Vector3::y()).norm() < 1e-12);
    }
}
