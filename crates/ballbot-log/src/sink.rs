//! [`LogSink`]: where a run's messages go, an MCAP file, a live Foxglove view, or both.

use std::path::Path;

use super::LogError;
use super::codec::{Codec, Json};
#[cfg(feature = "live")]
use super::live::{LiveChannel, LiveServer};
use super::writer::{Channel, ChannelInfo, McapLogger};

/// A channel of a [`LogSink`]: the file's channel and the live view's, where there are.
pub struct SinkChannel<T, C = Json> {
    file: Option<Channel<T, C>>,
    #[cfg(feature = "live")]
    live: Option<LiveChannel<T, C>>,
}

impl<T, C> std::fmt::Debug for SinkChannel<T, C> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("SinkChannel");
        d.field("file", &self.file);
        #[cfg(feature = "live")]
        d.field("live", &self.live);
        d.finish()
    }
}

/// Where a run's messages go: an MCAP file ([`McapLogger`]), a live Foxglove view
/// (`LiveServer`, feature `live`), or both. A message is encoded for each with the same
/// [`Codec`], so the live view shows exactly what the file holds.
///
/// ```
/// use ballbot_log::{LogSink, LoggerOptions, McapLog, McapLogger};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("run.mcap");
/// let mut sink = LogSink::file(McapLogger::create(&path, LoggerOptions::default())?);
/// let speed = sink.channel::<f64>("/speed_m_per_s")?;
/// sink.write(&speed, 0.0, &1.5)?;
/// sink.finish()?;
/// assert_eq!(McapLog::open(&path)?.channel("/speed_m_per_s").map(|c| c.message_count), Some(1));
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct LogSink {
    file: Option<McapLogger>,
    #[cfg(feature = "live")]
    live: Option<LiveServer>,
}

impl LogSink {
    /// Messages go to an MCAP file.
    pub fn file(logger: McapLogger) -> Self {
        Self {
            file: Some(logger),
            #[cfg(feature = "live")]
            live: None,
        }
    }

    /// Messages go to a live view only.
    #[cfg(feature = "live")]
    pub fn live(server: LiveServer) -> Self {
        Self {
            file: None,
            live: Some(server),
        }
    }

    /// Messages also go to a live view.
    #[cfg(feature = "live")]
    #[must_use]
    pub fn with_live(mut self, server: LiveServer) -> Self {
        self.live = Some(server);
        self
    }

    /// The MCAP file being written, if any.
    pub fn file_logger(&self) -> Option<&McapLogger> {
        self.file.as_ref()
    }

    /// The MCAP file being written, if any, e.g. to add channels of one's own.
    pub fn file_logger_mut(&mut self) -> Option<&mut McapLogger> {
        self.file.as_mut()
    }

    /// The live view, if any.
    #[cfg(feature = "live")]
    pub fn live_server(&self) -> Option<&LiveServer> {
        self.live.as_ref()
    }

    /// Registers a JSON channel on `topic` (see [`McapLogger::channel`]).
    pub fn channel<T: serde::Serialize + schemars::JsonSchema>(
        &mut self,
        topic: &str,
    ) -> Result<SinkChannel<T>, LogError> {
        self.channel_with::<T, Json>(topic)
    }

    /// Registers a channel on `topic` in every destination, its messages encoded by `C`.
    pub fn channel_with<T, C: Codec<T>>(
        &mut self,
        topic: &str,
    ) -> Result<SinkChannel<T, C>, LogError> {
        let file = match self.file.as_mut() {
            Some(log) => Some(log.channel_with::<T, C>(topic)?),
            None => None,
        };
        #[cfg(feature = "live")]
        let live = match self.live.as_mut() {
            Some(server) => Some(server.channel_with::<T, C>(topic)?),
            None => None,
        };
        Ok(SinkChannel {
            file,
            #[cfg(feature = "live")]
            live,
        })
    }

    /// Writes one message, stamped with simulated time, to every destination.
    pub fn write<T, C: Codec<T>>(
        &mut self,
        channel: &SinkChannel<T, C>,
        time_secs: f64,
        message: &T,
    ) -> Result<(), LogError> {
        if let (Some(log), Some(ch)) = (self.file.as_mut(), channel.file.as_ref()) {
            log.write(ch, time_secs, message)?;
        }
        #[cfg(feature = "live")]
        if let (Some(server), Some(ch)) = (self.live.as_mut(), channel.live.as_ref()) {
            server.write(ch, time_secs, message)?;
        }
        Ok(())
    }

    /// Waits up to `timeout` for a live client to connect (`LiveServer::wait_for_client`);
    /// whether one has. `false` at once without a live view.
    pub fn wait_for_client(&self, timeout: std::time::Duration) -> bool {
        #[cfg(feature = "live")]
        if let Some(server) = &self.live {
            return server.wait_for_client(timeout);
        }
        let _ = timeout;
        false
    }

    /// Waits up to `timeout` for a live client to subscribe to one of the channels registered
    /// so far (`LiveServer::wait_for_subscriber`); whether one has. `true` at once without a
    /// live view.
    pub fn wait_for_subscriber(&self, timeout: std::time::Duration) -> bool {
        #[cfg(feature = "live")]
        if let Some(server) = &self.live {
            return server.wait_for_subscriber(timeout);
        }
        let _ = timeout;
        true
    }

    /// Paces the run to the live view (`LiveServer::pace`, feature `live`); nothing without one.
    pub fn pace(&self, time_secs: f64) {
        #[cfg(feature = "live")]
        if let Some(server) = &self.live {
            server.pace(time_secs);
        }
        #[cfg(not(feature = "live"))]
        let _ = time_secs;
    }

    /// The file's path, if messages go to a file.
    pub fn path(&self) -> Option<&Path> {
        self.file.as_ref().map(McapLogger::path)
    }

    /// The file's channels with their message counts so far (empty without a file).
    pub fn channels(&self) -> Vec<ChannelInfo> {
        self.file
            .as_ref()
            .map_or_else(Vec::new, McapLogger::channels)
    }

    /// Finishes the file (see [`McapLogger::finish`]) and returns its channels with their
    /// message counts; empty without a file. The live view keeps serving until its last
    /// clone is dropped.
    pub fn finish(self) -> Result<Vec<ChannelInfo>, LogError> {
        self.file.map_or_else(|| Ok(Vec::new()), McapLogger::finish)
    }
}
