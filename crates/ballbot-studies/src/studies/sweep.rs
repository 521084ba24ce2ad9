//! Parameter sweeps from a TOML grid file (`ballbot sweep GRID.toml`): a study run at every
//! point of a grid of world-parameter fields and study arguments, on every core.
//!
//! ```toml
//! study = "failing_acceleration"   # or "push_recovery"
//! preset = "miapure_60kg"          # the base world; or `params = "world.toml"`
//! seed = 0                         # the sensors' noise seed of every run
//! quick = false                    # failing_acceleration: the CI-sized protocol
//!
//! [grid]
//! heading_deg = [0.0, 30.0, 60.0]                         # the study's argument
//! "robot.drivetrain.wheel_ball_friction" = [0.5, 0.8]    # a WorldParams field
//! "robot.{sagittal,frontal}.com_height_m" = [0.45, 0.6]  # two fields, one value
//! ```
//!
//! The points are the grid's cartesian product, its keys in sorted order, the last one varying
//! fastest. Every key other than `heading_deg` is a dotted path to a number in the world's
//! parameter file ([`WorldParams`] as TOML); a path that does not name one is an error naming
//! the key, and every point's world is validated.

use super::max_speed::{MaxSpeedStudySettings, failing_acceleration};
use super::push::{PushParams, PushSearch, push_recovery_limit};
use super::runner::run_jobs;
use ballbot_world::rig::Happened;
use ballbot_world::world::{WorldError, WorldParams};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A sweep file could not be read or a point could not run.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The file could not be read or parsed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A grid key or value is invalid.
    #[error("sweep grid key `{key}`: {message}")]
    Grid {
        /// The key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A point's world or study rejected its parameters.
    #[error("sweep point {point}: {source}")]
    Point {
        /// The point, as `key = value` pairs.
        point: String,
        /// The error.
        source: WorldError,
    },
}

/// The studies a sweep file can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SweepStudy {
    /// The maximum-speed study's failing acceleration at `heading_deg` (its capability map).
    FailingAcceleration,
    /// The largest push recovered at `heading_deg`.
    PushRecovery,
}

impl SweepStudy {
    /// The canonical name: `failing_acceleration` or `push_recovery`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::FailingAcceleration => "failing_acceleration",
            Self::PushRecovery => "push_recovery",
        }
    }
}

/// A sweep file (see the module docs).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// The study.
    pub study: SweepStudy,
    /// A `WorldParams` preset (`miapure_60kg`, `miapure_unloaded`); default `miapure_60kg`.
    #[serde(default)]
    pub preset: Option<String>,
    /// A world parameter file, relative to the sweep file (instead of `preset`).
    #[serde(default)]
    pub params: Option<PathBuf>,
    /// The sensors' noise seed of every run. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// `failing_acceleration`: the CI-sized protocol ([`MaxSpeedStudySettings::quick`]).
    #[serde(default)]
    pub quick: bool,
    /// The grid: a list of numbers per key.
    pub grid: BTreeMap<String, Vec<f64>>,
}

/// One point: its key-value pairs in the grid's key order.
pub type Point = Vec<(String, f64)>;

/// One point's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepRow {
    /// The point.
    pub point: BTreeMap<String, f64>,
    /// The study's numbers (`None`: censored, e.g. no failing acceleration in the bracket).
    pub values: BTreeMap<&'static str, Option<f64>>,
    /// The study's result as its table prints it.
    pub text: String,
    /// The run at the limit's failing end (the smallest failing acceleration or impulse): how
    /// it ended and its events; `None` when no run failed (censored).
    pub failing_run: Option<FailingRun>,
}

/// What happened in the run at a sweep point's limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FailingRun {
    /// The study's scalar at that run: the ramp acceleration (m/s^2) or the impulse (N s).
    pub value: f64,
    /// How it ended and its events (JSON: `outcome`, `events`, `events_dropped`).
    #[serde(flatten)]
    pub happened: Happened,
}

/// A sweep ready to run: the study, the base world and the points.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The study.
    pub study: SweepStudy,
    /// The base world.
    pub base: WorldParams,
    /// The sensors' noise seed.
    pub seed: u64,
    /// The CI-sized protocol.
    pub quick: bool,
    /// The points, in order.
    pub points: Vec<Point>,
    /// Each point's world, validated when the sweep was built.
    pub worlds: Vec<WorldParams>,
}

/// The study arguments a grid may set (every other key is a world field).
const STUDY_KEYS: [&str; 1] = ["heading_deg"];

impl Sweep {
    /// Reads and checks a sweep file: the base world, every key and every point's world.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let file_error = |message: String| SweepError::File {
            path: path.to_owned(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| file_error(e.to_string()))?;
        let file: SweepFile = toml::from_str(&text).map_err(|e| file_error(e.to_string()))?;
        let base = match (&file.preset, &file.params) {
            (Some(_), Some(_)) => {
                return Err(file_error("give `preset` or `params`, not both".into()));
            }
            (_, Some(p)) => {
                let full = path.parent().unwrap_or(Path::new(".")).join(p);
                let text = std::fs::read_to_string(&full)
                    .map_err(|e| file_error(format!("{}: {e}", full.display())))?;
                let w: WorldParams = toml::from_str(&text)
                    .map_err(|e| file_error(format!("{}: {e}", full.display())))?;
                w.validate()
                    .map_err(|e| file_error(format!("{}: {e}", full.display())))?;
                w
            }
            (Some(name), None) => match name.as_str() {
                "miapure_60kg" => WorldParams::miapure_60kg(),
                "miapure_unloaded" => {
                    WorldParams::with_robot(ballbot_core::BallbotParams::miapure_unloaded())
                }
                _ => {
                    return Err(file_error(format!(
                        "unknown preset `{name}`; known: miapure_60kg, miapure_unloaded"
                    )));
                }
            },
            (None, None) => WorldParams::miapure_60kg(),
        };
        Self::new(file.study, base, file.seed, file.quick, &file.grid)
    }

    /// The sweep of `study` over `grid` (keys in their map order) from `base`.
    pub fn new(
        study: SweepStudy,
        base: WorldParams,
        seed: u64,
        quick: bool,
        grid: &BTreeMap<String, Vec<f64>>,
    ) -> Result<Self, SweepError> {
        for (key, values) in grid {
            if values.is_empty() || !values.iter().all(|v| v.is_finite()) {
                return Err(SweepError::Grid {
                    key: key.clone(),
                    message: "needs a list of finite numbers".into(),
                });
            }
            if !STUDY_KEYS.contains(&key.as_str()) {
                // The path must name a number of the world (checked on the base's value).
                with_fields(&base, &[(key.clone(), values[0])]).map_err(|e| match e {
                    SweepError::Point { source, .. } => SweepError::Grid {
                        key: key.clone(),
                        message: source.to_string(),
                    },
                    other => other,
                })?;
            }
        }
        let mut points: Vec<Point> = vec![Vec::new()];
        for (key, values) in grid {
            points = points
                .into_iter()
                .flat_map(|p| {
                    values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.push((key.clone(), *v));
                        q
                    })
                })
                .collect();
        }
        let worlds = points
            .iter()
            .map(|p| {
                let fields: Vec<(String, f64)> = p
                    .iter()
                    .filter(|(k, _)| !STUDY_KEYS.contains(&k.as_str()))
                    .cloned()
                    .collect();
                with_fields(&base, &fields)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            study,
            base,
            seed,
            quick,
            points,
            worlds,
        })
    }

    /// Runs every point on `threads` threads (0: every core); `done(i)` after point `i`.
    pub fn run(
        &self,
        threads: usize,
        done: &(dyn Fn(usize) + Sync),
    ) -> Result<Vec<SweepRow>, SweepError> {
        let jobs: Vec<(&Point, &WorldParams)> = self.points.iter().zip(&self.worlds).collect();
        run_jobs(&jobs, threads, |(p, w)| self.run_point(p, **w), done)
    }

    fn run_point(&self, p: &Point, world: WorldParams) -> Result<SweepRow, SweepError> {
        let heading = p
            .iter()
            .find(|(k, _)| k == "heading_deg")
            .map_or(0.0, |(_, v)| *v);
        let point_error = |source| SweepError::Point {
            point: point_text(p),
            source,
        };
        let (values, text, failing_run) = match self.study {
            SweepStudy::FailingAcceleration => {
                let protocol = if self.quick {
                    MaxSpeedStudySettings::quick().protocol
                } else {
                    MaxSpeedStudySettings::paper().protocol
                };
                let r = failing_acceleration(world, &protocol, heading, self.seed)
                    .map_err(point_error)?;
                let values = BTreeMap::from([
                    ("largest_surviving_m_per_s2", r.largest_surviving_m_per_s2),
                    ("smallest_failing_m_per_s2", r.smallest_failing_m_per_s2),
                    ("runs", Some(r.runs as f64)),
                ]);
                let text = r.text();
                let failing = r.failing.map(|o| FailingRun {
                    value: o.accel_m_per_s2,
                    happened: o.happened,
                });
                (values, text, failing)
            }
            SweepStudy::PushRecovery => {
                let mut world = world;
                world.sensors.seed = self.seed;
                let r = push_recovery_limit(
                    world,
                    &PushParams::default(),
                    &PushSearch::default(),
                    heading,
                    &mut |_| {},
                )
                .map_err(point_error)?;
                let values = BTreeMap::from([
                    ("largest_recovered_ns", Some(r.largest_recovered_ns)),
                    ("smallest_failing_ns", r.smallest_failing_ns),
                    ("trials", Some(r.trials.len() as f64)),
                ]);
                let failing = r.smallest_failing().map(|t| FailingRun {
                    value: t.impulse_ns,
                    happened: t.happened.clone(),
                });
                (values, format!("{:.1}", r.largest_recovered_ns), failing)
            }
        };
        Ok(SweepRow {
            point: p.iter().cloned().collect(),
            values,
            text,
            failing_run,
        })
    }
}

fn point_text(p: &Point) -> String {
    let pairs: Vec<String> = p.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    format!("{{{}}}", pairs.join(", "))
}

/// `a.{b,c}.d` to `["a.b.d", "a.c.d"]` (one brace group).
pub fn expand_braces(path: &str) -> Vec<String> {
    match (path.find('{'), path.find('}')) {
        (Some(open), Some(close)) if open < close => path[open + 1..close]
            .split(',')
            .map(|alt| format!("{}{}{}", &path[..open], alt.trim(), &path[close + 1..]))
            .collect(),
        _ => vec![path.to_owned()],
    }
}

/// `base` with each dotted field path set (through its TOML form), validated.
///
/// ```
/// use ballbot_studies::studies::sweep::with_fields;
/// use ballbot_world::world::WorldParams;
/// let base = WorldParams::miapure_60kg();
/// let w = with_fields(&base, &[("robot.{sagittal,frontal}.com_height_m".into(), 0.55)])?;
/// assert_eq!(w.robot.sagittal.com_height_m, 0.55);
/// assert_eq!(w.robot.frontal.com_height_m, 0.55);
/// assert!(with_fields(&base, &[("robot.nope".into(), 1.0)]).is_err());
/// assert!(with_fields(&base, &[("dt_secs".into(), -1.0)]).is_err());
/// # Ok::<(), ballbot_studies::studies::sweep::SweepError>(())
/// ```
pub fn with_fields(
    base: &WorldParams,
    fields: &[(String, f64)],
) -> Result<WorldParams, SweepError> {
    let point = || fields.to_vec();
    let grid_error = |key: &str, message: &str| SweepError::Grid {
        key: key.to_owned(),
        message: message.to_owned(),
    };
    let mut value = toml::Value::try_from(base)
        .map_err(|e| grid_error("", &format!("world parameters as TOML: {e}")))?;
    for (key, v) in fields {
        for path in expand_braces(key) {
            let mut node = &mut value;
            for part in path.split('.') {
                node = node
                    .get_mut(part)
                    .ok_or_else(|| grid_error(key, &format!("no field `{path}` in WorldParams")))?;
            }
            match node {
                toml::Value::Float(x) => *x = *v,
                toml::Value::Integer(i) if v.fract() == 0.0 && v.abs() < 9.0e15 => *i = *v as i64,
                _ => {
                    return Err(grid_error(
                        key,
                        &format!("`{path}` is not a number field of WorldParams"),
                    ));
                }
            }
        }
    }
    let world: WorldParams = value
        .try_into()
        .map_err(|e: toml::de::Error| grid_error("", &e.to_string()))?;
    world.validate().map_err(|source| SweepError::Point {
        point: point_text(&point()),
        source,
    })?;
    Ok(world)
}
