//! Scanning one file: its public items, their doc examples, its `mod`s and re-exports.

use std::collections::{BTreeMap, BTreeSet};

use super::lex::{code_view, is_ident_char};

/// The block a `{` opens.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Block {
    /// An inline `mod x { .. }`: public or not, and whether it is `#[cfg(test)]`.
    Module { public: bool, test: bool },
    /// `impl Type { .. }` (`Some(type name)`) or `impl Trait for Type { .. }` (`None`).
    Impl(Option<String>),
    /// A trait definition, a function body, a struct/enum body, an expression.
    Other,
}

/// A `pub` item found in a file.
#[derive(Clone, Debug)]
pub(super) struct Item {
    /// 1-based line of the item's first non-attribute token.
    pub(super) line: usize,
    pub(super) kind: String,
    pub(super) name: String,
    /// The type of the inherent impl block it sits in, if any.
    pub(super) owner: Option<String>,
    pub(super) has_example: bool,
}

/// A `mod name;` declaration.
#[derive(Clone, Debug)]
pub(super) struct ModDecl {
    pub(super) name: String,
    pub(super) public: bool,
    pub(super) test: bool,
}

#[derive(Default, Debug)]
pub(super) struct Scan {
    pub(super) items: Vec<Item>,
    pub(super) mods: Vec<ModDecl>,
    /// `pub use first::...` statements: first path segment -> every identifier they name.
    pub(super) reexports: BTreeMap<String, BTreeSet<String>>,
}

/// Whether a fence's info string marks code that rustdoc compiles (and normally runs).
pub(super) fn runnable_fence(info: &str) -> bool {
    info.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .all(|t| matches!(t, "rust" | "no_run" | "should_panic") || t.starts_with("edition"))
}

/// Whether doc lines (without their `///`) contain a runnable fenced example with at least one
/// line rustdoc shows (a block of hidden `# ` lines only shows nothing).
pub(super) fn has_runnable_example(doc: &[String]) -> bool {
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
pub(super) fn split_visibility(header: &str) -> (Option<bool>, &str) {
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

pub(super) fn first_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    let end = s.find(|c: char| !is_ident_char(c)).unwrap_or(s.len());
    (&s[..end], &s[end..])
}

/// Drops a leading balanced `<...>` (generic parameters).
pub(super) fn skip_generics(s: &str) -> &str {
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
pub(super) fn impl_self_type(after_impl: &str) -> Option<String> {
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
pub(super) fn classify_item(header: &str) -> Option<(Option<bool>, String, String)> {
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

pub(super) fn has_cfg(attrs: &str, what: &str) -> bool {
    let squeezed: String = attrs.chars().filter(|c| !c.is_whitespace()).collect();
    squeezed.contains(&format!("#[cfg({what})]"))
}

/// Collects every identifier of a `use` tree except keywords: `a::{B, c::D as E}` -> a, B, c,
/// D, E (over-inclusion is harmless: the names only decide which items are public).
pub(super) fn use_names(tree: &str) -> (String, BTreeSet<String>) {
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

pub(super) fn scan(source: &str) -> Scan {
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
