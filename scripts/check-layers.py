#!/usr/bin/env python3
"""Fails if a workspace crate depends on a crate its layer may not import.

Usage:
    python3 scripts/check-layers.py [--root DIR]   check the workspace (default: the repository)
    python3 scripts/check-layers.py --self-test    check the checker on made-up graphs

The rule is the crate table of ARCHITECTURE.md (section "Crates"), read as written: its rows are
the layers in order, top first, and each row's last column lists the workspace crates that
crate may import, as `ballbot-...` names in backticks. The dependency graph is `cargo metadata`'s
(normal, build and dev dependencies alike: a test that pulls in a layer below it is an upward
arrow too). Checked:

- every workspace package has a row, and every row names a workspace package;
- a crate may import only crates in rows above its own (the table itself is layered);
- each dependency of a crate on a workspace crate is one its row allows.

Exit status 0: the graph keeps the layers; 1: a violation (each printed with the Cargo.toml to
fix); 2: bad usage or an unreadable table.

Standard library only (python3 >= 3.8).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

TABLE_HEADING = "## Crates"
NAME = re.compile(r"`(ballbot-[a-z0-9-]+)`")


@dataclass
class Row:
    """One crate of the table: its package name and the workspace crates it may import."""

    name: str
    may_import: list[str]
    line: int


class TableError(Exception):
    """The crate table is missing or a row cannot be read."""


def parse_table(text: str) -> list[Row]:
    """The rows of the crate table under `## Crates`, in order."""
    lines = text.splitlines()
    try:
        start = next(i for i, l in enumerate(lines) if l.strip() == TABLE_HEADING)
    except StopIteration:
        raise TableError(f"no '{TABLE_HEADING}' section") from None
    rows: list[Row] = []
    for i in range(start + 1, len(lines)):
        line = lines[i].strip()
        if line.startswith("## "):
            break
        if not line.startswith("|") or set(line) <= set("|-: "):
            if rows and not line:
                break
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if cells[0] == "crate":
            continue
        names = NAME.findall(cells[0])
        if len(names) != 1:
            raise TableError(f"ARCHITECTURE.md:{i + 1}: the first cell names no single `ballbot-...` crate")
        rows.append(Row(names[0], NAME.findall(cells[-1]), i + 1))
    if not rows:
        raise TableError(f"no table under '{TABLE_HEADING}'")
    return rows


def violations(rows: list[Row], deps: dict[str, dict[str, str]], manifests: dict[str, str]) -> list[str]:
    """Every break of the rule; `deps[crate]` maps each workspace dependency to its kind."""
    problems: list[str] = []
    order = {r.name: i for i, r in enumerate(rows)}
    for r in rows:
        if r.name not in deps:
            problems.append(f"ARCHITECTURE.md:{r.line}: `{r.name}` is not a workspace package")
        for up in r.may_import:
            if up not in order:
                problems.append(f"ARCHITECTURE.md:{r.line}: `{r.name}` may import `{up}`, which has no row")
            elif order[up] >= order[r.name]:
                problems.append(
                    f"ARCHITECTURE.md:{r.line}: `{r.name}` may import `{up}`, which is not above it in the table"
                )
    for crate in sorted(deps):
        if crate not in order:
            problems.append(f"{manifests.get(crate, crate)}: `{crate}` has no row in ARCHITECTURE.md's crate table")
            continue
        allowed = set(rows[order[crate]].may_import)
        for dep, kind in sorted(deps[crate].items()):
            if dep not in allowed:
                problems.append(
                    f"{manifests.get(crate, crate)}: `{crate}` depends on `{dep}` ({kind}), "
                    f"which its layer may not import (allowed: {', '.join(sorted(allowed)) or 'none'})"
                )
    return problems


def workspace_graph(root: Path) -> tuple[dict[str, dict[str, str]], dict[str, str]]:
    """The workspace packages' dependencies on each other, and each package's Cargo.toml."""
    out = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=root,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    meta = json.loads(out)
    names = {p["name"] for p in meta["packages"]}
    deps: dict[str, dict[str, str]] = {}
    manifests: dict[str, str] = {}
    for p in meta["packages"]:
        manifests[p["name"]] = str(Path(p["manifest_path"]).relative_to(root.resolve()))
        kinds = deps.setdefault(p["name"], {})
        for d in p["dependencies"]:
            if d["name"] in names and d["name"] != p["name"]:
                kinds.setdefault(d["name"], d["kind"] or "normal")
    return deps, manifests


def self_test() -> int:
    table = """# Architecture

## Crates

| crate | role | may import |
|---|---|---|
| `ballbot-a` | the bottom | nothing |
| `ballbot-b` | above a | `ballbot-a` |
| `ballbot-c` | the top | `ballbot-a`, `ballbot-b` |

## Next
"""
    rows = parse_table(table)
    cases = [
        ("the layers kept", {"ballbot-a": {}, "ballbot-b": {"ballbot-a": "normal"}, "ballbot-c": {"ballbot-b": "normal"}}, 0),
        ("an upward dependency", {"ballbot-a": {"ballbot-b": "normal"}, "ballbot-b": {}, "ballbot-c": {}}, 1),
        ("an upward dev-dependency", {"ballbot-a": {}, "ballbot-b": {"ballbot-c": "dev"}, "ballbot-c": {}}, 1),
        ("a crate without a row", {"ballbot-a": {}, "ballbot-b": {}, "ballbot-c": {}, "ballbot-d": {}}, 1),
        ("a row without a crate", {"ballbot-a": {}, "ballbot-b": {}}, 1),
    ]
    failed = 0
    for name, deps, expected in cases:
        got = len(violations(rows, deps, {}))
        if (got > 0) != (expected > 0):
            print(f"self-test FAILED: {name}: {got} violations", file=sys.stderr)
            failed += 1
    # A table whose own rows point down is refused even with no dependency at all.
    bad = table.replace("| `ballbot-a` | the bottom | nothing |", "| `ballbot-a` | the bottom | `ballbot-c` |")
    if not violations(parse_table(bad), {"ballbot-a": {}, "ballbot-b": {}, "ballbot-c": {}}, {}):
        print("self-test FAILED: a row allowing a crate below it", file=sys.stderr)
        failed += 1
    try:
        parse_table("# no table\n")
        print("self-test FAILED: a missing table was read", file=sys.stderr)
        failed += 1
    except TableError:
        pass
    if failed:
        return 1
    print(f"check-layers self-test: ok ({len(cases) + 2} cases)")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    try:
        rows = parse_table((args.root / "ARCHITECTURE.md").read_text(encoding="utf-8"))
    except (OSError, TableError) as e:
        print(f"check-layers: {e}", file=sys.stderr)
        return 2
    deps, manifests = workspace_graph(args.root)
    problems = violations(rows, deps, manifests)
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        return 1
    edges = sum(len(d) for d in deps.values())
    print(f"check-layers: {len(rows)} crates in layer order, {edges} workspace dependencies, none upward")
    return 0


if __name__ == "__main__":
    sys.exit(main())
