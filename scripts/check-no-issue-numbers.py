#!/usr/bin/env python3
"""Fails when source files cite issue numbers: "issue", optionally a space, "_", "-" or "#",
then digits, in any case (a comment's "issue N", a test's "..._issue_N_...").

The project has no public issue tracker, so a number means nothing to a reader: a name or a
comment says what it means instead. Scans the .rs, .py, .pyi, .sh and .toml files under
crates/, scripts/ and benches/ (no target/ directory, no CHANGELOG), prints file:line: text
for each mention and exits 1 if there is any.

A line that holds the marker ``check-no-issue-numbers: allow`` is not checked, nor is the
line after it (a deprecated alias keeps its old name for one release: put the marker in a
comment just above it).

Usage: scripts/check-no-issue-numbers.py [--exclude PATH]... [ROOT]
  --exclude PATH  skip a file or a directory (relative to ROOT or absolute); repeatable
  ROOT            the repository (default: this script's parent directory's parent)
"""

import argparse
import os
import re
import sys

DIRS = ("crates", "scripts", "benches")
EXTENSIONS = (".rs", ".py", ".pyi", ".sh", ".toml")
SKIP_DIRS = {"target", ".git", "__pycache__", ".venv", "venv", "node_modules"}
SKIP_NAMES = {"CHANGELOG.md", "CHANGELOG"}
# "issue" or "issues" in any case, not the end of a longer word ("tissue"), then at most one
# of " _-", at most one "#", then digits. "_" before it is allowed: test names cite them too.
PATTERN = re.compile(r"(?<![a-z])issues?[ _-]?#?\d+", re.IGNORECASE)
MARKER = "check-no-issue-numbers: allow"


def excluded(path, excludes):
    return any(path == e or path.startswith(e + os.sep) for e in excludes)


def source_files(root, excludes):
    for top in DIRS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames[:] = sorted(
                d for d in dirnames
                if d not in SKIP_DIRS and not excluded(os.path.join(dirpath, d), excludes)
            )
            for name in sorted(filenames):
                path = os.path.join(dirpath, name)
                if (name.endswith(EXTENSIONS) and name not in SKIP_NAMES
                        and not excluded(path, excludes)):
                    yield path


def mentions(path):
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except (UnicodeDecodeError, OSError) as e:
        print(f"check-no-issue-numbers: cannot read {path}: {e}", file=sys.stderr)
        return
    allowed = set()
    for number, line in enumerate(lines, 1):
        if MARKER in line:
            allowed.update((number, number + 1))
    for number, line in enumerate(lines, 1):
        if number not in allowed and PATTERN.search(line):
            yield number, line.strip()


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(
        description="Fail when source files cite issue numbers.")
    parser.add_argument("--exclude", action="append", default=[], metavar="PATH",
                        help="a file or directory to skip (relative to ROOT); repeatable")
    parser.add_argument("root", nargs="?", default=os.path.dirname(here),
                        help="the repository (default: the one holding this script)")
    args = parser.parse_args()
    root = os.path.abspath(args.root)
    excludes = [os.path.normpath(os.path.join(root, e)) for e in args.exclude]
    found = 0
    for path in source_files(root, excludes):
        for number, text in mentions(path):
            print(f"{os.path.relpath(path, root)}:{number}: {text}")
            found += 1
    if found:
        print(f"check-no-issue-numbers: {found} issue number(s) in the code; say what each "
              "means instead", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
