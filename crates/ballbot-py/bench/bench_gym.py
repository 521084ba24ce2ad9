"""Environment steps per second of ``ballbot.gym``, against the bare world step, in one run.

Measures, as medians over repeats (one agent step = 20 physics steps at 400 Hz over 8 kHz):

(a) the bare world: ``World.run`` (Balance: torques only) and ``WorldLoop.run`` (Velocity: the
    core's controller in the loop) of 20 x K physics steps, in Rust, as agent steps per second;
(b) one environment stepped from Python: ``BallbotEnv.step`` and the same through
    ``gymnasium.make`` (with Gymnasium's checker wrappers), and its ratio to (a): the cost of
    the Python layer;
(c) the native vector env (``BallbotVectorEnv``, Rust threads without the GIL) with 1, 2 and
    8 environments;
    and, with 1 environment, its Rust call alone (what the Python side's infos cost);
(d) Gymnasium's ``SyncVectorEnv`` over 8 single environments (a Python loop);
(e) where ``mujoco`` imports: the simple virtual-wheel MuJoCo ballbot of ``mujoco_ballbot.py``
    (no omniwheels: a cheaper, less faithful model) as one environment, its bare
    ``mj_step`` pair per action, and ``SyncVectorEnv`` over 8, in the same run.

Every run is seeded; actions are a fixed seeded sequence in [-0.05, 0.05] (small enough that
Balance episodes rarely end in the timed window; episodes that end are reset as the vector
envs do).

Usage: python crates/ballbot-py/bench/bench_gym.py [--quick] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from typing import Any, Callable

import gymnasium as gym
import numpy as np

import ballbot
import ballbot.gym
from ballbot.gym import BallbotEnv, BallbotVectorEnv


def median_rate(fn: Callable[[], int], repeats: int) -> float:
    """Median of (items per second) over repeats; ``fn`` returns the items it did."""
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        items = fn()
        rates.append(items / (time.perf_counter() - start))
    return statistics.median(rates)


def bare(task: str, steps: int) -> Callable[[], int]:
    def run() -> int:
        if task == "balance":
            world = ballbot.World()
            world.run(20 * steps, np.zeros(3), record_every=20 * steps)
        else:
            loop = ballbot.WorldLoop()
            loop.run(20 * steps, np.zeros(3), record_every=20 * steps)
        return steps

    return run


def single(env: Any, steps: int) -> Callable[[], int]:
    actions = np.random.default_rng(0).uniform(-0.05, 0.05, size=(steps, 3)).astype(np.float32)

    def run() -> int:
        env.reset(seed=0)
        for a in actions:
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
        return steps

    return run


def vector(envs: Any, steps: int) -> Callable[[], int]:
    n = envs.num_envs
    actions = np.random.default_rng(0).uniform(-0.05, 0.05, size=(steps, n, 3)).astype(np.float32)

    def run() -> int:
        envs.reset(seed=0)
        for a in actions:
            envs.step(a)
        return steps * n

    return run


def rust_call(envs: Any, steps: int) -> Callable[[], int]:
    """The native vector env's Rust call alone (``core.step``), without the Python side that
    builds Gymnasium's vector infos: the difference to ``vector`` is that side's cost."""
    n = envs.num_envs
    actions = np.random.default_rng(0).uniform(-0.05, 0.05, size=(steps, n, 3))

    def run() -> int:
        envs.reset(seed=0)
        for a in actions:
            envs.core.step(a)
        return steps * n

    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps and repeats")
    parser.add_argument("--json", help="also write the results to this JSON file")
    args = parser.parse_args()
    steps, repeats = (200, 3) if args.quick else (2000, 7)
    results: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d", time.gmtime()),
        "cores": os.cpu_count(),
        "steps": steps,
        "repeats": repeats,
        # What else the machine was doing: rates on a loaded machine are lower, ratios less so.
        "load_average_1min_before": os.getloadavg()[0],
        "ballbot_version": ballbot.__version__,
    }
    for task in ("balance", "velocity"):
        r: dict[str, float] = {}
        r["bare_world"] = median_rate(bare(task, steps), repeats)
        r["env"] = median_rate(single(BallbotEnv(task), steps), repeats)
        env_id = "ballbot/Balance-v0" if task == "balance" else "ballbot/Velocity-v0"
        r["env_via_make"] = median_rate(single(gym.make(env_id), steps), repeats)
        for n in (1, 2, 8):
            envs = BallbotVectorEnv(num_envs=n, task=task, threads=0)
            r[f"native_vector_{n}"] = median_rate(vector(envs, steps // max(1, n // 2)), repeats)
            if n == 1:
                r["native_vector_1_rust_call"] = median_rate(rust_call(envs, steps), repeats)
        sync = gym.vector.SyncVectorEnv([lambda: BallbotEnv(task) for _ in range(8)])
        r["sync_vector_8"] = median_rate(vector(sync, steps // 4), repeats)
        r["env_over_bare"] = r["env"] / r["bare_world"]
        r["native_8_over_sync_8"] = r["native_vector_8"] / r["sync_vector_8"]
        results[task] = r
    print(f"agent steps per second (400 Hz, 20 physics steps each), medians of {repeats}:")
    header = ["", "bare world", "env", "gym.make", "native 1", "native 2", "native 8", "sync 8"]
    print("  ".join(f"{h:>10}" for h in header))
    for task in ("balance", "velocity"):
        r = results[task]
        keys = ["bare_world", "env", "env_via_make", "native_vector_1", "native_vector_2",
                "native_vector_8", "sync_vector_8"]
        print("  ".join([f"{task:>10}"] + [f"{r[k]:>10,.0f}" for k in keys]))
    try:
        import mujoco

        from mujoco_ballbot import MujocoBallbotEnv
    except ImportError:
        mujoco = None
    if mujoco is not None:
        m: dict[str, float] = {}
        env = MujocoBallbotEnv()

        def bare_mujoco() -> int:
            env.reset(seed=0)
            mujoco.mj_step(env.model, env.data, nstep=2 * steps)
            return steps

        m["bare_mj_step"] = median_rate(bare_mujoco, repeats)
        m["env"] = median_rate(single(MujocoBallbotEnv(), steps), repeats)
        sync = gym.vector.SyncVectorEnv([MujocoBallbotEnv for _ in range(8)])
        m["sync_vector_8"] = median_rate(vector(sync, steps // 4), repeats)
        m["ballbot_env_over_mujoco_env"] = results["balance"]["env"] / m["env"]
        m["ballbot_native_8_over_mujoco_sync_8"] = results["balance"]["native_vector_8"] / m["sync_vector_8"]
        results["mujoco_virtual_wheel"] = m
        results["mujoco_version"] = mujoco.__version__
        print(
            f"MuJoCo {mujoco.__version__} virtual-wheel ballbot (no omniwheels, 1.25 ms steps): "
            f"bare {m['bare_mj_step']:,.0f}, env {m['env']:,.0f}, sync 8 {m['sync_vector_8']:,.0f}"
            f" agent steps/s; ballbot env / MuJoCo env = {results['balance']['env'] / m['env']:.2f},"
            f" ballbot native 8 / MuJoCo sync 8 = "
            f"{results['balance']['native_vector_8'] / m['sync_vector_8']:.2f}"
        )
    for task in ("balance", "velocity"):
        r = results[task]
        print(
            f"{task}: env / bare world = {r['env_over_bare']:.3f}; "
            f"native 8 / SyncVectorEnv 8 = {r['native_8_over_sync_8']:.2f}; "
            f"simulated seconds per wall second (native 8) = {r['native_vector_8'] / 400:.0f}"
        )
    results["load_average_1min_after"] = os.getloadavg()[0]
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
