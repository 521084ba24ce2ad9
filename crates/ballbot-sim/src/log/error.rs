//! The error type of MCAP logging and reading.

use std::path::PathBuf;

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
    /// A message could not be encoded to JSON.
    #[error("cannot encode a message on topic {topic} for {path}: {source}")]
    Encode {
        /// The log file.
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// serde_json's error.
        #[source]
        source: serde_json::Error,
    },
    /// A schema could not be encoded to JSON.
    #[error("cannot encode the JSON schema {schema_name} for {path}: {source}")]
    Schema {
        /// The log file.
        path: PathBuf,
        /// The schema's name.
        schema_name: String,
        /// serde_json's error.
        #[source]
        source: serde_json::Error,
    },
    /// No channel with this topic exists in the log.
    #[error("no channel with topic {topic} in {path}")]
    NoSuchTopic {
        /// The log file.
        path: PathBuf,
        /// The requested topic.
        topic: String,
    },
    /// The channel's messages are not JSON encoded.
    #[error("topic {topic} in {path} has message encoding {encoding:?}, not \"json\"")]
    NotJson {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The channel's message encoding.
        encoding: String,
    },
    /// A message is not valid JSON, or does not decode into the requested type.
    #[error("message {index} on topic {topic} in {path} does not decode: {source}")]
    Decode {
        /// The log file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Index of the message in the channel (file order, from 0).
        index: usize,
        /// serde_json's error.
        #[source]
        source: serde_json::Error,
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
