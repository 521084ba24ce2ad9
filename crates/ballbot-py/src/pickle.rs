//! Pickling (`__reduce__`) for the classes a user sends between processes (a Dask or
//! multiprocessing sweep): parameters, gains, problems and the records of world runs.
//!
//! Two forms: a class with a keyword constructor is re-created by calling it
//! ([`by_constructor`], so the round trip validates again); a record without one goes through
//! its serde JSON ([`by_json`], exact for floats: `serde_json`'s `float_roundtrip`); a
//! parameter file without a full keyword constructor through its TOML ([`by_toml`]).

use crate::errors::{Kind, error};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::Serialize;
use serde::de::DeserializeOwned;

/// `(copyreg.__newobj_ex__, (type(obj), (), kwargs))`: unpickling calls the class with
/// `kwargs`.
pub fn by_constructor<'py>(
    obj: &Bound<'py, PyAny>,
    kwargs: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let newobj = py.import("copyreg")?.getattr("__newobj_ex__")?;
    let args = (obj.get_type(), PyTuple::empty(py), kwargs);
    PyTuple::new(py, [newobj, args.into_pyobject(py)?.into_any()])
}

/// `(ballbot._pickle.from_json, (type(obj), json))`: unpickling calls the class's
/// `_from_json`.
pub fn by_json<'py, T: Serialize>(
    obj: &Bound<'py, PyAny>,
    value: &T,
) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let text = serde_json::to_string(value)
        .map_err(|e| error(py, Kind::Other, format!("pickling: {e}")))?;
    let rebuild = py.import("ballbot._pickle")?.getattr("from_json")?;
    let args = (obj.get_type(), text);
    PyTuple::new(py, [rebuild, args.into_pyobject(py)?.into_any()])
}

/// `(ballbot._pickle.from_toml, (type(obj), text))`: unpickling calls the class's
/// `from_toml` (which checks the file again), for a class that is a parameter file.
pub fn by_toml<'py>(obj: &Bound<'py, PyAny>, text: String) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let rebuild = py.import("ballbot._pickle")?.getattr("from_toml")?;
    let args = (obj.get_type(), text);
    PyTuple::new(py, [rebuild, args.into_pyobject(py)?.into_any()])
}

/// The value of a `by_json` state.
pub fn from_json<T: DeserializeOwned>(py: Python<'_>, text: &str) -> PyResult<T> {
    serde_json::from_str(text).map_err(|e| error(py, Kind::Parameter, format!("unpickling: {e}")))
}
