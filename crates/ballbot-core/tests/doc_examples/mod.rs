//! Every public item of the core carries a runnable doc example.
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

mod krate;
mod lex;
mod scan;

use krate::{Exposure, scan_crate};
use scan::{Item, scan};

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Files (relative to `crates/ballbot-core/src`) whose public items must all have examples.
pub(super) const CHECKED: &[&str] = &[
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
    "wip/momentum.rs",
    "traction/mod.rs",
    "traction/control.rs",
    "traction/envelope.rs",
    "traction/monitor.rs",
    "traction/params.rs",
    "command/limit.rs",
    "ballbot/balance.rs",
    "ballbot/balancing.rs",
    "ballbot/guard.rs",
    "ballbot/imu_lean.rs",
    "command/pending.rs",
    "command/envelope.rs",
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
    "lqr/riccati/status.rs",
    "control/mod.rs",
    "control/feedforward.rs",
    "control/lqr.rs",
    "control/lqr_pi.rs",
    "control/motor_pi.rs",
    "control/pi_pd.rs",
    "control/plane.rs",
    "control/terms.rs",
    "safety/mod.rs",
    "safety/fault.rs",
    "safety/mode.rs",
    "safety/motor_health.rs",
    "safety/params.rs",
    "safety/supervisor.rs",
    "estimation.rs",
    "command/mod.rs",
    "command/jerk.rs",
    "command/lean.rs",
    "command/shaper.rs",
    "command/trajectory.rs",
    "command/trajectory_limits.rs",
    "num.rs",
    "names.rs",
    "rates.rs",
    "ballbot/mod.rs",
    "ballbot/design.rs",
    "ballbot/feedforward.rs",
    "ballbot/mapping.rs",
    "ballbot/motor.rs",
    "ballbot/outer.rs",
    "ballbot/outer_io.rs",
    "ballbot/spin.rs",
    "ballbot/trajectory_limits.rs",
];

pub(super) fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
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
        "doc examples: CHECKED is out of date:\n{problems}"
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
