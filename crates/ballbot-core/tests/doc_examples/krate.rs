//! The crate: module tree, visibility, missing examples.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use super::scan::{Item, Scan, scan};
use super::src_dir;

/// How much of a file is public API.
#[derive(Clone, Debug)]
pub(super) enum Exposure {
    /// Reached through `pub mod`s only: all its `pub` items.
    Public,
    /// A private module: only the names its parent re-exports.
    Reexported(BTreeSet<String>),
    /// `#[cfg(test)]`: nothing.
    Test,
}

pub(super) struct CrateScan {
    /// Path relative to `src` (with `/`) -> (exposure, scan).
    pub(super) files: BTreeMap<String, (Exposure, Scan)>,
}

pub(super) fn rel(path: &Path) -> String {
    path.strip_prefix(src_dir())
        .unwrap_or(path)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

pub(super) fn scan_crate() -> CrateScan {
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
    pub(super) fn public_items(&self) -> BTreeMap<String, Vec<Item>> {
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
