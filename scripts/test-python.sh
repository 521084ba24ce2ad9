#!/usr/bin/env bash
# Builds the `ballbot` Python package into a fresh virtual environment the way a user would
# (`pip install ./crates/ballbot-py`), then runs pytest and mypy.stubtest on it.
# Usage: bash scripts/test-python.sh   (called by scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-$PWD/target}
venv="$target/py-venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "pytest>=7" "mypy>=1.10" \
    "maturin>=1.9.4,<2"
# Share the workspace's target directory so the Rust build is not repeated from scratch.
CARGO_TARGET_DIR="$target" "$venv/bin/python" -m pip install -q --disable-pip-version-check \
    --force-reinstall --no-deps ./crates/ballbot-py
# What `pip install "./crates/ballbot-py[gym,dask]"` adds, read from the installed package's own
# metadata (so the extras the README names are the ones tested): the base dependencies and
# the `gym` and `dask` extras.
mapfile -t requirements < <("$venv/bin/python" scripts/extra-requirements.py ballbot gym dask)
"$venv/bin/python" -m pip install -q --disable-pip-version-check "${requirements[@]}"
"$venv/bin/python" -m mypy.stubtest ballbot._core --allowlist crates/ballbot-py/stubtest-allowlist.txt
"$venv/bin/python" -m mypy --strict crates/ballbot-py/python/ballbot
"$venv/bin/python" -m pytest -q crates/ballbot-py/tests
