//! Issue 8: every public item of the core carries a runnable doc example.
//!
//! The test scans `src/**/*.rs` as text (no nightly rustdoc JSON needed) and requires, in the
//! doc comment of every public `fn`, `const fn`, `struct`, `enum`, `trait`, `type`, `const`,
//! `static` and `union` (inherent methods included), a fenced code block that rustdoc runs or at
//! least compiles: ```` ``` ````, ```` ```rust ````, ```` ```no_run ```` or
//! ```` ```should_panic ```` (not ```` ```text ````, ```` ```ignore ````, ```` ```compile_fail ````
//! or another language) with at least one line rustdoc shows (not only hidden `# ` lines).
//!
//! Skipped: `pub(crate)`/`pub(super)`/`pub(in ..)` items, trait-impl methods (they have no
//! `pub`), items of trait definitions, struct fields, enum variants, items inside function
//! bodies, `#[cfg(test)]`/`#[cfg(doctest)]` items and modules, and the items of a private module
//! that its parent does not re-export (`pub use`).
//!
//! Every source file of the core (but `#[cfg(test)]` modules) must be listed in [`CHECKED`], so
//! a new file cannot escape the check. A failure names each item without an example as
//! `crates/ballbot-core/src/FILE:LINE: pub KIND NAME`.

// Test code: a malformed source tree is a test failure.
#![allow(clippy::unwrap_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Files (relative to `crates/ballbot-core/src`) whose public items must all have examples.
const CHECKED: &[&str] = &[
    // One file a line, so that additions merge trivially.
    "check.rs",
    "integrate.rs",
    "lib.rs",
    "lqr/mod.rs",
    "error.rs",
    "params/mod.rs",
    "params/actuator.rs",
    "params/drivetrain.rs",
    "params/robot.rs",
    "params/spin.rs",
    "params/wip.rs",
    "spin.rs",
    "wip/mod.rs",
    "wip/dynamics.rs",
    "wip/energy.rs",
    "wip/linearization.rs",
    "hal.rs",
    "linalg.rs",
    "kinematics/mod.rs",
    "kinematics/maps.rs",
    "kinematics/planar.rs",
    "kinematics/saturation.rs",
    "kinematics/contact.rs",
    "kinematics/limits.rs",
    "lqr/design.rs",
    "lqr/riccati/mod.rs",
    "lqr/riccati/solve.rs",
    "control/mod.rs",
    "control/feedforward.rs",
    "control/lqr.rs",
    "control/lqr_pi.rs",
    "control/motor_pi.rs",
    "control/pi_pd.rs",
    "control/terms.rs",
    "safety/mod.rs",
    "safety/fault.rs",
    "safety/mode.rs",
    "safety/params.rs",
    "safety/supervisor.rs",
    "estimation.rs",
    "command/mod.rs",
    "command/jerk.rs",
    "command/lean.rs",
    "command/shaper.rs",
    "command/trajectory.rs",
    "num.rs",
    "names.rs",
    "rates.rs",
    "ballbot/mod.rs",
    "ballbot/design.rs",
    "ballbot/feedforward.rs",
    "ballbot/motor.rs",
    "ballbot/outer.rs",
    "ballbot/spin.rs",
];

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

// ---------------------------------------------------------------------------------------------
// Lexing: a copy of the source with comments and the contents of string and char literals
// blanked (newlines kept), so braces and keywords can be counted without being fooled.
// ---------------------------------------------------------------------------------------------

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Appends `c` blanked: newlines stay, everything else becomes a space.
fn blank(out: &mut String, c: char) {
    out.push(if c == '\n' { '\n' } else { ' ' });
}

fn code_view(source: &str) -> String {
    let b: Vec<char> = source.chars().collect();
    let n = b.len();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < n {
        let c = b[i];
        let next = b.get(i + 1).copied();
        let prev = if i > 0 { Some(b[i - 1]) } else { None };
        if c == '/' && next == Some('/') {
            while i < n && b[i] != '\n' {
                blank(&mut out, b[i]);
                i += 1;
            }
            continue;
        }
        if c == '/' && next == Some('*') {
            let mut depth = 0usize;
            while i < n {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    blank(&mut out, b[i]);
                    blank(&mut out, b[i + 1]);
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    blank(&mut out, b[i]);
                    blank(&mut out, b[i + 1]);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, b[i]);
                    i += 1;
                }
            }
            continue;
        }
        // Raw strings r"..", r#".."#, br"..": the `r` must start a token (or follow a `b` that
        // does); `r#ident` (a raw identifier) has no quote after the hashes.
        let starts_token = |k: usize| k == 0 || !is_ident_char(b[k - 1]);
        if c == 'r'
            && (starts_token(i) || (prev == Some('b') && starts_token(i - 1)))
            && matches!(next, Some('"') | Some('#'))
        {
            let mut j = i + 1;
            while j < n && b[j] == '#' {
                j += 1;
            }
            if j < n && b[j] == '"' {
                let hashes = j - i - 1;
                for &ch in &b[i..=j] {
                    out.push(ch);
                }
                i = j + 1;
                while i < n {
                    if b[i] == '"'
                        && b[i + 1..]
                            .iter()
                            .take(hashes)
                            .filter(|&&h| h == '#')
                            .count()
                            == hashes
                    {
                        for &ch in &b[i..=i + hashes] {
                            out.push(ch);
                        }
                        i += hashes + 1;
                        break;
                    }
                    blank(&mut out, b[i]);
                    i += 1;
                }
                continue;
            }
        }
        if c == '"' {
            out.push('"');
            i += 1;
            while i < n {
                if b[i] == '\\' && i + 1 < n {
                    blank(&mut out, b[i]);
                    blank(&mut out, b[i + 1]);
                    i += 2;
                } else if b[i] == '"' {
                    out.push('"');
                    i += 1;
                    break;
                } else {
                    blank(&mut out, b[i]);
                    i += 1;
                }
            }
            continue;
        }
        if c == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                out.push('\'');
                i += 1;
                while i < n {
                    if b[i] == '\\' && i + 1 < n {
                        blank(&mut out, b[i]);
                        blank(&mut out, b[i + 1]);
                        i += 2;
                    } else if b[i] == '\'' {
                        out.push('\'');
                        i += 1;
                        break;
                    } else {
                        blank(&mut out, b[i]);
                        i += 1;
                    }
                }
                continue;
            }
            if b.get(i + 2) == Some(&'\'') {
                out.push('\'');
                blank(&mut out, b[i + 1]);
                out.push('\'');
                i += 3;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Scanning one file.
// ---------------------------------------------------------------------------------------------

/// The block a `{` opens.
#[derive(Clone, Debug, PartialEq)]
enum Block {
    /// An inline `mod x { .. }`: public or not, and whether it is `#[cfg(test)]`.
    Module { public: bool, test: bool },
    /// `impl Type { .. }` (`Some(type name)`) or `impl Trait for Type { .. }` (`None`).
    Impl(Option<String>),
    /// A trait definition, a function body, a struct/enum body, an expression.
    Other,
}

/// A `pub` item found in a file.
#[derive(Clone, Debug)]
struct Item {
    /// 1-based line of the item's first non-attribute token.
    line: usize,
    kind: String,
    name: String,
    /// The type of the inherent impl block it sits in, if any.
    owner: Option<String>,
    has_example: bool,
}

/// A `mod name;` declaration.
#[derive(Clone, Debug)]
struct ModDecl {
    name: String,
    public: bool,
    test: bool,
}

#[derive(Default, Debug)]
struct Scan {
    items: Vec<Item>,
    mods: Vec<ModDecl>,
    /// `pub use first::...` statements: first path segment -> every identifier they name.
    reexports: BTreeMap<String, BTreeSet<String>>,
}

/// Whether a fence's info string marks code that rustdoc compiles (and normally runs).
fn runnable_fence(info: &str) -> bool {
    info.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .all(|t| matches!(t, "rust" | "no_run" | "should_panic") || t.starts_with("edition"))
}

/// Whether doc lines (without their `///`) contain a runnable fenced example with at least one
/// line rustdoc shows (a block of hidden `# ` lines only shows nothing).
fn has_runnable_example(doc: &[String]) -> bool {
    // (fence length, runnable, a visible code line seen)
    let mut open: Option<(usize, bool, bool)> = None;
    for line in doc {
        let t = line.trim();
        let ticks = t.chars().take_while(|&c| c == '`').count();
        match open {
            None if ticks >= 3 => open = Some((ticks, runnable_fence(&t[ticks..]), false)),
            None => {}
            Some((k, runnable, visible)) if ticks >= k && t[ticks..].trim().is_empty() => {
                if runnable && visible {
                    return true;
                }
                open = None;
            }
            Some((_, _, ref mut visible)) => {
                *visible |= !(t.is_empty() || t == "#" || t.starts_with("# "));
            }
        }
    }
    false
}

/// Splits `pub`, `pub(crate)`.. off a header: (is plain `pub`, rest).
fn split_visibility(header: &str) -> (Option<bool>, &str) {
    let h = header.trim_start();
    let Some(rest) = h.strip_prefix("pub") else {
        return (None, h);
    };
    if rest.starts_with(|c: char| is_ident_char(c)) {
        return (None, h);
    }
    let rest = rest.trim_start();
    if let Some(inner) = rest.strip_prefix('(') {
        let close = inner.find(')').map_or(inner.len(), |k| k + 1);
        return (Some(false), inner[close.min(inner.len())..].trim_start());
    }
    (Some(true), rest)
}

fn first_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    let end = s.find(|c: char| !is_ident_char(c)).unwrap_or(s.len());
    (&s[..end], &s[end..])
}

/// Drops a leading balanced `<...>` (generic parameters).
fn skip_generics(s: &str) -> &str {
    let s = s.trim_start();
    if !s.starts_with('<') {
        return s;
    }
    let mut depth = 0i32;
    for (k, c) in s.char_indices() {
        match c {
            '<' => depth += 1,
            '>' => {
                depth -= 1;
                if depth == 0 {
                    return &s[k + 1..];
                }
            }
            _ => {}
        }
    }
    ""
}

/// The self type of an `impl` header, or `None` for a trait impl.
fn impl_self_type(after_impl: &str) -> Option<String> {
    let normalized = after_impl.split_whitespace().collect::<Vec<_>>().join(" ");
    let s = skip_generics(&normalized);
    let s = s.split(" where ").next().unwrap_or(s);
    let padded = format!(" {} ", s.replace(['<', '>', ',', '(', ')'], " "));
    if padded.contains(" for ") {
        return None;
    }
    // The last path segment before any generic arguments: `crate::a::Wip<T>` -> `Wip`.
    let path = s.trim_start().split('<').next().unwrap_or("").trim();
    let last = path.rsplit("::").next().unwrap_or(path);
    let (name, _) = first_word(last);
    Some(name.to_string())
}

/// An item header (attributes removed) classified: (is plain `pub`, kind, name).
fn classify_item(header: &str) -> Option<(Option<bool>, String, String)> {
    let (vis, mut rest) = split_visibility(header);
    let mut quals = Vec::new();
    loop {
        let (w, r) = first_word(rest);
        match w {
            "unsafe" | "async" | "default" => {
                quals.push(w);
                rest = r;
            }
            "extern" => {
                quals.push(w);
                rest = r.trim_start();
                if let Some(r2) = rest.strip_prefix('"') {
                    rest = r2.find('"').map_or("", |k| &r2[k + 1..]);
                }
            }
            "const" => {
                let (w2, _) = first_word(r);
                if w2 == "fn" || w2 == "unsafe" || w2 == "async" || w2 == "extern" {
                    quals.push(w);
                    rest = r;
                } else {
                    break;
                }
            }
            _ => break,
        }
    }
    let (kw, r) = first_word(rest);
    let kind = match kw {
        "fn" | "struct" | "enum" | "trait" | "type" | "const" | "static" | "union" | "mod"
        | "use" | "impl" => kw,
        _ => return None,
    };
    let (name, _) = if kind == "static" {
        let r = r.trim_start();
        first_word(r.strip_prefix("mut ").unwrap_or(r))
    } else {
        first_word(r)
    };
    let mut kind_text = quals.join(" ");
    if !kind_text.is_empty() {
        kind_text.push(' ');
    }
    kind_text.push_str(kind);
    Some((vis, kind_text, name.to_string()))
}

fn has_cfg(attrs: &str, what: &str) -> bool {
    let squeezed: String = attrs.chars().filter(|c| !c.is_whitespace()).collect();
    squeezed.contains(&format!("#[cfg({what})]"))
}

/// Collects every identifier of a `use` tree except keywords: `a::{B, c::D as E}` -> a, B, c,
/// D, E (over-inclusion is harmless: the names only decide which items are public).
fn use_names(tree: &str) -> (String, BTreeSet<String>) {
    let mut words: Vec<&str> = tree
        .split(|c: char| !is_ident_char(c))
        .filter(|w| !w.is_empty())
        .collect();
    if words.first() == Some(&"self") {
        words.remove(0);
    }
    let first = words.first().map_or(String::new(), |w| (*w).to_string());
    let names = words
        .into_iter()
        .skip(1)
        .filter(|w| !matches!(*w, "as" | "self" | "crate" | "super"))
        .map(str::to_string)
        .collect();
    (first, names)
}

fn scan(source: &str) -> Scan {
    let raw_lines: Vec<&str> = source.lines().collect();
    let code = code_view(source);
    let chars: Vec<char> = code.chars().collect();
    let mut line_of = Vec::with_capacity(chars.len());
    let mut line = 0usize;
    for &c in &chars {
        line_of.push(line);
        if c == '\n' {
            line += 1;
        }
    }
    let mut attr_line = vec![false; raw_lines.len() + 1];

    let mut scan = Scan::default();
    let mut stack: Vec<Block> = Vec::new();
    let mut header = String::new();
    let mut attrs = String::new();
    let mut header_line: Option<usize> = None;
    let mut paren = 0i32;
    let mut use_brace = 0i32;

    // Doc comment lines directly above 0-based line `l` (attributes, blank lines and plain
    // comments may sit between).
    let doc_above = |l: usize, attr_line: &[bool]| -> Vec<String> {
        let mut doc = Vec::new();
        let mut j = l;
        while j > 0 {
            j -= 1;
            let t = raw_lines[j].trim_start();
            if let Some(d) = t.strip_prefix("///") {
                if d.starts_with('/') {
                    continue;
                }
                doc.push(d.strip_prefix(' ').unwrap_or(d).to_string());
            } else if attr_line[j] || t.is_empty() || (t.starts_with("//") && !t.starts_with("//!"))
            {
                continue;
            } else {
                break;
            }
        }
        doc.reverse();
        doc
    };

    // Whether a `pub` item in the current block stack can be public API, and its owner type.
    let placement = |stack: &[Block]| -> Option<Option<String>> {
        let mut owner = None;
        for (k, b) in stack.iter().enumerate() {
            match b {
                Block::Module {
                    public: true,
                    test: false,
                } => {}
                Block::Impl(Some(t)) if k + 1 == stack.len() => owner = Some(t.clone()),
                _ => return None,
            }
        }
        Some(owner)
    };

    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        // Outer attributes before an item: `#[..]` (inner `#![..]` too), possibly multi-line.
        if c == '#' && header.is_empty() {
            let mut j = i + 1;
            if chars.get(j) == Some(&'!') {
                j += 1;
            }
            if chars.get(j) == Some(&'[') {
                let mut depth = 0i32;
                let start = i;
                while j < chars.len() {
                    match chars[j] {
                        '[' => depth += 1,
                        ']' => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        _ => {}
                    }
                    j += 1;
                }
                let end = j.min(chars.len() - 1);
                attr_line[line_of[start]..=line_of[end]].fill(true);
                attrs.extend(&chars[start..=end]);
                i = end + 1;
                continue;
            }
        }
        let in_use = matches!(c, '{' | '}') && paren <= 0 && {
            let (_, rest) = split_visibility(&header);
            first_word(rest).0 == "use"
        };
        match c {
            '(' | '[' => {
                paren += 1;
                header.push(c);
            }
            ')' | ']' => {
                paren -= 1;
                header.push(c);
            }
            // A struct literal or closure inside parentheses or brackets: part of the header.
            '{' | '}' if paren > 0 => header.push(c),
            '{' if in_use => {
                use_brace += 1;
                header.push(c);
            }
            '}' if in_use && use_brace > 0 => {
                use_brace -= 1;
                header.push(c);
            }
            '{' | ';' if paren <= 0 => {
                let l = header_line.unwrap_or(line_of[i]);
                let item = classify_item(&header);
                let test = has_cfg(&attrs, "test") || has_cfg(&attrs, "doctest");
                let mut block = Block::Other;
                if let Some((vis, kind, name)) = &item {
                    let public = *vis == Some(true);
                    match kind.as_str() {
                        "mod" if c == ';' => scan.mods.push(ModDecl {
                            name: name.clone(),
                            public,
                            test,
                        }),
                        "mod" => block = Block::Module { public, test },
                        "impl" => {
                            let (_, rest) = split_visibility(&header);
                            let after = first_word(rest).1;
                            block = Block::Impl(impl_self_type(after));
                        }
                        "use" => {
                            if public && !test {
                                let (_, rest) = split_visibility(&header);
                                let (first, names) = use_names(first_word(rest).1);
                                scan.reexports.entry(first).or_default().extend(names);
                            }
                        }
                        _ => {
                            if let (true, false, Some(owner)) = (public, test, placement(&stack)) {
                                let doc = doc_above(l, &attr_line);
                                scan.items.push(Item {
                                    line: l + 1,
                                    kind: kind.clone(),
                                    name: name.clone(),
                                    owner,
                                    has_example: has_runnable_example(&doc),
                                });
                            }
                        }
                    }
                }
                if c == '{' {
                    stack.push(block);
                }
                header.clear();
                attrs.clear();
                header_line = None;
                paren = 0;
                use_brace = 0;
            }
            '}' => {
                stack.pop();
                header.clear();
                attrs.clear();
                header_line = None;
                paren = 0;
            }
            _ if c.is_whitespace() => {
                // Collapsed, so blanked doc comments do not make headers long.
                if !header.is_empty() && !header.ends_with(' ') {
                    header.push(' ');
                }
            }
            _ => {
                if header_line.is_none() {
                    header_line = Some(line_of[i]);
                }
                header.push(c);
            }
        }
        i += 1;
    }
    scan
}

// ---------------------------------------------------------------------------------------------
// The crate: module tree, visibility, missing examples.
// ---------------------------------------------------------------------------------------------

/// How much of a file is public API.
#[derive(Clone, Debug)]
enum Exposure {
    /// Reached through `pub mod`s only: all its `pub` items.
    Public,
    /// A private module: only the names its parent re-exports.
    Reexported(BTreeSet<String>),
    /// `#[cfg(test)]`: nothing.
    Test,
}

struct CrateScan {
    /// Path relative to `src` (with `/`) -> (exposure, scan).
    files: BTreeMap<String, (Exposure, Scan)>,
}

fn rel(path: &Path) -> String {
    path.strip_prefix(src_dir())
        .unwrap_or(path)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

fn scan_crate() -> CrateScan {
    let mut files = BTreeMap::new();
    let mut queue = vec![(src_dir().join("lib.rs"), Exposure::Public)];
    while let Some((path, exposure)) = queue.pop() {
        let source = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))
            .unwrap();
        let scan = scan(&source);
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let dir = if stem == "lib" || stem == "mod" {
            path.parent().unwrap().to_path_buf()
        } else {
            path.parent().unwrap().join(&stem)
        };
        for m in &scan.mods {
            let file = dir.join(format!("{}.rs", m.name));
            let child = if file.exists() {
                file
            } else {
                dir.join(&m.name).join("mod.rs")
            };
            let child_exposure = match (&exposure, m.test, m.public) {
                (Exposure::Test, _, _) | (_, true, _) => Exposure::Test,
                (Exposure::Public, false, true) => Exposure::Public,
                (Exposure::Reexported(names), false, true) => Exposure::Reexported(names.clone()),
                (_, false, false) => {
                    Exposure::Reexported(scan.reexports.get(&m.name).cloned().unwrap_or_default())
                }
            };
            queue.push((child, child_exposure));
        }
        files.insert(rel(&path), (exposure, scan));
    }
    CrateScan { files }
}

impl CrateScan {
    /// Public items of every file, with the types whose inherent methods are public.
    fn public_items(&self) -> BTreeMap<String, Vec<Item>> {
        let top_level_public = |exposure: &Exposure, item: &Item| match exposure {
            Exposure::Public => true,
            Exposure::Reexported(names) => names.contains(&item.name),
            Exposure::Test => false,
        };
        let public_types: BTreeSet<String> = self
            .files
            .values()
            .flat_map(|(exposure, scan)| {
                scan.items
                    .iter()
                    .filter(move |it| it.owner.is_none() && top_level_public(exposure, it))
                    .map(|it| it.name.clone())
            })
            .collect();
        self.files
            .iter()
            .map(|(file, (exposure, scan))| {
                let items = scan
                    .items
                    .iter()
                    .filter(|it| match &it.owner {
                        None => top_level_public(exposure, it),
                        Some(owner) => {
                            !matches!(exposure, Exposure::Test) && public_types.contains(owner)
                        }
                    })
                    .cloned()
                    .collect();
                (file.clone(), items)
            })
            .collect()
    }
}

fn describe(file: &str, item: &Item) -> String {
    let name = match &item.owner {
        Some(owner) => format!("{owner}::{}", item.name),
        None => item.name.clone(),
    };
    format!(
        "crates/ballbot-core/src/{file}:{}: pub {} {name}",
        item.line, item.kind
    )
}

#[test]
fn every_public_item_of_a_checked_file_has_a_runnable_example() {
    let krate = scan_crate();
    let items = krate.public_items();
    let mut missing = String::new();
    let mut covered = 0usize;
    for file in CHECKED {
        let Some(list) = items.get(*file) else {
            writeln!(missing, "  {file}: in CHECKED but not a module of the core").unwrap();
            continue;
        };
        for item in list {
            if item.has_example {
                covered += 1;
            } else {
                writeln!(missing, "  {}", describe(file, item)).unwrap();
            }
        }
    }
    assert!(
        missing.is_empty(),
        "public items without a runnable ``` example in their doc comment \
         ({covered} others have one):\n{missing}"
    );
}

#[test]
fn every_core_file_is_checked() {
    let krate = scan_crate();
    let mut problems = String::new();
    for (file, (exposure, _)) in &krate.files {
        if !CHECKED.contains(&file.as_str()) && !matches!(exposure, Exposure::Test) {
            writeln!(
                problems,
                "  {file}: give its public items runnable examples and add it to CHECKED \
                 (tests/doc_examples.rs)"
            )
            .unwrap();
        }
    }
    for file in CHECKED {
        if !krate.files.contains_key(*file) {
            writeln!(problems, "  {file}: listed but not a module of the core").unwrap();
        }
    }
    assert!(
        problems.is_empty(),
        "issue 8: CHECKED is out of date:\n{problems}"
    );
}

/// The scanner's rules on a fixture: what counts as public, what counts as an example.
#[test]
fn scanner_finds_public_items_and_their_examples() {
    let fixture = r####"
//! Crate doc.
//! ```
//! pub fn in_module_doc() {}
//! ```

/// Documented.
///
/// ```
/// assert!(true);
/// ```
#[inline]
#[cfg_attr(
    feature = "x",
    derive(Debug)
)]
pub fn good() {}

/// Only text.
///
/// ```text
/// pub fn not_code() {}
/// ```
pub const fn text_only() -> u8 { b'{' }

/// Ignored.
/// ```ignore
/// x
/// ```
pub const LIMIT: f64 = 1.0;

/// ```rust,no_run
/// let s = "{ not a brace";
/// ```
pub struct Wrapper<T>(pub [T; 3]);

pub(crate) fn internal() {}
pub(super) struct Hidden;

/// No example.
pub enum Mode { A, B }

impl<T: Copy> Wrapper<T> {
    /// ```
    /// let _ = 1;
    /// ```
    pub fn method(&self) -> &'static str { let _ = (P { x: 1 }, [P { x: 2 }]); "}" }

    /// Missing.
    pub const fn bare(&self) -> char { '}' }

    fn private(&self) {}
}

impl<T> core::fmt::Debug for Wrapper<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result { Ok(()) }
}

pub trait Shape {
    /// Trait items are not checked.
    fn area(&self) -> f64;
}

pub type Alias = Wrapper<f64>;

pub fn body() {
    pub fn nested() {}
}

#[cfg(doctest)]
pub struct Doctests;

pub mod inner {
    /* block { comment */
    pub static COUNT: u32 = 0;
}

mod private_inline {
    pub fn unreachable() {}
}

pub use self::inner::{COUNT as Total, Other};

#[cfg(test)]
mod tests {
    pub fn helper() {}
}

#[cfg(test)]
mod more_tests;
mod private_file;

/// ```
/// # let hidden_only = 1;
/// ```
pub fn hidden_example() {}

/// ```
/// #[derive(Debug)]
/// struct Shown;
/// ```
pub struct ShownAttribute;
"####;
    let scan = scan(fixture);
    let found: Vec<(String, String, bool, usize)> = scan
        .items
        .iter()
        .map(|it| {
            let name = match &it.owner {
                Some(o) => format!("{o}::{}", it.name),
                None => it.name.clone(),
            };
            (it.kind.clone(), name, it.has_example, it.line)
        })
        .collect();
    let expected: Vec<(String, String, bool, usize)> = [
        ("fn", "good", true, 17),
        ("const fn", "text_only", false, 24),
        ("const", "LIMIT", false, 30),
        ("struct", "Wrapper", true, 35),
        ("enum", "Mode", false, 41),
        ("fn", "Wrapper::method", true, 47),
        ("const fn", "Wrapper::bare", false, 50),
        ("trait", "Shape", false, 59),
        ("type", "Alias", false, 64),
        ("fn", "body", false, 66),
        ("static", "COUNT", false, 75),
        ("fn", "hidden_example", false, 96),
        ("struct", "ShownAttribute", true, 102),
    ]
    .into_iter()
    .map(|(k, n, e, l)| (k.to_string(), n.to_string(), e, l))
    .collect();
    assert_eq!(found, expected);
    let mods: Vec<(&str, bool, bool)> = scan
        .mods
        .iter()
        .map(|m| (m.name.as_str(), m.public, m.test))
        .collect();
    assert_eq!(
        mods,
        [("more_tests", false, true), ("private_file", false, false)]
    );
    let reexported: Vec<&str> = scan.reexports["inner"].iter().map(String::as_str).collect();
    assert_eq!(reexported, ["COUNT", "Other", "Total"]);
}

/// The check sees the core's real layout: private modules count through their re-exports,
/// `#[cfg(test)] mod tests;` files not at all.
#[test]
fn scanner_reads_the_core_module_tree() {
    let krate = scan_crate();
    let items = krate.public_items();
    let names = |file: &str| -> BTreeSet<String> {
        items[file]
            .iter()
            .map(|it| match &it.owner {
                Some(o) => format!("{o}::{}", it.name),
                None => it.name.clone(),
            })
            .collect()
    };
    assert!(matches!(
        krate.files["kinematics/tests.rs"].0,
        Exposure::Test
    ));
    assert!(matches!(
        krate.files["lqr/design.rs"].0,
        Exposure::Reexported(_)
    ));
    assert!(names("lqr/design.rs").contains("wip_lqr"));
    assert!(names("lqr/riccati/solve.rs").contains("solve_dare"));
    assert!(names("command/shaper.rs").contains("CommandShaper::step"));
    assert!(names("wip/mod.rs").contains("Wip::new"));
    assert!(names("wip/dynamics.rs").contains("Wip::derivative"));
    assert!(names("error.rs").contains("Error"));
    assert!(names("check.rs").is_empty());
    let total: usize = items.values().map(Vec::len).sum();
    assert!(total > 250, "only {total} public items found in the core");
}
