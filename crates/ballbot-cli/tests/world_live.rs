//! `ballbot world --live`: a WebSocket client on the loopback address connects to the Foxglove
//! SDK's server as Foxglove would (subprotocol `foxglove.sdk.v1`), reads the advertised
//! channels, subscribes, and decodes the messages it is sent.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ballbot_sim::log::foxglove::{FrameTransforms, SceneUpdate};
use ballbot_sim::log::topics;
use ballbot_sim::log::world::WorldTelemetryMsg;
use foxglove::Decode;
use serde_json::{Value, json};
use tungstenite::client::IntoClientRequest;
use tungstenite::http::HeaderValue;
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// Opcode of a server's binary message-data frame (Foxglove WebSocket protocol).
const MESSAGE_DATA: u8 = 1;
/// Opcode of a server's binary time frame.
const TIME: u8 = 2;

type Socket = WebSocket<MaybeTlsStream<TcpStream>>;

fn connect(url: &str) -> Socket {
    let mut request = url.into_client_request().unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        HeaderValue::from_static("foxglove.sdk.v1"),
    );
    let (socket, response) = tungstenite::connect(request).unwrap();
    assert_eq!(
        response.headers()["Sec-WebSocket-Protocol"],
        "foxglove.sdk.v1"
    );
    if let MaybeTlsStream::Plain(tcp) = socket.get_ref() {
        tcp.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    }
    socket
}

/// What the client received: advertised channels by topic, and per subscribed topic the
/// (log time, payload) of each message.
#[derive(Default)]
struct Received {
    channels: BTreeMap<String, Value>,
    messages: BTreeMap<String, Vec<(u64, Vec<u8>)>>,
    times_ns: Vec<u64>,
    /// Status messages of the server (warnings and errors), for the failure message.
    statuses: Vec<String>,
    /// Subscriptions sent again after the server refused them as unknown channels.
    resubscribed: usize,
    /// When the first and the last telemetry message arrived.
    telemetry_wall: Option<(Instant, Instant)>,
}

#[test]
fn a_websocket_client_on_loopback_reads_the_live_channels_and_messages() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("live.mcap");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args([
            "world",
            "--live",
            "--live-port",
            "0",
            "--live-wait-secs",
            "30",
            "--duration-secs",
            "1.5",
            "--decimate",
            "8",
            "--top-speed-m-per-s",
            "0.3",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    let url = first
        .split_whitespace()
        .find(|w| w.starts_with("ws://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no address in {first:?}"))
        .to_owned();

    let mut socket = connect(&url);
    let mut got = Received::default();
    let wanted = [topics::WORLD_TELEMETRY, topics::SCENE, topics::TRANSFORMS];
    let mut subscription_topics: BTreeMap<u32, String> = BTreeMap::new();
    let deadline = Instant::now() + Duration::from_secs(60);
    while Instant::now() < deadline {
        let message = match socket.read() {
            Ok(message) => message,
            Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => break,
            Err(tungstenite::Error::Protocol(_) | tungstenite::Error::Io(_)) => break,
            Err(e) => panic!("{e}"),
        };
        match message {
            Message::Text(text) => {
                let value: Value = serde_json::from_str(&text).unwrap();
                if value["op"] == "advertise" {
                    for channel in value["channels"].as_array().unwrap() {
                        let topic = channel["topic"].as_str().unwrap().to_owned();
                        got.channels.insert(topic, channel.clone());
                    }
                } else if value["op"] == "status" {
                    got.statuses.push(value.to_string());
                    // The SDK can refuse a subscription sent in the instant between a
                    // channel's advertisement and its registration for this client
                    // (docs/world-logs.md): subscribe again, as a robust client does.
                    let refused = value["message"]
                        .as_str()
                        .and_then(|m| m.strip_prefix("Unknown channel ID: "))
                        .and_then(|id| id.trim().parse::<u64>().ok());
                    if let Some(channel_id) = refused {
                        let again: Vec<Value> = subscription_topics
                            .iter()
                            .filter(|(_, topic)| got.channels[topic.as_str()]["id"] == channel_id)
                            .map(|(id, _)| json!({"id": id, "channelId": channel_id}))
                            .collect();
                        std::thread::sleep(Duration::from_millis(5));
                        let subscribe = json!({"op": "subscribe", "subscriptions": again});
                        socket.send(Message::text(subscribe.to_string())).unwrap();
                        got.resubscribed += again.len();
                    }
                }
                // Subscribe once every wanted channel has been advertised, as a panel does
                // once it knows its topics (the server advertises each as the run adds it).
                if subscription_topics.is_empty()
                    && wanted.iter().all(|t| got.channels.contains_key(*t))
                {
                    let mut subscriptions = Vec::new();
                    for topic in wanted {
                        let id = u32::try_from(subscription_topics.len() + 1).unwrap();
                        subscription_topics.insert(id, topic.to_owned());
                        let channel_id = &got.channels[topic]["id"];
                        subscriptions.push(json!({"id": id, "channelId": channel_id}));
                    }
                    let subscribe = json!({"op": "subscribe", "subscriptions": subscriptions});
                    socket.send(Message::text(subscribe.to_string())).unwrap();
                }
            }
            Message::Binary(data) => match data[0] {
                MESSAGE_DATA => {
                    let id = u32::from_le_bytes(data[1..5].try_into().unwrap());
                    let time_ns = u64::from_le_bytes(data[5..13].try_into().unwrap());
                    let topic = subscription_topics[&id].clone();
                    if topic == topics::WORLD_TELEMETRY {
                        let now = Instant::now();
                        let first = got.telemetry_wall.map_or(now, |(first, _)| first);
                        got.telemetry_wall = Some((first, now));
                    }
                    got.messages
                        .entry(topic)
                        .or_default()
                        .push((time_ns, data[13..].to_vec()));
                }
                TIME => got
                    .times_ns
                    .push(u64::from_le_bytes(data[1..9].try_into().unwrap())),
                other => panic!("unexpected binary opcode {other}"),
            },
            Message::Close(_) => break,
            _ => {}
        }
    }
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}");
    // Any other status is a failure; a refused subscription was sent again.
    println!(
        "statuses {:?}; subscriptions sent again: {}",
        got.statuses, got.resubscribed
    );
    assert!(
        got.statuses.iter().all(|s| s.contains("Unknown channel")),
        "{:?}",
        got.statuses
    );

    // The advertised channels: ours as JSON with JSON schemas, Foxglove's as protobuf.
    for topic in [
        topics::WORLD_TELEMETRY,
        topics::WORLD_CONTROLLER,
        topics::FAULTS,
    ] {
        let channel = &got.channels[topic];
        assert_eq!(channel["encoding"], "json", "{topic}");
        assert_eq!(channel["schemaEncoding"], "jsonschema", "{topic}");
        let schema: Value = serde_json::from_str(channel["schema"].as_str().unwrap()).unwrap();
        assert_eq!(schema["type"], "object");
    }
    for (topic, name) in [
        (topics::SCENE, "foxglove.SceneUpdate"),
        (topics::TRANSFORMS, "foxglove.FrameTransforms"),
        (topics::JOINT_STATES, "foxglove.JointStates"),
        (topics::LOG, "foxglove.Log"),
    ] {
        let channel = &got.channels[topic];
        assert_eq!(channel["encoding"], "protobuf", "{topic}");
        assert_eq!(channel["schemaName"], name);
        assert_eq!(channel["schemaEncoding"], "protobuf");
    }

    // Messages of each subscribed channel, stamped with simulated time, decoding as sent.
    let counts: BTreeMap<&str, usize> = got
        .messages
        .iter()
        .map(|(t, m)| (t.as_str(), m.len()))
        .collect();
    let telemetry = got
        .messages
        .get(topics::WORLD_TELEMETRY)
        .unwrap_or_else(|| {
            panic!(
                "no telemetry; received {counts:?}, {} time frames",
                got.times_ns.len()
            )
        });
    assert!(
        telemetry.len() > 100,
        "{} telemetry messages",
        telemetry.len()
    );
    for (time_ns, payload) in telemetry {
        let msg: WorldTelemetryMsg = serde_json::from_slice(payload).unwrap();
        assert_eq!(*time_ns, (msg.step.time_secs * 1e9).round() as u64);
    }
    let scenes = got.messages.get(topics::SCENE).unwrap_or_else(|| {
        panic!(
            "no scene; received {counts:?}, statuses {:?}, channels {:?}",
            got.statuses,
            got.channels.keys().collect::<Vec<_>>()
        )
    });
    assert!(!scenes.is_empty());
    let scene = SceneUpdate::decode(scenes[0].1.as_slice()).unwrap();
    let ids: Vec<&str> = scene.entities.iter().map(|e| e.id.as_str()).collect();
    assert!(
        ids.contains(&"ball") && ids.contains(&"contact_forces"),
        "{ids:?}"
    );
    let frames = &got.messages[topics::TRANSFORMS];
    let tf = FrameTransforms::decode(frames[frames.len() - 1].1.as_slice()).unwrap();
    assert_eq!(tf.transforms.len(), 5);
    // Paced to real time: the telemetry arrived over as much wall time as it spans in
    // simulated time (as fast as possible, the run takes a fraction of it), and the server's
    // clock follows the simulation.
    let sim_span_secs = (telemetry[telemetry.len() - 1].0 - telemetry[0].0) as f64 * 1e-9;
    let (first, last) = got.telemetry_wall.unwrap();
    let wall_span_secs = (last - first).as_secs_f64();
    assert!(sim_span_secs > 1.0, "{sim_span_secs} s");
    assert!(
        wall_span_secs > 0.9 * sim_span_secs,
        "{wall_span_secs} s of wall time for {sim_span_secs} s simulated"
    );
    assert!(got.times_ns.windows(2).all(|w| w[0] <= w[1]));
    assert!(
        got.times_ns.len() > 10,
        "{} time frames",
        got.times_ns.len()
    );
    // The file was written as well.
    let log = ballbot_sim::log::McapLog::open(&out).unwrap();
    assert!(log.is_complete());
    assert_eq!(
        log.channel(topics::WORLD_TELEMETRY)
            .map(|c| c.message_count),
        Some(1500)
    );
}

#[test]
fn live_flags_are_checked() {
    let output = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["world", "--as-fast-as-possible"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--live"), "{stderr}");
    let output = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["world", "--live", "--live-wait-secs=-1"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--live-wait-secs"), "{stderr}");
}
