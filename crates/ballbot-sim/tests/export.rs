//! `ballbot export`: the MJCF and URDF files, parsed back (roxmltree), carry the world's robot:
//! total mass, the ball's and the body's mass, centre of mass and inertia (the body as the
//! composite of chassis, hubs and rollers), the wheels' positions, contact angle and axles, the
//! rollers on the rim circle, the ball radius, and the actuators, to 1e-9, for the presets and
//! for seeded random robots.

use ballbot_core::BallbotParams;
use ballbot_sim::export::{ExportError, ExportFormat, export};
use ballbot_sim::world::{RollerParams, WorldParams};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use std::collections::HashMap;

const TOL: f64 = 1e-9;

/// A rigid body's mass properties in some frame.
#[derive(Clone, Copy, Debug)]
struct Mass {
    kg: f64,
    com: Vector3<f64>,
    /// About the centre of mass.
    inertia: Matrix3<f64>,
}

fn parallel_axis(kg: f64, d: &Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * kg
}

fn composite(parts: &[Mass]) -> Mass {
    let kg: f64 = parts.iter().map(|p| p.kg).sum();
    let com = parts.iter().fold(Vector3::zeros(), |a, p| a + p.com * p.kg) / kg;
    let inertia = parts.iter().fold(Matrix3::zeros(), |a, p| {
        a + p.inertia + parallel_axis(p.kg, &(p.com - com))
    });
    Mass { kg, com, inertia }
}

fn transformed(m: &Mass, pos: &Vector3<f64>, rot: &Rotation3<f64>) -> Mass {
    let r = rot.matrix();
    Mass {
        kg: m.kg,
        com: pos + r * m.com,
        inertia: r * m.inertia * r.transpose(),
    }
}

fn floats(s: &str) -> Vec<f64> {
    s.split_whitespace()
        .map(|x| x.parse().unwrap_or_else(|e| panic!("{x}: {e}")))
        .collect()
}

fn vec3(s: Option<&str>) -> Vector3<f64> {
    s.map_or_else(Vector3::zeros, |s| Vector3::from_column_slice(&floats(s)))
}

fn assert_close(what: &str, got: f64, want: f64) {
    assert!(
        (got - want).abs() <= TOL * want.abs().max(1.0),
        "{what}: got {got}, want {want}"
    );
}

fn assert_vec_close(what: &str, got: &Vector3<f64>, want: &Vector3<f64>) {
    for k in 0..3 {
        assert_close(&format!("{what}[{k}]"), got[k], want[k]);
    }
}

fn assert_mat_close(what: &str, got: &Matrix3<f64>, want: &Matrix3<f64>) {
    for (k, (g, w)) in got.iter().zip(want.iter()).enumerate() {
        assert_close(&format!("{what}[{k}]"), *g, *w);
    }
}

/// What both files must agree with: the world's parameters.
struct Expected {
    ball: Mass,
    body: Mass,
    ball_radius_m: f64,
    wheel_centres: [Vector3<f64>; 3],
    axles: [Vector3<f64>; 3],
    wheel_radius_m: f64,
    wheel_axle_inertia_kg_m2: f64,
    armature_kg_m2: f64,
    gear_ratio: f64,
    peak_torque_nm: f64,
    rollers: usize,
}

fn expected(p: &WorldParams) -> Expected {
    let robot = &p.robot;
    let dt = &robot.drivetrain;
    let r = robot.ball_radius_m();
    let a = dt.contact_angle_rad;
    let frames = dt.wheel_azimuths_rad.map(|b| {
        let n = Vector3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos());
        let d = Vector3::new(-b.sin(), b.cos(), 0.0);
        (n * (r + dt.wheel_radius_m), d.cross(&n))
    });
    let n = dt.actuator.gear_ratio;
    Expected {
        ball: Mass {
            kg: robot.sagittal.ball_mass_kg,
            com: Vector3::zeros(),
            inertia: Matrix3::identity() * robot.sagittal.ball_inertia_kg_m2,
        },
        body: Mass {
            kg: robot.sagittal.body_mass_kg,
            com: Vector3::new(0.0, 0.0, robot.sagittal.com_height_m),
            inertia: Matrix3::from_diagonal(&Vector3::new(
                robot.frontal.body_inertia_kg_m2,
                robot.sagittal.body_inertia_kg_m2,
                robot.spin.inertia_kg_m2,
            )),
        },
        ball_radius_m: r,
        wheel_centres: frames.map(|f| f.0),
        axles: frames.map(|f| f.1),
        wheel_radius_m: dt.wheel_radius_m,
        wheel_axle_inertia_kg_m2: p.wheel_inertia_kg_m2,
        armature_kg_m2: p.rotor_inertia_kg_m2 * n * n,
        gear_ratio: n,
        peak_torque_nm: dt.actuator.peak_torque_nm,
        rollers: match p.contact.rollers.count {
            0 => 10,
            c => c as usize,
        },
    }
}

/// One MJCF body with its pose in its parent, its inertial, and its children.
struct MjcfBody {
    name: String,
    pos: Vector3<f64>,
    rot: Rotation3<f64>,
    mass: Mass,
    joint: Option<(String, f64)>,
    children: Vec<MjcfBody>,
}

fn mjcf_body(node: roxmltree::Node) -> MjcfBody {
    let pos = vec3(node.attribute("pos"));
    let rot = node
        .attribute("quat")
        .map_or_else(Rotation3::identity, |q| {
            let q = floats(q);
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
                .to_rotation_matrix()
        });
    let inertial = node
        .children()
        .find(|c| c.has_tag_name("inertial"))
        .unwrap_or_else(|| panic!("body {:?} has no inertial", node.attribute("name")));
    assert!(inertial.attribute("quat").is_none());
    let inertia = match (
        inertial.attribute("diaginertia"),
        inertial.attribute("fullinertia"),
    ) {
        (Some(d), None) => Matrix3::from_diagonal(&Vector3::from_column_slice(&floats(d))),
        (None, Some(f)) => {
            let f = floats(f);
            Matrix3::new(f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2])
        }
        other => panic!("inertial without one inertia: {other:?}"),
    };
    let joint = node.children().find(|c| c.has_tag_name("joint")).map(|j| {
        assert_eq!(j.attribute("axis"), Some("0 0 1"));
        (
            j.attribute("name").unwrap_or_default().to_owned(),
            j.attribute("armature").map_or(0.0, |a| floats(a)[0]),
        )
    });
    MjcfBody {
        name: node.attribute("name").unwrap_or_default().to_owned(),
        pos,
        rot,
        mass: Mass {
            kg: floats(inertial.attribute("mass").unwrap_or("nan"))[0],
            com: vec3(inertial.attribute("pos")),
            inertia,
        },
        joint,
        children: node
            .children()
            .filter(|c| c.has_tag_name("body"))
            .map(mjcf_body)
            .collect(),
    }
}

/// Every body of the subtree in the frame of `b`'s parent.
fn subtree_masses(b: &MjcfBody, out: &mut Vec<Mass>) {
    out.push(transformed(&b.mass, &b.pos, &b.rot));
    for c in &b.children {
        let mut inner = Vec::new();
        subtree_masses(c, &mut inner);
        out.extend(inner.iter().map(|m| transformed(m, &b.pos, &b.rot)));
    }
}

fn check_mjcf(p: &WorldParams) {
    let e = expected(p);
    let text = export(p, ExportFormat::Mjcf).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let worldbody = doc
        .descendants()
        .find(|n| n.has_tag_name("worldbody"))
        .unwrap();
    let top: Vec<MjcfBody> = worldbody
        .children()
        .filter(|c| c.has_tag_name("body"))
        .map(mjcf_body)
        .collect();
    let ball = top.iter().find(|b| b.name == "ball").unwrap();
    let body = top.iter().find(|b| b.name == "body").unwrap();
    // Ball: on the floor, its radius, mass and inertia.
    assert_vec_close(
        "ball pos",
        &ball.pos,
        &Vector3::new(0.0, 0.0, e.ball_radius_m),
    );
    assert_vec_close(
        "body pos",
        &body.pos,
        &Vector3::new(0.0, 0.0, e.ball_radius_m),
    );
    let sphere = doc
        .descendants()
        .find(|n| n.attribute("name") == Some("ball") && n.has_tag_name("geom"))
        .unwrap();
    assert_close(
        "ball radius",
        floats(sphere.attribute("size").unwrap())[0],
        e.ball_radius_m,
    );
    assert_close("ball mass", ball.mass.kg, e.ball.kg);
    assert_mat_close("ball inertia", &ball.mass.inertia, &e.ball.inertia);
    // Body: the composite of chassis, hubs and rollers, in the body frame.
    let mut parts = Vec::new();
    subtree_masses(body, &mut parts);
    let parts: Vec<Mass> = parts
        .iter()
        .map(|m| transformed(m, &-body.pos, &Rotation3::identity()))
        .collect();
    let c = composite(&parts);
    assert_close("body mass", c.kg, e.body.kg);
    assert_vec_close("body com", &c.com, &e.body.com);
    assert_mat_close("body inertia", &c.inertia, &e.body.inertia);
    assert_close("total mass", c.kg + ball.mass.kg, e.body.kg + e.ball.kg);
    // Wheels: centres (contact angle, azimuths, r + r_W), axles, armature, axle inertia.
    assert_eq!(body.children.len(), 3);
    let mesh = floats(
        doc.descendants()
            .find(|n| n.has_tag_name("mesh"))
            .and_then(|n| n.attribute("vertex"))
            .unwrap(),
    );
    for (i, w) in body.children.iter().enumerate() {
        assert_eq!(w.name, format!("ow{}", i + 1));
        assert_vec_close(&w.name, &w.pos, &e.wheel_centres[i]);
        assert_vec_close("axle", &(w.rot * Vector3::z()), &e.axles[i]);
        let (joint, armature) = w.joint.clone().unwrap();
        assert_eq!(joint, w.name);
        assert_close("armature", armature, e.armature_kg_m2);
        assert_eq!(w.children.len(), e.rollers);
        let mut axle = w.mass.inertia[(2, 2)];
        for r in &w.children {
            let m = transformed(&r.mass, &r.pos, &r.rot);
            axle += (m.inertia + parallel_axis(m.kg, &m.com))[(2, 2)];
            rollers_on_rim(&mesh, r, e.wheel_radius_m);
        }
        assert_close("wheel axle inertia", axle, e.wheel_axle_inertia_kg_m2);
    }
    // Actuators: the gear ratio, the peak torque at the wheel.
    let motors: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("motor"))
        .collect();
    assert_eq!(motors.len(), 3);
    for m in motors {
        let gear = floats(m.attribute("gear").unwrap())[0];
        let range = floats(m.attribute("ctrlrange").unwrap());
        assert_close("gear", gear, e.gear_ratio);
        assert_close("peak torque", range[1] * gear, e.peak_torque_nm);
        assert_close("peak torque", -range[0] * gear, e.peak_torque_nm);
    }
}

/// The barrel's profile (vertices in the wheel plane) lies on the rim circle of radius r_W.
fn rollers_on_rim(mesh: &[f64], r: &MjcfBody, r_w: f64) {
    let mut on_profile = 0;
    for v in mesh.chunks(3) {
        let v = Vector3::new(v[0], v[1], v[2]);
        // In the hub frame; the wheel plane is z = 0.
        let p = r.pos + r.rot * v;
        if p.z.abs() < 1e-12 && v.x > 0.0 {
            assert_close("roller profile radius", p.norm(), r_w);
            on_profile += 1;
        }
    }
    assert!(on_profile >= 3, "{on_profile}");
}

struct UrdfJoint {
    kind: String,
    parent: String,
    child: String,
    pos: Vector3<f64>,
    rot: Rotation3<f64>,
    axis: Option<Vector3<f64>>,
    effort: Option<f64>,
}

fn urdf_origin(node: roxmltree::Node) -> (Vector3<f64>, Rotation3<f64>) {
    let o = node.children().find(|c| c.has_tag_name("origin"));
    let pos = vec3(o.and_then(|o| o.attribute("xyz")));
    let rpy = vec3(o.and_then(|o| o.attribute("rpy")));
    (pos, Rotation3::from_euler_angles(rpy.x, rpy.y, rpy.z))
}

fn check_urdf(p: &WorldParams) {
    let e = expected(p);
    let text = export(p, ExportFormat::Urdf).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let robot = doc.root_element();
    let mut links: HashMap<String, Mass> = HashMap::new();
    let mut cylinders: HashMap<String, f64> = HashMap::new();
    for l in robot.children().filter(|c| c.has_tag_name("link")) {
        let name = l.attribute("name").unwrap().to_owned();
        let i = l.children().find(|c| c.has_tag_name("inertial")).unwrap();
        let (com, rot) = urdf_origin(i);
        assert_eq!(rot, Rotation3::identity());
        let get = |tag: &str| {
            i.descendants()
                .find(|c| c.has_tag_name(tag))
                .unwrap_or_else(|| panic!("{name}: no {tag}"))
        };
        let t = get("inertia");
        let at = |k: &str| floats(t.attribute(k).unwrap())[0];
        let inertia = Matrix3::new(
            at("ixx"),
            at("ixy"),
            at("ixz"),
            at("ixy"),
            at("iyy"),
            at("iyz"),
            at("ixz"),
            at("iyz"),
            at("izz"),
        );
        let kg = floats(get("mass").attribute("value").unwrap())[0];
        if let Some(c) = l
            .descendants()
            .find(|c| c.has_tag_name("collision"))
            .and_then(|c| c.descendants().find(|g| g.has_tag_name("cylinder")))
        {
            cylinders.insert(name.clone(), floats(c.attribute("radius").unwrap())[0]);
        }
        links.insert(name, Mass { kg, com, inertia });
    }
    let joints: Vec<UrdfJoint> = robot
        .children()
        .filter(|c| c.has_tag_name("joint"))
        .map(|j| {
            let link = |tag: &str| {
                j.children()
                    .find(|c| c.has_tag_name(tag))
                    .and_then(|c| c.attribute("link"))
                    .unwrap()
                    .to_owned()
            };
            let (pos, rot) = urdf_origin(j);
            UrdfJoint {
                kind: j.attribute("type").unwrap().to_owned(),
                parent: link("parent"),
                child: link("child"),
                pos,
                rot,
                axis: j
                    .children()
                    .find(|c| c.has_tag_name("axis"))
                    .map(|a| vec3(a.attribute("xyz"))),
                effort: j
                    .children()
                    .find(|c| c.has_tag_name("limit"))
                    .map(|l| floats(l.attribute("effort").unwrap())[0]),
            }
        })
        .collect();
    // Ball: a floating joint at the body frame's origin (the nominal ball centre).
    let ball_joint = joints.iter().find(|j| j.child == "ball").unwrap();
    assert_eq!(
        (ball_joint.kind.as_str(), ball_joint.parent.as_str()),
        ("floating", "body")
    );
    assert_vec_close("ball joint", &ball_joint.pos, &Vector3::zeros());
    let ball = links["ball"];
    assert_close("ball mass", ball.kg, e.ball.kg);
    assert_mat_close("ball inertia", &ball.inertia, &e.ball.inertia);
    let sphere = doc
        .descendants()
        .find(|n| n.has_tag_name("sphere"))
        .and_then(|n| n.attribute("radius"))
        .unwrap();
    assert_close("ball radius", floats(sphere)[0], e.ball_radius_m);
    // Body: the root link and every link below it but the ball, in the body frame.
    fn below(link: &str, joints: &[UrdfJoint], links: &HashMap<String, Mass>, out: &mut Vec<Mass>) {
        out.push(links[link]);
        for j in joints
            .iter()
            .filter(|j| j.parent == link && j.child != "ball")
        {
            let mut inner = Vec::new();
            below(&j.child, joints, links, &mut inner);
            out.extend(inner.iter().map(|m| transformed(m, &j.pos, &j.rot)));
        }
    }
    let mut parts = Vec::new();
    below("body", &joints, &links, &mut parts);
    assert_eq!(parts.len(), 1 + 3 * (1 + e.rollers));
    let c = composite(&parts);
    assert_close("body mass", c.kg, e.body.kg);
    assert_vec_close("body com", &c.com, &e.body.com);
    assert_mat_close("body inertia", &c.inertia, &e.body.inertia);
    assert_close("total mass", c.kg + ball.kg, e.body.kg + e.ball.kg);
    // Wheels and rollers.
    for i in 0..3 {
        let name = format!("ow{}", i + 1);
        let j = joints.iter().find(|j| j.child == name).unwrap();
        assert_eq!((j.kind.as_str(), j.parent.as_str()), ("continuous", "body"));
        assert_vec_close(&name, &j.pos, &e.wheel_centres[i]);
        assert_vec_close("axle", &(j.rot * j.axis.unwrap()), &e.axles[i]);
        assert_close("effort", j.effort.unwrap(), e.peak_torque_nm);
        let mut axle = links[&name].inertia[(2, 2)];
        for r in joints.iter().filter(|r| r.parent == name) {
            assert_eq!(r.kind, "continuous");
            let m = transformed(&links[&r.child], &r.pos, &r.rot);
            axle += (m.inertia + parallel_axis(m.kg, &m.com))[(2, 2)];
            // Mid-roller touches the rim circle: axis offset plus mid radius is r_W.
            assert_close(
                "roller on the rim",
                r.pos.norm() + cylinders[&r.child],
                e.wheel_radius_m,
            );
        }
        assert_close("wheel axle inertia", axle, e.wheel_axle_inertia_kg_m2);
    }
    let reductions: Vec<f64> = doc
        .descendants()
        .filter(|n| n.has_tag_name("mechanicalReduction"))
        .map(|n| floats(n.text().unwrap())[0])
        .collect();
    assert_eq!(reductions, vec![e.gear_ratio; 3]);
}

fn presets() -> Vec<(&'static str, WorldParams)> {
    vec![
        ("miapure_60kg (default world)", WorldParams::miapure_60kg()),
        (
            "miapure_60kg (ideal world, continuous rim)",
            WorldParams::ideal(BallbotParams::miapure_60kg()),
        ),
        (
            "miapure_unloaded",
            WorldParams::with_robot(BallbotParams::miapure_unloaded()),
        ),
    ]
}

#[test]
fn export_mjcf_carries_the_world_robot() {
    for (name, p) in presets() {
        println!("{name}");
        check_mjcf(&p);
    }
}

#[test]
fn export_urdf_carries_the_world_robot() {
    for (name, p) in presets() {
        println!("{name}");
        check_urdf(&p);
    }
}

/// Seeded random robots: contact angle, azimuths, COM height, inertias, wheel size, rollers.
#[test]
fn export_matches_random_worlds() {
    let seed = 0x0e7b_0a11_u64;
    println!("seed {seed:#x}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut unit = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    for case in 0..40 {
        let mut p = WorldParams::miapure_60kg();
        let dt = &mut p.robot.drivetrain;
        dt.contact_angle_rad = (30.0 + 25.0 * unit()).to_radians();
        let offset = std::f64::consts::TAU * unit();
        for (i, b) in dt.wheel_azimuths_rad.iter_mut().enumerate() {
            *b = offset + (i as f64) * std::f64::consts::TAU / 3.0 + 0.2 * (unit() - 0.5);
        }
        dt.wheel_radius_m *= 0.8 + 0.4 * unit();
        let s = 0.8 + 0.4 * unit();
        p.robot.sagittal.com_height_m *= s;
        p.robot.frontal.com_height_m *= s;
        p.robot.sagittal.body_inertia_kg_m2 *= 0.8 + 0.4 * unit();
        p.robot.frontal.body_inertia_kg_m2 *= 0.8 + 0.4 * unit();
        p.robot.spin.inertia_kg_m2 *= 0.8 + 0.4 * unit();
        p.wheel_inertia_kg_m2 *= 0.8 + 0.4 * unit();
        p.contact.rollers = RollerParams {
            count: 6 + (unit() * 10.0) as u32,
            gap_width_m: 0.002 + 0.003 * unit(),
        };
        p.rigid_step_ratio = 1;
        println!("case {case}: {:?}", p.robot.drivetrain);
        check_mjcf(&p);
        check_urdf(&p);
    }
}

#[test]
fn export_rejects_wheels_heavier_than_the_body() {
    let mut p = WorldParams::miapure_60kg();
    p.wheel_inertia_kg_m2 = 1.0;
    let e = export(&p, ExportFormat::Mjcf).unwrap_err();
    assert!(
        matches!(
            e,
            ExportError::Split {
                field: "robot.sagittal.body_mass_kg",
                ..
            }
        ),
        "{e}"
    );
    let mut p = WorldParams::miapure_60kg();
    p.contact.rollers.count = 2;
    let e = export(&p, ExportFormat::Urdf).unwrap_err();
    assert!(
        matches!(
            e,
            ExportError::Split {
                field: "contact.rollers.count",
                ..
            }
        ),
        "{e}"
    );
    assert!(matches!(
        "sdf".parse::<ExportFormat>(),
        Err(ExportError::UnknownFormat(_))
    ));
}
