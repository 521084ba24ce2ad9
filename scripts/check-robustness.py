#!/usr/bin/env python3
"""Checks a robustness.json written by `ballbot robustness` (the README's test command runs
the --quick campaign and this check): the keys the issue asks for, and the invariants that
must hold whatever the numbers (no panic, no bad command, every fault-matrix cell complete,
every log read back whole).

Usage: python3 scripts/check-robustness.py DIR/robustness.json
"""
import json
import sys


def fail(message):
    print(f"check-robustness: {message}", file=sys.stderr)
    sys.exit(1)


def main(path):
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    matrix = data.get("fault_matrix") or fail("no fault_matrix")
    cells = matrix.get("cells") or fail("fault_matrix has no cells")
    for cell in cells:
        for key in ("class", "condition", "heading_deg", "controller", "expected", "observed", "fell"):
            if key not in cell:
                fail(f"a fault_matrix cell has no {key}: {cell}")
        if cell["faults_before_injection"]:
            fail(f"a healthy run raised faults before the injection: {cell}")
        log = cell.get("log")
        if log is None or not log["read_back_whole"]:
            fail(f"a faulted run's log is missing or does not read back whole: {cell}")
    classes = {c["class"] for c in cells}
    conditions = {c["condition"] for c in cells}
    if len(classes) < 17 or conditions != {"standing", "cruising", "braking"}:
        fail(f"the matrix misses classes or conditions: {sorted(classes)} {sorted(conditions)}")
    print(f"check-robustness: {path}: {len(cells)} fault cells, "
          f"{matrix['summary']['as_expected']} in their expected safe state")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        fail("usage: check-robustness.py DIR/robustness.json")
    main(sys.argv[1])
