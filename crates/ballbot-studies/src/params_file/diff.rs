//! The keys in which two parameter files of one kind differ (`ballbot params diff`).

use super::{ParamsFile, ParamsFileError};
use toml_edit::{DocumentMut, Item, Value};

/// One key whose values differ; `None` where a file does not set it (an optional key).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyDiff {
    /// The dotted key (`sagittal.body_mass_kg`).
    pub key: String,
    /// Its value in the first file, as TOML.
    pub a: Option<String>,
    /// Its value in the second file, as TOML.
    pub b: Option<String>,
}

/// The keys whose values differ between `a` and `b`, in the order of the types' fields
/// (`a`'s keys first, then those only `b` sets). Values are compared after reading, so a key
/// left at its default and the same default written out are equal; arrays compare whole.
///
/// ```
/// use ballbot_studies::params_file::{FileKind, diff, preset};
/// let (_, loaded) = preset("miapure_60kg", Some(FileKind::Robot))?;
/// let (_, empty) = preset("miapure_unloaded", Some(FileKind::Robot))?;
/// let keys: Vec<String> = diff(&loaded, &empty)?.into_iter().map(|d| d.key).collect();
/// assert!(keys.contains(&"sagittal.body_mass_kg".to_owned()));
/// assert!(diff(&loaded, &loaded)?.is_empty());
/// # Ok::<(), ballbot_studies::params_file::ParamsFileError>(())
/// ```
pub fn diff(a: &ParamsFile, b: &ParamsFile) -> Result<Vec<KeyDiff>, ParamsFileError> {
    if a.kind() != b.kind() {
        return Err(ParamsFileError::KindMismatch {
            a: a.kind().as_str(),
            b: b.kind().as_str(),
        });
    }
    let (a, b) = (leaves(a)?, leaves(b)?);
    let value_in = |leaves: &[(String, String)], key: &str| {
        leaves
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
    };
    let mut keys: Vec<&String> = a.iter().map(|(k, _)| k).collect();
    keys.extend(
        b.iter()
            .map(|(k, _)| k)
            .filter(|k| value_in(&a, k).is_none()),
    );
    Ok(keys
        .into_iter()
        .filter_map(|key| {
            let (va, vb) = (value_in(&a, key), value_in(&b, key));
            (va != vb).then(|| KeyDiff {
                key: key.clone(),
                a: va,
                b: vb,
            })
        })
        .collect())
}

/// Every value of `file` with its dotted key, in the serializer's order.
fn leaves(file: &ParamsFile) -> Result<Vec<(String, String)>, ParamsFileError> {
    let doc: DocumentMut = file
        .to_toml()?
        .parse()
        .map_err(|e: toml_edit::TomlError| ParamsFileError::Write(e.to_string()))?;
    let mut out = Vec::new();
    walk(doc.as_item(), "", &mut out);
    Ok(out)
}

fn walk(item: &Item, prefix: &str, out: &mut Vec<(String, String)>) {
    let key = |k: &str| {
        if prefix.is_empty() {
            k.to_owned()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match item {
        Item::Table(table) => table.iter().for_each(|(k, v)| walk(v, &key(k), out)),
        Item::Value(Value::InlineTable(table)) => table
            .iter()
            .for_each(|(k, v)| walk(&Item::Value(v.clone()), &key(k), out)),
        Item::Value(value) => out.push((prefix.to_owned(), value.to_string().trim().to_owned())),
        Item::ArrayOfTables(tables) => {
            for (i, table) in tables.iter().enumerate() {
                table
                    .iter()
                    .for_each(|(k, v)| walk(v, &format!("{prefix}[{i}].{k}"), out));
            }
        }
        Item::None => {}
    }
}
