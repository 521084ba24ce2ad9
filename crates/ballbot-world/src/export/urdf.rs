//! The URDF writer: see the parent module for what the file carries.

use super::model::{Inertial, Pose, RobotModel, Wheel};
use super::xml::{rpy, vec3};
use std::fmt::Write as _;

/// The URDF document of `model`.
pub(super) fn write(model: &RobotModel) -> String {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n<robot name=\"ballbot\">\n");
    out.push_str(
        "  <!-- Written by `ballbot export` from the world's parameters (ballbot_world::export).\n\
         \x20      The root link is the chassis; its frame's origin is the nominal ball centre,\n\
         \x20      z up, x towards OW1. Frames, the split of the body into chassis, hubs and\n\
         \x20      rollers, and the estimates behind it: ballbot_world::export::model. -->\n",
    );
    chassis(&mut out, model);
    ball(&mut out, model);
    for w in &model.wheels {
        wheel(&mut out, model, w);
    }
    out.push_str("</robot>\n");
    out
}

/// `<inertial>` with the centre of mass as origin and the tensor in the link's axes.
fn inertial(out: &mut String, indent: &str, i: &Inertial) {
    let t = &i.inertia_kg_m2;
    let _ = writeln!(
        out,
        "{indent}<inertial>\n{indent}  <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n{indent}  \
         <mass value=\"{}\"/>\n{indent}  <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" \
         iyz=\"{}\" izz=\"{}\"/>\n{indent}</inertial>",
        vec3(&i.com_m),
        i.mass_kg,
        t[(0, 0)],
        t[(0, 1)],
        t[(0, 2)],
        t[(1, 1)],
        t[(1, 2)],
        t[(2, 2)],
    );
}

fn origin(pose: &Pose) -> String {
    format!(
        "<origin xyz=\"{}\" rpy=\"{}\"/>",
        vec3(&pose.position_m),
        rpy(&pose.rotation)
    )
}

fn chassis(out: &mut String, m: &RobotModel) {
    let h = m.chassis_height_m;
    let w = 2.0 * m.chassis_half_width_m;
    out.push_str("  <link name=\"body\">\n");
    inertial(out, "    ", &m.chassis);
    let _ = writeln!(
        out,
        "    <visual>\n      <origin xyz=\"0 0 {}\" rpy=\"0 0 0\"/>\n      \
         <geometry><box size=\"{w} {w} {h}\"/></geometry>\n    </visual>\n  </link>",
        0.5 * h
    );
}

fn ball(out: &mut String, m: &RobotModel) {
    let r = m.ball_radius_m;
    out.push_str("  <link name=\"ball\">\n");
    inertial(out, "    ", &m.ball);
    let _ = writeln!(
        out,
        "    <visual><geometry><sphere radius=\"{r}\"/></geometry></visual>\n    \
         <collision><geometry><sphere radius=\"{r}\"/></geometry></collision>\n  </link>"
    );
    // The ball is held by contacts only: a floating joint at the nominal ball centre.
    out.push_str(
        "  <joint name=\"ball\" type=\"floating\">\n    <parent link=\"body\"/>\n    \
         <child link=\"ball\"/>\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n  </joint>\n",
    );
}

fn wheel(out: &mut String, m: &RobotModel, w: &Wheel) {
    let name = &w.name;
    let shape = &m.roller;
    let _ = writeln!(out, "  <link name=\"{name}\">");
    inertial(out, "    ", &w.hub);
    let _ = writeln!(
        out,
        "    <visual><geometry><cylinder radius=\"{}\" length=\"{}\"/></geometry></visual>\n  \
         </link>",
        shape.axis_offset_m - shape.mid_radius_m,
        2.0 * shape.mid_radius_m
    );
    let _ = writeln!(
        out,
        "  <joint name=\"{name}\" type=\"continuous\">\n    <parent link=\"body\"/>\n    \
         <child link=\"{name}\"/>\n    {}\n    <axis xyz=\"0 0 1\"/>\n    \
         <limit effort=\"{}\" velocity=\"{}\"/>\n    <dynamics damping=\"{}\" friction=\"0\"/>\n  \
         </joint>",
        origin(&w.pose),
        m.peak_wheel_torque_nm,
        m.no_load_speed_rad_per_s,
        m.wheel_damping_nm_s_per_rad,
    );
    let _ = writeln!(
        out,
        "  <!-- {name}: the rotor's inertia reflected onto the joint (armature) is {} kg m^2. -->\n  \
         <transmission name=\"{name}_transmission\">\n    \
         <type>transmission_interface/SimpleTransmission</type>\n    \
         <joint name=\"{name}\"><hardwareInterface>hardware_interface/EffortJointInterface\
         </hardwareInterface></joint>\n    <actuator name=\"{name}_motor\">\
         <mechanicalReduction>{}</mechanicalReduction></actuator>\n  </transmission>",
        m.armature_kg_m2, m.gear_ratio,
    );
    for (j, r) in w.rollers.iter().enumerate() {
        let _ = writeln!(out, "  <link name=\"{name}_roller{j}\">");
        inertial(out, "    ", &r.inertial);
        let _ = writeln!(
            out,
            "    <collision><geometry><cylinder radius=\"{0}\" length=\"{1}\"/></geometry>\
             </collision>\n    <visual><geometry><cylinder radius=\"{0}\" length=\"{1}\"/>\
             </geometry></visual>\n  </link>",
            shape.mid_radius_m,
            2.0 * shape.half_length_m
        );
        let _ = writeln!(
            out,
            "  <joint name=\"{name}_roller{j}\" type=\"continuous\">\n    \
             <parent link=\"{name}\"/>\n    <child link=\"{name}_roller{j}\"/>\n    {}\n    \
             <axis xyz=\"0 0 1\"/>\n  </joint>",
            origin(&r.pose),
        );
    }
}
