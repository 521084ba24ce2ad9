//! `ballbot params {schema, check, show, diff}`: the parameter files' JSON Schemas, checking a
//! file, the presets as commented files, and the keys two files differ in
//! (`ballbot_sim::params_file`; `docs/params.md`).

use anyhow::Context;
use ballbot_sim::params_file::{
    self, FileKind, KeyDiff, PRESETS, ParamsFile, commented_toml, schema_text,
};
use clap::{Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ballbot params`.
#[derive(Debug, clap::Args)]
pub struct ParamsArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: ParamsCommand,
}

/// The `ballbot params` subcommands.
#[derive(Debug, Subcommand)]
pub enum ParamsCommand {
    /// Write the JSON Schema of every parameter file (robot, scenario, world, controller),
    /// generated from the Rust types, into DIR.
    Schema {
        /// Output folder (created if missing).
        #[arg(long, default_value = "schemas")]
        out: PathBuf,
    },
    /// Check a parameter file against its type and its validation; print one OK line, or
    /// exit non-zero naming the key (dotted) and the bound.
    #[command(after_help = KIND_HELP)]
    Check {
        /// The file (TOML).
        file: PathBuf,
        /// The kind of file; inferred when missing (see below).
        #[arg(long, value_enum)]
        kind: Option<KindArg>,
    },
    /// Print a preset as a complete TOML file with every key's description, unit and bound as
    /// a comment (`params check` accepts it).
    #[command(after_help = presets_help())]
    Show {
        /// The preset (`miapure` is `miapure_60kg`).
        #[arg(long, default_value = "miapure")]
        preset: String,
        /// The kind of file; default the first kind that has the preset (robot, then
        /// scenario, then world, then controller).
        #[arg(long, value_enum)]
        kind: Option<KindArg>,
    },
    /// Print the keys whose values differ between two files of one kind (dotted key, value in
    /// A, value in B). Exit 0 when they are equal, 1 when they differ, 2 on an error.
    #[command(after_help = KIND_HELP)]
    Diff {
        /// The first file.
        a: PathBuf,
        /// The second file.
        b: PathBuf,
        /// The kind of both files; inferred from each when missing.
        #[arg(long, value_enum)]
        kind: Option<KindArg>,
    },
}

/// `--kind`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum KindArg {
    /// A robot (`BallbotParams`): `examples/params/`.
    Robot,
    /// A planar scenario (`Scenario`) for `ballbot simulate`: `scenarios/`.
    Scenario,
    /// The 3D world with its robot (`WorldParams`), e.g. a sweep's `params` file.
    World,
    /// The 3D robot's controller (`BallbotControllerConfig`): `--controller FILE`.
    Controller,
}

impl From<KindArg> for FileKind {
    fn from(kind: KindArg) -> Self {
        match kind {
            KindArg::Robot => Self::Robot,
            KindArg::Scenario => Self::Scenario,
            KindArg::World => Self::World,
            KindArg::Controller => Self::Controller,
        }
    }
}

/// How the kind of a file is found without `--kind`.
pub const KIND_HELP: &str = "Without --kind, the kind comes from the file:
  1. a `#:schema PATH` line among its leading comments whose PATH ends in
     ballbot-params.schema.json (robot), scenario.schema.json, world-params.schema.json or
     controller.schema.json;
  2. else its top-level keys: `shaping` or `traction` -> controller; `controller` ->
     scenario; `contact`, or a `[robot]` table with `sagittal` -> world; `sagittal`,
     `frontal`, `spin` or `drivetrain` -> robot.";

fn presets_help() -> String {
    let mut text = String::from("Presets (--kind, --preset):\n");
    for p in PRESETS {
        text.push_str(&format!(
            "  {:<9} {:<17} {}\n",
            p.kind.as_str(),
            p.name,
            p.about
        ));
    }
    text
}

/// Runs `ballbot params`.
pub fn run(args: &ParamsArgs) -> anyhow::Result<ExitCode> {
    match &args.command {
        ParamsCommand::Schema { out } => schema(out).map(|()| ExitCode::SUCCESS),
        ParamsCommand::Check { file, kind } => check(file, *kind).map(|()| ExitCode::SUCCESS),
        ParamsCommand::Show { preset, kind } => show(preset, *kind).map(|()| ExitCode::SUCCESS),
        ParamsCommand::Diff { a, b, kind } => Ok(match diff(a, b, *kind) {
            Ok(true) => ExitCode::SUCCESS,
            Ok(false) => ExitCode::from(1),
            Err(e) => {
                eprintln!("Error: {e:#}");
                ExitCode::from(2)
            }
        }),
    }
}

fn schema(out: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    for kind in FileKind::ALL {
        let path = out.join(kind.schema_file_name());
        std::fs::write(&path, schema_text(kind))
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {} ({} file)", path.display(), kind.as_str());
    }
    Ok(())
}

/// Reads `path` and its kind (`--kind` or inferred).
fn read(path: &Path, kind: Option<KindArg>) -> anyhow::Result<(String, FileKind)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let kind = match kind {
        Some(kind) => kind.into(),
        None => FileKind::infer(&text).with_context(|| format!("{}", path.display()))?,
    };
    Ok((text, kind))
}

fn check(path: &Path, kind: Option<KindArg>) -> anyhow::Result<()> {
    let (text, kind) = read(path, kind)?;
    ParamsFile::check(&text, kind).with_context(|| {
        format!(
            "{} is not a valid {} file ({})",
            path.display(),
            kind.as_str(),
            kind.type_name()
        )
    })?;
    println!(
        "OK: {} is a valid {} file ({})",
        path.display(),
        kind.as_str(),
        kind.type_name()
    );
    Ok(())
}

fn show(name: &str, kind: Option<KindArg>) -> anyhow::Result<()> {
    let (preset, file) = params_file::preset(name, kind.map(FileKind::from))?;
    let kind = preset.kind;
    let header = [
        format!(
            "{} file ({}): preset {}, {}.",
            kind.as_str(),
            kind.type_name(),
            preset.name,
            preset.about
        ),
        format!(
            "Written by `ballbot params show --kind {} --preset {}`; check a copy with `ballbot \
             params check FILE`.",
            kind.as_str(),
            preset.name
        ),
        format!(
            "Editors (Taplo, Even Better TOML): make the first line `#:schema PATH` with PATH \
             the relative path to schemas/{}.",
            kind.schema_file_name()
        ),
    ];
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    print!("{}", commented_toml(&file, &header)?);
    Ok(())
}

/// `Ok(true)` when the files are equal.
fn diff(a: &Path, b: &Path, kind: Option<KindArg>) -> anyhow::Result<bool> {
    let parse = |path: &Path| -> anyhow::Result<ParamsFile> {
        let (text, kind) = read(path, kind)?;
        ParamsFile::parse(&text, kind).with_context(|| {
            format!(
                "{} is not a {} file ({})",
                path.display(),
                kind.as_str(),
                kind.type_name()
            )
        })
    };
    let differences = params_file::diff(&parse(a)?, &parse(b)?)?;
    print!("{}", diff_table(&differences, a, b));
    Ok(differences.is_empty())
}

/// One line per key: `key  value-in-A  value-in-B`, aligned, under a header naming the files.
fn diff_table(differences: &[KeyDiff], a: &Path, b: &Path) -> String {
    if differences.is_empty() {
        return String::new();
    }
    let shown = |v: &Option<String>| v.clone().unwrap_or_else(|| "(not set)".to_owned());
    let rows: Vec<[String; 3]> = std::iter::once([
        "key".to_owned(),
        a.display().to_string(),
        b.display().to_string(),
    ])
    .chain(
        differences
            .iter()
            .map(|d| [d.key.clone(), shown(&d.a), shown(&d.b)]),
    )
    .collect();
    let width = |i: usize| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0);
    let (w0, w1) = (width(0), width(1));
    rows.iter()
        .map(|[k, va, vb]| format!("{k:<w0$}  {va:<w1$}  {vb}\n"))
        .collect()
}
