//! Reading an MCAP log back into numpy arrays (`ballbot_sim::log::McapLog`).

use crate::errors::{Kind, error};
use ballbot_sim::log::{LogError, McapLog};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict, PyList};
use serde::Serialize;
use serde_json::Value;

/// Maps a log error: unreadable or malformed files, and a live view that cannot serve, to
/// `FileError`; a missing or undecodable topic to `ParameterError`.
pub fn log_error(py: Python<'_>, e: LogError) -> PyErr {
    let kind = match &e {
        LogError::NoSuchTopic { .. } | LogError::NotJson { .. } => Kind::Parameter,
        _ => Kind::File,
    };
    error(py, kind, e.to_string())
}

/// A JSON value as plain Python objects, through `pythonize` (as [`crate::results::build`]):
/// an integer as an `int`, any other number as a `float`.
pub fn json_to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(pythonize::pythonize(py, value)?)
}

/// A channel as `McapLog.channels` lists it.
#[derive(Serialize)]
struct ChannelView<'a> {
    topic: &'a str,
    schema_name: &'a str,
    schema_encoding: &'a str,
    message_encoding: &'a str,
    message_count: u64,
}

/// An MCAP log read into memory, complete or recovered from a killed writer.
#[pyclass(name = "McapLog", module = "ballbot", frozen)]
pub struct PyMcapLog {
    inner: McapLog,
}

impl PyMcapLog {
    /// Wraps a log read by Rust.
    pub fn from_log(inner: McapLog) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyMcapLog {
    /// Reads the log at `path` (without the GIL).
    #[new]
    fn py_new(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let inner = py
            .detach(|| McapLog::open(&path))
            .map_err(|e| log_error(py, e))?;
        Ok(Self { inner })
    }

    /// The file read.
    #[getter]
    fn path(&self) -> std::path::PathBuf {
        self.inner.path().to_owned()
    }

    /// Whether the whole data section was read (`False` for a recovered file).
    #[getter]
    fn is_complete(&self) -> bool {
        self.inner.is_complete()
    }

    /// Why reading stopped early, for an incomplete file.
    #[getter]
    fn stop_reason(&self) -> Option<String> {
        self.inner.stop_reason().map(str::to_owned)
    }

    /// Total number of messages.
    #[getter]
    fn message_count(&self) -> u64 {
        self.inner.message_count()
    }

    /// The topics, in file order.
    fn topics(&self) -> Vec<String> {
        self.inner
            .channels()
            .iter()
            .map(|c| c.topic.clone())
            .collect()
    }

    /// Every channel as a dict: `topic`, `schema_name`, `schema_encoding`,
    /// `message_encoding`, `message_count`.
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let channels: Vec<ChannelView<'_>> = self
            .inner
            .channels()
            .iter()
            .map(|c| ChannelView {
                topic: &c.topic,
                schema_name: &c.schema_name,
                schema_encoding: &c.schema_encoding,
                message_encoding: &c.message_encoding,
                message_count: c.message_count,
            })
            .collect();
        Ok(pythonize::pythonize(py, &channels)?)
    }

    /// A channel's numeric fields (JSON, or Foxglove's protobuf messages) as `(n,)` float
    /// arrays: `time_secs` (log time) and one column per field path (`body.tilt_rad`,
    /// `wheels[2].normal_force_n`; NaN where a message lacks the field or logged a non-finite
    /// value).
    fn numeric_series<'py>(&self, py: Python<'py>, topic: &str) -> PyResult<Bound<'py, PyDict>> {
        let series = py
            .detach(|| self.inner.numeric_series(topic))
            .map_err(|e| log_error(py, e))?;
        // The columns made numpy arrays from the Rust buffers (no copy), in file order.
        let time = (
            "time_secs".to_owned(),
            PyArray1::from_vec(py, series.time_secs),
        );
        let columns = series
            .columns
            .into_iter()
            .map(|(name, column)| (name, PyArray1::from_vec(py, column)));
        std::iter::once(time).chain(columns).into_py_dict(py)
    }

    /// A channel's messages (JSON, or Foxglove's protobuf messages with their schema's field
    /// names): `(time_secs (n,), [message, ...])`, each message decoded to plain Python values.
    fn messages<'py>(
        &self,
        py: Python<'py>,
        topic: &str,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyList>)> {
        let series = py
            .detach(|| self.inner.json_series(topic))
            .map_err(|e| log_error(py, e))?;
        let list = PyList::empty(py);
        for v in &series.values {
            list.append(json_to_py(py, v)?)?;
        }
        Ok((PyArray1::from_vec(py, series.time_secs), list))
    }

    fn __repr__(&self) -> String {
        format!(
            "McapLog(path={:?}, channels={}, messages={}, complete={})",
            self.inner.path(),
            self.inner.channels().len(),
            self.inner.message_count(),
            self.inner.is_complete()
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMcapLog>()?;
    Ok(())
}
