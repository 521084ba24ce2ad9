//! Building the result classes of `ballbot._results` (frozen dataclasses with typed
//! attributes) from the fields the bindings collect in a dict.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;

static RESULTS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// An instance of `ballbot._results.<class_name>` with `fields` as keyword arguments (the
/// class's constructor checks that every field is given, and no other).
pub fn make<'py>(
    py: Python<'py>,
    class_name: &str,
    fields: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    let module =
        RESULTS_MODULE.get_or_try_init(py, || py.import("ballbot._results").map(|m| m.unbind()))?;
    module.bind(py).getattr(class_name)?.call((), Some(&fields))
}
