#!/usr/bin/env python3
"""Renders the numbers the docs quote from a run, so that each figure is written once.

Usage:
    python3 scripts/render-docs.py           rewrite the marked numbers in README.md, docs/*.md
    python3 scripts/render-docs.py --check   exit 1 if any marked number differs from its source
    python3 scripts/render-docs.py --self-test
    python3 scripts/render-docs.py FILE ...  only these files

A number taken from a run is written between two markers that Markdown does not show:

    J_P is <!--= piptb.lqr_pi.j_p .3f -->0.679<!--/--> N^2 m^2 s

The opening marker names a value of a summary by its path (dotted keys, `[i]` for a list item;
a key may be a number, `max_speed_by_heading.180`) and, optionally, how to write it: a Python
format spec (`.3f`, `.0f`, `+.2f`, `.1%`, `d`) or `sciN` (`6.1e5`: N decimals, no `+` or
leading zeros in the exponent); a `deg` prefix (`deg.2f`) writes an angle the summary holds in
radians in degrees. `[*]` in a path takes every item of a list (`by_heading[*].envelope_m_per_s2`),
and a `min` or `max` prefix (`min.2f`, `maxdeg.1f`) writes the smallest or largest of them (nulls
left out). `[key=value]` takes the one item of a list whose `key` is `value`
(`headings[heading_deg=180]`; an error unless exactly one matches), `[*key=value]` every item
that matches (as `[*]` does), and the `count` format how many of them are true or nonzero
(`cells[*controller=design].as_expected count`). Several keys, comma-separated, must all match
(`cells[controller=design,class=motor_dead,condition=standing,heading_deg=0]`); a number as the
key takes a list item of a list by its position (`outcomes[0=failed].1`: the pair whose first
item is `failed`). `%XX` in a key is the character of that hex code (`%20` a space: a path holds
no blank). The `len` format writes a list's length (`settings.classes len`), a `pct` prefix
(`pct.1f`) a fraction as a percentage without the sign (0.843 as `84.3`). Without a format the
value is written as JSON would (strings bare).
The value comes from the full `ballbot reproduce`'s `summary.json`, through
`docs/figures/reproduce-figures.json`: the values the docs quote, by path, taken from a summary by
`--import` (the whole summary is 5 MB). With a `quick:` prefix on the path it comes from
`scripts/reference/reproduce-quick-summary.json` (the CI's run, checked against the code). With
a `robustness:` prefix it comes from the full reliability campaign's `robustness.json`, through
`docs/figures/robustness-figures.json` (refreshed by `--import-robustness PATH`). With a
`balance:` prefix it comes from `docs/figures/balance-eval.json`, the shipped balancing
policy's evaluation, written whole by `python examples/python/evaluate_balance.py --json
docs/figures/balance-eval.json`; with `gymbench:` from `docs/figures/bench-gym.json`, the
environments' speed, written whole by `python crates/ballbot-py/bench/bench_gym.py --json
docs/figures/bench-gym.json` (a dated measurement, not a deterministic run).

Rendering replaces the text between the markers and nothing else. After a full run, refresh the
figures with:

    ballbot reproduce --out out
    python3 scripts/render-docs.py --import out/summary.json && git diff docs README.md

(`--import` also takes the values of markers added since, and drops those no page quotes.)

`--check` (in the test command) fails when the docs and the committed summaries disagree, and
names each file:line, the path, the text written and the text rendered. A path that does not
exist, or a format the value does not take, is an error (exit 2). Standard library only.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import tempfile
from pathlib import Path
from urllib.parse import unquote

ROOT = Path(__file__).resolve().parent.parent
SOURCES = {
    "full": ROOT / "docs/figures/reproduce-figures.json",
    "quick": ROOT / "scripts/reference/reproduce-quick-summary.json",
    "robustness": ROOT / "docs/figures/robustness-figures.json",
    "balance": ROOT / "docs/figures/balance-eval.json",
    "gymbench": ROOT / "docs/figures/bench-gym.json",
}
# The sources that are extracts of a run too large to commit, refreshed by an import; the
# command whose output each is taken from.
EXTRACTS = {
    "full": "ballbot reproduce --out out` then `--import out/summary.json",
    "robustness": "ballbot robustness --out rob` then `--import-robustness rob/robustness.json",
}
# A path and a format hold no `<` or `>`, so that a marker without a format cannot swallow the
# `-->` that closes it (and with it the next marker).
MARKER = re.compile(r"<!--=\s*(?P<path>[^\s<>]+)(?:\s+(?P<fmt>[^\s<>]+))?\s*-->(?P<text>.*?)<!--/-->", re.S)
FIGURES_TAG = "$comment"
STEP = re.compile(r"\.?([^.\[\]]+)|\[(\d+|\*)\]|\[(\*?)(\w+=[^\]]+)\]")


class RenderError(Exception):
    """A marker that cannot be rendered."""


def same(value: object, wanted: str) -> bool:
    """Whether a summary's `value` is the literal `wanted` of a path (`180` is 180.0 too)."""
    if isinstance(value, str):
        return value == wanted
    try:
        return json.loads(wanted) == value
    except json.JSONDecodeError:
        return False


def matches(item: object, conditions: list[tuple[str, str]]) -> bool:
    """Whether a list's `item` has every `(key, value)` of `conditions` (a number as the key is a
    position in an item that is itself a list)."""
    for field, wanted in conditions:
        if isinstance(item, dict) and field in item:
            value = item[field]
        elif isinstance(item, list) and field.isdigit() and int(field) < len(item):
            value = item[int(field)]
        else:
            return False
        if not same(value, wanted):
            return False
    return True


def lookup(summary: object, path: str) -> object:
    """The value at dotted `path` of `summary` (or under the key `path` of a figures file)."""
    if isinstance(summary, dict) and summary.get(FIGURES_TAG) and path in summary:
        return summary[path]
    if isinstance(summary, dict) and summary.get(FIGURES_TAG):
        raise RenderError(f"`{path}` is not in the figures file: run its import (see --help)")
    node = summary
    pos = 0
    while pos < len(path):
        m = STEP.match(path, pos)
        if not m or m.end() == pos:
            raise RenderError(f"bad path `{path}` at `{path[pos:]}`")
        key, index = m.group(1), m.group(2)
        if key is not None:
            key = unquote(key)
        if m.group(4) is not None:
            # A list's item by a key's value (`[heading_deg=180]`: exactly one must match), or
            # every item that matches (`[*controller=design]`, like `[*]`).
            if not isinstance(node, list):
                raise RenderError(f"`{path}`: `{m.group(0)}` on something that is not a list")
            conditions = []
            for condition in m.group(4).split(","):
                field, eq, wanted = condition.partition("=")
                if not eq or not re.fullmatch(r"\w+", field):
                    raise RenderError(f"bad path `{path}` at `{m.group(0)}`")
                conditions.append((field, unquote(wanted)))
            matching = [item for item in node if matches(item, conditions)]
            rest = path[m.end() :].lstrip(".")
            if m.group(3):
                return [lookup(item, rest) if rest else item for item in matching]
            if len(matching) != 1:
                raise RenderError(f"`{path}`: {len(matching)} items with {m.group(4)}, expected one")
            node = matching[0]
            pos = m.end()
            continue
        if index == "*":
            # Every item of a list: the rest of the path in each, as a list.
            if not isinstance(node, list):
                raise RenderError(f"`{path}`: `[*]` on something that is not a list")
            rest = path[m.end() :].lstrip(".")
            return [lookup(item, rest) if rest else item for item in node]
        try:
            if index is not None:
                node = node[int(index)]  # type: ignore[index]
            elif isinstance(node, list):
                node = node[int(key)]
            else:
                node = node[key]  # type: ignore[index]
        except (KeyError, IndexError, TypeError, ValueError):
            raise RenderError(f"`{path}`: no `{m.group(0).lstrip('.')}` there") from None
        pos = m.end()
    return node


def write(value: object, fmt: str | None) -> str:
    """`value` written with `fmt`."""
    if fmt is None:
        return value if isinstance(value, str) else json.dumps(value)
    if fmt == "count":
        # How many items of a list (`[*]` or `[*key=value]` in the path) are true or nonzero.
        if not isinstance(value, list):
            raise RenderError(f"cannot count {value!r}: not a list")
        return str(sum(1 for v in value if v))
    if fmt == "len":
        # How many items a list has (`[*key=value]` in the path: how many match).
        if not isinstance(value, list):
            raise RenderError(f"cannot take the length of {value!r}: not a list")
        return str(len(value))
    reduce = re.match(r"(min|max)(?=[^a-z]|deg|pct|sci|$)", fmt)
    if reduce:
        # The smallest or largest of a list (`[*]` in the path), nulls left out.
        fmt = fmt[3:]
        numbers = [v for v in value if v is not None] if isinstance(value, list) else None
        if not numbers:
            raise RenderError(f"cannot take the {reduce.group(1)} of {value!r}")
        value = min(numbers) if reduce.group(1) == "min" else max(numbers)  # type: ignore[type-var]
        if not fmt:
            return json.dumps(value)
    if fmt.startswith("deg"):
        # An angle the summary holds in radians, written in degrees (the docs' unit).
        fmt = fmt[3:]
        try:
            value = math.degrees(float(value))  # type: ignore[arg-type]
        except (TypeError, ValueError) as e:
            raise RenderError(f"cannot write {value!r} in degrees: {e}") from None
    elif fmt.startswith("pct"):
        # A fraction written as a percentage, without the sign (a table's column says `%`).
        fmt = fmt[3:]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise RenderError(f"cannot write {value!r} as a percentage")
        value = 100.0 * value
    sci = re.fullmatch(r"sci(\d)", fmt)
    try:
        if sci:
            mantissa, exponent = f"{float(value):.{sci.group(1)}e}".split("e")  # type: ignore[arg-type]
            return f"{mantissa}e{int(exponent)}"
        return format(value, fmt)
    except (TypeError, ValueError) as e:
        raise RenderError(f"cannot write {value!r} as `{fmt}`: {e}") from None


def render(text: str, summaries: dict[str, object], where: str) -> tuple[str, list[str]]:
    """`text` with every marker rendered, and a line per marker whose text changed."""
    changes: list[str] = []

    def one(m: re.Match[str]) -> str:
        path = m.group("path")
        source, _, rest = path.partition(":") if ":" in path else ("full", "", path)
        if source not in summaries:
            raise RenderError(f"{where}: `{path}`: unknown source `{source}` ({', '.join(SOURCES)})")
        try:
            new = write(lookup(summaries[source], rest), m.group("fmt"))
        except RenderError as e:
            line = text.count("\n", 0, m.start()) + 1
            raise RenderError(f"{where}:{line}: {e}") from None
        if new != m.group("text"):
            line = text.count("\n", 0, m.start()) + 1
            changes.append(f"{where}:{line}: {path}: written {m.group('text')!r}, rendered {new!r}")
        head = m.group(0)[: m.start("text") - m.start()]
        return f"{head}{new}<!--/-->"

    return MARKER.sub(one, text), changes


def load(sources: dict[str, Path]) -> dict[str, object]:
    return {name: json.loads(path.read_text(encoding="utf-8")) for name, path in sources.items()}


def import_figures(summary_path: Path, files: list[Path], source: str = "full") -> None:
    """Writes the figures file of `source`: every path of that source the files mark (a
    `full` path has no prefix, a `robustness` one the `robustness:` prefix), from the summary."""
    summary = json.loads(summary_path.read_text(encoding="utf-8"))
    paths = set()
    for path in files:
        for m in MARKER.finditer(path.read_text(encoding="utf-8")):
            marked = m.group("path")
            prefix, _, rest = marked.partition(":") if ":" in marked else ("full", "", marked)
            if prefix == source:
                paths.add(rest)
    figures: dict[str, object] = {
        FIGURES_TAG: f"The numbers the docs quote from `{EXTRACTS[source].split('`')[0]}`, by "
        f"their path in its output. Written by `{EXTRACTS[source]}` (scripts/render-docs.py); "
        "do not edit."
    }
    for path in sorted(paths):
        figures[path] = lookup(summary, path)
    SOURCES[source].write_text(json.dumps(figures, indent=1) + "\n", encoding="utf-8")
    target = SOURCES[source]
    shown = target.relative_to(ROOT) if target.is_relative_to(ROOT) else target
    print(f"wrote {len(paths)} figures from {summary_path} to {shown}")


def default_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def run(files: list[Path], summaries: dict[str, object], check: bool) -> int:
    changed, markers = 0, 0
    for path in files:
        text = path.read_text(encoding="utf-8")
        markers += len(MARKER.findall(text))
        new, changes = render(text, summaries, str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path))
        for line in changes:
            print(line)
        changed += len(changes)
        if changes and not check:
            path.write_text(new, encoding="utf-8")
    if check and changed:
        print(
            f"{changed} of {markers} rendered numbers differ from the committed summaries; "
            "run `python3 scripts/render-docs.py` (see its docstring)",
            file=sys.stderr,
        )
        return 1
    verb = "would change" if check else "changed"
    print(f"{markers} rendered numbers in {len(files)} files; {changed} {verb}")
    return 0


def self_test() -> int:
    summary = {"a": {"b": [1.23456, {"c": "x"}], "180": 2.5, "big": 612345.6, "half_pi": math.pi / 2, "rows": [{"v": 2.0}, {"v": None}, {"v": 0.5}]}, "n": 3,
               "cells": [{"who": "a", "h": 0.0, "ok": True}, {"who": "a", "h": 180.0, "ok": False}, {"who": "b", "h": 90.0, "ok": True}],
               "pairs": [["up", 7], ["down", 2]], "by what": {"a b": 5}, "rate": 0.8434, "rates": [0.5, 0.125]}
    cases = [
        ("<!--= a.b[0] .2f -->?<!--/-->", "<!--= a.b[0] .2f -->1.23<!--/-->"),
        ("<!--= a.b[1].c -->?<!--/-->", "<!--= a.b[1].c -->x<!--/-->"),
        ("<!--= a.180 .1f -->2.5<!--/-->", "<!--= a.180 .1f -->2.5<!--/-->"),
        ("<!--= a.big sci1 -->?<!--/-->", "<!--= a.big sci1 -->6.1e5<!--/-->"),
        ("<!--= a.b[1].c -->?<!--/--> <!--= n d -->?<!--/-->", "<!--= a.b[1].c -->x<!--/--> <!--= n d -->3<!--/-->"),
        ("<!--= a.half_pi deg.1f -->?<!--/-->", "<!--= a.half_pi deg.1f -->90.0<!--/-->"),
        ("<!--= a.rows[*].v min.1f -->?<!--/--> to <!--= a.rows[*].v max.1f -->?<!--/-->", "<!--= a.rows[*].v min.1f -->0.5<!--/--> to <!--= a.rows[*].v max.1f -->2.0<!--/-->"),
        ("<!--= quick:n d -->?<!--/--> and <!--= n -->0<!--/-->", "<!--= quick:n d -->4<!--/--> and <!--= n -->3<!--/-->"),
        ("<!--= cells[h=180].ok -->?<!--/--> <!--= cells[who=b].h .0f -->?<!--/-->", "<!--= cells[h=180].ok -->false<!--/--> <!--= cells[who=b].h .0f -->90<!--/-->"),
        ("<!--= cells[*who=a].ok count -->?<!--/--> of <!--= cells[*who=a].who count -->?<!--/-->", "<!--= cells[*who=a].ok count -->1<!--/--> of <!--= cells[*who=a].who count -->2<!--/-->"),
        ("<!--= cells[who=a,h=180].ok -->?<!--/--> <!--= cells[*who=a,ok=true].h len -->?<!--/-->", "<!--= cells[who=a,h=180].ok -->false<!--/--> <!--= cells[*who=a,ok=true].h len -->1<!--/-->"),
        ("<!--= pairs[0=down].1 d -->?<!--/--> <!--= by%20what.a%20b d -->?<!--/-->", "<!--= pairs[0=down].1 d -->2<!--/--> <!--= by%20what.a%20b d -->5<!--/-->"),
        ("<!--= rate pct.1f -->?<!--/--> <!--= rates[*] maxpct.1f -->?<!--/--> <!--= cells[*] len -->?<!--/-->", "<!--= rate pct.1f -->84.3<!--/--> <!--= rates[*] maxpct.1f -->50.0<!--/--> <!--= cells[*] len -->3<!--/-->"),
    ]
    failures = 0
    for source, expected in cases:
        got, _ = render(source, {"full": summary, "quick": {"n": 4}}, "self-test")
        if got != expected:
            print(f"self-test: {source!r} -> {got!r}, expected {expected!r}", file=sys.stderr)
            failures += 1
    for bad in ["<!--= a.zz -->?<!--/-->", "<!--= a.b[1].c .2f -->?<!--/-->", "<!--= a.b[1].c deg.1f -->?<!--/-->", "<!--= a.b[*] .1f -->?<!--/-->", "<!--= other:n -->?<!--/-->",
                "<!--= cells[who=a].h -->?<!--/-->", "<!--= cells[who=z].h -->?<!--/-->", "<!--= n count -->?<!--/-->",
                "<!--= n len -->?<!--/-->", "<!--= a.b[1].c pct.1f -->?<!--/-->", "<!--= pairs[2=up].1 -->?<!--/-->", "<!--= cells[who=a,=1].h -->?<!--/-->"]:
        try:
            render(bad, {"full": summary, "quick": {}}, "self-test")
            print(f"self-test: {bad!r} rendered, expected an error", file=sys.stderr)
            failures += 1
        except RenderError:
            pass
    with tempfile.TemporaryDirectory() as tmp:
        doc = Path(tmp) / "page.md"
        doc.write_text("x <!--= n d -->2<!--/-->\n", encoding="utf-8")
        if run([doc], {"full": summary, "quick": {}}, check=True) != 1:
            print("self-test: --check passed a stale number", file=sys.stderr)
            failures += 1
        # An import writes the figures of its own source only, by path without the prefix.
        page = Path(tmp) / "rob.md"
        page.write_text("<!--= robustness:a.b[0] .1f -->?<!--/--> <!--= n d -->3<!--/-->\n", encoding="utf-8")
        run_json = Path(tmp) / "robustness.json"
        run_json.write_text(json.dumps(summary), encoding="utf-8")
        saved = SOURCES["robustness"]
        SOURCES["robustness"] = Path(tmp) / "robustness-figures.json"
        try:
            import_figures(run_json, [page], "robustness")
            written = json.loads(SOURCES["robustness"].read_text(encoding="utf-8"))
        finally:
            SOURCES["robustness"] = saved
        if set(written) != {FIGURES_TAG, "a.b[0]"}:
            print(f"self-test: the robustness import wrote {sorted(written)}", file=sys.stderr)
            failures += 1
    total = len(cases) + 14
    print(f"render-docs self-test: {total - failures}/{total} pass")
    return 1 if failures else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--import", dest="summary", type=Path, help="a full run's summary.json")
    parser.add_argument(
        "--import-robustness", dest="robustness", type=Path, help="a full campaign's robustness.json"
    )
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    try:
        files = [p.resolve() for p in args.files] or default_files()
        if args.summary:
            import_figures(args.summary, default_files())
        if args.robustness:
            import_figures(args.robustness, default_files(), "robustness")
        return run(files, load(SOURCES), args.check)
    except RenderError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
