#!/usr/bin/env python3
"""Fails if the modules of a Rust crate import each other in a cycle.

Usage:
    python3 scripts/check-cycles.py [--root DIR]   check the workspace (default: the repository)
    python3 scripts/check-cycles.py --self-test    check the checker on small temporary crates

Exit status 0: no cycle; 1: at least one cycle (each printed as `a.rs -> b.rs -> a.rs`, with
the lines that make each edge); 2: bad usage.

What is checked. Every package under `crates/`, and the top-level `benches/` and `examples/`
packages. Each crate root of a package (`src/lib.rs`, `src/main.rs`, `src/bin/*.rs`,
`benches/*.rs`, `examples/*.rs`, `tests/*.rs`) is its own crate, and its module tree is found
by following `mod name;` declarations (`#[path = "..."]` included), as rustc does.

Granularity. One node per file: a file is a module (`mod.rs` is its folder's module); inline
modules (`mod tests { ... }`) belong to their file. An edge `a.rs -> b.rs` means that code in
`a.rs` names an item of `b.rs` through `use crate::...`, `use super::...`, `use self::...`, or a
`crate::`/`super::`/`self::` path in code. Comments, doc comments and string literals are not
code. A path is resolved to the file that *defines* the name: re-exports (`pub use`, also
globs) are followed, so importing `crate::world::BallbotWorld` is an edge to `world/sim.rs`,
not to `world/mod.rs`. Edges from a module to one of its own descendants are dropped: a parent
may use and re-export its children (`mod.rs` re-exporting its children is an edge parent ->
child only, and the re-export itself is not a node in anyone's path). A child naming an item
defined in an ancestor (e.g. `super::WorldError` defined in `world/mod.rs`) is an edge, and
so is anything between siblings or across the tree. A cycle is a set of files each reachable
from the others; the shortest cycle through each such set is printed.

Limits: a glob import (`use super::*`) is an edge to the module globbed, not to the files its
names come from; macros (`$crate::...`) and paths built inside macro bodies are not followed;
`#[cfg]` is ignored (test modules count: a cycle through a test is still a cycle).

Standard library only (python3 >= 3.8).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

# ---------------------------------------------------------------------------------------------
# Lexing: identifiers, `::`, single punctuation characters and string literals; comments and
# the insides of char literals are dropped.

IDENT_START = re.compile(r"[A-Za-z_]")
IDENT_CHAR = re.compile(r"[A-Za-z0-9_]")


@dataclass
class Token:
    kind: str  # "ident", "punct", "str"
    text: str
    line: int


def lex(src: str) -> list[Token]:
    """Splits Rust source into tokens, dropping comments, whitespace, numbers and chars."""
    tokens: list[Token] = []
    i, n, line = 0, len(src), 1
    while i < n:
        c = src[i]
        if c == "\n":
            line += 1
            i += 1
        elif c.isspace():
            i += 1
        elif src.startswith("//", i):
            j = src.find("\n", i)
            i = n if j < 0 else j
        elif src.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if src.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif src.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    line += src[i] == "\n"
                    i += 1
        elif (m := re.match(r'(b|c)?r(#*)"', src[i:])) is not None:
            end = '"' + m.group(2)
            j = src.find(end, i + m.end())
            j = n if j < 0 else j
            text = src[i + m.end() : j]
            tokens.append(Token("str", text, line))
            line += text.count("\n")
            i = j + len(end)
        elif c == '"' or (c in "bc" and src.startswith('"', i + 1)):
            j = i + (1 if c == '"' else 2)
            start = j
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            text = src[start:j]
            tokens.append(Token("str", text, line))
            line += text.count("\n")
            i = j + 1
        elif c == "'" or (c == "b" and src.startswith("'", i + 1)):
            # A char literal ('x', '\n', '\u{1F600}', b'x') or a lifetime / label ('a).
            j = i + (1 if c == "'" else 2)
            m = re.match(r"(\\u\{[0-9A-Fa-f_]*\}|\\x[0-9A-Fa-f]{2}|\\.|[^\\'\n])'", src[j:])
            if m is not None:
                i = j + m.end()
            else:
                i = j
                while i < n and IDENT_CHAR.match(src[i]):
                    i += 1
        elif IDENT_START.match(c) or (src.startswith("r#", i) and i + 2 < n and IDENT_START.match(src[i + 2])):
            j = i + 2 if src.startswith("r#", i) else i
            k = j
            while k < n and IDENT_CHAR.match(src[k]):
                k += 1
            tokens.append(Token("ident", src[j:k], line))
            i = k
        elif c.isdigit():
            j = i
            while j < n and (IDENT_CHAR.match(src[j]) or (src[j] == "." and j + 1 < n and src[j + 1].isdigit())):
                j += 1
            i = j
        elif src.startswith("::", i):
            tokens.append(Token("punct", "::", line))
            i += 2
        else:
            tokens.append(Token("punct", c, line))
            i += 1
    return tokens


# ---------------------------------------------------------------------------------------------
# Parsing one file: its outline modules, the items it defines, its `use` declarations and the
# `crate::`/`super::`/`self::` paths in its code.

ITEM_KEYWORDS = {"struct", "enum", "fn", "trait", "type", "const", "static", "union"}


@dataclass
class UsePath:
    """One imported path, e.g. `super::problem::Drive` as segments, with what names it."""

    segments: list[str]
    line: int
    inline_depth: int  # how many inline modules of the file enclose it
    public: bool  # `pub use` / `pub(crate) use` at the file's top level: a re-export
    alias: str | None  # the name it is known by here (None for a glob)
    glob: bool


@dataclass
class FileInfo:
    path: Path
    outline_mods: list[tuple[str, str | None]] = field(default_factory=list)  # (name, #[path])
    defines: set[str] = field(default_factory=set)
    uses: list[UsePath] = field(default_factory=list)


def parse_file(path: Path) -> FileInfo:
    info = FileInfo(path)
    toks = lex(path.read_text(encoding="utf-8", errors="replace"))
    n = len(toks)
    depth = 0  # brace depth
    inline_starts: list[int] = []  # brace depths at which inline modules opened
    pending_path: str | None = None
    i = 0

    def is_(k: int, text: str) -> bool:
        return k < n and toks[k].text == text and toks[k].kind != "str"

    while i < n:
        t = toks[i]
        if t.kind == "punct" and t.text == "{":
            depth += 1
            i += 1
            continue
        if t.kind == "punct" and t.text == "}":
            depth -= 1
            if inline_starts and inline_starts[-1] == depth:
                inline_starts.pop()
            i += 1
            continue
        if t.kind == "punct" and t.text == "#" and is_(i + 1, "[") and is_(i + 2, "path") and is_(i + 3, "="):
            if i + 4 < n and toks[i + 4].kind == "str":
                pending_path = toks[i + 4].text
        top = depth == 0 and not inline_starts
        if t.kind == "ident" and t.text == "mod" and i + 1 < n and toks[i + 1].kind == "ident":
            name = toks[i + 1].text
            if is_(i + 2, ";"):
                if top:
                    info.outline_mods.append((name, pending_path))
                pending_path = None
                i += 3
                continue
            if is_(i + 2, "{"):
                inline_starts.append(depth)
                depth += 1
                pending_path = None
                i += 3
                continue
        if t.kind == "ident" and t.text in ITEM_KEYWORDS and top and i + 1 < n and toks[i + 1].kind == "ident":
            info.defines.add(toks[i + 1].text)
        if t.kind == "ident" and t.text == "macro_rules" and is_(i + 1, "!") and i + 2 < n:
            info.defines.add(toks[i + 2].text)
        if t.kind == "ident" and t.text == "use" and (i == 0 or toks[i - 1].text != "::"):
            public = top and _is_pub_before(toks, i)
            j = i + 1
            if is_(j, "::"):
                j += 1
            out: list[tuple[list[str], str | None, bool, int]] = []
            j = _use_tree(toks, j, [], out)
            for segs, alias, glob, line in out:
                info.uses.append(UsePath(segs, line, len(inline_starts), public, alias, glob))
            i = max(j, i + 1)
            continue
        if t.kind == "ident" and t.text in ("crate", "super", "self") and is_(i + 1, "::"):
            if i > 0 and toks[i - 1].text in ("::", "$"):
                i += 1
                continue
            segs = [t.text]
            j = i + 1
            while is_(j, "::") and j + 1 < n and toks[j + 1].kind == "ident":
                segs.append(toks[j + 1].text)
                j += 2
            if len(segs) > 1:
                info.uses.append(UsePath(segs, t.line, len(inline_starts), False, None, False))
            i = j
            continue
        i += 1
    return info


def _is_pub_before(toks: list[Token], i: int) -> bool:
    """Whether the `use` at `i` is preceded by `pub` or `pub(...)`."""
    k = i - 1
    if k >= 0 and toks[k].text == ")":
        while k >= 0 and toks[k].text != "(":
            k -= 1
        k -= 1
    return k >= 0 and toks[k].text == "pub"


def _use_tree(toks: list[Token], j: int, prefix: list[str], out: list) -> int:
    """Parses a use tree from `j`, appending (segments, alias, glob, line); returns the index
    after it (after the `;` at the top level)."""
    n = len(toks)
    segs = list(prefix)
    while j < n:
        t = toks[j]
        if t.kind == "ident" and t.text != "as":
            segs.append(t.text)
            j += 1
            if j < n and toks[j].text == "::":
                j += 1
                continue
            alias = segs[-1]
            if j + 1 < n and toks[j].text == "as":
                alias = toks[j + 1].text
                j += 2
            if segs[-1] == "self":
                segs = segs[:-1]
                alias = segs[-1] if segs and alias == "self" else alias
            out.append((segs, alias, False, t.line))
            break
        if t.text == "*":
            out.append((segs, None, True, t.line))
            j += 1
            break
        if t.text == "{":
            j += 1
            while j < n and toks[j].text != "}":
                if toks[j].text == ",":
                    j += 1
                    continue
                j = _use_tree(toks, j, segs, out)
            j += 1
            break
        break
    if not prefix:
        while j < n and toks[j].text != ";":
            j += 1
        j += 1
    return j


# ---------------------------------------------------------------------------------------------
# Module trees and name resolution.


@dataclass
class Module:
    path: tuple[str, ...]  # ("crate", "world", "sim")
    file: Path
    info: FileInfo
    children: dict[str, "Module"] = field(default_factory=dict)
    parent: "Module | None" = None


def _owns_folder(file: Path, is_root: bool) -> bool:
    return is_root or file.name == "mod.rs"


def build_tree(root_file: Path) -> dict[tuple[str, ...], Module]:
    modules: dict[tuple[str, ...], Module] = {}
    root = Module(("crate",), root_file, parse_file(root_file))
    modules[root.path] = root
    stack = [(root, True)]
    seen = {root_file.resolve()}
    while stack:
        mod, is_root = stack.pop()
        base = mod.file.parent if _owns_folder(mod.file, is_root) else mod.file.parent / mod.file.stem
        for name, explicit in mod.info.outline_mods:
            if explicit is not None:
                candidates = [mod.file.parent / explicit]
            else:
                candidates = [base / f"{name}.rs", base / name / "mod.rs"]
            file = next((c for c in candidates if c.is_file()), None)
            if file is None or file.resolve() in seen:
                continue
            seen.add(file.resolve())
            child = Module(mod.path + (name,), file, parse_file(file), parent=mod)
            mod.children[name] = child
            modules[child.path] = child
            stack.append((child, False))
    return modules


def start_module(mod: Module, use: UsePath) -> tuple[Module | None, list[str]]:
    """The module a path starts from, and its remaining segments."""
    segs = list(use.segments)
    here: Module | None = mod
    # `super` inside an inline module first leaves the inline module (same file).
    inline = use.inline_depth
    if segs and segs[0] == "crate":
        while here is not None and here.parent is not None:
            here = here.parent
        return here, segs[1:]
    if segs and segs[0] == "self":
        return here, segs[1:]
    while segs and segs[0] == "super":
        segs = segs[1:]
        if inline > 0:
            inline -= 1
        else:
            here = here.parent if here is not None else None
    if len(segs) == len(use.segments):
        return None, segs  # an external crate, a local name or a prelude item
    return here, segs


def resolve(mod: Module | None, segs: list[str], modules: dict, depth: int = 0) -> Module | None:
    """The module that defines the item named by `segs` relative to `mod`."""
    if mod is None or depth > 32:
        return mod
    while segs and segs[0] in mod.children:
        mod = mod.children[segs[0]]
        segs = segs[1:]
    if not segs:
        return mod
    name = segs[0]
    if name in mod.info.defines:
        return mod
    for use in mod.info.uses:
        if not use.public or use.inline_depth:
            continue
        if use.alias == name:
            start, rest = start_module(mod, use)
            if start is None:
                start, rest = _child_relative(mod, use.segments)
            if start is not None:
                return resolve(start, rest + segs[1:], modules, depth + 1)
    for use in mod.info.uses:
        if use.public and use.glob and not use.inline_depth:
            start, rest = start_module(mod, use)
            if start is None:
                start, rest = _child_relative(mod, use.segments)
            target = resolve(start, rest, modules, depth + 1) if start is not None else None
            if target is not None and target is not mod:
                found = resolve(target, segs, modules, depth + 1)
                if found is not None and found is not target or name in target.info.defines:
                    return found
    return mod


def _child_relative(mod: Module, segs: list[str]) -> tuple[Module | None, list[str]]:
    """`pub use child::Name` (2018 paths relative to the module's own children)."""
    if segs and segs[0] in mod.children:
        return mod, segs
    return None, segs


def is_ancestor(a: Module, b: Module) -> bool:
    """Whether `a` is `b` or an ancestor of `b`."""
    return b.path[: len(a.path)] == a.path


@dataclass
class Edge:
    target: Path
    line: int
    path: str


def crate_edges(root_file: Path) -> dict[Path, dict[Path, Edge]]:
    modules = build_tree(root_file)
    edges: dict[Path, dict[Path, Edge]] = {m.file: {} for m in modules.values()}
    for mod in modules.values():
        for use in mod.info.uses:
            start, rest = start_module(mod, use)
            if start is None:
                start, rest = _child_relative(mod, use.segments)
            if start is None:
                continue
            target = resolve(start, rest, modules)
            if target is None or is_ancestor(mod, target):
                continue
            edges[mod.file].setdefault(target.file, Edge(target.file, use.line, "::".join(use.segments)))
    return edges


# ---------------------------------------------------------------------------------------------
# Cycles: strongly connected components (Tarjan), then the shortest cycle through each.


def components(graph: dict[Path, dict[Path, Edge]]) -> list[list[Path]]:
    index: dict[Path, int] = {}
    low: dict[Path, int] = {}
    on_stack: set[Path] = set()
    stack: list[Path] = []
    out: list[list[Path]] = []
    counter = [0]

    def visit(v: Path) -> None:
        work = [(v, iter(sorted(graph.get(v, {}))))]
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        while work:
            node, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, {})))))
                    advanced = True
                    break
                if w in on_stack:
                    low[node] = min(low[node], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def shortest_cycle(graph: dict[Path, dict[Path, Edge]], comp: list[Path]) -> list[Path]:
    members = set(comp)
    best: list[Path] = []
    for start in comp:
        prev: dict[Path, Path] = {}
        queue = deque([start])
        found = None
        while queue and found is None:
            v = queue.popleft()
            for w in sorted(graph.get(v, {})):
                if w not in members:
                    continue
                if w == start:
                    found = v
                    break
                if w not in prev:
                    prev[w] = v
                    queue.append(w)
        if found is None:
            continue
        path = [found]
        while path[-1] != start:
            path.append(prev[path[-1]])
        cycle = list(reversed(path)) + [start]
        if not best or len(cycle) < len(best):
            best = cycle
    return best


# ---------------------------------------------------------------------------------------------
# The workspace.


def crate_roots(package: Path) -> list[Path]:
    roots = [package / "src" / "lib.rs", package / "src" / "main.rs"]
    for folder in ("src/bin", "benches", "examples", "tests"):
        d = package / folder
        if d.is_dir():
            roots += sorted(d.glob("*.rs"))
            roots += sorted(p for p in d.glob("*/main.rs"))
    return [r for r in roots if r.is_file()]


def packages(root: Path) -> list[Path]:
    found = sorted(p.parent for p in (root / "crates").glob("*/Cargo.toml"))
    for extra in ("benches", "examples"):
        if (root / extra / "Cargo.toml").is_file():
            found.append(root / extra)
    return found


def check(root: Path, out=sys.stdout) -> int:
    """Prints every cycle under `root`; returns how many there are."""
    count = 0
    roots = [r for p in packages(root) for r in crate_roots(p)]
    for crate_root in roots:
        graph = crate_edges(crate_root)
        for comp in components(graph):
            cycle = shortest_cycle(graph, comp)
            rel = [os.path.relpath(p, root) for p in cycle]
            print(" -> ".join(rel), file=out)
            for a, b in zip(cycle, cycle[1:]):
                e = graph[a][b]
                print(f"    {os.path.relpath(a, root)}:{e.line} names {e.path}", file=out)
            if len(comp) > len(cycle) - 1:
                others = [os.path.relpath(p, root) for p in comp if p not in cycle]
                print(f"    (same cycle set: {', '.join(others)})", file=out)
            count += 1
    return count


# ---------------------------------------------------------------------------------------------
# Self-test.


def _write(root: Path, files: dict[str, str]) -> None:
    (root / "crates" / "demo").mkdir(parents=True, exist_ok=True)
    (root / "crates" / "demo" / "Cargo.toml").write_text('[package]\nname = "demo"\n')
    for rel, text in files.items():
        p = root / "crates" / "demo" / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)


ACYCLIC = {
    "src/lib.rs": "//! use crate::a::A; (a comment)\npub mod a;\npub mod b;\npub mod c;\n"
    "pub use a::A;\npub use c::{D, E};\n",
    # A grouped, aliased import; a string and a char that look like paths.
    "src/a.rs": "use crate::{b::{B as Bee}, c::E};\npub struct A;\n"
    'const S: &str = "crate::c::d::D";\nconst Q: char = \'"\';\nfn f<\'a>(x: &\'a u8) {}\n',
    "src/b.rs": "/* use crate::a::A; */\npub struct B;\n#[cfg(test)]\nmod tests {\n"
    "    use super::*;\n    use super::super::c::D;\n}\n",
    # The parent re-exports its child and defines E, which the child uses.
    "src/c/mod.rs": "mod d;\npub use d::D;\npub struct E;\nfn g() -> D { d::make() }\n",
    "src/c/d.rs": "use super::E;\n/// Doc: [`crate::a::A`].\npub struct D;\npub fn make() -> D { D }\n",
}

CYCLIC = dict(
    ACYCLIC,
    **{
        # d.rs names A through the crate root's re-export: the edge goes to a.rs, and
        # a.rs -> c/d.rs (D through c/mod.rs's re-export) closes the cycle.
        "src/a.rs": "use crate::c::D;\npub struct A;\n",
        "src/c/d.rs": "use super::E;\npub struct D;\npub fn make() -> D { let _ = crate::A; D }\n",
        "src/b.rs": "pub struct B;\n",
    },
)

PATH_CYCLE = {
    "src/lib.rs": "mod x;\n",
    "src/x.rs": "#[cfg(test)]\n#[path = \"x_tests.rs\"]\nmod tests;\npub(crate) fn y() {}\n"
    "mod inner { fn z() { super::super::w::W::default(); } }\n",
    "src/w.rs": "",
    "src/x_tests.rs": "use crate::x::y;\n",
}


def self_test() -> int:
    failures = []

    def run(files: dict[str, str]) -> tuple[int, str]:
        import io

        with tempfile.TemporaryDirectory() as d:
            _write(Path(d), files)
            buf = io.StringIO()
            return check(Path(d), buf), buf.getvalue()

    count, text = run(ACYCLIC)
    if count != 0:
        failures.append(f"acyclic crate reported cycles:\n{text}")
    count, text = run(CYCLIC)
    want = "crates/demo/src/a.rs -> crates/demo/src/c/d.rs -> crates/demo/src/a.rs"
    if count != 1 or want not in text:
        failures.append(f"cyclic crate: expected `{want}`, got {count} cycle(s):\n{text}")
    # A `#[path]` test module naming its parent is a child -> parent edge, not a cycle.
    count, text = run(PATH_CYCLE)
    if count != 0:
        failures.append(f"#[path] child reported as a cycle:\n{text}")
    # Two siblings that name each other through `super::` are a cycle.
    sibling = {
        "src/lib.rs": "mod p;\n",
        "src/p/mod.rs": "mod q;\nmod r;\n",
        "src/p/q.rs": "use super::r::R;\npub struct Q;\n",
        "src/p/r.rs": "pub struct R(super::q::Q);\n",
    }
    count, text = run(sibling)
    if count != 1 or "src/p/q.rs -> crates/demo/src/p/r.rs -> crates/demo/src/p/q.rs" not in text:
        failures.append(f"sibling cycle not found:\n{text}")
    # Tokens.
    toks = [t.text for t in lex("r#\"crate::x\"# 'a' b'\\'' crate::y // crate::z\n")]
    if toks != ["crate::x", "crate", "::", "y"]:
        failures.append(f"lexer: {toks}")
    for f in failures:
        print("self-test FAILED:", f, file=sys.stderr)
    if not failures:
        print("check-cycles self-test: ok (4 crates, lexer)")
    return 1 if failures else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--self-test", action="store_true", help="test the checker itself")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    count = check(args.root.resolve())
    if count:
        print(f"{count} import cycle(s)", file=sys.stderr)
        return 1
    print("no import cycles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
