#!/usr/bin/env bash
# Builds the documentation site (mkdocs-material, mkdocstrings, mkdocs-jupyter) in strict mode,
# executing every tutorial notebook (docs/tutorials/*.py, paired with jupytext) against the
# abi3 wheel that scripts/test-python.sh built, in a fresh venv: a broken example fails.
# Usage: bash scripts/test-docs.sh   (called by scripts/test.sh after scripts/test-python.sh)
# Output: target/site/index.html
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-$PWD/target}
venv="$target/docs-venv"
shopt -s nullglob
built=("$target"/wheels/ballbot-*-cp39-abi3-*.whl)
if [ "${#built[@]}" -ne 1 ]; then
    echo "expected the one wheel of scripts/test-python.sh in $target/wheels (run it first)" >&2
    exit 1
fi
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r docs/requirements.txt \
    "${built[0]}[gym,mcap]"
# Always execute the notebooks (mkdocs-jupyter would reuse its cache of executed pages).
rm -rf .cache/mkdocs-jupyter
NO_MKDOCS_2_WARNING=1 "$venv/bin/python" -m mkdocs build --strict --site-dir "$target/site"
echo "site: $target/site/index.html"
