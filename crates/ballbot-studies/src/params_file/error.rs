//! [`ParamsFileError`]: what is wrong with a parameter file, naming the key.

/// What is wrong with a parameter file. Every variant about a value names its dotted key
/// (`sagittal.ball_mass_kg`, `contact.rollers.count`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsFileError {
    /// The text is not TOML.
    #[error("not a TOML file: {message}")]
    Toml {
        /// The TOML parser's message (with the line).
        message: String,
    },
    /// A key does not fit the type: unknown, missing, or a value of the wrong type.
    #[error("`{key}`: {message}{}", line.map(|(l, c)| format!(" (line {l}, column {c})")).unwrap_or_default())]
    Key {
        /// The dotted key (empty for the file as a whole).
        key: String,
        /// What is wrong with it.
        message: String,
        /// Line and column (1-based) in the file, when known.
        line: Option<(usize, usize)>,
    },
    /// A value is outside the bound that `validate()` enforces.
    #[error("`{key}` {requirement}")]
    Invalid {
        /// The dotted key.
        key: String,
        /// The bound, in words (`must be finite and > 0`).
        requirement: String,
    },
    /// Neither `--kind` nor the file says which kind of file it is.
    #[error(
        "cannot tell which kind of file this is: no `#:schema` line naming one of the \
         schemas, and none of the keys `shaping` or `traction` (controller), `controller` \
         (scenario), `robot.sagittal` or `contact` (world), `sagittal`/`frontal`/`spin`/\
         `drivetrain` (robot) at the top level; pass --kind"
    )]
    UnknownKind,
    /// An unknown kind name.
    #[error("unknown kind `{0}` (robot, scenario, world, controller)")]
    KindName(String),
    /// An unknown preset, or one that does not exist for the kind asked for.
    #[error("no preset `{name}`{}; presets: {known}", kind.map(|k| format!(" for kind {k}")).unwrap_or_default())]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The kind asked for, if any (`robot`, `scenario`, `world`).
        kind: Option<&'static str>,
        /// The presets there are (`kind/name` pairs).
        known: String,
    },
    /// Two files of different kinds cannot be compared.
    #[error("the files are of different kinds: {a} and {b}")]
    KindMismatch {
        /// The first file's kind (`robot`, `scenario`, `world`).
        a: &'static str,
        /// The second file's kind.
        b: &'static str,
    },
    /// A value could not be written as TOML (a bug: every parameter type is plain data).
    #[error("cannot write TOML: {0}")]
    Write(String),
}
