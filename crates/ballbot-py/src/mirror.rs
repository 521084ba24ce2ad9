//! The Python mirror's schema: one JSON Schema bundle of every result class of
//! `ballbot._results`, every status enum of `ballbot._enums` and every settings class of
//! `ballbot._settings`, from the Rust types
//! (schemars; the doc comments are the descriptions).
//!
//! `scripts/gen-python-mirror.py` (stdlib only) writes `python/ballbot/_results.py` and
//! `python/ballbot/_enums.py` from the committed bundle `schemas/python-mirror.schema.json`;
//! `--check` fails when they differ from it (`scripts/test.sh`), and the Python tests fail when
//! the bundle differs from the one the built extension exports (`ballbot._core._mirror_schema`).
//!
//! What only Python needs is in the schema as extension keys: `x-python-type` (an annotation
//! other than the JSON type's: `numpy.ndarray`, `ballbot._core.Failure`, an enum class),
//! `x-python-dtype` and `x-python-shape` (a numpy array's; `"n"` for the rows of a run),
//! `x-python-base` (the class a result class extends), `x-python-enum` (an enum class's
//! members, in [`crate::enums`]), `x-python-settings` (a settings class), `x-python-check`
//! (how a settings field is checked) and `x-python-default` (a default as Python source).

use crate::results::PyResultClass;
use pyo3::prelude::*;
use schemars::SchemaGenerator;
use schemars::generate::SchemaSettings;
use serde_json::{Map, Value, json};

/// The command that regenerates the bundle and the Python modules.
pub const REGENERATE: &str = "python3 scripts/gen-python-mirror.py --from-extension";

/// The result classes of the bundle: each type gets [`PyResultClass`] (so that
/// [`crate::results::build`] takes it) and its schema in the bundle, under its schema name
/// (the Python class's).
macro_rules! result_classes {
    ($($ty:ty),* $(,)?) => {
        $(impl PyResultClass for $ty {})*

        fn result_schemas(generator: &mut SchemaGenerator) {
            $(generator.subschema_for::<$ty>();)*
        }
    };
}

/// The settings classes of `ballbot._settings`, in the order the module lists them.
fn settings_schemas(generator: &mut SchemaGenerator) -> Vec<Value> {
    use crate::studies::settings::{BrakingSettings, MaxSpeedSettings, PushSettings, RampSettings};
    [
        generator.subschema_for::<MaxSpeedSettings>(),
        generator.subschema_for::<BrakingSettings>(),
        generator.subschema_for::<PushSettings>(),
        generator.subschema_for::<RampSettings>(),
    ]
    .into_iter()
    .filter_map(|s| {
        let name = s.get("$ref")?.as_str()?.rsplit('/').next()?.to_owned();
        Some(json!(name))
    })
    .collect()
}

result_classes![
    crate::world::RampRunView<'_>,
    crate::world::WorldRunView<'_>,
    crate::world::WorldLoopRunView<'_>,
    crate::world::TractionStatusView,
    crate::world::TractionEnvelopeView,
    crate::studies::TrialOutcomeView<'_>,
    crate::studies::SlowRampTrialView<'_>,
    crate::studies::FailingAccelerationView<'_>,
    crate::studies::MaxSpeedStudyView<'_>,
    crate::studies::BrakingRunView<'_>,
    crate::studies::BrakingStudyView<'_>,
    crate::studies::PushTrialView<'_>,
    crate::studies::PushRecoveryView<'_>,
    crate::sim::ScenarioRunView<'_>,
    crate::sim::PiptbExperimentView,
    crate::control::RolloutView<'_>,
    crate::trajopt::MinBrakingTimeView<'_>,
];

/// The bundle as a JSON value: `definitions` holds every result class and enum (and the
/// nested types they use), `x-python-results` and `x-python-enums` list the classes of each
/// module in the order they are written.
pub fn bundle() -> Value {
    let mut generator = SchemaSettings::draft07().for_serialize().into_generator();
    result_schemas(&mut generator);
    let settings = settings_schemas(&mut generator);
    let mut definitions = generator.take_definitions(true);
    let enums = crate::enums::schemas();
    let enum_names: Vec<Value> = enums.iter().map(|(name, _)| json!(name)).collect();
    for (name, schema) in enums {
        definitions.insert(name, schema);
    }
    let results: Vec<Value> = definitions
        .iter()
        .filter(|(_, d)| {
            ["x-python-type", "x-python-enum", "x-python-settings"]
                .iter()
                .all(|key| d.get(key).is_none())
        })
        .map(|(name, _)| json!(name))
        .collect();
    let mut root = Map::new();
    root.insert(
        "$schema".into(),
        json!("http://json-schema.org/draft-07/schema#"),
    );
    root.insert(
        "$comment".into(),
        json!(format!(
            "The Python mirror (ballbot._results, ballbot._enums). Generated from the Rust \
             types by `{REGENERATE}`; do not edit."
        )),
    );
    root.insert("x-python-results".into(), Value::Array(results));
    root.insert("x-python-enums".into(), Value::Array(enum_names));
    root.insert("x-python-settings".into(), Value::Array(settings));
    root.insert("definitions".into(), Value::Object(definitions));
    Value::Object(root)
}

/// The bundle's text, as committed in `schemas/python-mirror.schema.json` (pretty, with a
/// final newline).
#[pyfunction(name = "_mirror_schema")]
pub fn mirror_schema() -> String {
    let text = serde_json::to_string_pretty(&bundle())
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
    format!("{text}\n")
}

/// Adds `_mirror_schema`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mirror_schema, m)?)
}
