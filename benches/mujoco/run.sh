#!/usr/bin/env bash
# Our world against a MuJoCo roller-omniwheel ballbot, simulated seconds per wall second, in one
# run (docs/world.md, "Speed against MuJoCo"). Optional: not part of the test command.
# Makes its own venv (BENCH_VENV, default target/bench-mujoco-venv) with MuJoCo from PyPI.
# Usage: bash benches/mujoco/run.sh [--seconds S] [--repeats N] [--json FILE]
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=${BENCH_VENV:-target/bench-mujoco-venv}
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q -r benches/mujoco/requirements.txt
cargo build -q --release -p ballbot-benches --example world_speed
target=${CARGO_TARGET_DIR:-$PWD/target}
exec "$venv/bin/python" benches/mujoco/bench.py --world-speed "$target/release/examples/world_speed" "$@"
