//! `LiveView`: a Foxglove WebSocket server that `World.run` and `WorldLoop.run` serve a run to
//! as it happens (`ballbot_sim::log::LiveServer`).

use crate::log::log_error;
use ballbot_sim::log::{LiveOptions, LivePace, LiveServer};
use pyo3::prelude::*;
use std::time::Duration;

/// A live view for Foxglove (Open connection, Foxglove WebSocket, `url`): pass it as `live=`
/// to `World.run` or `WorldLoop.run` and the run's log (telemetry, controller, 3D scene,
/// transforms, wheel joints, events) is served while it runs, paced to real time when
/// `realtime` (else as fast as the simulation goes). `port=0` picks a free port. The server
/// stops at `close()` or when the object is garbage-collected.
#[pyclass(name = "LiveView", module = "ballbot", frozen)]
pub struct PyLiveView {
    pub(crate) server: LiveServer,
}

#[pymethods]
impl PyLiveView {
    #[new]
    #[pyo3(signature = (*, host = "127.0.0.1", port = 8765, realtime = true))]
    fn py_new(py: Python<'_>, host: &str, port: u16, realtime: bool) -> PyResult<Self> {
        let pace = if realtime {
            LivePace::RealTime
        } else {
            LivePace::AsFastAsPossible
        };
        let options = LiveOptions {
            host: host.to_owned(),
            port,
            pace,
            ..LiveOptions::default()
        };
        let server = py
            .detach(|| LiveServer::start(options))
            .map_err(|e| log_error(py, e))?;
        Ok(Self { server })
    }

    /// The port listened on.
    #[getter]
    fn port(&self) -> u16 {
        self.server.port()
    }

    /// The address to open in Foxglove, `ws://host:port`.
    #[getter]
    fn url(&self) -> String {
        self.server.url()
    }

    /// Whether runs are paced to real time.
    #[getter]
    fn realtime(&self) -> bool {
        self.server.pace_mode() == LivePace::RealTime
    }

    /// How many clients are connected.
    fn client_count(&self) -> usize {
        self.server.client_count()
    }

    /// Waits (without the GIL) until a client connects or `timeout_secs` pass; whether one did.
    fn wait_for_client(&self, py: Python<'_>, timeout_secs: f64) -> bool {
        let timeout = Duration::try_from_secs_f64(timeout_secs.max(0.0)).unwrap_or(Duration::MAX);
        py.detach(|| self.server.wait_for_client(timeout))
    }

    /// Stops the server: clients are disconnected and the port is freed.
    fn close(&self, py: Python<'_>) {
        py.detach(|| self.server.stop());
    }

    fn __repr__(&self) -> String {
        format!(
            "LiveView(url={:?}, realtime={})",
            self.url(),
            self.realtime()
        )
    }
}
