"""A balancing policy against the core's LQR-PI on the same seeded 10 s episodes.

Each shipped policy (``ballbot.gym.pretrained(name)`` for every name of
``ballbot.gym.PRETRAINED``, or ``--policy FILE``) runs on
``ballbot/Balance-v0`` (wheel torques from the sensors), from the task's initial tilts (up to
0.1 rad in any direction) and from tilts up to 0.045 rad. The LQR-PI runs on
``ballbot/Velocity-v0`` with a zero residual and a zero command from tilts up to 0.045 rad:
the shipped controller alone, which does not arm beyond 90 % of its 3 deg arming tilt. Both on the native vector env,
one episode per seed; once with the tasks' own randomisation (the initial tilt only), once with
the reliability campaign's ranges added (``randomization="recommended"``: payload, COM
height, friction, drive friction, IMU noise, sensor delay, pushes of up to 20 N s every 2 to
5 s).

Prints the tables and writes them as JSON (``--json FILE``; the docs' figures are
``docs/figures/balance-eval.json``, written by this script with its defaults).

Usage: python examples/python/evaluate_balance.py [--policy FILE] [--seeds 100] [--first-seed 20000]
       [--json FILE]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from ballbot.gym import PRETRAINED, Policy, evaluate, pretrained

# Below 90 % of the shipped controller's arming tilt (3 deg): the LQR-PI refuses to start beyond.
ARMABLE = {"randomization": {"initial_tilt_rad": [0.0, 0.045]}}


def lqr_pi(balance: Policy) -> Policy:
    """The zero residual on the Velocity task: the core's LQR-PI alone, holding still."""
    n = balance.weights.shape[1]
    return Policy(
        weights=np.zeros((3, n)),
        obs_mean=np.zeros(n),
        obs_std=np.ones(n),
        env_id="ballbot/Velocity-v0",
        env_kwargs={"commands": {"max_speed_m_per_s": 0.0, "max_yaw_rate_rad_per_s": 0.0}},
    )


def row(name: str, tilt_to_rad: float, result: dict[str, Any], n: int) -> dict[str, Any]:
    ends: dict[str, int] = {}
    for e in result["episodes"]:
        if e["termination"]:
            ends[e["termination"]] = ends.get(e["termination"], 0) + 1
    return {
        "controller": name,
        "tilt_to_rad": tilt_to_rad,
        "episodes": n,
        "standing": result["standing"],
        "mean_episode_secs": result["mean_episode_secs"],
        "mean_abs_tilt_deg": result["mean_abs_tilt_deg"],
        "lift_off_episodes": result["lift_off_episodes"],
        "terminations": ends,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--policy", type=Path, help="a policy file (default: the pretrained one)")
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--first-seed", type=int, default=20_000)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    policies = {"file": Policy.load(args.policy)} if args.policy else {n: pretrained(n) for n in PRETRAINED}
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    out: dict[str, Any] = {
        "seeds": [seeds[0], seeds[-1]],
        "policies": {name: p.trained for name, p in policies.items()},
    }
    for name, ranges in (("task_default", {"randomization": None}), ("recommended", {"randomization": "recommended"})):
        print(f"\nseeds {seeds[0]} to {seeds[-1]}; randomisation: {name}")
        out[name] = table(policies, seeds, ranges)
    if args.json:
        args.json.write_text(json.dumps(out, indent=1) + "\n")
        print(f"wrote {args.json}")


def table(policies: dict[str, Policy], seeds: list[int], ranges: dict[str, Any]) -> list[dict[str, Any]]:
    """Each policy from both tilt ranges and the LQR-PI from the armable one, printed."""
    rows = []
    for name, policy in policies.items():
        rows.append(row(name, 0.1, evaluate(policy, seeds, **ranges), len(seeds)))
        # "recommended" leaves the initial tilt to the task; the reset's options narrow it.
        rows.append(row(name, 0.045, evaluate(policy, seeds, options=ARMABLE, **ranges), len(seeds)))
    baseline = evaluate(lqr_pi(next(iter(policies.values()))), seeds, options=ARMABLE, **ranges)
    rows.append(row("LQR-PI", 0.045, baseline, len(seeds)))
    print(f"{'':20} {'tilts to':>8} {'standing 10 s':>14} {'mean s':>7} {'mean tilt deg':>14} {'lift-offs':>10}  ended by")
    for r in rows:
        print(f"{r['controller']:20} {r['tilt_to_rad']:8.3f} {r['standing']:>9} / {r['episodes']:<3} "
              f"{r['mean_episode_secs']:7.2f} {r['mean_abs_tilt_deg']:14.3f} {r['lift_off_episodes']:>10}  "
              f"{r['terminations'] or '-'}")
    return rows


if __name__ == "__main__":
    main()
