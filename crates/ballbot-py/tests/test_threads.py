"""Long calls release the GIL: Python keeps running in another thread while Rust works.

This does not time a speed-up (the benchmark script measures that, on an idle machine); it
checks the mechanism, which holds even on one core: while a rollout runs in a worker thread,
the main thread executes Python bytecode. With the GIL held for the whole call, the main loop
could not advance until the call returned."""

import threading
import time

import numpy as np

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
