//! The error type of MCAP logging and reading.

use std::path::PathBuf;

use super::codec::CodecError;

/// What went wrong while writing or reading an MCAP log. Every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// The file could not be created, opened, read or flushed.
    #[error("I/O error on MCAP log {path}: {source}")]
    Io {
        /// The log file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The `mcap` crate rejected a record, or the file is not MCAP.
    #[error("MCAP error in {path}: {source}")]
    Mcap {
        /// The log file.
        path: PathBuf,
        /// The `mcap` crate's error.
        #[source]
        source: mcap::McapError,
    },
    /// A logger option is out of range (checked once, when the logger is created).
    #[error("invalid logger option `{field}` for {path}: must be {requirement}")]
    InvalidOption {
        /// The log file.
        path: PathBuf,
        /// The option's field name in [`LoggerOptions`](super::LoggerOptions).
        field: &'static str,
        /// What the value must satisfy.
        requirement: &'static str,
    },
    /// A message's time stamp cannot be a log time (negative, not finite, or beyond 2^64 ns).
    #[error(
        "invalid log time {time_secs} s on topic {topic} in {path}: must be finite, >= 0 and < 1.8e10 s"
    )]
    InvalidTime {
        /// The log file.
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// The rejected time stamp in seconds.
        time_secs: f64,
    },
    /// A second channel was registered on a topic that already has one.
    #[error("topic {topic} is already registered in {path}")]
    DuplicateTopic {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A [`Channel`](super::Channel) handle was used with a logger that did not create it.
    #[error(
        "channel handle for topic {topic} belongs to another logger than the one writing {path}"
    )]
    ForeignChannel {
        /// The log file.
        path: PathBuf,
        /// The topic the handle was created for.
        topic: String,
    },
    /// Writing after [`McapLogger::finish`](super::McapLogger::finish) or after a failed write.
    #[error("MCAP log {path} is already finished")]
    Finished {
        /// The log file.
        path: PathBuf,
    },
    /// A message could not be encoded (JSON or protobuf).
    #[error("cannot encode a message on topic {topic} for {path}: {source}")]
    Encode {
        /// The log file (or the live view's address).
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// The codec's error.
        #[source]
        source: CodecError,
    },
    /// A channel's schema could not be produced.
    #[error("cannot produce the schema of topic {topic} for {path}: {source}")]
    Schema {
        /// The log file (or the live view's address).
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// The codec's error.
        #[source]
        source: CodecError,
    },
    /// The live view's server could not start, or refused a channel.
    #[error("live view on {address}: {source}")]
    Live {
        /// The address served, `host:port` or `ws://host:port`.
        address: String,
        /// The Foxglove SDK's error.
        #[source]
        source: foxglove::FoxgloveError,
    },
    /// No channel with this topic exists in the log.
    #[error("no channel with topic {topic} in {path}")]
    NoSuchTopic {
        /// The log file.
        path: PathBuf,
        /// The requested topic.
        topic: String,
    },
    /// The channel's messages are in an encoding this reader cannot decode: JSON, and the
    /// Foxglove well-known protobuf messages (by schema name) are decoded.
    #[error(
        "topic {topic} in {path} has message encoding {encoding:?}, which is neither \"json\" \
         nor a Foxglove well-known protobuf message"
    )]
    NotJson {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The channel's message encoding.
        encoding: String,
    },
    /// A message is not valid JSON (or protobuf), or does not decode into the requested type.
    #[error("message {index} on topic {topic} in {path} does not decode: {source}")]
    Decode {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Index of the message in the channel (file order, from 0).
        index: usize,
        /// serde_json's or prost's error.
        #[source]
        source: CodecError,
    },
    /// A message path names no numeric field of its channel.
    #[error("no numeric field {field} in topic {topic} of {path}")]
    NoSuchField {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The field path, e.g. `wheels[0].normal_force_n`.
        field: String,
    },
}
