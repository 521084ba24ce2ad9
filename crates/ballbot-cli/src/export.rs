//! `ballbot export`: the world's robot as MJCF (MuJoCo) or URDF, from the same parameters the
//! 3D world runs on (`ballbot_sim::export`).
//!
//! ```text
//! ballbot export --format mjcf --out out/ballbot.xml
//! ballbot export --format urdf --world world.toml --out out/ballbot.urdf
//! ```

use anyhow::Context;
use ballbot_sim::export::{ExportFormat, export};
use ballbot_sim::params_file::{FileKind, ParamsFile};
use ballbot_sim::world::WorldParams;
use std::path::{Path, PathBuf};

/// The formats, for clap.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// MuJoCo's MJCF.
    Mjcf,
    /// URDF (Drake, Isaac, ROS tools).
    Urdf,
}

impl From<FormatArg> for ExportFormat {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Mjcf => Self::Mjcf,
            FormatArg::Urdf => Self::Urdf,
        }
    }
}

/// Arguments of `ballbot export`.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// The format to write.
    #[arg(long, value_enum)]
    pub format: FormatArg,
    /// A world parameter file (TOML, `ballbot params show --kind world` writes one);
    /// default: MiaPURE with 60 kg in the default world.
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// The file to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `ballbot export`.
pub fn run(args: &ExportArgs) -> anyhow::Result<()> {
    let params = match &args.world {
        Some(path) => read_world(path)?,
        None => WorldParams::miapure_60kg(),
    };
    let format = ExportFormat::from(args.format);
    let text = export(&params, format)?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(&args.out, text).with_context(|| format!("writing {}", args.out.display()))?;
    println!("wrote {} ({format})", args.out.display());
    Ok(())
}

/// A world file, checked like `ballbot params check` (errors name the dotted key).
fn read_world(path: &Path) -> anyhow::Result<WorldParams> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    match ParamsFile::check(&text, FileKind::World)
        .with_context(|| format!("checking {}", path.display()))?
    {
        ParamsFile::World(world) => Ok(*world),
        other => anyhow::bail!("{} is a {} file, not a world", path.display(), other.kind()),
    }
}
