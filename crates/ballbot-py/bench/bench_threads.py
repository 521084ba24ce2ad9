"""One 3D world simulation against two in two Python threads: does the GIL get out of the way?

Each simulation is `WorldLoop.run` (the core's 3D controller in the loop on the rapier3d world,
8 kHz physics) cruising at 0.5 m/s, which runs entirely in Rust with the GIL released. The
script times, as medians over repeats:

- wall time of one simulation alone and of two at once in a `ThreadPoolExecutor`; the ratio
  two-thread time / one-thread time is ~1.0 with perfect parallelism on two free cores and
  ~2.0 if the runs were serialised (by the GIL or by a lack of free cores);
- process CPU time (`time.process_time`, all threads) for both: two simulations should cost
  twice the CPU of one (a CPU ratio of ~2.0) whatever the machine's load, and the CPU time
  divided by the wall time of the two-thread phase shows how many cores the process used at
  once (up to 2.0). On a loaded machine the wall ratio is pessimistic; the CPU figures and the
  load average tell how much;
- the gap between the two runs' finish times over the one-thread wall time: a call that held
  the GIL would keep the other thread out of its call until it returned, so the second run
  would finish about one run later (gap ~1); run in parallel, equal runs finish together
  (gap ~0). Unlike the wall ratio this holds on a loaded machine, since both threads are
  slowed alike.

Usage: python crates/ballbot-py/bench/bench_threads.py [--seconds 2.0] [--repeats 5] [--quick]
"""

import argparse
import os
import statistics
import time
from concurrent.futures import ThreadPoolExecutor

import ballbot


def simulate(n_steps: int) -> float:
    """One closed-loop world run of `n_steps`; returns the ball's final speed (m/s)."""
    sim = ballbot.WorldLoop()
    run = sim.run(n_steps, [0.5, 0.0, 0.0], record_every=400)
    return float(run.ball_velocity_m_per_s[-1, 0])


def simulate_finish(n_steps: int) -> tuple[float, float]:
    """`simulate` and the wall-clock time it returned: (finish time, final speed)."""
    speed = simulate(n_steps)
    return time.perf_counter(), speed


def timed(fn: "object") -> tuple[float, float]:
    """(wall seconds, process CPU seconds) of one call."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    fn()  # type: ignore[operator]
    return time.perf_counter() - wall0, time.process_time() - cpu0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="simulated time per run (s)")
    parser.add_argument("--repeats", type=int, default=5, help="repeats (medians are reported)")
    parser.add_argument("--quick", action="store_true", help="0.25 s runs, 2 repeats (CI smoke)")
    args = parser.parse_args()
    seconds, repeats = (0.25, 2) if args.quick else (args.seconds, args.repeats)
    n_steps = int(round(seconds * 8000))

    pool = ThreadPoolExecutor(max_workers=2)
    simulate(800)  # warm-up: load the module, fault in the pages

    def one() -> None:
        simulate(n_steps)

    gaps: list[float] = []

    def two() -> None:
        futures = [pool.submit(simulate_finish, n_steps) for _ in range(2)]
        (e0, v0), (e1, v1) = [f.result() for f in futures]
        assert v0 == v1, "the same seeded run must give the same result"
        gaps.append(abs(e1 - e0))

    ones, twos = [], []
    for _ in range(repeats):
        ones.append(timed(one))
        twos.append(timed(two))
    pool.shutdown()
    wall1 = statistics.median(w for w, _ in ones)
    cpu1 = statistics.median(c for _, c in ones)
    wall2 = statistics.median(w for w, _ in twos)
    cpu2 = statistics.median(c for _, c in twos)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"world simulation: {seconds:g} s simulated = {n_steps} physics steps, "
        f"{repeats} repeats (medians), {os.cpu_count()} CPUs, load average {load:.2f}"
    )
    print(
        f"one thread : wall {wall1:.3f} s, process CPU {cpu1:.3f} s "
        f"({n_steps / cpu1:,.0f} steps per CPU second)"
    )
    print(f"two threads: wall {wall2:.3f} s, process CPU {cpu2:.3f} s")
    print(
        f"ratio two-thread / one-thread wall time {wall2 / wall1:.2f} "
        f"(1.0 = perfect parallelism on 2 free cores, 2.0 = serialised); "
        f"CPU ratio {cpu2 / cpu1:.2f} (2.0 = no threading overhead); "
        f"cores used at once in the two-thread phase {cpu2 / wall2:.2f}"
    )
    print(
        f"finish-time gap of the two threads / one-thread wall time "
        f"{statistics.median(gaps) / wall1:.2f} (0 = ran in parallel, 1 = serialised by the GIL)"
    )


if __name__ == "__main__":
    main()
