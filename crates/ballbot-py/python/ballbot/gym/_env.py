"""``BallbotEnv``: one environment, a Gymnasium ``Env`` over the Rust ``GymEnv``."""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union

import gymnasium
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from ballbot._core import GymEnv, WorldParams
from ballbot.gym._render import Viewer, has_matplotlib, viewer

Obs = NDArray[np.float32]
Act = NDArray[np.float32]
Randomization = Union[str, dict[str, Any], None]
StopOn = Union[str, Sequence[str], None]


class BallbotEnv(gymnasium.Env[Obs, Act]):
    """A ballbot on the rapier3d world (see ``ballbot.gym`` for the tasks, the observation and
    the randomisation).

    Args:
        task: ``"balance"`` (wheel torques) or ``"velocity"`` (track velocity commands).
        params: the nominal world (default MiaPURE with 60 kg).
        control_hz: agent steps per second (400); the physics runs at ``1 / params.dt_secs``.
        max_episode_secs: the time limit (s, default 10): ``truncated`` when reached.
        last_action_in_observation: append the last action to the observation.
        residual: Velocity task: act on top of the core's LQR-PI (default) or drive the
            torques alone.
        residual_fraction: the residual's full scale, a fraction of peak torque (0.2).
        randomization: ``"recommended"``, ``"none"`` or a dict of ranges.
        commands: Velocity task: ``max_speed_m_per_s`` (1.0), ``max_yaw_rate_rad_per_s``
            (0.5), ``period_secs`` (2.5).
        reward: weights ``alive``, ``tilt``, ``body_rate``, ``velocity_error``,
            ``yaw_rate_error``, ``action``.
        stop_on: the world failures that end an episode ``terminated`` besides the chassis
            on the floor, as ``ballbot world --stop-on`` takes them: ``"all"``, ``"none"``,
            or rule names among ``tilt``, ``slip``, ``lift-off``, ``driver-trip`` (a string
            separated by commas, or a list). Default (``None``): ``"tilt,driver-trip"``, a
            fall; slips and lift-offs are ``info["events"]``. ``"all"`` is the old behaviour.
        render_mode: ``"rgb_array"`` (a ``(360, 480, 3)`` uint8 frame of
            :class:`ballbot.SceneRenderer`: a 3/4 view following the ball over a floor grid,
            the omniwheels and rollers, contact-force arrows coloured by friction-cone use, a
            lifted wheel red), ``"human"`` (the same frames in a matplotlib window, after
            every step; needs matplotlib, and is listed in ``metadata["render_modes"]`` only when
            it is installed) or ``"ansi"`` (a line of text).

    Info of ``step``: ``time_secs``; ``termination``, why the episode ended ``terminated``
    (``"fell"``: the chassis on the floor; a stop rule's ``"tilt"``, ``"sustained_slip"``,
    ``"lift_off"``, ``"driver_trip"``; ``"controller_off"``), else ``None``; ``failure`` (the
    ``Failure`` that ended it); ``controller_off``; ``push_ns``; ``command``; ``events``, the
    contact events in progress during the step (dicts: ``kind`` among ``slip``, ``lift_off``,
    ``driver_trip``, ``controller_fault``, ``traction_limit``; ``wheel``; ``onset_secs``,
    ``duration_secs``, ``ongoing`` and the peak); at the episode's end (terminated or
    truncated) ``episode_events``, all of them, and ``events_dropped``.

    Seeding: ``reset(seed=s)`` starts the episode seeded ``s``; ``reset()`` continues with the
    next seed of that stream. The first reset without any seed draws one from Gymnasium's
    ``np_random``. Each episode's seed is ``info["episode_seed"]``: ``reset(seed=...)`` with it
    replays the episode.
    """

    # "human" only where matplotlib is installed (render_mode="human" without it raises an
    # ImportError saying so).
    metadata = {
        "render_modes": ["rgb_array", "ansi"] + (["human"] if has_matplotlib() else []),
        "render_fps": 50,
    }

    def __init__(
        self,
        task: str = "balance",
        params: Optional[WorldParams] = None,
        *,
        control_hz: float = 400.0,
        max_episode_secs: Optional[float] = None,
        last_action_in_observation: bool = False,
        residual: bool = True,
        residual_fraction: float = 0.2,
        randomization: Randomization = None,
        commands: Optional[dict[str, float]] = None,
        reward: Optional[dict[str, float]] = None,
        stop_on: StopOn = None,
        render_mode: Optional[str] = None,
    ) -> None:
        modes = ["rgb_array", "human", "ansi"]
        if render_mode is not None and render_mode not in modes:
            raise ValueError(f"render_mode must be one of {modes}, got {render_mode!r}")
        self._core = GymEnv(
            task,
            params,
            control_hz=control_hz,
            max_episode_secs=max_episode_secs,
            last_action_in_observation=last_action_in_observation,
            residual=residual,
            residual_fraction=residual_fraction,
            randomization=randomization,
            commands=commands,
            reward=reward,
            stop_on=stop_on,
        )
        self.task = task
        high = self._core.observation_high
        self.observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": min(50, int(control_hz))}
        self._viewer: Optional[Viewer] = viewer(
            self._core.params, render_mode, self.metadata["render_fps"]
        )
        self._seeded = False

    @property
    def core(self) -> GymEnv:
        """The Rust environment (its ``telemetry``, ``params``, ``steps_per_action``)."""
        return self._core

    @property
    def stop_on(self) -> str:
        """The stop rules in force, as ``stop_on=`` takes them (``"tilt,driver-trip"`` by
        default)."""
        return self._core.stop_on

    def reset(
        self,
        *,
        seed: Optional[int] = None,
        options: Optional[dict[str, Any]] = None,
    ) -> tuple[Obs, dict[str, Any]]:
        super().reset(seed=seed)
        if seed is None and not self._seeded:
            seed = int(self.np_random.integers(2**63))
        out = self._core.reset(seed, options)
        self._seeded = True  # only once a reset succeeded
        if self.render_mode == "human":
            self.render()
        return out

    def step(self, action: Act) -> tuple[Obs, float, bool, bool, dict[str, Any]]:
        a = np.asarray(action, dtype=np.float64).reshape(3).tolist()
        out = self._core.step(a)
        if self.render_mode == "human":
            self.render()
        return out

    def render(self) -> Any:
        t = self._core.telemetry
        if self.render_mode is None or t is None:
            return None
        if self.render_mode == "ansi":
            v = t.ball_velocity_m_per_s
            tilt = np.degrees(t.tilt_rad)
            return (
                f"t={t.time_secs:7.3f} s  tilt=({tilt[0]:+6.2f}, {tilt[1]:+6.2f}) deg  "
                f"ball v=({v[0]:+5.2f}, {v[1]:+5.2f}) m/s\n"
            )
        assert self._viewer is not None
        if self.render_mode == "human":
            self._viewer.show(t)
            return None
        return self._viewer.frame(t)

    def close(self) -> None:
        if self._viewer is not None:
            self._viewer.close()
        super().close()
