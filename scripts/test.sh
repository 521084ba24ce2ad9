#!/usr/bin/env bash
# Every test of the project: the README's test command, and what CI (.ci/run) runs.
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
# Each step prints the seconds since the start, so a slow step shows in CI's log.
step() { printf '\n==> [%ds] %s\n' "$SECONDS" "$*"; }

step "format"
cargo fmt --all --check

step "clippy (all targets, warnings denied)"
cargo clippy --all-targets -- -D warnings

step "clippy (Python bindings)"
cargo clippy -p ballbot-py --all-targets -- -D warnings

step "clippy (ballbot-sim and ballbot-studies without the plot feature, as the Python extension builds them)"
cargo clippy -p ballbot-sim -p ballbot-studies --no-default-features -- -D warnings

step "layers: the Python extension links no command-line or plotting crate"
# Procedural macros run at build time and are not linked (prost-derive uses anyhow).
if cargo tree -p ballbot-py -e normal,no-proc-macro | grep -E 'clap|indicatif|anyhow|plotters'; then
    echo "ballbot-py must not depend on clap, indicatif, anyhow or plotters" >&2
    exit 1
fi

step "layers: each crate depends only on the crates its row of ARCHITECTURE.md allows"
python3 scripts/check-layers.py --self-test && python3 scripts/check-layers.py

step "no import cycles"
python3 scripts/check-cycles.py --self-test && python3 scripts/check-cycles.py

step "the shipped path (core, runtime) in functions of at most 80 lines"
python3 scripts/check-function-length.py --self-test && python3 scripts/check-function-length.py

step "the docs' rendered numbers agree with the committed run summaries"
python3 scripts/render-docs.py --self-test && python3 scripts/render-docs.py --check

step "the Python mirror (ballbot._results, ballbot._enums) is what the committed schema generates"
# The other half, the committed schema against the Rust types, is test_mirror.py (it needs the
# built extension).
python3 scripts/gen-python-mirror.py --self-test && python3 scripts/gen-python-mirror.py --check

step "no issue numbers in the code (there is no public tracker to follow them to)"
python3 scripts/check-no-issue-numbers.py

step "docs (warnings denied)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps

step "crates.io: ballbot-core and ballbot-runtime package, and build from their packages (cargo package)"
# Both at once: cargo resolves ballbot-runtime's `ballbot-core = "0.1.0"` against the packaged
# ballbot-core of the same run (not crates.io, where it is not published yet), then builds
# each .crate unpacked on its own (the verify step), so a file missing from a package or a path
# outside it fails here (the READMEs' examples are the crates' docs, run by `cargo test --doc`
# below). Needs crates.io's index only. --allow-dirty: packages the work tree as it is.
# The verify step extracts the local registry's crates into $CARGO_HOME/registry/src/-<hash>/
# (the hash is of target/package/tmp-registry's path) and reuses an extraction of the same name
# and version: a second run from the same checkout after a change to the core's API would build
# the runtime against the first run's core. Our own crates' extractions go first.
cargo_home="${CARGO_HOME:-$HOME/.cargo}"
rm -rf "$cargo_home"/registry/src/-*/ballbot-core-* "$cargo_home"/registry/src/-*/ballbot-runtime-*
cargo package -p ballbot-core -p ballbot-runtime --allow-dirty

step "no_std: ballbot-core pulls in no std or alloc feature"
if cargo tree -p ballbot-core -e normal,features --target all | grep -E 'feature "(std|alloc)"'; then
    echo "ballbot-core must not enable std or alloc in any dependency" >&2
    exit 1
fi

step "no_std: a #![no_std] staticlib without allocator links the core (panic=abort)"
cargo build --release --manifest-path nostd-check/Cargo.toml
lib=nostd-check/target/release/libballbot_nostd_check.a
if nm "$lib" 2>/dev/null | grep -E ' U (__rust_alloc|__rust_dealloc|__rdl_alloc)'; then
    echo "the no_std staticlib references the Rust allocator" >&2
    exit 1
fi

step "workspace tests"
cargo test --all-targets
cargo test --doc

step "instruction-count budgets (valgrind callgrind)"
bash scripts/icount.sh

step "reproduce smoke run (ballbot reproduce --quick)"
cargo run -q -p ballbot-cli --bin ballbot -- reproduce --quick --out target/reproduce-quick
grep -q '"piptb"' target/reproduce-quick/summary.json
grep -q '"max_speed_by_heading"' target/reproduce-quick/summary.json
grep -q '"min_braking_time_3d_secs": 2' target/reproduce-quick/summary.json
grep -q '"push_recovery_ns"' target/reproduce-quick/summary.json
grep -q '"traction_aware"' target/reproduce-quick/summary.json
# Every number of the summary equal to the committed reference, to the last digit (the
# simulations are seeded and deterministic; only the wall-clock solve time and the log paths
# may differ). A change that moves a number updates the reference in the same commit and says
# why: scripts/reference/README.md.
python3 scripts/compare-summary.py scripts/reference/reproduce-quick-summary.json \
    target/reproduce-quick/summary.json --ignore solve_ms --ignore log_path

step "reliability campaign smoke run (ballbot robustness --quick)"
cargo run -q -p ballbot-cli --bin ballbot -- robustness --quick --out target/robustness-quick
python3 scripts/check-robustness.py target/robustness-quick/robustness.json

step "Python package: pip install into a fresh venv (with the gym, dask, mcap and mujoco extras), mypy.stubtest, mypy --strict, pytest"
bash scripts/test-python.sh


step "documentation site: mkdocs build --strict, the tutorial notebooks executed against the wheel"
bash scripts/test-docs.sh

printf '\n==> [%ds] every test passed\n' "$SECONDS"
