#!/usr/bin/env bash
# What a decimated log costs `ballbot world` (docs/world.md, "What a decimated log
# costs"): the same run with its log decimated to 1 Hz (`--decimate 8000`) and without a log
# (`--no-log`), alternating, each REPEATS times; prints each one's wall and CPU (user + sys)
# times, their medians in simulated seconds per second, and the ratio of the medians.
# Optional: not part of the test command.
# Usage: bash benches/world_log/run.sh [SECONDS (60)] [REPEATS (9)] [DECIMATE (8000)]
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build -q --release -p ballbot-cli
target=${CARGO_TARGET_DIR:-$PWD/target}
exec python3 - "$target/release/ballbot" "${1:-60}" "${2:-9}" "${3:-8000}" <<'PY'
import os, statistics, subprocess, sys, tempfile, time

ballbot, seconds, repeats, decimate = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
out = os.path.join(tempfile.mkdtemp(), "world.mcap")
runs = {
    f"--decimate {decimate}": ["--decimate", decimate, "--out", out],
    "--no-log": ["--no-log"],
}
times = {name: [] for name in runs}


def once(flags):
    """One run: its wall and CPU (user + sys) seconds."""
    start = time.perf_counter()
    child = subprocess.Popen(
        [ballbot, "world", "--duration-secs", str(seconds), *flags], stdout=subprocess.DEVNULL
    )
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    if status != 0:
        sys.exit(f"ballbot world {' '.join(flags)} failed")
    return wall, usage.ru_utime + usage.ru_stime


for _ in range(repeats):
    for name, flags in runs.items():
        times[name].append(once(flags))
medians = {}
for name, rows in times.items():
    wall = statistics.median(r[0] for r in rows)
    cpu = statistics.median(r[1] for r in rows)
    medians[name] = (wall, cpu)
    print(
        f"{name:>16}: wall {' '.join(f'{r[0]:.3f}' for r in rows)} s; median "
        f"{seconds / wall:.1f} sim s per wall s, {seconds / cpu:.1f} per CPU s"
    )
logged, unlogged = medians.values()
print(f"logged / unlogged: wall {logged[0] / unlogged[0]:.3f}, CPU {logged[1] / unlogged[1]:.3f}")
PY
