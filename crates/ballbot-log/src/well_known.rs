//! The Foxglove well-known protobuf messages that the reader decodes, by schema name, into
//! the SDK's types or into JSON values (with the field names and enum names of the Foxglove
//! schemas, as Foxglove shows them).

use foxglove::Decode;
use foxglove::schemas::{FrameTransform, FrameTransforms, JointStates, Log, SceneUpdate};
use serde_json::Value;

use super::codec::CodecError;

/// The schema names that [`McapLog`](super::McapLog) decodes from protobuf: the messages the
/// world's log writes, and the single frame transform.
pub const DECODED_SCHEMAS: [&str; 5] = [
    "foxglove.FrameTransform",
    "foxglove.FrameTransforms",
    "foxglove.JointStates",
    "foxglove.Log",
    "foxglove.SceneUpdate",
];

fn json_of<T: Decode + serde::Serialize>(data: &[u8]) -> Result<Value, CodecError>
where
    T::Error: Send + Sync + 'static,
{
    Ok(serde_json::to_value(T::decode(data)?)?)
}

/// Whether a channel with this encoding and schema decodes to JSON: `json` messages, and the
/// protobuf messages of [`DECODED_SCHEMAS`].
pub fn decodable(message_encoding: &str, schema_name: &str) -> bool {
    message_encoding == super::MESSAGE_ENCODING
        || (message_encoding == "protobuf" && DECODED_SCHEMAS.contains(&schema_name))
}

/// Decodes one message into a JSON value: JSON as is, a protobuf message of a schema in
/// [`DECODED_SCHEMAS`] through its SDK type.
pub fn to_json(
    message_encoding: &str,
    schema_name: &str,
    data: &[u8],
) -> Result<Value, CodecError> {
    if message_encoding == super::MESSAGE_ENCODING {
        return Ok(serde_json::from_slice(data)?);
    }
    match schema_name {
        "foxglove.FrameTransform" => json_of::<FrameTransform>(data),
        "foxglove.FrameTransforms" => json_of::<FrameTransforms>(data),
        "foxglove.JointStates" => json_of::<JointStates>(data),
        "foxglove.Log" => json_of::<Log>(data),
        "foxglove.SceneUpdate" => json_of::<SceneUpdate>(data),
        other => Err(format!("no decoder for {message_encoding} schema {other:?}").into()),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::codec::{Codec, Protobuf};

    #[test]
    fn every_decoded_schema_name_is_the_sdk_types_own() {
        let names = [
            <Protobuf as Codec<FrameTransform>>::schema().unwrap().name,
            <Protobuf as Codec<FrameTransforms>>::schema().unwrap().name,
            <Protobuf as Codec<JointStates>>::schema().unwrap().name,
            <Protobuf as Codec<Log>>::schema().unwrap().name,
            <Protobuf as Codec<SceneUpdate>>::schema().unwrap().name,
        ];
        assert_eq!(names, DECODED_SCHEMAS);
    }

    #[test]
    fn log_levels_decode_to_their_names() {
        let log = Log {
            level: foxglove::schemas::log::Level::Warning as i32,
            message: "slip on OW2".to_owned(),
            ..Log::default()
        };
        let mut data = Vec::new();
        Protobuf::encode(&log, &mut data).unwrap();
        let value = to_json("protobuf", "foxglove.Log", &data).unwrap();
        assert_eq!(value["level"], "WARNING");
        assert_eq!(value["message"], "slip on OW2");
        assert!(to_json("protobuf", "foxglove.Grid", &data).is_err());
    }
}
