//! The status, mode and failure enums as Python `enum.Enum` members (`ballbot._enums`).
//!
//! The names are the Rust crates' own (`as_str`, `label`), and the Python classes have them
//! as values. Batch outputs keep step statuses as int8 codes for speed: the code is the core's
//! [`StepStatus::code`], and the names by code are exported as `ballbot._core.STEP_STATUS_NAMES`
//! so that `StepStatus.from_code` reads the core's mapping.

use ballbot_core::control::StepStatus;
use ballbot_core::lqr::RiccatiStatus;
use ballbot_core::safety::Mode;
use ballbot_sim::studies::push::PushOutcome;
use ballbot_sim::studies::world_braking::{BrakingOutcome, TrajectoryFeedforward};
use ballbot_sim::trajopt::SolveStatus;
use ballbot_sim::world::FailureKind;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use schemars::JsonSchema;
use schemars::generate::SchemaSettings;
use serde_json::{Value, json};

/// Step-status names by code ([`StepStatus::from_code`]): 0 nominal, 1 saturated, 2 invalid
/// input.
pub fn step_status_names() -> Vec<&'static str> {
    (0..=u8::MAX)
        .map_while(StepStatus::from_code)
        .map(|s| s.as_str())
        .collect()
}

/// The int8 code of a step status in batch outputs: the core's [`StepStatus::code`] (at most
/// 2, so the conversion is exact).
pub fn step_status_code(status: StepStatus) -> i8 {
    status.code() as i8
}

static ENUMS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// The member of the Python enum `class_name` (in `ballbot._enums`) whose value is `name`.
pub fn member<'py>(py: Python<'py>, class_name: &str, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let module =
        ENUMS_MODULE.get_or_try_init(py, || py.import("ballbot._enums").map(|m| m.unbind()))?;
    module.bind(py).getattr(class_name)?.call1((name,))
}

/// One function per status enum, `name(py, value)`: the member of `ballbot._enums.<Class>`
/// whose value is `value.as_str()`, the Rust enum's canonical name (written once, in Rust; the
/// Python classes check themselves against it); and [`schemas`], the enums' part of the
/// Python mirror's bundle ([`crate::mirror`]), from which `ballbot._enums` is generated.
macro_rules! python_enums {
    (
        functions { $($(#[$doc:meta])* $name:ident($ty:ty) => $class:literal;)* }
        schemas { $($schema_ty:ty => $schema_class:literal $(with $methods:literal)?;)* }
    ) => {
        $(
            $(#[$doc])*
            pub fn $name<'py>(py: Python<'py>, value: $ty) -> PyResult<Bound<'py, PyAny>> {
                member(py, $class, value.as_str())
            }
        )*

        /// The schema of each enum class of `ballbot._enums`, by class name, in the order the
        /// module lists them.
        pub fn schemas() -> Vec<(String, Value)> {
            vec![$(enum_schema::<$schema_ty>($schema_class, None $(.or(Some($methods)))?),)*]
        }
    };
}

python_enums! {
    functions {
        /// `ballbot.StepStatus`.
        step_status(StepStatus) => "StepStatus";
        /// `ballbot.Mode`.
        mode(Mode) => "Mode";
        /// `ballbot.FailureKind`.
        failure_kind(&FailureKind) => "FailureKind";
        /// `ballbot.RiccatiStatus`.
        riccati_status(RiccatiStatus) => "RiccatiStatus";
        /// `ballbot.SolveStatus` of the trajectory optimiser.
        solve_status(SolveStatus) => "SolveStatus";
    }
    schemas {
        StepStatus => "StepStatus" with "ballbot._enum_methods.StepStatusCodes";
        Mode => "Mode";
        FailureKind => "FailureKind";
        RiccatiStatus => "RiccatiStatus";
        SolveStatus => "SolveStatus";
        BrakingOutcome => "BrakingOutcome";
        PushOutcome => "PushOutcome";
        TrajectoryFeedforward => "Feedforward";
    }
}

/// The enum class `class` of the Rust enum `T`: its doc comment, and its members (the
/// variants' snake_case names, which are the canonical names `as_str`/`label` give, with
/// their doc comments) under `x-python-enum`; `methods`, the hand-written class it extends.
fn enum_schema<T: JsonSchema>(class: &str, methods: Option<&str>) -> (String, Value) {
    let schema = SchemaSettings::draft07()
        .into_generator()
        .into_root_schema_for::<T>()
        .to_value();
    let mut members = Vec::new();
    let variants = schema.get("oneOf").and_then(Value::as_array);
    for variant in variants.into_iter().flatten() {
        let description = variant.get("description").cloned().unwrap_or(Value::Null);
        let name = variant
            .get("const")
            .or_else(|| variant.get("enum").and_then(|e| e.get(0)))
            .or_else(|| variant.get("required").and_then(|r| r.get(0)))
            .cloned()
            .unwrap_or(Value::Null);
        members.push(json!({ "name": name, "description": description }));
    }
    let mut out = json!({
        "description": schema.get("description").cloned().unwrap_or(Value::Null),
        "x-python-enum": members,
        "x-rust-type": std::any::type_name::<T>(),
    });
    if let (Some(methods), Some(map)) = (methods, out.as_object_mut()) {
        map.insert("x-python-base".into(), json!(methods));
    }
    (class.to_owned(), out)
}

/// Adds the name tables the Python enums check themselves against.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("STEP_STATUS_NAMES", step_status_names())?;
    m.add("FAILURE_KIND_NAMES", FailureKind::NAMES)?;
    Ok(())
}
