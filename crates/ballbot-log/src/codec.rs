//! How a channel's messages are encoded: JSON with a JSON schema ([`Json`], our own typed
//! channels) or protobuf with its file descriptor set ([`Protobuf`], the Foxglove SDK's
//! well-known messages such as `foxglove.SceneUpdate`).
//!
//! A [`Codec`] gives a channel's [`ChannelSchema`] (what an MCAP file and a Foxglove WebSocket
//! client are told about the channel) and encodes each message. [`McapLogger`] and
//! [`LiveServer`] take the codec as the second type parameter of their channel handles, so a
//! message can only be written with the encoding its channel announced.
//!
//! [`McapLogger`]: super::McapLogger
//! [`LiveServer`]: super::LiveServer

use schemars::JsonSchema;
use serde::Serialize;

use super::schema::{MESSAGE_ENCODING, SCHEMA_ENCODING, schema_for, schema_name_for};

/// The error of a codec: what serde_json or prost reported.
pub type CodecError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// What a channel announces about its messages.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelSchema {
    /// The schema's name, e.g. `ballbot.WorldTelemetryMsg` or `foxglove.SceneUpdate`.
    pub name: String,
    /// The schema encoding: `jsonschema` or `protobuf`.
    pub encoding: String,
    /// The schema document: a JSON schema (UTF-8) or a serialised protobuf
    /// `FileDescriptorSet`.
    pub data: Vec<u8>,
    /// The message encoding: `json` or `protobuf`.
    pub message_encoding: String,
}

/// Encodes messages of type `T` for a channel.
pub trait Codec<T: ?Sized> {
    /// The schema of the channel's messages.
    fn schema() -> Result<ChannelSchema, CodecError>;

    /// Appends the encoded `message` to `buf`.
    fn encode(message: &T, buf: &mut Vec<u8>) -> Result<(), CodecError>;
}

/// JSON messages with the JSON schema generated from the type's [`JsonSchema`] derive, named
/// by [`schema_name_for`](super::schema_name_for). Floats that are not finite are written as
/// `null`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Json;

impl Json {
    /// The schema of `T` under an explicit name.
    pub fn schema_named<T: JsonSchema + ?Sized>(name: &str) -> Result<ChannelSchema, CodecError> {
        Ok(ChannelSchema {
            name: name.to_owned(),
            encoding: SCHEMA_ENCODING.to_owned(),
            data: serde_json::to_vec(&schema_for::<T>())?,
            message_encoding: MESSAGE_ENCODING.to_owned(),
        })
    }
}

impl<T: Serialize + JsonSchema + ?Sized> Codec<T> for Json {
    fn schema() -> Result<ChannelSchema, CodecError> {
        Self::schema_named::<T>(&schema_name_for::<T>())
    }

    fn encode(message: &T, buf: &mut Vec<u8>) -> Result<(), CodecError> {
        serde_json::to_writer(buf, message)?;
        Ok(())
    }
}

/// The Foxglove SDK's protobuf messages (`foxglove::schemas`), with the schema the SDK ships
/// for each: a `FileDescriptorSet` under the well-known name (`foxglove.SceneUpdate`,
/// `foxglove.FrameTransforms`, `foxglove.JointStates`, `foxglove.Log`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Protobuf;

impl<T: foxglove::Encode> Codec<T> for Protobuf
where
    T::Error: Send + Sync + 'static,
{
    fn schema() -> Result<ChannelSchema, CodecError> {
        let schema = T::get_schema().ok_or("the message type has no schema")?;
        Ok(ChannelSchema {
            name: schema.name,
            encoding: schema.encoding,
            data: schema.data.into_owned(),
            message_encoding: T::get_message_encoding(),
        })
    }

    fn encode(message: &T, buf: &mut Vec<u8>) -> Result<(), CodecError> {
        if let Some(len) = message.encoded_len() {
            buf.reserve(len);
        }
        message.encode(buf)?;
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use foxglove::Decode;
    use foxglove::schemas::{FrameTransforms, SceneUpdate};

    #[test]
    fn protobuf_codec_names_the_well_known_schema_and_round_trips() {
        let schema = <Protobuf as Codec<SceneUpdate>>::schema().unwrap();
        assert_eq!(schema.name, "foxglove.SceneUpdate");
        assert_eq!(schema.encoding, "protobuf");
        assert_eq!(schema.message_encoding, "protobuf");
        assert!(!schema.data.is_empty());
        let tf = FrameTransforms {
            transforms: vec![foxglove::schemas::FrameTransform {
                parent_frame_id: "world".to_owned(),
                child_frame_id: "body".to_owned(),
                ..Default::default()
            }],
        };
        let mut buf = Vec::new();
        Protobuf::encode(&tf, &mut buf).unwrap();
        assert_eq!(FrameTransforms::decode(buf.as_slice()).unwrap(), tf);
    }

    #[test]
    fn json_codec_writes_the_json_schema_and_null_for_non_finite_floats() {
        #[derive(Serialize, JsonSchema)]
        struct Tilt {
            /// Tilt (rad).
            tilt_rad: f64,
        }
        let schema = <Json as Codec<Tilt>>::schema().unwrap();
        assert_eq!(schema.name, "ballbot.Tilt");
        assert_eq!(
            (schema.encoding.as_str(), schema.message_encoding.as_str()),
            ("jsonschema", "json")
        );
        let mut buf = Vec::new();
        Json::encode(&Tilt { tilt_rad: f64::NAN }, &mut buf).unwrap();
        assert_eq!(buf, br#"{"tilt_rad":null}"#);
    }
}
