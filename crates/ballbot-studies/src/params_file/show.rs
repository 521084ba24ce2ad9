//! A parameter file written out in full with every key's description, unit and bound as a
//! comment above it (`ballbot params show`).

use super::schema::{bound_text, object_schema, property, resolve, schema_json};
use super::{ParamsFile, ParamsFileError};
use serde_json::Value;
use toml_edit::{DocumentMut, Item, Table};

/// Comment lines are wrapped at this width (characters, `# ` included).
const WIDTH: usize = 96;

/// `file` as TOML with comments: `header` (one comment line each) first, then every table
/// and key preceded by its description from the schema (units in the name and the text), the
/// bound `validate()` enforces and, for an optional key that is not set, a note. The result
/// reads back into the same value.
///
/// ```
/// use ballbot_studies::params_file::{FileKind, ParamsFile, commented_toml, preset};
/// let (_, robot) = preset("miapure_60kg", Some(FileKind::Robot))?;
/// let text = commented_toml(&robot, &["MiaPURE carrying 60 kg."])?;
/// assert!(text.contains("# Ball mass `m_S` (kg). Must be > 0.\nball_mass_kg = 3.6\n"));
/// assert_eq!(ParamsFile::check(&text, FileKind::Robot)?, robot);
/// # Ok::<(), ballbot_studies::params_file::ParamsFileError>(())
/// ```
pub fn commented_toml(file: &ParamsFile, header: &[&str]) -> Result<String, ParamsFileError> {
    let mut doc: DocumentMut = file
        .to_toml()?
        .parse()
        .map_err(|e: toml_edit::TomlError| ParamsFileError::Write(e.to_string()))?;
    let schema = schema_json(file.kind());
    let mut top = String::new();
    for line in header {
        top.push_str(&comment(line));
    }
    let unset = unset_keys(&schema, &schema, doc.as_table());
    if !unset.is_empty() {
        top.push_str(&comment(&unset));
    }
    annotate(doc.as_table_mut(), &schema, &schema);
    Ok(format!("{top}\n{}", doc.to_string().trim_start()))
}

/// Puts each key's comment above it, recursively.
fn annotate(table: &mut Table, root: &Value, node: &Value) {
    let tag = table.get("kind").and_then(Item::as_str).map(str::to_owned);
    for (mut key, item) in table.iter_mut() {
        let Some(field) = property(root, node, key.get(), tag.as_deref()) else {
            continue;
        };
        let text = describe(root, field);
        match item {
            Item::Table(sub) => {
                let sub_node = object_schema(root, field);
                let unset = unset_keys(root, sub_node, sub);
                let mut prefix = String::from("\n");
                for part in [&text, &unset] {
                    if !part.is_empty() {
                        prefix.push_str(&comment(part));
                    }
                }
                sub.decor_mut().set_prefix(prefix);
                // A table of tables only (a world's `[robot]`) gets its header, for the comment.
                sub.set_implicit(false);
                annotate(sub, root, sub_node);
            }
            Item::Value(_) if !text.is_empty() => {
                key.leaf_decor_mut().set_prefix(comment(&text));
            }
            _ => {}
        }
    }
}

/// A key's comment: its description and the bound its schema states.
fn describe(root: &Value, field: &Value) -> String {
    let description = field
        .get("description")
        .or_else(|| resolve(root, field).get("description"))
        .and_then(Value::as_str)
        .unwrap_or_default();
    match bound_text(resolve(root, field)) {
        Some(bound) if description.is_empty() => format!("Must be {bound}."),
        Some(bound) => format!("{description} Must be {bound}."),
        None => description.to_owned(),
    }
}

/// A note naming the optional keys of `node` that `table` does not set, with their
/// descriptions; empty when there are none.
fn unset_keys(root: &Value, node: &Value, table: &Table) -> String {
    let node = resolve(root, node);
    let Some(properties) = node.get("properties").and_then(Value::as_object) else {
        return String::new();
    };
    let notes: Vec<String> = properties
        .iter()
        .filter(|(key, _)| !table.contains_key(key))
        .map(|(key, field)| format!("`{key}`: {}", describe(root, field)))
        .collect();
    if notes.is_empty() {
        String::new()
    } else {
        format!("Optional, not set here: {}", notes.join(" "))
    }
}

/// `text` as `# ` comment lines of at most [`WIDTH`] characters (paragraphs kept).
fn comment(text: &str) -> String {
    let mut out = String::new();
    for paragraph in text.split('\n') {
        let mut line = String::from("#");
        for word in paragraph.split_whitespace() {
            if line.len() > 1 && line.len() + 1 + word.len() > WIDTH {
                out.push_str(&line);
                out.push('\n');
                line = String::from("#");
            }
            line.push(' ');
            line.push_str(word);
        }
        out.push_str(&line);
        out.push('\n');
    }
    out
}
