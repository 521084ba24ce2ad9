//! Reading a log back: channel list with message counts, and time series per channel.

use std::{
    collections::{BTreeMap, HashMap},
    fs::File,
    io::{BufReader, Read},
    path::{Path, PathBuf},
};

use mcap::{
    records::Record,
    sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions},
};
use serde::de::DeserializeOwned;
use serde_json::Value;

use super::{ChannelInfo, LogError, ns_to_secs, well_known};

/// One message as stored: log time and the encoded payload.
#[derive(Debug, Clone)]
struct StoredMessage {
    log_time_ns: u64,
    data: Vec<u8>,
}

/// An MCAP log read into memory, complete or recovered from a truncated file.
///
/// [`open`](Self::open) reads the data section from the start, record by record, and stops at
/// its end record. A file whose writer was killed has no end: reading stops at the first
/// incomplete record (the chunk that was open), every message of every complete chunk before it
/// is kept, and [`is_complete`](Self::is_complete) is `false`.
///
/// See [`McapLogger`](super::McapLogger) for an example.
#[derive(Debug, Clone)]
pub struct McapLog {
    path: PathBuf,
    channels: Vec<ChannelInfo>,
    messages: Vec<Vec<StoredMessage>>,
    complete: bool,
    stop_reason: Option<String>,
}

/// A channel's messages decoded as JSON values, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct JsonSeries {
    /// Log time of each message (s).
    pub time_secs: Vec<f64>,
    /// Each message as a JSON value.
    pub values: Vec<Value>,
}

/// A channel's numeric fields as columns of equal length, one row per message.
///
/// Nested fields are named by their path as in Foxglove's message paths, `body.tilt_rad`,
/// `wheels[2].normal_force_n`; a message that is a bare number gives the column `value`.
/// Numbers are read as `f64`, booleans as 0 or 1, `null` (how non-finite floats are logged) as
/// NaN; a field missing from a message is NaN in that row. Strings are left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NumericSeries {
    /// Log time of each row (s).
    pub time_secs: Vec<f64>,
    /// Columns by field path, sorted by name, each as long as `time_secs`.
    pub columns: BTreeMap<String, Vec<f64>>,
}

impl NumericSeries {
    /// The column of a field path, if any message had a numeric value there.
    pub fn column(&self, field: &str) -> Option<&[f64]> {
        self.columns.get(field).map(Vec::as_slice)
    }

    /// Number of rows (messages).
    pub fn len(&self) -> usize {
        self.time_secs.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.time_secs.is_empty()
    }
}

impl McapLog {
    /// Reads the log at `path`, recovering what a killed writer left (see the type's doc).
    ///
    /// Fails only when the file cannot be read at all or does not start as an MCAP file.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, LogError> {
        let path = path.as_ref().to_owned();
        let io_error = |source| LogError::Io {
            path: path.clone(),
            source,
        };
        let file = File::open(&path).map_err(io_error)?;
        let file_len = file.metadata().map_err(io_error)?.len();
        let mut source = BufReader::new(file);
        // A record cannot be longer than the file: this stops a placeholder length (left by a
        // killed writer) from asking for an absurd buffer.
        let limit = usize::try_from(file_len).unwrap_or(usize::MAX);
        let mut reader = LinearReader::new_with_options(
            LinearReaderOptions::default()
                .with_skip_end_magic(true)
                .with_record_length_limit(limit),
        );

        let mut log = Self {
            path: path.clone(),
            channels: Vec::new(),
            messages: Vec::new(),
            complete: false,
            stop_reason: None,
        };
        let mut schemas: HashMap<u16, (String, String, Vec<u8>)> = HashMap::new();
        let mut by_id: HashMap<u16, usize> = HashMap::new();
        let mut records_seen = 0_usize;

        while let Some(event) = reader.next_event() {
            let event = match event {
                Ok(event) => event,
                Err(error) => {
                    if records_seen == 0 {
                        return Err(LogError::Mcap {
                            path,
                            source: error,
                        });
                    }
                    log.stop_reason = Some(error.to_string());
                    break;
                }
            };
            match event {
                LinearReadEvent::ReadRequest(wanted) => {
                    let read = source.read(reader.insert(wanted)).map_err(io_error)?;
                    reader.notify_read(read);
                }
                LinearReadEvent::Record { data, opcode } => {
                    records_seen += 1;
                    let record = match mcap::parse_record(opcode, data) {
                        Ok(record) => record,
                        Err(error) => {
                            log.stop_reason = Some(error.to_string());
                            break;
                        }
                    };
                    match record {
                        Record::Schema { header, data } => {
                            schemas.insert(
                                header.id,
                                (header.name, header.encoding, data.into_owned()),
                            );
                        }
                        Record::Channel(channel) => {
                            if by_id.contains_key(&channel.id) {
                                continue;
                            }
                            let (schema_name, schema_encoding, schema) =
                                schemas.get(&channel.schema_id).cloned().unwrap_or_default();
                            by_id.insert(channel.id, log.channels.len());
                            log.channels.push(ChannelInfo {
                                id: channel.id,
                                topic: channel.topic,
                                schema_name,
                                schema_encoding,
                                schema,
                                message_encoding: channel.message_encoding,
                                message_count: 0,
                            });
                            log.messages.push(Vec::new());
                        }
                        Record::Message { header, data } => {
                            let Some(&index) = by_id.get(&header.channel_id) else {
                                log.stop_reason = Some(format!(
                                    "message on unknown channel id {}",
                                    header.channel_id
                                ));
                                break;
                            };
                            log.channels[index].message_count += 1;
                            log.messages[index].push(StoredMessage {
                                log_time_ns: header.log_time,
                                data: data.into_owned(),
                            });
                        }
                        Record::DataEnd(_) => {
                            log.complete = true;
                            break;
                        }
                        _ => {}
                    }
                }
            }
        }
        if !log.complete && log.stop_reason.is_none() {
            log.stop_reason = Some("the file ends before its data end record".to_owned());
        }
        Ok(log)
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the whole data section was read (the writer finished the file). `false` for a
    /// file recovered from a killed or crashed writer.
    pub fn is_complete(&self) -> bool {
        self.complete
    }

    /// Why reading stopped before the end of the data section, for an incomplete file.
    pub fn stop_reason(&self) -> Option<&str> {
        self.stop_reason.as_deref()
    }

    /// Every channel, in the order they appear in the file, with its message count.
    pub fn channels(&self) -> &[ChannelInfo] {
        &self.channels
    }

    /// The channel on `topic`, if there is one.
    pub fn channel(&self, topic: &str) -> Option<&ChannelInfo> {
        self.channels.iter().find(|c| c.topic == topic)
    }

    /// Total number of messages over all channels.
    pub fn message_count(&self) -> u64 {
        self.channels.iter().map(|c| c.message_count).sum()
    }

    /// The index of the channel on `topic`.
    fn channel_index(&self, topic: &str) -> Result<usize, LogError> {
        self.channels
            .iter()
            .position(|c| c.topic == topic)
            .ok_or_else(|| LogError::NoSuchTopic {
                path: self.path.clone(),
                topic: topic.to_owned(),
            })
    }

    /// The channel on `topic` and its messages, if they decode to JSON
    /// ([`well_known::decodable`]).
    fn decodable_messages(
        &self,
        topic: &str,
    ) -> Result<(&ChannelInfo, &[StoredMessage]), LogError> {
        let index = self.channel_index(topic)?;
        let channel = &self.channels[index];
        if !well_known::decodable(&channel.message_encoding, &channel.schema_name) {
            return Err(LogError::NotJson {
                path: self.path.clone(),
                topic: topic.to_owned(),
                encoding: channel.message_encoding.clone(),
            });
        }
        Ok((channel, &self.messages[index]))
    }

    /// Message `index` of `channel` as a JSON value.
    fn json_value(
        &self,
        channel: &ChannelInfo,
        index: usize,
        message: &StoredMessage,
    ) -> Result<Value, LogError> {
        well_known::to_json(
            &channel.message_encoding,
            &channel.schema_name,
            &message.data,
        )
        .map_err(|source| LogError::Decode {
            path: self.path.clone(),
            topic: channel.topic.clone(),
            index,
            source,
        })
    }

    /// Decodes every message of a channel into `T`, with its log time (s): a JSON channel, or a
    /// Foxglove well-known protobuf channel through its JSON form (the field and enum names of
    /// the Foxglove schema).
    pub fn decode<T: DeserializeOwned>(&self, topic: &str) -> Result<Vec<(f64, T)>, LogError> {
        let (channel, messages) = self.decodable_messages(topic)?;
        let decode_error = |index, source| LogError::Decode {
            path: self.path.clone(),
            topic: topic.to_owned(),
            index,
            source,
        };
        messages
            .iter()
            .enumerate()
            .map(|(index, message)| {
                let value = if channel.message_encoding == super::MESSAGE_ENCODING {
                    serde_json::from_slice(&message.data)
                        .map_err(|e| decode_error(index, e.into()))?
                } else {
                    serde_json::from_value(self.json_value(channel, index, message)?)
                        .map_err(|e| decode_error(index, e.into()))?
                };
                Ok((ns_to_secs(message.log_time_ns), value))
            })
            .collect()
    }

    /// Decodes every message of a protobuf channel into one of the Foxglove SDK's types (e.g.
    /// `foxglove::schemas::SceneUpdate`), with its log time (s).
    pub fn decode_protobuf<T: foxglove::Decode>(
        &self,
        topic: &str,
    ) -> Result<Vec<(f64, T)>, LogError>
    where
        T::Error: Send + Sync + 'static,
    {
        let index = self.channel_index(topic)?;
        if self.channels[index].message_encoding != "protobuf" {
            return Err(LogError::NotJson {
                path: self.path.clone(),
                topic: topic.to_owned(),
                encoding: self.channels[index].message_encoding.clone(),
            });
        }
        self.messages[index]
            .iter()
            .enumerate()
            .map(|(i, message)| {
                T::decode(message.data.as_slice())
                    .map(|value| (ns_to_secs(message.log_time_ns), value))
                    .map_err(|source| LogError::Decode {
                        path: self.path.clone(),
                        topic: topic.to_owned(),
                        index: i,
                        source: source.into(),
                    })
            })
            .collect()
    }

    /// A channel's messages as JSON values with their log times (JSON channels, and the
    /// Foxglove well-known protobuf messages).
    pub fn json_series(&self, topic: &str) -> Result<JsonSeries, LogError> {
        let decoded = self.decode::<Value>(topic)?;
        let (time_secs, values) = decoded.into_iter().unzip();
        Ok(JsonSeries { time_secs, values })
    }

    /// A channel's numeric fields as columns (see [`NumericSeries`]); JSON channels, and the
    /// Foxglove well-known protobuf messages.
    pub fn numeric_series(&self, topic: &str) -> Result<NumericSeries, LogError> {
        let (channel, messages) = self.decodable_messages(topic)?;
        let mut time_secs = Vec::with_capacity(messages.len());
        let mut columns: HashMap<String, Vec<f64>> = HashMap::new();
        let mut path = String::new();
        for (row, message) in messages.iter().enumerate() {
            let value = self.json_value(channel, row, message)?;
            time_secs.push(ns_to_secs(message.log_time_ns));
            path.clear();
            flatten(&value, &mut path, &mut |name, number| {
                let column = match columns.get_mut(name) {
                    Some(column) => column,
                    None => columns
                        .entry(name.to_owned())
                        .or_insert_with(|| Vec::with_capacity(messages.len())),
                };
                // A column first seen now, or a field repeated by a malformed message: align.
                column.resize(row, f64::NAN);
                column.push(number);
            });
            for column in columns.values_mut() {
                column.resize(row + 1, f64::NAN);
            }
        }
        Ok(NumericSeries {
            time_secs,
            columns: columns.into_iter().collect(),
        })
    }
}

impl McapLog {
    /// One numeric field over time, named by a Foxglove message path
    /// `/topic.field[index].subfield` (as in Foxglove's plot panel and the column names of
    /// [`NumericSeries`]): log times (s) and values.
    ///
    /// ```
    /// use ballbot_log::{LoggerOptions, McapLog, McapLogger};
    ///
    /// #[derive(serde::Serialize, schemars::JsonSchema)]
    /// struct Wheels {
    ///     normal_force_n: [f64; 3],
    /// }
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let dir = tempfile::tempdir()?;
    /// let path = dir.path().join("wheels.mcap");
    /// let mut log = McapLogger::create(&path, LoggerOptions::default())?;
    /// let wheels = log.channel::<Wheels>("/world/wheels")?;
    /// log.write(&wheels, 0.0, &Wheels { normal_force_n: [200.0, 210.0, 220.0] })?;
    /// log.write(&wheels, 0.5, &Wheels { normal_force_n: [190.0, 215.0, 225.0] })?;
    /// log.finish()?;
    ///
    /// let (time_secs, force_n) = McapLog::open(&path)?.field("/world/wheels.normal_force_n[1]")?;
    /// assert_eq!(time_secs, [0.0, 0.5]);
    /// assert_eq!(force_n, [210.0, 215.0]);
    /// # Ok(())
    /// # }
    /// ```
    pub fn field(&self, message_path: &str) -> Result<(Vec<f64>, Vec<f64>), LogError> {
        // The longest topic that the path starts with, followed by the field path.
        let channel = self
            .channels
            .iter()
            .filter(|c| {
                message_path
                    .strip_prefix(c.topic.as_str())
                    .is_some_and(|rest| rest.is_empty() || rest.starts_with('.'))
            })
            .max_by_key(|c| c.topic.len())
            .ok_or_else(|| LogError::NoSuchTopic {
                path: self.path.clone(),
                topic: message_path.to_owned(),
            })?;
        let field = message_path[channel.topic.len()..].trim_start_matches('.');
        let field = if field.is_empty() { "value" } else { field };
        let mut series = self.numeric_series(&channel.topic)?;
        let values = series
            .columns
            .remove(field)
            .ok_or_else(|| LogError::NoSuchField {
                path: self.path.clone(),
                topic: channel.topic.clone(),
                field: field.to_owned(),
            })?;
        Ok((series.time_secs, values))
    }
}

/// Calls `emit` with each numeric leaf of a JSON value and its Foxglove-style path, built in
/// `path` (left as it was found).
fn flatten(value: &Value, path: &mut String, emit: &mut impl FnMut(&str, f64)) {
    match value {
        Value::Number(number) => emit(leaf_name(path), number.as_f64().unwrap_or(f64::NAN)),
        Value::Bool(flag) => emit(leaf_name(path), if *flag { 1.0 } else { 0.0 }),
        Value::Null => emit(leaf_name(path), f64::NAN),
        Value::String(_) => {}
        Value::Array(elements) => {
            let base = path.len();
            for (i, element) in elements.iter().enumerate() {
                path.push('[');
                path.push_str(&i.to_string());
                path.push(']');
                flatten(element, path, emit);
                path.truncate(base);
            }
        }
        Value::Object(fields) => {
            let base = path.len();
            for (key, field) in fields {
                if base > 0 {
                    path.push('.');
                }
                path.push_str(key);
                flatten(field, path, emit);
                path.truncate(base);
            }
        }
    }
}

/// The column name of a leaf: its path, or `value` for a message that is a bare scalar.
fn leaf_name(path: &str) -> &str {
    if path.is_empty() { "value" } else { path }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn flatten_names_nested_paths_like_foxglove() {
        let mut out: Vec<(String, f64)> = Vec::new();
        let mut collect = |name: &str, v: f64| out.push((name.to_owned(), v));
        flatten(
            &json!({"body": {"tilt_rad": 0.1}, "wheels": [{"n": 1.0}, {"n": 2.0}], "ok": true, "name": "x"}),
            &mut String::new(),
            &mut collect,
        );
        out.sort_by(|a, b| a.0.cmp(&b.0));
        let names: Vec<&str> = out.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["body.tilt_rad", "ok", "wheels[0].n", "wheels[1].n"]);
        assert_eq!(out[1].1, 1.0);
        let mut scalar: Vec<(String, f64)> = Vec::new();
        let mut collect = |name: &str, v: f64| scalar.push((name.to_owned(), v));
        flatten(&json!(2.5), &mut String::new(), &mut collect);
        assert_eq!(scalar, [("value".to_owned(), 2.5)]);
    }
}
