//! The live view: a running simulation served to Foxglove over the Foxglove SDK's WebSocket
//! server (feature `live`).
//!
//! A [`LiveServer`] listens on an address; Foxglove (Open connection, Foxglove WebSocket,
//! `ws://127.0.0.1:8765`) connects, sees the advertised channels and plots and draws what the
//! simulation writes. Channels carry the same encodings and schemas as the MCAP log
//! ([`Codec`]), and messages are stamped with simulated time, which the server also
//! broadcasts as its clock. [`LiveServer::pace`] holds the simulation to real time
//! ([`LivePace::RealTime`]) or lets it run as fast as it can.

use std::marker::PhantomData;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use foxglove::websocket::Capability;
use foxglove::{
    Context, PartialMetadata, RawChannel, Schema, WebSocketServer, WebSocketServerHandle,
};

use super::codec::{Codec, Json};
use super::{LogError, secs_to_ns};

/// How the simulation is paced while it is served.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LivePace {
    /// Simulated time follows the wall clock (a simulation slower than real time runs as
    /// fast as it can, without catching up later).
    #[default]
    RealTime,
    /// As fast as the simulation runs.
    AsFastAsPossible,
}

/// Where and how a [`LiveServer`] serves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiveOptions {
    /// Address to listen on. Default `127.0.0.1` (this machine only); `0.0.0.0` serves the
    /// network.
    pub host: String,
    /// Port to listen on; 0 picks a free one ([`LiveServer::port`] tells which). Default 8765,
    /// Foxglove's default.
    pub port: u16,
    /// Pacing of the simulation. Default [`LivePace::RealTime`].
    pub pace: LivePace,
    /// Server name shown by Foxglove. Default `ballbot`.
    pub name: String,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            host: "127.0.0.1".to_owned(),
            port: 8765,
            pace: LivePace::RealTime,
            name: "ballbot".to_owned(),
        }
    }
}

/// A typed handle to a channel of a [`LiveServer`].
pub struct LiveChannel<T, C = Json> {
    raw: Arc<RawChannel>,
    _message: PhantomData<fn(&T, C)>,
}

impl<T, C> Clone for LiveChannel<T, C> {
    fn clone(&self) -> Self {
        Self {
            raw: Arc::clone(&self.raw),
            _message: PhantomData,
        }
    }
}

impl<T, C> std::fmt::Debug for LiveChannel<T, C> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveChannel")
            .field("topic", &self.raw.topic())
            .finish()
    }
}

/// The wall-clock instant at which a simulated time was reached.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    wall: Instant,
    sim_secs: f64,
}

struct Shared {
    context: Arc<Context>,
    server: Mutex<Option<WebSocketServerHandle>>,
    port: u16,
    host: String,
    pace: LivePace,
    clock: Mutex<Clock>,
    /// Every channel registered, to tell whether a client subscribed to one.
    channels: Mutex<Vec<Arc<RawChannel>>>,
}

/// The pacing state: where simulated time was anchored to the wall clock, and when the
/// server's clock is next broadcast.
#[derive(Debug, Default)]
struct Clock {
    anchor: Option<Anchor>,
    next_broadcast_secs: f64,
}

impl Shared {
    /// Stops the server, once: clients are disconnected and the port is freed.
    fn stop(&self) {
        let server = self
            .server
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        if let Some(server) = server {
            server.stop().wait_blocking();
        }
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        self.stop();
    }
}

/// A Foxglove WebSocket server that a simulation writes to as it runs.
///
/// Clones share the server; it stops when the last clone is dropped (or at
/// [`stop`](Self::stop)).
///
/// ```
/// use ballbot_log::{LiveOptions, LivePace, LiveServer};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// #[derive(serde::Serialize, schemars::JsonSchema)]
/// struct Tilt {
///     /// Body tilt (rad).
///     tilt_rad: f64,
/// }
/// let options = LiveOptions { port: 0, pace: LivePace::AsFastAsPossible, ..LiveOptions::default() };
/// let mut live = LiveServer::start(options)?;
/// println!("open {} in Foxglove", live.url());
/// let tilt = live.channel::<Tilt>("/tilt")?;
/// for step in 0..400 {
///     let time_secs = f64::from(step) / 400.0;
///     live.pace(time_secs);
///     live.write(&tilt, time_secs, &Tilt { tilt_rad: 0.01 * time_secs })?;
/// }
/// live.stop();
/// # Ok(())
/// # }
/// ```
#[derive(Clone)]
pub struct LiveServer {
    shared: Arc<Shared>,
    buffer: Vec<u8>,
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer")
            .field("url", &self.url())
            .field("pace", &self.shared.pace)
            .finish()
    }
}

/// Simulated time between two broadcasts of the server's clock (s).
const TIME_BROADCAST_SECS: f64 = 0.01;

impl LiveServer {
    /// Starts serving on `options.host:options.port`.
    pub fn start(options: LiveOptions) -> Result<Self, LogError> {
        let context = Context::new();
        let server = WebSocketServer::new()
            .name(options.name.clone())
            .bind(options.host.clone(), options.port)
            .capabilities([Capability::Time])
            .context(&context)
            .start_blocking()
            .map_err(|source| LogError::Live {
                address: format!("{}:{}", options.host, options.port),
                source,
            })?;
        let port = server.port();
        Ok(Self {
            shared: Arc::new(Shared {
                context,
                server: Mutex::new(Some(server)),
                port,
                host: options.host,
                pace: options.pace,
                clock: Mutex::new(Clock::default()),
                channels: Mutex::new(Vec::new()),
            }),
            buffer: Vec::new(),
        })
    }

    /// The port listened on.
    pub fn port(&self) -> u16 {
        self.shared.port
    }

    /// The address to give Foxglove, `ws://host:port`.
    pub fn url(&self) -> String {
        format!("ws://{}:{}", self.shared.host, self.shared.port)
    }

    /// The pacing in use.
    pub fn pace_mode(&self) -> LivePace {
        self.shared.pace
    }

    /// How many clients are connected.
    pub fn client_count(&self) -> usize {
        self.with_server(WebSocketServerHandle::client_count)
            .unwrap_or(0)
    }

    /// Waits until at least one client is connected or `timeout` has passed; whether one is.
    pub fn wait_for_client(&self, timeout: Duration) -> bool {
        // `None`: a timeout too long to represent, i.e. wait for ever.
        let deadline = Instant::now().checked_add(timeout);
        while self.client_count() == 0 {
            if deadline.is_some_and(|d| Instant::now() >= d) {
                return false;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        true
    }

    /// Waits until a client has subscribed to at least one channel registered so far, or
    /// `timeout` has passed; whether one has. A run that registers its channels, then waits
    /// here, is seen by Foxglove from its first step.
    pub fn wait_for_subscriber(&self, timeout: Duration) -> bool {
        let deadline = Instant::now().checked_add(timeout);
        loop {
            let subscribed = self
                .shared
                .channels
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .iter()
                .any(|c| c.has_sinks());
            if subscribed {
                return true;
            }
            if deadline.is_some_and(|d| Instant::now() >= d) {
                return false;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    fn with_server<R>(&self, f: impl FnOnce(&WebSocketServerHandle) -> R) -> Option<R> {
        let server = self
            .shared
            .server
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        server.as_ref().map(f)
    }

    /// The file-like name of this server in errors.
    fn error_path(&self) -> PathBuf {
        PathBuf::from(self.url())
    }

    /// Registers (or joins, if an identical one exists) a channel on `topic` whose messages
    /// `C` encodes.
    pub fn channel_with<T, C: Codec<T>>(
        &mut self,
        topic: &str,
    ) -> Result<LiveChannel<T, C>, LogError> {
        let schema = C::schema().map_err(|source| LogError::Schema {
            path: self.error_path(),
            topic: topic.to_owned(),
            source,
        })?;
        let raw = self
            .shared
            .context
            .channel_builder(topic)
            .schema(Schema::new(schema.name, schema.encoding, schema.data))
            .message_encoding(schema.message_encoding)
            .build_raw()
            .map_err(|source| LogError::Live {
                address: self.url(),
                source,
            })?;
        self.shared
            .channels
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(Arc::clone(&raw));
        Ok(LiveChannel {
            raw,
            _message: PhantomData,
        })
    }

    /// Registers a JSON channel on `topic` (as [`McapLogger::channel`](super::McapLogger::channel)).
    pub fn channel<T: serde::Serialize + schemars::JsonSchema>(
        &mut self,
        topic: &str,
    ) -> Result<LiveChannel<T>, LogError> {
        self.channel_with::<T, Json>(topic)
    }

    /// Sends one message stamped with simulated time `time_secs` to the clients subscribed to
    /// its channel (nothing is encoded while none is).
    pub fn write<T, C: Codec<T>>(
        &mut self,
        channel: &LiveChannel<T, C>,
        time_secs: f64,
        message: &T,
    ) -> Result<(), LogError> {
        if !channel.raw.has_sinks() {
            return Ok(());
        }
        let Some(time_ns) = secs_to_ns(time_secs) else {
            return Err(LogError::InvalidTime {
                path: self.error_path(),
                topic: channel.raw.topic().to_owned(),
                time_secs,
            });
        };
        self.buffer.clear();
        C::encode(message, &mut self.buffer).map_err(|source| LogError::Encode {
            path: self.error_path(),
            topic: channel.raw.topic().to_owned(),
            source,
        })?;
        channel
            .raw
            .log_with_meta(&self.buffer, PartialMetadata::with_log_time(time_ns));
        Ok(())
    }

    /// Called once per simulation step with the simulated time reached: with
    /// [`LivePace::RealTime`] it sleeps until the wall clock has caught up with it (a run
    /// that restarts at an earlier time, or falls behind by more than half a second,
    /// re-anchors the clock), and it broadcasts the simulated time as the server's clock
    /// every 10 ms of simulated time.
    pub fn pace(&self, time_secs: f64) {
        if !time_secs.is_finite() {
            return;
        }
        let now = Instant::now();
        let mut clock = self
            .shared
            .clock
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        let anchor = match clock.anchor {
            Some(a) if time_secs >= a.sim_secs => a,
            _ => {
                clock.next_broadcast_secs = time_secs;
                let a = Anchor {
                    wall: now,
                    sim_secs: time_secs,
                };
                clock.anchor = Some(a);
                a
            }
        };
        let broadcast = time_secs >= clock.next_broadcast_secs;
        if broadcast {
            clock.next_broadcast_secs = time_secs + TIME_BROADCAST_SECS;
        }
        let mut wait = Duration::ZERO;
        if self.shared.pace == LivePace::RealTime {
            let target = anchor.wall + Duration::from_secs_f64(time_secs - anchor.sim_secs);
            if target > now {
                wait = target - now;
            } else if now - target > Duration::from_millis(500) {
                clock.anchor = Some(Anchor {
                    wall: now,
                    sim_secs: time_secs,
                });
            }
        }
        drop(clock);
        // Sleep only a millisecond or more at a time: the step rate is far higher.
        if wait >= Duration::from_millis(1) {
            std::thread::sleep(wait);
        }
        if broadcast {
            self.broadcast_time(time_secs);
        }
    }

    fn broadcast_time(&self, time_secs: f64) {
        if let Some(time_ns) = secs_to_ns(time_secs) {
            self.with_server(|s| s.broadcast_time(time_ns));
        }
    }

    /// Stops the server now (otherwise it stops when the last clone is dropped): clients are
    /// disconnected and the port is freed.
    pub fn stop(&self) {
        self.shared.stop();
    }
}
