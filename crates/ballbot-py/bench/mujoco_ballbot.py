"""A simple MuJoCo ballbot environment, for the speed comparison of ``bench_gym.py`` only (not
part of the package, not tested; needs ``pip install mujoco``).

The model is the common *virtual-wheel* simplification, written here from MiaPURE's
parameters (``WorldParams()``): a ball on a free joint on the floor, the body on a ball joint
at the ball's centre, and three motors acting between ball and body about the body's x, y and
z axes (the omniwheels' torques mapped through the drivetrain's geometry, the way the planar
models see them). It has no omniwheels, no rollers and no wheel-ball contacts, so it cannot
slip at a wheel: a lower bar of fidelity than the rapier3d world, and a cheaper one. MuJoCo
steps it at 1.25 ms (two steps per 400 Hz action) with elliptic friction cones.
"""

from __future__ import annotations

from typing import Any, Optional

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

import ballbot


def mjcf(params: ballbot.WorldParams) -> str:
    """The MJCF of the virtual-wheel ballbot with ``params``' masses and inertias."""
    r = params.robot
    sag, fro = r.sagittal, r.frontal
    radius, com = sag.ball_radius_m, sag.com_height_m
    # Torque between ball and body about each axis: the three wheels' peak torques mapped
    # through the drivetrain (ball radius over wheel radius, contact angle).
    d = r.drivetrain
    scale = sag.ball_radius_m / d.wheel_radius_m
    planar = 1.5 * scale * np.cos(d.contact_angle_rad) * d.actuator.peak_torque_nm
    spin = 3.0 * scale * np.sin(d.contact_angle_rad) * d.actuator.peak_torque_nm
    return f"""
<mujoco model="virtual-wheel ballbot">
  <option timestep="0.00125" integrator="implicitfast" cone="elliptic"/>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 0.1" friction="{d.ball_floor_friction} 0.01 0.001"/>
    <body name="ball" pos="0 0 {radius}">
      <freejoint/>
      <inertial pos="0 0 0" mass="{sag.ball_mass_kg}"
                diaginertia="{sag.ball_inertia_kg_m2} {sag.ball_inertia_kg_m2} {sag.ball_inertia_kg_m2}"/>
      <geom type="sphere" size="{radius}" contype="1" conaffinity="1"/>
      <body name="body" pos="0 0 0">
        <joint name="tilt" type="ball" damping="{params.wheel_damping_nm_s_per_rad}"/>
        <inertial pos="0 0 {com}" mass="{sag.body_mass_kg}"
                  diaginertia="{fro.body_inertia_kg_m2} {sag.body_inertia_kg_m2} {r.spin.inertia_kg_m2}"/>
        <geom type="box" pos="0 0 {com}" size="0.18 0.18 0.3" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="tilt" gear="1 0 0" ctrlrange="-{planar} {planar}"/>
    <motor joint="tilt" gear="0 1 0" ctrlrange="-{planar} {planar}"/>
    <motor joint="tilt" gear="0 0 1" ctrlrange="-{spin} {spin}"/>
  </actuator>
</mujoco>
"""


class MujocoBallbotEnv(gym.Env[np.ndarray, np.ndarray]):
    """Balance the virtual-wheel ballbot: actions are the three torques normalised to [-1, 1],
    observations roll, pitch, yaw, the body rates, the ball-body joint rates and a zero
    command (the layout of ``ballbot/Balance-v0``), 400 Hz, 10 s time limit, terminated past
    25 deg."""

    metadata = {"render_modes": []}

    def __init__(self) -> None:
        self.model = mujoco.MjModel.from_xml_string(mjcf(ballbot.WorldParams()))
        self.data = mujoco.MjData(self.model)
        high = np.full(12, np.inf, dtype=np.float32)
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        self.range = self.model.actuator_ctrlrange[:, 1].copy()
        self.steps = 0

    def _obs(self) -> np.ndarray:
        q = self.data.qpos[7:11]  # the ball joint's quaternion (w, x, y, z), ball to body
        w, x, y, z = q
        roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
        pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
        yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        rates = self.data.qvel[3:6] + self.data.qvel[6:9]
        obs = np.concatenate([[roll, pitch, yaw], rates, self.data.qvel[6:9], np.zeros(3)])
        return obs.astype(np.float32)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        mujoco.mj_resetData(self.model, self.data)
        tilt = self.np_random.uniform(0.0, 0.1)
        axis = self.np_random.uniform(0.0, 2 * np.pi)
        half = tilt / 2
        self.data.qpos[7:11] = [np.cos(half), np.sin(half) * np.cos(axis), np.sin(half) * np.sin(axis), 0.0]
        mujoco.mj_forward(self.model, self.data)
        self.steps = 0
        return self._obs(), {}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self.data.ctrl[:] = np.clip(action, -1.0, 1.0) * self.range
        mujoco.mj_step(self.model, self.data, nstep=2)
        self.steps += 1
        obs = self._obs()
        tilt2 = float(obs[0] ** 2 + obs[1] ** 2)
        terminated = tilt2 > np.radians(25.0) ** 2
        truncated = not terminated and self.steps >= 4000
        reward = (0.0 if terminated else 1.0) - 0.5 * tilt2 / 0.01
        return obs, reward, terminated, truncated, {}
