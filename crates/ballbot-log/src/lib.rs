//! MCAP logging of simulated runs, and reading logs back.
//!
//! - [`McapLogger`] writes typed channels. Our own messages are JSON
//!   (`message_encoding = "json"`) with a JSON schema (`schema_encoding = "jsonschema"`)
//!   generated from the message type's [`schemars::JsonSchema`] derive ([`Json`]), so
//!   Foxglove's plot panel sees every field with its type. Foxglove's well-known messages come
//!   from the official SDK as protobuf with the SDK's schemas ([`Protobuf`]). Log time is
//!   simulated time. The file is written in bounded chunks and flushed at a fixed interval of
//!   simulated time, so a killed run leaves a readable file.
//! - [`McapLog`] reads a log (complete, or what a killed writer left): the channels with their
//!   message counts, and a channel's messages as JSON values, typed values, numeric columns,
//!   or the SDK's types ([`McapLog::decode_protobuf`]).
//! - [`foxglove`]: the SDK's `FrameTransforms`, `SceneUpdate`, `JointStates`, `Log`, ...,
//!   helpers to build them, and [`foxglove::BallbotScene`] to see a ballbot in Foxglove's 3D
//!   panel.
//! - [`LogSink`]: an MCAP file, a live view (`LiveServer`, feature `live`: the SDK's WebSocket
//!   server, which Foxglove connects to), or both.
//! - [`world`]: the 3D world's log ([`WorldLogger`]): telemetry, controller, commands,
//!   wheel joints, events and a Foxglove scene of a run.
//! - [`check_schema`] and [`check_message`] check schemas and messages against each other.
//!
//! Message types derive `serde::Serialize` and `schemars::JsonSchema`; doc comments become the
//! schema's field descriptions. Put units in field names (`tilt_rad`, `torque_nm`).
//!
//! See [`McapLogger`] for a complete write-and-read example.

mod codec;
mod error;
pub mod foxglove;
#[cfg(feature = "live")]
mod live;
pub mod planar;
mod reader;
mod schema;
mod sink;
pub mod topics;
mod well_known;
pub mod world;
mod writer;

pub use codec::{ChannelSchema, Codec, CodecError, Json, Protobuf};
pub use error::LogError;
#[cfg(feature = "live")]
pub use live::{LiveChannel, LiveOptions, LivePace, LiveServer};
pub use reader::{JsonSeries, McapLog, NumericSeries};
pub use schema::{
    MESSAGE_ENCODING, SCHEMA_ENCODING, SchemaViolation, check_message, check_schema, schema_for,
    schema_name_for,
};
pub use sink::{LogSink, SinkChannel};
pub use well_known::DECODED_SCHEMAS;
pub use world::{WorldLogOptions, WorldLogger};
pub use writer::{
    Channel, ChannelInfo, LogCompression, LoggerOptions, McapLogger, ns_to_secs, secs_to_ns,
};
