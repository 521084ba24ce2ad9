"""The maximum-speed study's capability map (the failing acceleration per heading) over a grid
of roller friction mu and COM height, with ``ballbot.sweep`` on one thread, on two threads and
on a two-worker Dask ``LocalCluster``, and a figure.

The study is ``ballbot.failing_acceleration``: at each heading, bisection on ramp
accelerations for the largest one MiaPURE (60 kg) survives in the 3D world. The same call runs
on each executor; the tables must be equal bit for bit (the runs are seeded), and the wall
times show what each executor buys.

Usage: python examples/python/sweep_capability_map.py [--quick] [--out DIR] [--no-dask]
       (the figure needs matplotlib: pip install matplotlib; Dask: the `dask` extra)
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import time
from pathlib import Path
from typing import Any

import numpy as np

import ballbot
from ballbot.sweep import SweepResult, run

MU = "params.robot.drivetrain.wheel_ball_friction"
COM = "params.robot.{sagittal,frontal}.com_height_m"


def capability(params: ballbot.WorldParams, heading_deg: float) -> dict[str, Any]:
    """One point: the failing-acceleration search at one heading (module level: Dask's
    workers import it by name)."""
    r = ballbot.failing_acceleration(params, heading_deg=heading_deg)
    return {
        "largest_surviving_m_per_s2": r.largest_surviving_m_per_s2,
        "smallest_failing_m_per_s2": r.smallest_failing_m_per_s2,
        "censored": r.censored,
        "runs": r.runs,
    }


def same(a: SweepResult, b: SweepResult) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a.keys())


def figure(table: SweepResult, out: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure (pip install matplotlib)")
        return
    mus, coms = np.unique(table[MU]), np.unique(table[COM])
    fig, axes = plt.subplots(1, len(coms), figsize=(4.2 * len(coms), 3.6), sharey=True)
    for ax, com in zip(np.atleast_1d(axes), coms):
        for mu in mus:
            rows = (table[MU] == mu) & (table[COM] == com)
            heading = table["heading_deg"][rows]
            accel = table["largest_surviving_m_per_s2"][rows].astype(float)
            censored = table["censored"][rows].astype(bool)
            line = ax.plot(heading, accel, marker="o", label=f"mu = {mu:g}")[0]
            ax.plot(heading[censored], accel[censored], "^", color=line.get_color(), ms=9)
        ax.set_title(f"COM height {com:g} m")
        ax.set_xlabel("heading (deg, 0 towards OW1)")
        ax.set_xticks(np.arange(0, 361, 60))
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("largest surviving ramp accel. (m/s$^2$)")
    np.atleast_1d(axes)[0].legend(title="roller friction", fontsize=8)
    fig.suptitle("MiaPURE 60 kg, 3D world: failing acceleration per heading (triangles: >= bracket top)")
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(out / f"capability_map.{ext}", dpi=120)
    print(f"wrote {out}/capability_map.png and .svg")


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 headings x 2 mu x 1 COM height")
    parser.add_argument("--out", default=".", help="folder of the figure")
    parser.add_argument("--no-dask", action="store_true", help="skip the Dask cluster")
    args = parser.parse_args()
    if args.quick:
        grid = {MU: [0.5, 0.8], COM: [0.5], "heading_deg": [0.0, 60.0]}
    else:
        grid = {MU: [0.4, 0.6, 0.8], COM: [0.4, 0.5, 0.7], "heading_deg": list(range(0, 360, 30))}
    params = ballbot.WorldParams()
    n = int(np.prod([len(v) for v in grid.values()]))
    print(f"capability map: {n} points (mu x COM height x heading)")
    walls: dict[str, float] = {}
    tables: dict[str, SweepResult] = {}
    for threads in (1, 2):
        start = time.perf_counter()
        with cf.ThreadPoolExecutor(threads) as pool:
            tables[f"{threads} thread(s)"] = run(
                capability, params=params, grid=grid, executor=pool, progress=False
            )
        walls[f"{threads} thread(s)"] = time.perf_counter() - start
    if not args.no_dask:
        from distributed import Client, LocalCluster

        start = time.perf_counter()
        with LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster, Client(cluster) as client:
            started = time.perf_counter() - start
            tables["Dask, 2 workers"] = run(
                capability, params=params, grid=grid, executor=client.get_executor(),
                progress=False,
            )
        walls["Dask, 2 workers"] = time.perf_counter() - start
        print(f"(the Dask cluster took {started:.1f} s to start, included below)")
    ref = tables["1 thread(s)"]
    for name, table in tables.items():
        equal = "equal to 1 thread bit for bit" if same(table, ref) else "DIFFERS"
        print(f"{name:>16}: {walls[name]:6.1f} s wall, {n / walls[name]:5.2f} points/s, {equal}")
    if not all(same(t, ref) for t in tables.values()):
        raise SystemExit("the executors disagree")
    print(f"{'mu':>5} {'COM (m)':>8} " + " ".join(f"{h:>6g}" for h in grid["heading_deg"]))
    for mu in grid[MU]:
        for com in grid[COM]:
            rows = (ref[MU] == mu) & (ref[COM] == com)
            cells = [
                f"{'>=' if c else ''}{a:.2f}" if a is not None else "<"
                for a, c in zip(ref["largest_surviving_m_per_s2"][rows], ref["censored"][rows])
            ]
            print(f"{mu:>5g} {com:>8g} " + " ".join(f"{c:>6}" for c in cells))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    figure(ref, out)


if __name__ == "__main__":
    main()
