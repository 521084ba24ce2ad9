"""``BallbotVectorEnv``: N environments stepped in Rust in one call (``GymVecEnv``)."""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from ballbot._core import GymVecEnv, WorldParams
from ballbot.gym._render import Viewer

Obs = NDArray[np.float32]
Act = NDArray[np.float32]
Seed = Union[int, Sequence[Optional[int]], None]


class BallbotVectorEnv(VectorEnv[Obs, Act, NDArray[Any]]):
    """``num_envs`` ballbot environments stepped in Rust on ``threads`` cores (0: all) without
    the GIL. Autoreset is ``AutoresetMode.NEXT_STEP`` (Gymnasium's default): an environment
    that ended is reset at its next step, whose action is ignored (reward 0, neither
    terminated nor truncated, ``infos["episode_seed"]`` set for it).

    The keyword arguments are ``BallbotEnv``'s. Seeding follows ``SyncVectorEnv``:
    ``reset(seed=s)`` seeds environment ``i`` with ``s + i``, a list gives each its seed, and
    environment ``i`` then produces exactly what a single ``BallbotEnv`` would.

    Infos of ``step``, each masked by its ``_key``: ``time_secs`` and ``events`` (the contact
    events in progress during the step, a list of dicts per environment) where the environment
    stepped; ``episode_seed`` where it was reset; ``failure`` (a ``Failure``) where one ended
    the episode; ``termination`` (``"fell"``, a stop rule's failure, ``"controller_off"``)
    where the episode ended ``terminated``; ``episode_events`` (all its events) and
    ``events_dropped`` where it ended, terminated or truncated (the reset comes at the next
    step). As ``SyncVectorEnv`` over ``BallbotEnv`` gives them.
    """

    metadata = {
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": ["rgb_array"],
    }

    def __init__(
        self,
        num_envs: int = 1,
        task: str = "balance",
        params: Optional[WorldParams] = None,
        *,
        threads: int = 0,
        render_mode: Optional[str] = None,
        **kwargs: Any,
    ) -> None:
        if render_mode is not None and render_mode != "rgb_array":
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self._core = GymVecEnv(task, num_envs, params, threads=threads, **kwargs)
        self.num_envs = num_envs
        self.task = task
        self.render_mode = render_mode
        self._viewer: Optional[Viewer] = None
        high = self._core.observation_high
        self.single_observation_space = spaces.Box(-high, high, dtype=np.float32)
        self.single_action_space = spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._seeded = False

    @property
    def core(self) -> GymVecEnv:
        """The Rust vector environment (``telemetry(i)``, ``threads``)."""
        return self._core

    @property
    def stop_on(self) -> str:
        """The stop rules in force, as ``stop_on=`` takes them."""
        return self._core.stop_on

    def reset(
        self,
        *,
        seed: Seed = None,
        options: Optional[dict[str, Any]] = None,
    ) -> tuple[Obs, dict[str, Any]]:
        n = self.num_envs
        if seed is None:
            seeds: list[Optional[int]] = [None] * n
            if not self._seeded:
                self._np_random, _ = _seeded_rng(None)
                seeds = [int(s) for s in self._np_random.integers(2**63, size=n)]
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = [None if s is None else int(s) for s in seed]
        if len(seeds) != n:
            raise ValueError(f"seed: a list of {n} seeds is needed, got {len(seeds)}")
        obs, infos = self._core.reset(seeds, options)
        self._seeded = True  # only once a reset succeeded
        episode_seed = np.array([i["episode_seed"] for i in infos], dtype=np.int64)
        return obs, {"episode_seed": episode_seed, "_episode_seed": np.ones(n, dtype=bool)}

    def step(
        self, actions: Act
    ) -> tuple[Obs, NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_], dict[str, Any]]:
        a = np.ascontiguousarray(actions, dtype=np.float64).reshape(self.num_envs, 3)
        # The infos come in Gymnasium's vector form from Rust (`GymVecEnv.step_gym`).
        obs, rewards, terminated, truncated, infos = self._core.step_gym(a)
        return obs, rewards, terminated, truncated, infos

    def render(self) -> Optional[tuple[NDArray[np.uint8], ...]]:
        if self.render_mode is None:
            return None
        if self._viewer is None:
            self._viewer = Viewer(self._core.params)
        frames = []
        for i in range(self.num_envs):
            t = self._core.telemetry(i)
            if t is None:
                return None
            frames.append(self._viewer.frame(t))
        return tuple(frames)


def _seeded_rng(seed: Optional[int]) -> tuple[np.random.Generator, int]:
    from gymnasium.utils import seeding

    return seeding.np_random(seed)
