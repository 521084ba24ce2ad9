"""Gymnasium environments on the rapier3d world (needs the ``gym`` extra:
``pip install "./crates/ballbot-py[gym]"``).

Importing this module registers:

- ``ballbot/Balance-v0``: the agent commands the three wheel torques, normalised to [-1, 1]
  of the actuator's peak torque, and should keep the robot up from a random initial tilt.
- ``ballbot/Velocity-v0``: track random velocity commands; by default the agent acts on top
  of the core's cascaded LQR-PI with a residual wheel torque (``residual=False``: torque
  control as in Balance).

Both run MiaPURE with 60 kg by default (``params=`` takes any ``WorldParams``), at 400 agent
steps per second (``control_hz=``) over the 8 kHz physics, ``terminated`` on a fall (the
chassis on the floor, or tilt beyond 25 deg), a motor driver trip, or the controller switching
the motors off, and ``truncated`` at the time limit (``max_episode_secs=``, 10 s). A wheel's
slip or lift-off does not end an episode: it is reported in ``info["events"]`` (the contact
events in progress during the step) and, at the episode's end, ``info["episode_events"]``;
``info["termination"]`` says why an episode ended. ``stop_on="all"`` ends episodes at a slip
longer than 0.1 s or a lift-off longer than 20 ms too, as before (``stop_on=`` takes
``ballbot world --stop-on``'s rules). Observations (float32, bounded): IMU roll, pitch, yaw,
gyro rates, encoder wheel speeds, the command, and with ``last_action_in_observation=True``
the last action.

Domain randomisation: ``randomization=`` at construction (``"recommended"``, ``"none"`` or a
dict of ranges) and ``reset(options={"randomization": {...}})`` per episode, seeded by the
episode's seed (``info["episode_seed"]``). Keys: ``added_payload_kg``, ``com_height_m``,
``wheel_ball_friction``, ``wheel_damping_nm_s_per_rad``, ``imu_noise_factor``,
``sensor_delay_secs``, ``initial_tilt_rad``, ``push_impulse_ns``, ``push_interval_secs``; each
a ``[lo, hi]`` pair or a number. Other reset options: ``initial_tilt_rad`` (2 numbers) and
``command`` (3 numbers, a fixed command).

``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")`` gives
``BallbotVectorEnv``: N worlds stepped in Rust in one call on ``threads=`` cores without the
GIL, with next-step autoreset.

``pretrained("balance")`` (and ``"balance_randomized"``) returns a shipped balancing policy, a
``Policy`` evaluated in numpy; ``evaluate(policy, seeds)`` runs it on seeded episodes.

>>> import gymnasium as gym
>>> import ballbot.gym
>>> env = gym.make("ballbot/Balance-v0")
>>> obs, info = env.reset(seed=0)
>>> obs.shape, info["episode_seed"]
((12,), 0)
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as e:  # pragma: no cover - depends on the install
    raise ImportError(
        'ballbot.gym needs gymnasium: pip install "ballbot[gym]" '
        '(from the repository: pip install "./crates/ballbot-py[gym]")'
    ) from e

from ballbot.gym._env import BallbotEnv
from ballbot.gym._policy import PRETRAINED, Policy, evaluate, pretrained
from ballbot.gym._vector import BallbotVectorEnv

__all__ = [
    "BallbotEnv",
    "BallbotVectorEnv",
    "ENV_IDS",
    "PRETRAINED",
    "Policy",
    "evaluate",
    "pretrained",
    "register_envs",
]

#: The registered environment ids and their task.
ENV_IDS = {"ballbot/Balance-v0": "balance", "ballbot/Velocity-v0": "velocity"}


def register_envs() -> None:
    """Registers the environments with Gymnasium (done on import; repeated calls do nothing)."""
    for env_id, task in ENV_IDS.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point="ballbot.gym._env:BallbotEnv",
            vector_entry_point="ballbot.gym._vector:BallbotVectorEnv",
            kwargs={"task": task},
            # The environments end episodes at their own time limit (`truncated`).
            max_episode_steps=None,
        )


register_envs()
