"""A MuJoCo ballbot with roller omniwheels, written from ballbot's own parameters, for the speed
comparison of ``bench.py`` (not part of the package or the test command).

The model is what a MuJoCo user would build to see omniwheel slip: a ball on a free joint on the
floor; the body on its own free joint, resting on the ball only through three omniwheels; each
omniwheel a hinge-driven hub carrying ``ROLLERS_PER_WHEEL`` capsule rollers, each on its own hinge
along the rim's tangent, so the contact is free along the wheel's axle and gripping along its
rolling direction, with MuJoCo's elliptic friction cones. Masses, inertias, geometry and friction
come from ``world_speed params`` (the default MiaPURE world): the wheels' and rollers' masses are
taken out of the body's, the rotor's reflected inertia is the hub hinge's armature.

The project's own MJCF of the robot is ``ballbot export --format mjcf`` (``ballbot_sim::export``,
docs/export.md): barrel rollers on the world's roller count, the body split so that chassis, hubs
and rollers keep the world body's inertia. This bench keeps its own 24-roller capsule model so
that the speed comparison it measured stays the same.

Usage: ``python roller_ballbot.py PARAMS.json > ballbot.xml``.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import numpy as np

#: Rollers per omniwheel (a single row, as on MiaPURE's wheels).
ROLLERS_PER_WHEEL = 24
#: Roller radius (m): 24 rollers on a 62.5 mm wheel leave about 15 mm of rim each.
ROLLER_RADIUS_M = 0.005
#: Mass of one roller (kg) and of one hub (kg) (estimates, taken out of the body's mass).
ROLLER_MASS_KG = 0.01
HUB_MASS_KG = 0.3
#: MuJoCo's step (s): 1 ms, as in the earlier MuJoCo roller-model measurement that docs/world.md
#: cites ("Speed against MuJoCo").
TIMESTEP_S = 0.001


def _vec(v: Any) -> str:
    return " ".join(f"{x:.9g}" for x in v)


def wheel_frames(p: dict[str, Any]) -> list[dict[str, np.ndarray]]:
    """Per omniwheel: contact normal ``n`` (ball centre to contact), rolling direction ``d`` and
    axle ``a = d x n`` in the body frame (MODEL.md section 1)."""
    alpha = p["contact_angle_rad"]
    frames = []
    for beta in p["wheel_azimuths_rad"]:
        n = np.array([math.sin(alpha) * math.cos(beta), math.sin(alpha) * math.sin(beta), math.cos(alpha)])
        d = np.array([-math.sin(beta), math.cos(beta), 0.0])
        frames.append({"n": n, "d": d, "a": np.cross(d, n)})
    return frames


def mjcf(p: dict[str, Any]) -> str:
    """The MJCF of the roller-omniwheel ballbot with the parameters ``p`` (``world_speed
    params``)."""
    r, r_w = p["ball_radius_m"], p["wheel_radius_m"]
    rho = ROLLER_RADIUS_M
    r_c = r_w - rho  # roller axes' circle
    arc = 2.0 * math.pi * r_c / ROLLERS_PER_WHEEL
    half_len = max(0.45 * arc - rho, 0.0005)  # capsule cylinder half-length, 10 % gap
    rollers_axle = ROLLERS_PER_WHEEL * ROLLER_MASS_KG * r_c**2
    hub_axle = max(p["wheel_inertia_kg_m2"] - rollers_axle, 1e-5)
    armature = p["rotor_inertia_kg_m2"] * p["gear_ratio"] ** 2
    wheel_mass = HUB_MASS_KG + ROLLERS_PER_WHEEL * ROLLER_MASS_KG
    body_mass = p["body_mass_kg"] - 3.0 * wheel_mass
    roller_i_axis = 0.5 * ROLLER_MASS_KG * rho**2
    roller_i_cross = ROLLER_MASS_KG * (3.0 * rho**2 + (2.0 * half_len) ** 2) / 12.0
    mu = p["wheel_ball_friction"]
    peak = p["peak_wheel_torque_nm"]
    wheels = []
    actuators = []
    for i, f in enumerate(wheel_frames(p)):
        centre = (r + r_w) * f["n"]
        rollers = []
        for j in range(ROLLERS_PER_WHEEL):
            g = 2.0 * math.pi * j / ROLLERS_PER_WHEEL
            pos = (r_c * math.cos(g), r_c * math.sin(g), 0.0)
            tangent = (-math.sin(g), math.cos(g), 0.0)
            rollers.append(
                f'        <body name="ow{i + 1}_roller{j}" pos="{_vec(pos)}" zaxis="{_vec(tangent)}">\n'
                f'          <joint type="hinge" axis="0 0 1" damping="1e-5"/>\n'
                f'          <inertial pos="0 0 0" mass="{ROLLER_MASS_KG}" '
                f'diaginertia="{roller_i_cross:.6g} {roller_i_cross:.6g} {roller_i_axis:.6g}"/>\n'
                f'          <geom type="capsule" size="{rho} {half_len:.6g}" contype="2" '
                f'conaffinity="0" friction="{mu} 0.005 0.0001"/>\n'
                f"        </body>"
            )
        # Hub frame: x towards the ball (-n), z along the axle a, so y = a x (-n) = d.
        wheels.append(
            f'      <body name="ow{i + 1}" pos="{_vec(centre)}" xyaxes="{_vec(-f["n"])} {_vec(f["d"])}">\n'
            f'        <joint name="ow{i + 1}" type="hinge" axis="0 0 1" armature="{armature:.6g}" '
            f'damping="{p["wheel_damping_nm_s_per_rad"]}"/>\n'
            f'        <inertial pos="0 0 0" mass="{HUB_MASS_KG}" '
            f'diaginertia="{hub_axle / 2:.6g} {hub_axle / 2:.6g} {hub_axle:.6g}"/>\n'
            + "\n".join(rollers)
            + "\n      </body>"
        )
        actuators.append(
            f'    <motor name="ow{i + 1}" joint="ow{i + 1}" gear="1" ctrlrange="{-peak} {peak}"/>'
        )
    ix, iy, iz = p["body_inertia_kg_m2"]
    i_b = p["ball_inertia_kg_m2"]
    return f"""<mujoco model="roller-omniwheel ballbot">
  <option timestep="{TIMESTEP_S}" integrator="implicitfast" cone="elliptic"/>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 0.1" contype="1" conaffinity="1"
          friction="{p["ball_floor_friction"]} 0.005 0.0001"/>
    <body name="ball" pos="0 0 {r}">
      <freejoint/>
      <inertial pos="0 0 0" mass="{p["ball_mass_kg"]}" diaginertia="{i_b} {i_b} {i_b}"/>
      <geom type="sphere" size="{r}" contype="1" conaffinity="3" friction="{mu} 0.005 0.0001"/>
    </body>
    <body name="body" pos="0 0 {r}">
      <freejoint/>
      <inertial pos="0 0 {p["com_height_m"]}" mass="{body_mass:.6g}" diaginertia="{ix} {iy} {iz}"/>
      <geom type="box" pos="0 0 {p["com_height_m"]}" size="0.15 0.15 0.3" contype="0" conaffinity="0"/>
{chr(10).join(wheels)}
    </body>
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
</mujoco>
"""


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        print(mjcf(json.load(f)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
