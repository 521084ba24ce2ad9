//! The committed Foxglove layout refers only to panels it defines, to the shared topic names,
//! and to the frames [`BallbotScene`] publishes.

use std::collections::BTreeSet;

use ballbot_sim::{
    log::planar::{PlanarCommandMsg, PlanarControlMsg, PlanarStateMsg},
    log::world::{WorldCommandMsg, WorldTelemetryMsg},
    log::{foxglove::BallbotScene, schema_for, topics},
};
use serde_json::Value;

fn layout() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../foxglove/ballbot-layout.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Panel ids placed in a layout tree (a panel id, or a split with `first` and `second`),
/// following tab panels into their tabs.
fn placed_panels(node: &Value, config: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => {
            out.push(id.clone());
            if id.starts_with("Tab!") {
                for tab in config[id]["tabs"].as_array().unwrap() {
                    placed_panels(&tab["layout"], config, out);
                }
            }
        }
        Value::Object(split) => {
            assert!(["row", "column"].contains(&split["direction"].as_str().unwrap()));
            placed_panels(&split["first"], config, out);
            placed_panels(&split["second"], config, out);
        }
        other => panic!("unexpected layout node {other}"),
    }
}

/// Splits a Foxglove message path `/topic.field[0].sub` into topic and field path.
fn split_message_path(path: &str) -> (&str, &str) {
    match path.find('.') {
        Some(dot) => (&path[..dot], &path[dot..]),
        None => (path, ""),
    }
}

fn is_field_path(fields: &str) -> bool {
    fields.split('.').skip(1).all(|part| {
        let name = part.split('[').next().unwrap_or("");
        !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
            && part[name.len()..].split_terminator(']').all(|index| {
                index
                    .strip_prefix('[')
                    .is_some_and(|i| i.parse::<usize>().is_ok())
            })
    }) && fields.starts_with('.')
}

/// The message schema logged on a topic, for the topics whose message types exist so far.
fn logged_schema(topic: &str) -> Option<Value> {
    match topic {
        topics::PLANAR_STATE => Some(schema_for::<PlanarStateMsg>()),
        topics::PLANAR_COMMAND => Some(schema_for::<PlanarCommandMsg>()),
        topics::PLANAR_CONTROL => Some(schema_for::<PlanarControlMsg>()),
        topics::WORLD_TELEMETRY => Some(schema_for::<WorldTelemetryMsg>()),
        topics::WORLD_COMMAND => Some(schema_for::<WorldCommandMsg>()),
        _ => None,
    }
}

/// Whether a field path `.a[0].b` leads to a number or boolean in a JSON schema.
fn schema_has_numeric_field(schema: &Value, fields: &str) -> bool {
    let mut node = schema;
    for part in fields.split('.').skip(1) {
        let name = part.split('[').next().unwrap_or("");
        node = &node["properties"][name];
        for _ in part.matches('[') {
            node = &node["items"];
        }
    }
    let numeric = |t: &Value| ["number", "integer", "boolean"].contains(&t.as_str().unwrap_or(""));
    match &node["type"] {
        Value::Array(types) => types.iter().any(numeric),
        other => numeric(other),
    }
}

#[test]
fn foxglove_layout_is_consistent_with_topics_and_frames() {
    let layout = layout();
    let config = &layout["configById"];
    let mut placed = Vec::new();
    placed_panels(&layout["layout"], config, &mut placed);
    let placed: BTreeSet<String> = placed.into_iter().collect();
    let defined: BTreeSet<String> = config.as_object().unwrap().keys().cloned().collect();
    assert_eq!(placed, defined, "every panel placed once and defined");

    let known: BTreeSet<&str> = topics::ALL.into_iter().collect();
    let mut plotted = 0;
    for (id, panel) in config.as_object().unwrap() {
        if id.starts_with("Plot!") {
            for path in panel["paths"].as_array().unwrap() {
                let value = path["value"].as_str().unwrap();
                let (topic, fields) = split_message_path(value);
                assert!(known.contains(topic), "{id} plots unknown topic {topic}");
                assert!(is_field_path(fields), "{id}: bad message path {value}");
                if let Some(schema) = logged_schema(topic) {
                    assert!(
                        schema_has_numeric_field(&schema, fields),
                        "{id}: {value} is not a numeric field of what is logged on {topic}"
                    );
                }
                // Log time is simulated time: plot against it.
                assert_eq!(path["timestampMethod"], "receiveTime");
                plotted += 1;
            }
        }
        if id.starts_with("RawMessages!") {
            let (topic, _) = split_message_path(panel["topicPath"].as_str().unwrap());
            assert!(known.contains(topic), "{id} shows unknown topic {topic}");
        }
    }
    assert!(plotted >= 10, "{plotted} plotted paths");

    let robot = BallbotScene::miapure_like();
    let three_d = &config["3D!ballbot"];
    assert_eq!(three_d["followTf"], robot.body_frame.as_str());
    assert_eq!(
        three_d["layers"]["grid"]["frameId"],
        robot.world_frame.as_str()
    );
    assert!(
        three_d["topics"][topics::SCENE]["visible"]
            .as_bool()
            .unwrap()
    );
    for frame in [&robot.world_frame, &robot.ball_frame, &robot.body_frame] {
        assert!(
            three_d["transforms"][format!("frame:{frame}")].is_object(),
            "{frame}"
        );
    }
}

#[test]
fn schema_field_lookup_follows_arrays_and_rejects_missing_fields() {
    let schema = serde_json::json!({
        "type": "object",
        "properties": {
            "wheels": {"type": "array", "items": {"type": "object", "properties": {
                "normal_force_n": {"type": "number"}, "name": {"type": "string"}
            }}},
            "reference": {"type": ["number", "null"]}
        }
    });
    assert!(schema_has_numeric_field(
        &schema,
        ".wheels[1].normal_force_n"
    ));
    assert!(schema_has_numeric_field(&schema, ".reference"));
    assert!(!schema_has_numeric_field(&schema, ".wheels[1].name"));
    assert!(!schema_has_numeric_field(&schema, ".wheels[1].traction_n"));
    assert!(!schema_has_numeric_field(&schema, ".tilt_rad"));
}

#[test]
fn message_path_checker_rejects_malformed_paths() {
    assert!(is_field_path(".wheels[2].normal_force_n"));
    assert!(is_field_path(".tilt_rad[0]"));
    assert!(!is_field_path(".wheels[x].n"));
    assert!(!is_field_path("wheels"));
    assert!(!is_field_path(".Wheels"));
    assert!(!is_field_path("..n"));
}
