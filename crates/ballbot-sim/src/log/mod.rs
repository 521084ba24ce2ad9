//! MCAP logging of simulated runs, and reading logs back.
//!
//! - [`McapLogger`] writes typed channels: JSON messages (`message_encoding = "json"`) with a
//!   JSON schema (`schema_encoding = "jsonschema"`) generated from the message type's
//!   [`schemars::JsonSchema`] derive, so Foxglove's plot panel sees every field with its type.
//!   Log time is simulated time. The file is written in bounded chunks and flushed at a fixed
//!   interval of simulated time, so a killed run leaves a readable file.
//! - [`McapLog`] reads a log (complete, or what a killed writer left): the channels with their
//!   message counts, and a channel's messages as JSON values, typed values, or numeric columns.
//! - [`foxglove`] has the well-known `foxglove.FrameTransform(s)` and `foxglove.SceneUpdate`
//!   messages, and [`foxglove::BallbotScene`] to see a ballbot in Foxglove's 3D panel.
//! - [`world`]: the 3D world's log ([`WorldLogger`]): telemetry, controller, commands,
//!   events and a Foxglove scene of a run.
//! - [`check_schema`] and [`check_message`] check schemas and messages against each other.
//!
//! Message types derive `serde::Serialize` and `schemars::JsonSchema`; doc comments become the
//! schema's field descriptions. Put units in field names (`tilt_rad`, `torque_nm`).
//!
//! See [`McapLogger`] for a complete write-and-read example.

mod error;
pub mod foxglove;
mod reader;
mod schema;
pub mod topics;
pub mod world;
mod writer;

pub use error::LogError;
pub use reader::{JsonSeries, McapLog, NumericSeries};
pub use schema::{
    MESSAGE_ENCODING, SCHEMA_ENCODING, SchemaViolation, check_message, check_schema, schema_for,
    schema_name_for,
};
pub use world::{WorldLogOptions, WorldLogger};
pub use writer::{
    Channel, ChannelInfo, LogCompression, LoggerOptions, McapLogger, ns_to_secs, secs_to_ns,
};
