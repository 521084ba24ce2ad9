#!/usr/bin/env bash
# Builds the `ballbot` Python package as a user gets it: `maturin build --release` makes one abi3
# wheel (CPython >= 3.9), which is installed into a fresh virtual environment (the wheel, not the
# source tree); then mypy.stubtest, mypy and pytest run against the installed package.
# Usage: bash scripts/test-python.sh   (called by scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-$PWD/target}
venv="$target/py-venv"
wheels="$target/wheels"
rm -rf "$venv" "$wheels"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "pytest>=7" "mypy>=1.10" \
    "websockets>=12" "maturin>=1.9.4,<2"
# Share the workspace's target directory so the Rust build is not repeated from scratch.
CARGO_TARGET_DIR="$target" "$venv/bin/maturin" build --release --quiet \
    --manifest-path crates/ballbot-py/Cargo.toml --out "$wheels"
shopt -s nullglob
built=("$wheels"/ballbot-*.whl)
if [ "${#built[@]}" -ne 1 ] || [[ "${built[0]}" != *-cp39-abi3-* ]]; then
    echo "expected one abi3 wheel (ballbot-*-cp39-abi3-*.whl) in $wheels, found: ${built[*]:-none}" >&2
    exit 1
fi
echo "built ${built[0]##*/}"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps \
    "${built[0]}"
# What `pip install "ballbot[gym,dask,mcap,mujoco]"` adds, read from the installed wheel's own
# metadata (so the extras the README names are the ones tested): the base dependencies and the
# `gym`, `dask`, `mcap` and `mujoco` extras (MuJoCo loads the exported MJCF in test_export.py).
mapfile -t requirements < <("$venv/bin/python" scripts/extra-requirements.py ballbot gym dask mcap mujoco)
"$venv/bin/python" -m pip install -q --disable-pip-version-check "${requirements[@]}"
# The tests must see the installed wheel, not the sources under crates/ballbot-py/python.
(cd "$target" && "$venv/bin/python" -c "
import ballbot, sys
where = ballbot.__file__
assert 'site-packages' in where, f'ballbot imported from {where}, not from the installed wheel'
print('testing', where)
")
"$venv/bin/python" -m mypy.stubtest ballbot._core --allowlist crates/ballbot-py/stubtest-allowlist.txt
"$venv/bin/python" -m mypy --strict crates/ballbot-py/python/ballbot
"$venv/bin/python" -m pytest -q -p no:cacheprovider crates/ballbot-py/tests
