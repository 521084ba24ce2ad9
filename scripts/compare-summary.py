#!/usr/bin/env python3
"""Compares two `ballbot reproduce` summary.json files number by number.

Usage: python3 scripts/compare-summary.py REFERENCE ACTUAL [--ignore KEY ...]

Every number must be equal to the last digit (JSON round-trips f64 exactly), every string and
bool equal, and the two files must hold the same keys. Prints each difference as
`path: reference -> actual` and exits 1 if there is any. Keys given with --ignore (dotted paths,
a `*` matches any one component, a bare name that key anywhere) are skipped: wall-clock timings, for example.
"""

import argparse
import json
import sys


def walk(ref, act, path, ignore, out):
    if any(match(path, pattern) for pattern in ignore):
        return
    if isinstance(ref, dict) and isinstance(act, dict):
        for key in sorted(set(ref) | set(act)):
            sub = f"{path}.{key}" if path else str(key)
            if key not in ref:
                if not any(match(sub, p) for p in ignore):
                    out.append(f"{sub}: (absent) -> {json.dumps(act[key])[:80]}")
            elif key not in act:
                if not any(match(sub, p) for p in ignore):
                    out.append(f"{sub}: {json.dumps(ref[key])[:80]} -> (absent)")
            else:
                walk(ref[key], act[key], sub, ignore, out)
    elif isinstance(ref, list) and isinstance(act, list):
        if len(ref) != len(act):
            out.append(f"{path}: length {len(ref)} -> {len(act)}")
        for i, (r, a) in enumerate(zip(ref, act)):
            walk(r, a, f"{path}[{i}]", ignore, out)
    elif type(ref) is not type(act) and not (
        isinstance(ref, (int, float)) and isinstance(act, (int, float))
        and not isinstance(ref, bool) and not isinstance(act, bool)
    ):
        out.append(f"{path}: {json.dumps(ref)[:80]} -> {json.dumps(act)[:80]} (type)")
    elif ref != act:
        out.append(f"{path}: {json.dumps(ref)[:80]} -> {json.dumps(act)[:80]}")


def match(path, pattern):
    if "." not in pattern and "[" not in pattern:
        # A bare key name matches that key anywhere.
        return path.rsplit(".", 1)[-1] == pattern
    a = path.replace("[", ".[").split(".")
    b = pattern.replace("[", ".[").split(".")
    return len(a) == len(b) and all(q in ("*", "[*]") or p == q for p, q in zip(a, b))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference")
    parser.add_argument("actual")
    parser.add_argument("--ignore", action="append", default=[])
    args = parser.parse_args()
    with open(args.reference) as f:
        ref = json.load(f)
    with open(args.actual) as f:
        act = json.load(f)
    out = []
    walk(ref, act, "", args.ignore, out)
    for line in out:
        print(line)
    print(f"{len(out)} difference(s) between {args.reference} and {args.actual}")
    sys.exit(1 if out else 0)


if __name__ == "__main__":
    main()
