"""What the Python layer costs on top of the Rust code it calls.

Measures, as medians over repeats:

(a) a batch closed-loop rollout called from Python against the same rollout's time inside
    Rust (`compute_secs`, timed around the Rust loop itself): the ratio is the binding's cost
    (argument checks, GIL release, result arrays). Target <= 1.2.
(b) one controller `step` call from Python against one step in Rust (`step_many` over a
    million measurements, per step): the difference is the per-call overhead. Target < 1 us.
(c) two rollouts in two threads against the same two one after the other: with the GIL
    released the ratio approaches 0.5 on an idle machine with two free cores.

Usage: python crates/ballbot-py/bench/bench_overhead.py [--quick]
"""

import argparse
import statistics
import threading
import time
import timeit

import numpy as np

import ballbot


def median_time(fn: "object", repeats: int) -> float:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()  # type: ignore[operator]
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats (for CI smoke)")
    args = parser.parse_args()
    repeats = 3 if args.quick else 15

    wip = ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))
    gains = ballbot.LqrGains.for_wip(wip, 83.9)
    controller = ballbot.LqrController(gains)

    # (a) batch rollout: 100 trajectories x 4000 periods (10 s at 400 Hz), RK4 plant.
    initial = np.zeros((100, 4))
    initial[:, 0] = np.radians(np.linspace(-10.0, 10.0, 100))
    walls, inner = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        run = ballbot.closed_loop_rollout(wip, controller, initial, n_steps=4000)
        walls.append(time.perf_counter() - start)
        inner.append(run.compute_secs)
    wall, rust = statistics.median(walls), statistics.median(inner)
    print(
        f"(a) rollout 100 x 4000 steps: Python call {wall * 1e3:.2f} ms, Rust loop "
        f"{rust * 1e3:.2f} ms, ratio {wall / rust:.3f} (target <= 1.2)"
    )

    # (b) single step overhead.
    measured = np.array([0.01, 0.0, 0.02, 0.3])
    command = np.zeros(4)
    n_calls = 200_000 if not args.quick else 20_000
    per_call = (
        min(
            timeit.repeat(
                lambda: controller.step(measured, command, 0.0025),
                number=n_calls,
                repeat=repeats,
            )
        )
        / n_calls
    )
    per_call_list = (
        min(
            timeit.repeat(
                lambda: controller.step([0.01, 0.0, 0.02, 0.3], None, 0.0025),
                number=n_calls,
                repeat=repeats,
            )
        )
        / n_calls
    )
    many = np.tile(measured, (1_000_000, 1))
    rust_step = median_time(lambda: controller.step_many(many, command), repeats) / len(many)
    # The whole call bounds the overhead from above, whatever the Rust step costs; the
    # replay loop (`step_many`, memory traffic of 1e6 rows included) bounds the Rust step.
    print(
        f"(b) step from Python {per_call * 1e9:.0f} ns per call (numpy state; list: "
        f"{per_call_list * 1e9:.0f} ns), so overhead < {per_call * 1e9:.0f} ns (target < 1000 "
        f"ns); step_many in Rust {rust_step * 1e9:.1f} ns per step, overhead beyond it "
        f"{(per_call - rust_step) * 1e9:.0f} ns"
    )

    # (c) two threads.
    def one() -> None:
        ballbot.closed_loop_rollout(wip, controller, initial, n_steps=4000)

    def sequential() -> None:
        one()
        one()

    def threaded() -> None:
        workers = [threading.Thread(target=one) for _ in range(2)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()

    seq = median_time(sequential, repeats)
    par = median_time(threaded, repeats)
    print(
        f"(c) two rollouts: sequential {seq * 1e3:.1f} ms, two threads {par * 1e3:.1f} ms, "
        f"ratio {par / seq:.2f} (0.5 = perfect, 1.0 = no parallelism)"
    )


if __name__ == "__main__":
    main()
