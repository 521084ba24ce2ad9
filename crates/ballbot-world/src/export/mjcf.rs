//! The MJCF writer (MuJoCo): see the parent module for what the file carries.

use super::model::{RobotModel, RollerShape, Wheel};
use super::xml::{full_inertia, quat, vec3};
use nalgebra::Vector3;
use std::fmt::Write as _;

/// Stations along a roller's axis and around it of its barrel mesh.
const MESH_STATIONS: usize = 9;
const MESH_SEGMENTS: usize = 16;

/// Collision classes (`contype`/`conaffinity`): the floor and ball collide, the rollers touch
/// the ball only; the chassis and hubs are drawn, not collided.
const FLOOR_BALL: u32 = 1;
const ROLLER: u32 = 2;

/// The MJCF document of `model`.
pub(super) fn write(model: &RobotModel) -> String {
    let mut out = String::new();
    header(&mut out, model);
    worldbody(&mut out, model);
    actuators(&mut out, model);
    out.push_str("</mujoco>\n");
    out
}

fn header(out: &mut String, m: &RobotModel) {
    out.push_str("<mujoco model=\"ballbot\">\n");
    out.push_str(
        "  <!-- Written by `ballbot export` from the world's parameters (ballbot_world::export).\n\
         \x20      Frames, the split of the body into chassis, hubs and rollers, and the\n\
         \x20      estimates behind it: ballbot_world::export::model. -->\n",
    );
    out.push_str("  <compiler angle=\"radian\" autolimits=\"true\"/>\n");
    let _ = writeln!(
        out,
        "  <option timestep=\"{}\" gravity=\"0 0 {}\" integrator=\"implicitfast\" \
         cone=\"elliptic\"/>",
        m.timestep_secs, -m.gravity_m_per_s2
    );
    let _ = writeln!(
        out,
        "  <asset>\n    <mesh name=\"roller\" vertex=\"{}\"/>\n  </asset>",
        roller_mesh(&m.roller)
    );
}

/// The barrel's vertices in the roller frame (z along its axis): rings whose radius follows
/// the rim circle ([`RollerShape::radius_at_m`]); MuJoCo collides with their convex hull.
fn roller_mesh(shape: &RollerShape) -> String {
    let mut points = Vec::with_capacity(MESH_STATIONS * MESH_SEGMENTS);
    for k in 0..MESH_STATIONS {
        let t = k as f64 / (MESH_STATIONS - 1) as f64;
        let s = shape.half_length_m * (2.0 * t - 1.0);
        let rho = shape.radius_at_m(s);
        for j in 0..MESH_SEGMENTS {
            let g = std::f64::consts::TAU * j as f64 / MESH_SEGMENTS as f64;
            points.push(vec3(&Vector3::new(rho * g.cos(), rho * g.sin(), s)));
        }
    }
    points.join("  ")
}

fn worldbody(out: &mut String, m: &RobotModel) {
    let r = m.ball_radius_m;
    out.push_str("  <worldbody>\n");
    // The floor carries the ball-floor friction, torsional and rolling included (condim 6);
    // MuJoCo takes each coefficient's maximum over a pair, and the ball's own are no larger.
    let _ = writeln!(
        out,
        "    <geom name=\"floor\" type=\"plane\" size=\"50 50 0.1\" condim=\"6\" \
         contype=\"{FLOOR_BALL}\" conaffinity=\"{FLOOR_BALL}\" friction=\"{} {} {}\" \
         solref=\"{} 1\"/>",
        m.ball_floor_friction,
        m.spin_friction_m,
        m.rolling_friction_m,
        m.floor_contact_timeconst_secs
    );
    let _ = writeln!(
        out,
        "    <body name=\"ball\" pos=\"0 0 {r}\">\n      <freejoint name=\"ball\"/>\n      \
         <inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"{}\"/>\n      \
         <geom name=\"ball\" type=\"sphere\" size=\"{r}\" condim=\"3\" contype=\"{FLOOR_BALL}\" \
         conaffinity=\"{}\" friction=\"{} 0 0\"/>\n    </body>",
        m.ball.mass_kg,
        vec3(&m.ball.inertia_kg_m2.diagonal()),
        FLOOR_BALL | ROLLER,
        m.ball_floor_friction.min(m.wheel_ball_friction),
    );
    let c = &m.chassis;
    let h = m.chassis_height_m;
    let _ = writeln!(
        out,
        "    <body name=\"body\" pos=\"0 0 {r}\">\n      <freejoint name=\"body\"/>\n      \
         <inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>\n      \
         <geom name=\"chassis\" type=\"box\" pos=\"0 0 {}\" size=\"{} {} {}\" contype=\"0\" \
         conaffinity=\"0\"/>",
        vec3(&c.com_m),
        c.mass_kg,
        full_inertia(&c.inertia_kg_m2),
        0.5 * h,
        m.chassis_half_width_m,
        m.chassis_half_width_m,
        0.5 * h,
    );
    for w in &m.wheels {
        wheel(out, m, w);
    }
    out.push_str("    </body>\n  </worldbody>\n");
}

fn wheel(out: &mut String, m: &RobotModel, w: &Wheel) {
    let name = &w.name;
    let shape = &m.roller;
    let _ = writeln!(
        out,
        "      <body name=\"{name}\" pos=\"{}\" quat=\"{}\">\n        \
         <joint name=\"{name}\" type=\"hinge\" axis=\"0 0 1\" armature=\"{}\" damping=\"{}\"/>\n        \
         <inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"{}\"/>\n        \
         <geom name=\"{name}_hub\" type=\"cylinder\" size=\"{} {}\" contype=\"0\" \
         conaffinity=\"0\"/>",
        vec3(&w.pose.position_m),
        quat(&w.pose.rotation),
        m.armature_kg_m2,
        m.wheel_damping_nm_s_per_rad,
        w.hub.mass_kg,
        vec3(&w.hub.inertia_kg_m2.diagonal()),
        shape.axis_offset_m - shape.mid_radius_m,
        shape.mid_radius_m,
    );
    for (j, r) in w.rollers.iter().enumerate() {
        let _ = writeln!(
            out,
            "        <body name=\"{name}_roller{j}\" pos=\"{}\" quat=\"{}\">\n          \
             <joint name=\"{name}_roller{j}\" type=\"hinge\" axis=\"0 0 1\"/>\n          \
             <inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"{}\"/>\n          \
             <geom type=\"mesh\" mesh=\"roller\" condim=\"3\" contype=\"{ROLLER}\" \
             conaffinity=\"0\" friction=\"{} 0 0\" solref=\"{} 1\"/>\n        </body>",
            vec3(&r.pose.position_m),
            quat(&r.pose.rotation),
            r.inertial.mass_kg,
            vec3(&r.inertial.inertia_kg_m2.diagonal()),
            m.wheel_ball_friction,
            m.roller_contact_timeconst_secs,
        );
    }
    out.push_str("      </body>\n");
}

fn actuators(out: &mut String, m: &RobotModel) {
    // The control is the rotor's torque; the gear multiplies it onto the hub joint, so the
    // range is the peak wheel torque over the gear ratio. The world's torque-speed line
    // (no-load speed at the wheel) has no MJCF counterpart.
    let limit = m.peak_wheel_torque_nm / m.gear_ratio;
    let _ = writeln!(
        out,
        "  <!-- ctrl: rotor torque (N m); wheel torque = gear * ctrl, at most {} N m; no-load \
         speed at the wheel {} rad/s (not modelled). -->",
        m.peak_wheel_torque_nm, m.no_load_speed_rad_per_s
    );
    out.push_str("  <actuator>\n");
    for w in &m.wheels {
        let _ = writeln!(
            out,
            "    <motor name=\"{0}\" joint=\"{0}\" gear=\"{1}\" ctrlrange=\"{2} {3}\"/>",
            w.name, m.gear_ratio, -limit, limit
        );
    }
    out.push_str("  </actuator>\n");
}
