"""``ballbot.export``: the world's robot as MJCF and URDF, loaded by MuJoCo and by a URDF library
(``yourdfpy``) when installed, with the world's masses, inertias and geometry to 1e-9."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ballbot

TOL = 1e-9
PRESETS = ["miapure_60kg", "miapure_unloaded", "ideal_miapure_60kg"]


def _expected(params: ballbot.WorldParams) -> dict[str, Any]:
    """The world's robot, from its parameters alone."""
    robot = params.robot
    dt = robot.drivetrain
    r, r_w, a = robot.sagittal.ball_radius_m, dt.wheel_radius_m, dt.contact_angle_rad
    centres = [
        (r + r_w) * np.array([math.sin(a) * math.cos(b), math.sin(a) * math.sin(b), math.cos(a)])
        for b in dt.wheel_azimuths_rad
    ]
    gear = dt.actuator.gear_ratio
    return {
        "ball_mass": robot.sagittal.ball_mass_kg,
        "ball_inertia": robot.sagittal.ball_inertia_kg_m2,
        "ball_radius": r,
        "body_mass": robot.sagittal.body_mass_kg,
        "body_com": np.array([0.0, 0.0, robot.sagittal.com_height_m]),
        "body_inertia": np.diag(
            [
                robot.frontal.body_inertia_kg_m2,
                robot.sagittal.body_inertia_kg_m2,
                robot.spin.inertia_kg_m2,
            ]
        ),
        "wheel_centres": centres,
        "armature": params.rotor_inertia_kg_m2 * gear**2,
        "gear": gear,
        "peak_torque": dt.actuator.peak_torque_nm,
    }


def _composite(
    masses: list[float], coms: list[np.ndarray], inertias: list[np.ndarray]
) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of mass and inertia about it of bodies given in one frame."""
    total = float(sum(masses))
    com = sum(m * c for m, c in zip(masses, coms)) / total
    inertia = np.zeros((3, 3))
    for m, c, i in zip(masses, coms, inertias):
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return total, com, inertia


def test_export_writes_both_formats_and_the_file(tmp_path: Path) -> None:
    params = ballbot.WorldParams.preset("miapure_60kg")
    mjcf = ballbot.export("mjcf", params, tmp_path / "ballbot.xml")
    assert mjcf.startswith('<mujoco model="ballbot">')
    assert (tmp_path / "ballbot.xml").read_text() == mjcf
    assert ballbot.export("mjcf") == mjcf  # the default world
    assert "<robot name=\"ballbot\">" in ballbot.export("urdf", params)
    assert ballbot.world.export is ballbot.export


def test_export_errors_name_the_problem() -> None:
    with pytest.raises(ballbot.ParameterError, match="unknown export format `sdf`"):
        ballbot.export("sdf")  # type: ignore[arg-type]
    heavy = ballbot.WorldParams.preset("miapure_60kg").replace(wheel_inertia_kg_m2=1.0)
    with pytest.raises(ValueError, match="robot.sagittal.body_mass_kg"):
        ballbot.export("urdf", heavy)


@pytest.mark.parametrize("preset", PRESETS)
def test_mjcf_loads_in_mujoco_with_the_world_masses(preset: str) -> None:
    mujoco = pytest.importorskip("mujoco")
    params = ballbot.WorldParams.preset(preset)  # type: ignore[arg-type]
    e = _expected(params)
    model = mujoco.MjModel.from_xml_string(ballbot.export("mjcf", params))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    ball, body = model.body("ball").id, model.body("body").id
    # The ball: mass, inertia, radius, on the floor.
    assert abs(model.body_mass[ball] - e["ball_mass"]) < TOL
    np.testing.assert_allclose(model.body_inertia[ball], [e["ball_inertia"]] * 3, rtol=0, atol=TOL)
    assert abs(model.geom("ball").size[0] - e["ball_radius"]) < TOL
    assert abs(data.xpos[ball][2] - e["ball_radius"]) < TOL
    # The body: chassis, hubs and rollers together, in the body frame (upright at the start).
    subtree = [b for b in range(model.nbody) if model.body_rootid[b] == body]
    masses = [float(model.body_mass[b]) for b in subtree]
    coms = [data.xipos[b] - data.xpos[body] for b in subtree]
    inertias = []
    for b in subtree:
        rot = data.ximat[b].reshape(3, 3)
        inertias.append(rot @ np.diag(model.body_inertia[b]) @ rot.T)
    mass, com, inertia = _composite(masses, coms, inertias)
    assert abs(mass - e["body_mass"]) < TOL
    assert abs(model.body_subtreemass[body] - e["body_mass"]) < TOL
    np.testing.assert_allclose(com, e["body_com"], rtol=0, atol=TOL)
    np.testing.assert_allclose(inertia, e["body_inertia"], rtol=0, atol=TOL)
    assert abs(float(np.sum(model.body_mass)) - e["ball_mass"] - e["body_mass"]) < TOL
    # The omniwheels: positions (contact angle, azimuths), armature, actuators.
    for i in range(3):
        name = f"ow{i + 1}"
        np.testing.assert_allclose(
            data.xpos[model.body(name).id] - data.xpos[body], e["wheel_centres"][i], rtol=0, atol=TOL
        )
        assert abs(model.dof_armature[model.joint(name).dofadr[0]] - e["armature"]) < TOL
        act = model.actuator(name)
        assert abs(act.gear[0] - e["gear"]) < TOL
        np.testing.assert_allclose(act.ctrlrange * act.gear[0], [-e["peak_torque"], e["peak_torque"]], rtol=0, atol=TOL)


def test_mjcf_robot_stands_on_its_rollers_in_mujoco() -> None:
    """With the motors off for 0.125 s the body rests on the ball through the rollers (a free
    fall would drop it 77 mm) and nothing blows up."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(ballbot.export("mjcf"))
    data = mujoco.MjData(model)
    body = model.body("body").id
    mujoco.mj_forward(model, data)
    z0 = float(data.xpos[body][2])
    steps = round(0.125 / model.opt.timestep)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    assert np.all(np.isfinite(data.qpos))
    assert abs(float(data.xpos[body][2]) - z0) < 0.005, (z0, data.xpos[body][2])


@pytest.mark.parametrize("preset", PRESETS)
def test_urdf_loads_in_yourdfpy_with_the_world_masses(preset: str, tmp_path: Path) -> None:
    yourdfpy = pytest.importorskip("yourdfpy")
    params = ballbot.WorldParams.preset(preset)  # type: ignore[arg-type]
    e = _expected(params)
    path = tmp_path / "ballbot.urdf"
    ballbot.export("urdf", params, path)
    urdf = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert urdf.base_link == "body"
    links = urdf.link_map
    ball = links["ball"].inertial
    assert abs(ball.mass - e["ball_mass"]) < TOL
    np.testing.assert_allclose(ball.inertia, e["ball_inertia"] * np.eye(3), rtol=0, atol=TOL)
    assert abs(links["ball"].collisions[0].geometry.sphere.radius - e["ball_radius"]) < TOL
    # The body: every link but the ball, in the body frame (all joints at zero).
    masses, coms, inertias = [], [], []
    for name, link in links.items():
        if name == "ball":
            continue
        pose = urdf.get_transform(name, "body") @ link.inertial.origin
        rot = pose[:3, :3]
        masses.append(link.inertial.mass)
        coms.append(pose[:3, 3])
        inertias.append(rot @ link.inertial.inertia @ rot.T)
    mass, com, inertia = _composite(masses, coms, inertias)
    assert abs(mass - e["body_mass"]) < TOL
    np.testing.assert_allclose(com, e["body_com"], rtol=0, atol=TOL)
    np.testing.assert_allclose(inertia, e["body_inertia"], rtol=0, atol=TOL)
    for i in range(3):
        name = f"ow{i + 1}"
        centre = urdf.get_transform(name, "body")[:3, 3]
        np.testing.assert_allclose(centre, e["wheel_centres"][i], rtol=0, atol=TOL)
        assert abs(urdf.joint_map[name].limit.effort - e["peak_torque"]) < TOL
