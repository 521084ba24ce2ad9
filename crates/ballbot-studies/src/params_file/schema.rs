//! JSON Schemas of the parameter files, generated from the Rust types (schemars), so that they
//! cannot drift from them. Draft-07: the newest draft that Taplo (Even Better TOML) reads.
//!
//! The descriptions are the fields' doc comments, cleaned of what only rustdoc reads (code
//! examples, intra-doc link brackets); the bounds are the ones `validate()` enforces, written
//! on the fields (`#[schemars(range(min = 0))]`, `exclusiveMinimum`).

use super::FileKind;
use crate::studies::scenario::Scenario;
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_world::world::WorldParams;
use schemars::generate::SchemaSettings;
use serde_json::Value;

/// The command that regenerates the committed schemas.
pub(super) const REGENERATE: &str =
    "cargo run -p ballbot-cli --bin ballbot -- params schema --out schemas";

/// The JSON Schema of a file of `kind`.
///
/// ```
/// use ballbot_studies::params_file::{FileKind, schema_json};
/// let schema = schema_json(FileKind::Robot);
/// let mass = &schema["definitions"]["WipParams"]["properties"]["ball_mass_kg"];
/// assert_eq!(mass["exclusiveMinimum"], 0);
/// assert_eq!(mass["description"], "Ball mass `m_S` (kg).");
/// ```
pub fn schema_json(kind: FileKind) -> Value {
    let generator = SchemaSettings::draft07().into_generator();
    let schema = match kind {
        FileKind::Robot => generator.into_root_schema_for::<BallbotParams<f64>>(),
        FileKind::Scenario => generator.into_root_schema_for::<Scenario>(),
        FileKind::World => generator.into_root_schema_for::<WorldParams>(),
        FileKind::Controller => generator.into_root_schema_for::<BallbotControllerConfig<f64>>(),
    };
    let mut value = schema.to_value();
    clean_docs(&mut value);
    if let Value::Object(root) = &mut value {
        root.insert(
            "$comment".to_owned(),
            Value::String(format!(
                "The {} file ({}). Generated from the Rust types by `{REGENERATE}`; do not \
                 edit. `ballbot params check FILE` checks a file against the types.",
                kind.as_str(),
                kind.type_name()
            )),
        );
    }
    value
}

/// [`schema_json`] as the text of its file in `schemas/` (pretty, with a final newline).
pub fn schema_text(kind: FileKind) -> String {
    let text = serde_json::to_string_pretty(&schema_json(kind))
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
    format!("{text}\n")
}

/// Cleans every `title` and `description` below `value` ([`clean_doc`]); the names of
/// properties (which could be called `description`) are left alone.
fn clean_docs(value: &mut Value) {
    match value {
        Value::Object(map) => {
            for (key, child) in map.iter_mut() {
                match child {
                    Value::String(text) if key == "title" || key == "description" => {
                        *text = clean_doc(text);
                    }
                    Value::Object(properties) if key == "properties" || key == "definitions" => {
                        properties.values_mut().for_each(clean_docs);
                    }
                    _ => clean_docs(child),
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(clean_docs),
        _ => {}
    }
}

/// A doc comment as plain text: fenced code blocks dropped, intra-doc links "[`x`]" written
/// as "`x`", paragraphs kept, the lines of a paragraph joined.
pub(super) fn clean_doc(doc: &str) -> String {
    let mut paragraphs: Vec<String> = Vec::new();
    let mut current = String::new();
    let mut in_code = false;
    for line in doc.lines() {
        let line = line.trim();
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        if line.is_empty() {
            if !current.is_empty() {
                paragraphs.push(std::mem::take(&mut current));
            }
            continue;
        }
        if !current.is_empty() {
            // A list item starts a line of its own.
            current.push(if line.starts_with("* ") || line.starts_with("- ") {
                '\n'
            } else {
                ' '
            });
        }
        current.push_str(line);
    }
    if !current.is_empty() {
        paragraphs.push(current);
    }
    unlink(&paragraphs.join("\n\n"))
}

/// Rustdoc links as plain text: "[`x`]" and "[`x`](target)" become "`x`", "[text](target)"
/// becomes "text"; brackets inside code spans ("`[100, 10, 1]`") and other brackets stay.
fn unlink(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_code = false;
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        let link = (c == '[' && !in_code)
            .then(|| {
                rest[1..]
                    .find(']')
                    .map(|close| (&rest[1..=close], &rest[close + 2..]))
            })
            .flatten()
            .filter(|(inner, after)| {
                !inner.contains('[')
                    && ((inner.len() > 1 && inner.starts_with('`') && inner.ends_with('`'))
                        || after.starts_with('('))
            });
        match link {
            Some((inner, after)) => {
                out.push_str(inner);
                rest = match after
                    .strip_prefix('(')
                    .and_then(|a| a.find(')').map(|e| &a[e + 1..]))
                {
                    Some(tail) => tail,
                    None => after,
                };
            }
            None => {
                in_code ^= c == '`';
                out.push(c);
                rest = &rest[c.len_utf8()..];
            }
        }
    }
    out
}

/// The schema that `node` stands for: a `$ref` (alone or as the only `allOf` entry)
/// resolved in `root`'s definitions.
pub(super) fn resolve<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    let reference = node.get("$ref").or_else(|| {
        node.get("allOf")
            .and_then(Value::as_array)
            .filter(|all| all.len() == 1)
            .and_then(|all| all[0].get("$ref"))
    });
    match reference
        .and_then(Value::as_str)
        .and_then(|r| r.strip_prefix("#/definitions/"))
        .and_then(|name| root.get("definitions").and_then(|d| d.get(name)))
    {
        Some(target) => resolve(root, target),
        None => node,
    }
}

/// The schema of property `key` of an object schema `node` whose instance is `table`: looked
/// up in `properties`, then in the `oneOf`/`anyOf` branches (the branch whose `kind` constant
/// matches the table's `kind` first: a tagged enum).
pub(super) fn property<'a>(
    root: &'a Value,
    node: &'a Value,
    key: &str,
    tag: Option<&str>,
) -> Option<&'a Value> {
    let node = resolve(root, node);
    if let Some(found) = node.get("properties").and_then(|p| p.get(key)) {
        return Some(found);
    }
    let branches: Vec<&Value> = ["oneOf", "anyOf"]
        .into_iter()
        .filter_map(|k| node.get(k).and_then(Value::as_array))
        .flatten()
        .collect();
    let tag_of = |branch: &Value| {
        let kind = resolve(root, branch).get("properties")?.get("kind")?;
        kind.get("const")
            .or_else(|| kind.get("enum").and_then(|e| e.get(0)))
            .and_then(Value::as_str)
            .map(str::to_owned)
    };
    let tagged = branches
        .iter()
        .find(|b| tag.is_some() && tag_of(b).as_deref() == tag);
    tagged
        .into_iter()
        .chain(branches.iter())
        .find_map(|b| property(root, b, key, tag))
}

/// The object schemas of the `oneOf`/`anyOf` branches of `node` (an optional table is a
/// branch and `null`), or `node` itself.
pub(super) fn object_schema<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    let node = resolve(root, node);
    ["anyOf", "oneOf"]
        .into_iter()
        .filter_map(|k| node.get(k).and_then(Value::as_array))
        .flatten()
        .map(|b| resolve(root, b))
        .find(|b| b.get("properties").is_some())
        .unwrap_or(node)
}

/// The bound a numeric schema states, in words (`> 0`, `>= 0`, `in (0, 1]`), if any.
pub(super) fn bound_text(node: &Value) -> Option<String> {
    let number = |key: &str| node.get(key).and_then(Value::as_f64);
    let lower = number("exclusiveMinimum")
        .map(|v| ('(', v))
        .or_else(|| number("minimum").map(|v| ('[', v)));
    let upper = number("exclusiveMaximum")
        .map(|v| (')', v))
        .or_else(|| number("maximum").map(|v| (']', v)));
    // The integer types' own minimum 0 is a bound of the type, not of a field's validation.
    let integer = node.get("type").and_then(Value::as_str) == Some("integer");
    match (lower, upper) {
        (Some((l, lo)), Some((u, hi))) => Some(format!("in {l}{lo}, {hi}{u}")),
        (Some(('(', lo)), None) => Some(format!("> {lo}")),
        (Some((_, lo)), None) if !(integer && lo == 0.0) => Some(format!(">= {lo}")),
        (None, Some((')', hi))) => Some(format!("< {hi}")),
        (None, Some((_, hi))) => Some(format!("<= {hi}")),
        _ => None,
    }
}
