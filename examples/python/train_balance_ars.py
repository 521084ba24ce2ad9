"""Learn to balance MiaPURE from random tilts with Augmented Random Search on
``ballbot/Balance-v0``, on the package's native vector env, with numpy only (no torch).

The policy is linear on normalised observations, ``a = clip(W (obs - mean) / std, -1, 1)``:
the three wheel torques (fractions of peak torque) at 400 Hz from the IMU and the encoders.
The method is ARS V2-t (H. Mania, A. Guy, B. Recht, "Simple random search of static linear
policies is competitive for reinforcement learning", NeurIPS 2018): each iteration perturbs
``W`` along ``directions`` random directions, runs the pair ``W +- noise * delta`` on the same
seeded episode, and steps along the ``top`` directions whose pairs differ most, scaled by the
spread of their returns; the observation statistics are those of every state visited.

Why not PPO: a balancing policy is close to linear (the core's LQR is), and ARS evaluates a
policy on whole episodes, so hard corrections that lift a wheel cost their episode at once;
and with no network to train the simulator gets both cores (`docs/gym.md`, section 4).

All ``2 directions`` episodes of an iteration run together in one ``BallbotVectorEnv``
(stepped in Rust on every core). Every ``--eval-every`` iterations the current policy is
evaluated on 20 seeded 10 s episodes (seeds 10,000 to 10,019, the task's default
randomisation: initial tilts up to 0.1 rad in any direction); the best one is kept.

Writes to ``--out``: ``balance_ars.json`` (the policy: ``ballbot.gym.Policy.load`` reads it),
``curve.json`` (iteration, environment steps, wall time, mean training return, evaluation),
and ``curve.png`` when matplotlib is installed.

Usage: python examples/python/train_balance_ars.py [--iterations 200] [--seed 0] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import gymnasium as gym

import ballbot
import ballbot.gym  # noqa: F401  (registers the environments)
from ballbot.gym import Policy, evaluate

try:
    from tqdm import tqdm
except ImportError:  # pragma: no cover - tqdm is a base dependency
    tqdm = None  # type: ignore[assignment]

ENV_ID = "ballbot/Balance-v0"
EVAL_SEEDS = list(range(10_000, 10_020))


class Stats:
    """Running mean and variance of the observations (batched; Chan et al.'s merge)."""

    def __init__(self, dim: int) -> None:
        self.n = 0
        self.mean = np.zeros(dim)
        self.m2 = np.zeros(dim)

    def add(self, batch: NDArray[np.float64]) -> None:
        if len(batch) == 0:
            return
        n_b = len(batch)
        mean_b = batch.mean(axis=0)
        m2_b = ((batch - mean_b) ** 2).sum(axis=0)
        n = self.n + n_b
        delta = mean_b - self.mean
        self.mean = self.mean + delta * n_b / n
        self.m2 = self.m2 + m2_b + delta**2 * self.n * n_b / n
        self.n = n

    def std(self, floor: NDArray[np.float64]) -> NDArray[np.float64]:
        var = self.m2 / max(self.n - 1, 1)
        return np.maximum(np.sqrt(var), floor)


def rollouts(
    envs: Any,
    weights: NDArray[np.float64],
    mean: NDArray[np.float64],
    std: NDArray[np.float64],
    seeds: list[int],
    stats: Stats,
) -> tuple[NDArray[np.float64], int]:
    """One episode per environment, environment ``i`` run by ``weights[i]``: the returns and
    the environment steps taken. The visited observations go into ``stats``."""
    obs, _ = envs.reset(seed=seeds)
    n = len(seeds)
    returns = np.zeros(n)
    alive = np.ones(n, dtype=bool)
    steps = 0
    while alive.any():
        stats.add(np.asarray(obs, dtype=np.float64)[alive])
        z = (np.asarray(obs, dtype=np.float64) - mean) / std
        actions = np.clip(np.einsum("nij,nj->ni", weights, z), -1.0, 1.0)
        obs, reward, terminated, truncated, _ = envs.step(actions.astype(np.float32))
        returns[alive] += np.asarray(reward)[alive]
        steps += int(alive.sum())
        alive &= ~(np.asarray(terminated) | np.asarray(truncated))
    return returns, steps


def env_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    """The environment's keyword arguments besides the time limit (the policy records them)."""
    return {"randomization": args.randomization} if args.randomization else {}


def train(args: argparse.Namespace) -> dict[str, Any]:
    rng = np.random.default_rng(args.seed)
    print(f"seed {args.seed}")
    n = 2 * args.directions
    envs = gym.make_vec(
        ENV_ID,
        num_envs=n,
        vectorization_mode="vector_entry_point",
        max_episode_secs=args.train_episode_secs,
        **env_kwargs(args),
    )
    dim = envs.single_observation_space.shape[0]
    # A floor under each observation's spread: the command is always zero in Balance and the
    # yaw barely moves, and dividing by their tiny spread would amplify noise.
    floor = np.maximum(1e-3, 0.01 * np.asarray(envs.single_observation_space.high, dtype=np.float64))
    stats = Stats(dim)
    weights = np.zeros((3, dim))
    mean, std = np.zeros(dim), np.ones(dim)
    curve: list[dict[str, Any]] = []
    best: dict[str, Any] = {"standing": -1}
    env_steps, start = 0, time.perf_counter()
    bar = tqdm(range(args.iterations), unit="it") if tqdm else range(args.iterations)
    for it in bar:
        deltas = rng.standard_normal((args.directions, 3, dim))
        pair = np.concatenate([weights + args.noise * deltas, weights - args.noise * deltas])
        episode_seeds = [int(s) for s in rng.integers(0, 2**62, args.directions)]
        returns, steps = rollouts(envs, pair, mean, std, episode_seeds * 2, stats)
        env_steps += steps
        plus, minus = returns[: args.directions], returns[args.directions :]
        order = np.argsort(-np.maximum(plus, minus))[: args.top]
        spread = np.concatenate([plus[order], minus[order]]).std() or 1.0
        step = np.einsum("k,kij->ij", plus[order] - minus[order], deltas[order])
        weights = weights + args.step_size / (args.top * spread) * step
        mean, std = stats.mean.copy(), stats.std(floor)
        point: dict[str, Any] = {
            "iteration": it + 1,
            "env_steps": env_steps,
            "wall_secs": time.perf_counter() - start,
            "train_return": float(returns.mean()),
        }
        if (it + 1) % args.eval_every == 0 or it + 1 == args.iterations:
            policy = Policy(weights=weights, obs_mean=mean, obs_std=std, env_id=ENV_ID, env_kwargs=env_kwargs(args))
            result = evaluate(policy, seeds=EVAL_SEEDS)
            point["standing"] = result["standing"]
            point["mean_secs"] = result["mean_episode_secs"]
            if result["standing"] > best["standing"] or (
                result["standing"] == best["standing"] and result["mean_abs_tilt_deg"] < best["tilt"]
            ):
                best = {"standing": result["standing"], "tilt": result["mean_abs_tilt_deg"], "policy": policy,
                        "iteration": it + 1, "env_steps": env_steps, "wall_secs": time.perf_counter() - start}
            if tqdm:
                bar.set_postfix(standing=f"{result['standing']}/20", ret=f"{returns.mean():.0f}")  # type: ignore[union-attr]
        curve.append(point)
    envs.close()
    return {"curve": curve, "best": best, "wall_secs": time.perf_counter() - start}


def plot(curve: list[dict[str, Any]], path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no curve.png")
        return
    fig, ax = plt.subplots(figsize=(7, 4))
    steps = [p["env_steps"] / 1e6 for p in curve]
    ax.plot(steps, [p["train_return"] for p in curve], label="mean training return (5 s episodes)")
    ax.set_xlabel("environment steps (millions)")
    ax.set_ylabel("return")
    ax2 = ax.twinx()
    ev = [p for p in curve if "standing" in p]
    ax2.plot([p["env_steps"] / 1e6 for p in ev], [p["standing"] for p in ev], "o-", color="C1",
             label="evaluation: standing 10 s (of 20)")
    ax2.set_ylim(-0.5, 20.5)
    ax2.set_ylabel("standing 10 s (of 20 seeded episodes)")
    fig.legend(loc="lower right", bbox_to_anchor=(0.86, 0.2))
    ax.set_title(f"ARS on ballbot/Balance-v0 (linear policy, numpy): {curve[-1]['wall_secs']:.0f} s wall")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--iterations", type=int, default=200)
    parser.add_argument("--directions", type=int, default=8)
    parser.add_argument("--top", type=int, default=4)
    parser.add_argument("--step-size", type=float, default=0.05)
    parser.add_argument("--noise", type=float, default=0.1)
    parser.add_argument("--train-episode-secs", type=float, default=5.0)
    parser.add_argument("--eval-every", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--randomization", default=None,
                        help='"recommended": train (and select) with the reliability campaign\'s ranges too')
    parser.add_argument("--out", type=Path, default=Path("target/train-ars"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    out = train(args)
    best = out["best"]
    policy: Policy = best["policy"]
    policy.trained = {
        "method": "ARS V2-t, linear policy",
        "command": "python examples/python/train_balance_ars.py "
        + " ".join(f"--{k.replace('_', '-')} {v}" for k, v in vars(args).items() if k != "out" and v is not None),
        "iteration": best["iteration"],
        "env_steps": best["env_steps"],
        "wall_secs": round(best["wall_secs"], 1),
        "total_wall_secs": round(out["wall_secs"], 1),
        "ballbot_version": ballbot.__version__,
    }
    policy.save(args.out / "balance_ars.json")
    (args.out / "curve.json").write_text(json.dumps(out["curve"], indent=1) + "\n")
    print(f"best policy: iteration {best['iteration']}, {best['standing']}/20 standing 10 s; "
          f"{out['wall_secs']:.0f} s in all; wrote {args.out / 'balance_ars.json'}")
    plot(out["curve"], args.out / "curve.png")


if __name__ == "__main__":
    main()
