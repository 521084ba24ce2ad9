"""Policies evaluated in numpy: ``Policy`` (a linear policy on normalised observations),
``pretrained``, the shipped ones, and ``evaluate``, seeded episodes on the native vector env."""

from __future__ import annotations

import dataclasses
import json
import math
from importlib import resources
from pathlib import Path
from typing import Any, Optional, Sequence, Union

import gymnasium
import numpy as np
from numpy.typing import ArrayLike, NDArray

_FORMAT = "ballbot.linear_policy/1"
#: The shipped policies, by name: their file under ``ballbot/gym/policies/``.
PRETRAINED = {"balance": "balance.json", "balance_randomized": "balance_randomized.json"}


@dataclasses.dataclass
class Policy:
    """``action = clip(weights @ ((obs - obs_mean) / obs_std), -1, 1)``: the environment's
    normalised action (wheel torques as fractions of peak torque) from its observation.

    ``env_id`` and ``env_kwargs`` name the environment it was trained on (``evaluate`` and
    ``make_env`` use them); ``trained`` records how (the command, the steps).
    """

    weights: NDArray[np.float64]
    obs_mean: NDArray[np.float64]
    obs_std: NDArray[np.float64]
    env_id: str = "ballbot/Balance-v0"
    env_kwargs: dict[str, Any] = dataclasses.field(default_factory=dict)
    trained: dict[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        self.weights = np.array(self.weights, dtype=np.float64)
        self.obs_mean = np.array(self.obs_mean, dtype=np.float64)
        self.obs_std = np.array(self.obs_std, dtype=np.float64)
        if self.weights.ndim != 2:
            raise ValueError(f"`weights` must be (actions, observations), got shape {self.weights.shape}")
        n = self.weights.shape[1]
        for name in ("obs_mean", "obs_std"):
            if getattr(self, name).shape != (n,):
                raise ValueError(f"`{name}` must have shape ({n},), got {getattr(self, name).shape}")
        for name in ("weights", "obs_mean", "obs_std"):
            if not np.isfinite(getattr(self, name)).all():
                raise ValueError(f"`{name}` must be finite")
        if not (self.obs_std > 0).all():
            raise ValueError("`obs_std` must be > 0")

    def __call__(self, obs: ArrayLike) -> NDArray[np.float32]:
        """The action for one observation ``(n,)`` or a batch ``(k, n)``. A non-finite
        observation raises ``ValueError`` (no action is made from it)."""
        x = np.asarray(obs, dtype=np.float64)
        if x.shape[-1:] != self.obs_mean.shape:
            raise ValueError(f"observation must end in ({len(self.obs_mean)},), got shape {x.shape}")
        if not np.isfinite(x).all():
            bad = np.argwhere(~np.isfinite(x))[0]
            raise ValueError(f"observation entry {tuple(int(i) for i in bad)} is not finite")
        z = (x - self.obs_mean) / self.obs_std
        return np.clip(z @ self.weights.T, -1.0, 1.0).astype(np.float32)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": _FORMAT,
            "env_id": self.env_id,
            "env_kwargs": self.env_kwargs,
            "weights": self.weights.tolist(),
            "obs_mean": self.obs_mean.tolist(),
            "obs_std": self.obs_std.tolist(),
            "trained": self.trained,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Policy:
        if d.get("format") != _FORMAT:
            raise ValueError(f"not a policy file: `format` is {d.get('format')!r}, expected {_FORMAT!r}")
        return cls(
            weights=np.asarray(d["weights"]),
            obs_mean=np.asarray(d["obs_mean"]),
            obs_std=np.asarray(d["obs_std"]),
            env_id=d["env_id"],
            env_kwargs=dict(d.get("env_kwargs", {})),
            trained=dict(d.get("trained", {})),
        )

    def save(self, path: Union[str, Path]) -> None:
        Path(path).write_text(json.dumps(self.to_dict(), indent=1) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path: Union[str, Path]) -> Policy:
        return cls.from_dict(json.loads(Path(path).read_text(encoding="utf-8")))

    def make_env(self, **kwargs: Any) -> gymnasium.Env[Any, Any]:
        """The environment the policy was trained on (``kwargs`` on top of its own)."""
        return gymnasium.make(self.env_id, **{**self.env_kwargs, **kwargs})


def pretrained(name: str = "balance") -> Policy:
    """A policy that ships with the package, a linear policy for ``ballbot/Balance-v0``
    trained by ``examples/python/train_balance_ars.py`` (its ``trained`` record says with which
    command): ``"balance"``, trained and selected on the task's own randomisation (initial
    tilts up to 0.1 rad), and ``"balance_randomized"``, on the reliability campaign's ranges as
    well (``randomization="recommended"``: payload, COM height, friction, IMU noise, delay,
    pushes), which its ``env_kwargs`` keep. ``docs/gym.md`` compares both with the LQR-PI."""
    if name not in PRETRAINED:
        raise ValueError(f"no pretrained policy {name!r}; there are: {', '.join(PRETRAINED)}")
    text = resources.files("ballbot.gym").joinpath("policies").joinpath(PRETRAINED[name]).read_text(encoding="utf-8")
    return Policy.from_dict(json.loads(text))


def evaluate(
    policy: Policy,
    seeds: Sequence[int] = tuple(range(10_000, 10_020)),
    *,
    threads: int = 0,
    options: Optional[dict[str, Any]] = None,
    **env_kwargs: Any,
) -> dict[str, Any]:
    """Runs one episode per seed, all at once on the native vector env (``threads`` cores),
    ``policy`` acting deterministically, and says how they went: ``standing`` (episodes that
    reached the time limit), ``mean_episode_secs``, ``mean_abs_tilt_deg`` (the body's true tilt
    from the vertical over the steps lived), ``lift_off_episodes`` (episodes with a wheel lift-off), and per episode
    its ``seed``, ``secs``, ``termination`` and ``lift_offs``. ``env_kwargs`` go on top of the
    policy's own; ``options`` are the reset's (``{"randomization": {...}}`` overrides ranges)."""
    kwargs = {**policy.env_kwargs, **env_kwargs}
    envs = gymnasium.make_vec(
        policy.env_id, num_envs=len(seeds), vectorization_mode="vector_entry_point", threads=threads, **kwargs
    )
    try:
        return _run(policy, envs, list(seeds), options)
    finally:
        envs.close()


def _run(policy: Policy, envs: Any, seeds: list[int], options: Optional[dict[str, Any]]) -> dict[str, Any]:
    obs, _ = envs.reset(seed=seeds, options=options)
    n = len(seeds)
    alive = np.ones(n, dtype=bool)
    steps = np.zeros(n, dtype=np.int64)
    tilt_sum = np.zeros(n)
    ended: list[Optional[dict[str, Any]]] = [None] * n
    while alive.any():
        obs, _, terminated, truncated, infos = envs.step(policy(obs))
        for i in np.flatnonzero(alive):
            tilt_sum[i] += envs.core.telemetry(int(i)).tilt_from_vertical_rad
        steps[alive] += 1
        done = alive & (np.asarray(terminated) | np.asarray(truncated))
        for i in np.flatnonzero(done):
            events = infos["episode_events"][i] if infos.get("_episode_events", np.zeros(n, bool))[i] else []
            ended[i] = {
                "seed": seeds[i],
                "secs": float(infos["time_secs"][i]),
                "termination": infos["termination"][i] if infos.get("_termination", np.zeros(n, bool))[i] else None,
                "lift_offs": sum(1 for e in events if e["kind"] == "lift_off"),
                "truncated": bool(truncated[i]),
            }
        alive &= ~done
    episodes = [e for e in ended if e is not None]
    return {
        "standing": sum(1 for e in episodes if e["truncated"]),
        "episodes": episodes,
        "mean_episode_secs": float(np.mean([e["secs"] for e in episodes])),
        "mean_abs_tilt_deg": float(math.degrees(float(np.mean(tilt_sum / np.maximum(steps, 1))))),
        "lift_off_episodes": sum(1 for e in episodes if e["lift_offs"]),
    }
