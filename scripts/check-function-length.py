#!/usr/bin/env python3
"""Fails if a function on the shipped path is longer than a limit.

Usage:
    python3 scripts/check-function-length.py [--max-lines N] [DIR ...]
    python3 scripts/check-function-length.py --self-test

Checks every `.rs` file under each DIR (default: `crates/ballbot-core/src` and
`crates/ballbot-runtime/src`, the code a robot runs) and prints each function longer than
`--max-lines` (default 80) as `lines name path:line`, longest first. Exit status 0: none over;
1: some over; 2: bad usage.

A function's length is its lines from the `fn` keyword to its closing brace, blank and comment
lines included (the doc comment above it is not counted). Items under `#[cfg(test)]` (test
modules and test-only functions) are skipped: the limit is for code that ships. Comments,
string literals (raw ones too) and character literals are blanked before braces are counted,
so a `'{'` or a `"}"` does not end a function. Functions without a body (trait declarations,
`extern` blocks) are not counted. Standard library only (python3 >= 3.8).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from pathlib import Path

DEFAULT_ROOTS = ("crates/ballbot-core/src", "crates/ballbot-runtime/src")
FN = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)")
CFG_TEST = re.compile(r"#\[cfg\(test\)\]")
# `#[cfg(test)] mod name;` (other attributes between allowed): a test module in its own file.
TEST_MOD_DECL = re.compile(
    r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;"
)
RAW_STRING = re.compile(r'b?r(#*)"')


def blank(text: str) -> str:
    """`text` with comments, strings and char literals replaced by spaces (newlines kept)."""
    out: list[str] = []
    i, n = 0, len(text)

    def keep_newlines(chunk: str) -> str:
        return "".join(c if c == "\n" else " " for c in chunk)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(keep_newlines(text[i:j]))
            i = j
        elif (m := RAW_STRING.match(text, i)) and (i == 0 or not text[i - 1].isalnum()):
            end = '"' + m.group(1)
            j = text.find(end, m.end())
            j = n if j < 0 else j + len(end)
            out.append(keep_newlines(text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(keep_newlines(text[i : j + 1]))
            i = j + 1
        elif c == "'":
            # A char literal ('x', '\n', '\u{7f}', '{'), not a lifetime ('a).
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'\n])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching_brace(code: str, open_at: int) -> int:
    """Index of the `}` closing the `{` at `open_at` (or the end of `code`)."""
    depth = 0
    for j in range(open_at, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


def body_start(code: str, after: int) -> int | None:
    """Where the body of the function whose signature starts at `after` opens: the first `{`
    outside parentheses and brackets, unless a `;` there ends the signature first (a
    declaration). A `;` inside brackets is an array type (`[f64; 3]`)."""
    depth = 0
    for j in range(after, len(code)):
        c = code[j]
        if c in "([":
            depth += 1
        elif c in ")]":
            depth -= 1
        elif depth == 0 and c == "{":
            return j
        elif depth == 0 and c == ";":
            return None
    return None


def test_spans(code: str) -> list[tuple[int, int]]:
    """The character spans of the items under `#[cfg(test)]`."""
    spans = []
    for m in CFG_TEST.finditer(code):
        brace, semi = code.find("{", m.end()), code.find(";", m.end())
        if brace < 0 or (0 <= semi < brace):
            continue  # `#[cfg(test)] mod tests;` or a `use`: nothing inline to skip
        spans.append((m.start(), matching_brace(code, brace)))
    return spans


def functions(text: str) -> list[tuple[int, str, int]]:
    """`(lines, name, first line)` of each function with a body outside test items."""
    code = blank(text)
    skipped = test_spans(code)
    found = []
    for m in FN.finditer(code):
        if any(a <= m.start() <= b for a, b in skipped):
            continue
        brace = body_start(code, m.end())
        if brace is None:
            continue
        end = matching_brace(code, brace)
        first = code.count("\n", 0, m.start()) + 1
        last = code.count("\n", 0, end) + 1
        found.append((last - first + 1, m.group(1), first))
    return found


def test_module_paths(path: Path, code: str) -> list[Path]:
    """The files and folders of the test modules that `path` declares as `#[cfg(test)] mod x;`
    (`x.rs` or `x/mod.rs` beside a `mod.rs`/`lib.rs`/`main.rs`, else in the folder named after
    the file), as rustc finds them."""
    folder = path.parent if path.name in ("mod.rs", "lib.rs", "main.rs") else path.with_suffix("")
    found = []
    for m in TEST_MOD_DECL.finditer(code):
        found += [folder / f"{m.group(1)}.rs", folder / m.group(1)]
    return found


def check(roots: list[Path], max_lines: int) -> list[tuple[int, str, str]]:
    """Every function over `max_lines` under `roots`, longest first."""
    over = []
    for root in roots:
        paths = sorted(root.rglob("*.rs"))
        skipped = set()
        for path in paths:
            skipped.update(test_module_paths(path, blank(path.read_text(encoding="utf-8"))))
        for path in paths:
            if path in skipped or any(p in skipped for p in path.parents):
                continue
            for lines, name, line in functions(path.read_text(encoding="utf-8")):
                if lines > max_lines:
                    over.append((lines, name, f"{os.path.relpath(path)}:{line}"))
    return sorted(over, reverse=True)


SELF_TEST = {
    # (source of lib.rs, or of each file, max_lines, names expected over the limit)
    "short": ("fn a() {\n    1;\n}\n", 3, []),
    "long": ("fn a() {\n    1;\n    2;\n}\n", 3, ["a"]),
    "brace in string and char": (
        'fn a() {\n    let s = "}}}";\n    let c = \'}\';\n    let r = r#"}"#;\n'
        "    // }\n    /* } */\n    0\n}\n",
        7,
        ["a"],
    ),
    "lifetime is no char": ("fn a<'x>(v: &'x u8) -> &'x u8 {\n    v\n\n\n}\n", 4, ["a"]),
    "test module skipped": (
        "#[cfg(test)]\nmod tests {\n    fn t() {\n        1;\n        2;\n        3;\n    }\n}\n",
        2,
        [],
    ),
    "array type in a signature": (
        "fn a(x: [u8; 3]) -> [u8; 3] {\n    x;\n    x\n}\n",
        3,
        ["a"],
    ),
    "test module in its own file": (
        {
            "lib.rs": "#[cfg(test)]\n#[allow(clippy::unwrap_used)]\nmod tests;\nmod shipped;\n",
            "tests.rs": "fn t() {\n    1;\n    2;\n}\n",
            "shipped.rs": "fn s() {\n    1;\n    2;\n}\n",
        },
        3,
        ["s"],
    ),
    "trait declaration has no body": (
        "trait T {\n    fn a(&self);\n    fn b(&self) {\n        1;\n    }\n}\n",
        2,
        ["b"],
    ),
}


def self_test() -> int:
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for case, (source, limit, expected) in SELF_TEST.items():
            root = Path(tmp) / case.replace(" ", "_")
            root.mkdir()
            files = source if isinstance(source, dict) else {"lib.rs": source}
            for name, text in files.items():
                (root / name).write_text(text, encoding="utf-8")
            got = [name for _, name, _ in check([root], limit)]
            if got != expected:
                print(f"self-test {case!r}: expected {expected}, got {got}", file=sys.stderr)
                failures += 1
    print(f"check-function-length self-test: {len(SELF_TEST) - failures}/{len(SELF_TEST)} pass")
    return 1 if failures else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("roots", nargs="*", type=Path, help="folders to check")
    parser.add_argument("--max-lines", type=int, default=80)
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    roots = args.roots or [Path(__file__).resolve().parent.parent / r for r in DEFAULT_ROOTS]
    missing = [r for r in roots if not r.is_dir()]
    if missing:
        print(f"not a folder: {', '.join(map(str, missing))}", file=sys.stderr)
        return 2
    every = check(roots, 0)
    over = [f for f in every if f[0] > args.max_lines]
    for lines, name, where in over:
        print(f"{lines} {name} {where}")
    if over:
        print(f"{len(over)} function(s) over {args.max_lines} lines", file=sys.stderr)
        return 1
    longest = f"{every[0][0]} lines, {every[0][1]} at {every[0][2]}" if every else "none"
    print(f"no function over {args.max_lines} lines in {len(every)} (longest: {longest})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
