"""Long calls release the GIL: Python keeps running in another thread while Rust works.

This does not time a speed-up (the benchmark script measures that, on an idle machine); it
checks the mechanism, which holds even on one core: while a rollout runs in a worker thread,
the main thread executes Python bytecode. With the GIL held for the whole call, the main loop
could not advance until the call returned."""

import threading
import time

import numpy as np
import pytest

import ballbot


def test_rollout_lets_other_python_threads_run(wip: ballbot.Wip) -> None:
    controller = ballbot.LqrController(ballbot.LqrGains.for_wip(wip, 83.9))
    initial = np.zeros((64, 4))
    initial[:, 0] = 0.1
    window: list[float] = []

    def work() -> None:
        start = time.perf_counter()
        ballbot.closed_loop_rollout(wip, controller, initial, n_steps=20_000, substeps=4)
        window.extend([start, time.perf_counter()])

    worker = threading.Thread(target=work)
    ticks: list[float] = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    start, end = window
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.05, "the rollout was too short to observe"
    assert len(during) >= 5, f"main thread ran {len(during)} times in {end - start:.3f} s"


def test_world_run_lets_other_python_threads_run() -> None:
    sim = ballbot.WorldLoop()
    window: list[float] = []

    def work() -> None:
        start = time.perf_counter()
        # 15 simulated s: the multi-rate default world runs about 180 of them per wall second,
        # long enough to watch the main thread tick.
        sim.run(120_000, [0.3, 0.0, 0.0], record_every=400)
        window.extend([start, time.perf_counter()])

    worker = threading.Thread(target=work)
    ticks: list[float] = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    start, end = window
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.05, "the run was too short to observe"
    assert len(during) >= 5, f"main thread ran {len(during)} times in {end - start:.3f} s"
    assert sim.time_secs == pytest.approx(15.0)


def test_worlds_in_threads_give_the_same_results_as_in_sequence() -> None:
    """Two worlds stepping at once share nothing: each gives what it gives alone."""
    from concurrent.futures import ThreadPoolExecutor

    def run(heading_deg: float) -> float:
        return ballbot.max_speed_ramp(
            heading_deg=heading_deg, accel_m_per_s2=1.0, max_command_m_per_s=0.5, settle_secs=0.1
        ).max_speed_m_per_s

    alone = [run(0.0), run(90.0)]
    with ThreadPoolExecutor(max_workers=2) as pool:
        together = list(pool.map(run, [0.0, 90.0]))
    assert together == alone


def test_thread_benchmark_runs() -> None:
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "bench" / "bench_threads.py"
    done = subprocess.run(
        [sys.executable, str(script), "--quick"], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert "ratio two-thread / one-thread wall time" in done.stdout, done.stdout
    assert "finish-time gap" in done.stdout, done.stdout



def test_a_world_in_use_by_another_thread_raises_runtime_error() -> None:
    world = ballbot.World()
    worker = threading.Thread(target=lambda: world.run(80_000, record_every=1000))
    worker.start()
    refused = 0
    while worker.is_alive():
        try:
            world.kinetic_energy_j()
        except RuntimeError:
            refused += 1
        time.sleep(0.001)
    worker.join()
    assert refused > 0, "the running world must refuse a second user"
    assert world.time_secs == pytest.approx(10.0)
