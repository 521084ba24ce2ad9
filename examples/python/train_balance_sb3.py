"""Learn to balance MiaPURE from random tilts with PPO (stable-baselines3) on
``ballbot/Balance-v0``: the policy commands the three wheel torques at 400 Hz in the rapier3d
world, from the IMU and encoders only.

PPO's settings are the usual ones for continuous control (as in the rl-baselines3-zoo), taken
after a first run with SB3's defaults failed, and not searched: observations and rewards normalised (``VecNormalize``), an
initial action noise of std 0.22 (``log_std_init=-1.5``: random torques of std 1 lift a wheel
25 to 170 ms into an episode), 512 steps per environment per update, minibatches of 256, discount
0.995 (a horizon of about 0.5 s at 400 Hz). ``--defaults`` uses SB3's defaults instead.

Saves the learning curve (episode return and length against environment steps, with the wall
time) as ``train_balance.png`` / ``.svg`` and its data as ``train_balance.json``, keeps the best
policy of the periodic evaluations (``best_model.zip``), then evaluates the final and the best
policy on 20 seeded episodes: how many reach the 10 s time limit standing, the mean tilt, and
what ended the others.

Not part of the test command (stable-baselines3 pulls in torch). Install its own extra:
    pip install "./crates/ballbot-py[train]"
Usage: python examples/python/train_balance_sb3.py [--steps 2000000] [--envs 8] [--seed 0]
       [--out DIR] [--defaults]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback, EvalCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import VecNormalize

import ballbot.gym  # noqa: F401  (registers the environments)
from ballbot.gym import BallbotEnv


class Curve(BaseCallback):
    """Records every finished episode's return and length (from SB3's Monitor wrapper)."""

    def __init__(self) -> None:
        super().__init__()
        self.start = time.perf_counter()
        self.points: list[tuple[int, float, int, float]] = []

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            ep = info.get("episode")
            if ep is not None:
                wall = time.perf_counter() - self.start
                self.points.append((self.num_timesteps, float(ep["r"]), int(ep["l"]), wall))
        return True


class SaveNormalization(BaseCallback):
    """Called by ``EvalCallback`` on a new best policy: keeps the observation statistics that
    policy was evaluated with."""

    def __init__(self, norm: VecNormalize, path: Path) -> None:
        super().__init__()
        self.norm, self.path = norm, path

    def _on_step(self) -> bool:
        self.norm.save(str(self.path))
        return True


def evaluate(
    model: PPO, norm: Optional[VecNormalize], episodes: int, seed: int
) -> dict[str, Any]:
    env = BallbotEnv("balance")
    standing, tilts, lengths = 0, [], []
    failures: dict[str, int] = {}
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + 10_000 + k)
        done, steps = False, 0
        while not done:
            seen = norm.normalize_obs(obs) if norm is not None else obs
            action, _ = model.predict(seen, deterministic=True)
            obs, _, term, trunc, info = env.step(action)
            tilts.append(float(np.hypot(obs[0], obs[1])))
            steps += 1
            done = term or trunc
        standing += int(trunc and not term)
        if info["failure"] is not None:
            kind = info["failure"].kind.value
            failures[kind] = failures.get(kind, 0) + 1
        lengths.append(steps / 400.0)
    return {
        "episodes": episodes,
        "reached_time_limit": standing,
        "mean_episode_secs": float(np.mean(lengths)),
        "mean_tilt_deg": float(np.degrees(np.mean(tilts))),
        "failures": failures,
    }


def figure(
    points: list[tuple[int, float, int, float]], wall: float, out: Path, steps: int, label: str
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.array([p[0] for p in points])
    ret = np.array([p[1] for p in points])
    length = np.array([p[2] for p in points]) / 400.0
    window = max(1, len(points) // 50)
    smooth = np.convolve(ret, np.ones(window) / window, mode="valid")
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.6))
    a.plot(t, ret, ".", ms=2, alpha=0.3, color="tab:blue")
    a.plot(t[window - 1 :], smooth, color="tab:blue")
    a.set_xlabel("environment steps")
    a.set_ylabel("episode return")
    a.grid(alpha=0.3)
    b.plot(t, length, ".", ms=2, alpha=0.3, color="tab:green")
    b.axhline(10.0, color="k", lw=0.8, ls="--", label="time limit (10 s)")
    b.set_xlabel("environment steps")
    b.set_ylabel("episode length (s)")
    b.legend(fontsize=8)
    b.grid(alpha=0.3)
    fig.suptitle(
        f"PPO ({label}) on ballbot/Balance-v0: {steps:,} steps in {wall / 60:.1f} min wall "
        f"({os.cpu_count()} cores)"
    )
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(out / f"train_balance.{ext}", dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--steps", type=int, default=2_000_000, help="environment steps")
    parser.add_argument("--envs", type=int, default=8, help="parallel environments")
    parser.add_argument("--seed", type=int, default=0, help="seed of everything")
    parser.add_argument("--out", default=".", help="output folder")
    parser.add_argument("--defaults", action="store_true", help="SB3's default PPO settings")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"PPO on ballbot/Balance-v0: {args.steps:,} steps, {args.envs} envs, seed {args.seed}")
    envs = make_vec_env("ballbot/Balance-v0", n_envs=args.envs, seed=args.seed)
    norm: Optional[VecNormalize] = None
    if args.defaults:
        model = PPO("MlpPolicy", envs, seed=args.seed, verbose=0, device="cpu")
    else:
        norm = VecNormalize(envs, norm_obs=True, norm_reward=True, clip_obs=10.0)
        model = PPO(
            "MlpPolicy",
            norm,
            seed=args.seed,
            verbose=0,
            device="cpu",
            n_steps=512,
            batch_size=256,
            gamma=0.995,
            gae_lambda=0.95,
            policy_kwargs={"log_std_init": -1.5, "net_arch": [64, 64]},
        )
    curve = Curve()
    callbacks: list[BaseCallback] = [curve]
    best_stats = out / "best_vecnormalize.pkl"
    if norm is not None:
        # Every 200,000 steps, 5 deterministic episodes on their own seeds; the best policy is
        # kept (best_model.zip), with the observation statistics it was evaluated with.
        eval_env = VecNormalize(
            make_vec_env("ballbot/Balance-v0", n_envs=1, seed=args.seed + 1000),
            training=False,
            norm_reward=False,
        )
        callbacks.append(
            EvalCallback(
                eval_env,
                n_eval_episodes=5,
                eval_freq=max(1, 200_000 // args.envs),
                best_model_save_path=str(out),
                callback_on_new_best=SaveNormalization(norm, best_stats),
                verbose=0,
            )
        )
    start = time.perf_counter()
    model.learn(total_timesteps=args.steps, callback=callbacks, progress_bar=False)
    wall = time.perf_counter() - start
    model.save(out / "train_balance_ppo")
    if norm is not None:
        norm.training = False
        norm.save(str(out / "train_balance_vecnormalize.pkl"))
    result = evaluate(model, norm, 20, args.seed)
    best: Optional[dict[str, Any]] = None
    if norm is not None and (out / "best_model.zip").exists():
        best_model = PPO.load(out / "best_model", device="cpu")
        best_norm = VecNormalize.load(str(best_stats), make_vec_env("ballbot/Balance-v0", n_envs=1))
        best_norm.training = False
        best = evaluate(best_model, best_norm, 20, args.seed)
    print(f"trained in {wall / 60:.1f} min ({args.steps / wall:,.0f} steps/s with learning)")
    for name, r in [("final policy", result), ("best evaluated policy", best)]:
        if r is not None:
            print(
                f"{name}: {r['reached_time_limit']}/{r['episodes']} episodes standing at the "
                f"10 s limit, mean episode {r['mean_episode_secs']:.2f} s, mean tilt "
                f"{r['mean_tilt_deg']:.2f} deg, failures {r['failures']}"
            )
    data = {"seed": args.seed, "steps": args.steps, "envs": args.envs, "wall_secs": wall,
            "defaults": args.defaults, "evaluation": result, "best_evaluation": best,
            "curve": curve.points}
    (out / "train_balance.json").write_text(json.dumps(data))
    figure(curve.points, wall, out, args.steps, "SB3 defaults" if args.defaults else "zoo-style")
    print(f"wrote {out}/train_balance.png, .svg, .json")


if __name__ == "__main__":
    main()
