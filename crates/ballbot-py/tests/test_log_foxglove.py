"""World logs read by the `mcap` package (the reader Foxglove's Python users have), decoded to
numpy: our JSON telemetry with `json`, Foxglove's protobuf messages (the SDK's SceneUpdate,
FrameTransforms, JointStates, Log) with `mcap-protobuf-support` from the schemas the file
carries. And the live view: a WebSocket client connects to `LiveView` as Foxglove would."""

import json
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from websockets.sync.client import connect

import ballbot


def write_log(path: Path) -> ballbot.WorldLoopRun:
    sim = ballbot.WorldLoop()
    # 0.5 s at 8 kHz, towards OW1 at 0.3 m/s.
    return sim.run(4000, [0.3, 0.0, 0.0], log_path=path)


def test_the_mcap_package_reads_a_world_log_into_numpy(tmp_path: Path) -> None:
    path = tmp_path / "world.mcap"
    run = write_log(path)
    ours = ballbot.McapLog(path)

    time_ns: list[int] = []
    normal_n: list[list[float]] = []
    transforms: list[Any] = []
    joints: list[Any] = []
    scenes: list[Any] = []
    encodings: dict[str, tuple[str, str]] = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages(
            topics=["/tf", "/joint_states", "/scene"]
        ):
            assert schema is not None
            encodings[channel.topic] = (schema.name, channel.message_encoding)
            {"/tf": transforms, "/joint_states": joints, "/scene": scenes}[channel.topic].append(
                (message.log_time, decoded)
            )
        f.seek(0)
        for _, channel, message in make_reader(f).iter_messages(topics=["/world/telemetry"]):
            assert channel.message_encoding == "json"
            msg = json.loads(message.data)
            time_ns.append(message.log_time)
            normal_n.append([w["normal_force_n"] for w in msg["wheels"]])

    # JSON telemetry to numpy: the same numbers as the package's own reader and the run.
    normal = np.array(normal_n)
    assert normal.shape == (4000, 3)
    columns = ours.numeric_series("/world/telemetry")
    for i in range(3):
        np.testing.assert_array_equal(normal[:, i], columns[f"wheels[{i}].normal_force_n"])
    np.testing.assert_array_equal(normal, run.normal_force_n)
    np.testing.assert_allclose(np.array(time_ns) * 1e-9, run.time_secs, rtol=0, atol=1e-12)

    # Foxglove's messages, decoded from the protobuf schemas embedded in the file.
    assert encodings == {
        "/tf": ("foxglove.FrameTransforms", "protobuf"),
        "/joint_states": ("foxglove.JointStates", "protobuf"),
        "/scene": ("foxglove.SceneUpdate", "protobuf"),
    }
    assert len(transforms) == len(joints) == 51 and len(scenes) == 26
    by_time = {round(t * 1e9): i for i, t in enumerate(run.time_secs)}
    for log_time, tf in transforms:
        k = by_time[log_time]
        ball = next(f for f in tf.transforms if f.child_frame_id == "ball")
        assert [ball.translation.x, ball.translation.y, ball.translation.z] == list(
            run.ball_position_m[k]
        )
    angles = np.array([[j.position for j in js.joints] for _, js in joints])
    steps = [by_time[t] for t, _ in joints]
    np.testing.assert_array_equal(angles, run.wheel_angle_rad[steps])
    assert [j.name for j in joints[0][1].joints] == ["ow1", "ow2", "ow3"]
    ids = {e.id for e in scenes[-1][1].entities}
    assert {"floor", "ball", "body", "ow1", "contact_forces", "labels"} <= ids
    # The package's reader gives the same messages as JSON, with Foxglove's field names.
    _, values = ours.messages("/joint_states")
    assert values[0]["joints"][2]["name"] == "ow3"


def test_a_websocket_client_watches_a_run_through_the_live_view(tmp_path: Path) -> None:
    view = ballbot.LiveView(port=0, realtime=True)
    assert view.url == f"ws://127.0.0.1:{view.port}" and view.port > 0
    received: dict[str, Any] = {"channels": {}, "telemetry": []}

    def client() -> None:
        with connect(view.url, subprotocols=["foxglove.sdk.v1"], open_timeout=10) as ws:  # type: ignore[list-item]
            subscribed: dict[int, str] = {}
            for frame in ws:
                if isinstance(frame, str):
                    msg = json.loads(frame)
                    if msg["op"] == "advertise":
                        for ch in msg["channels"]:
                            received["channels"][ch["topic"]] = ch
                    # Subscribe once the run's channels are all advertised (the last is /log).
                    channels = received["channels"]
                    if not subscribed and {"/world/telemetry", "/log"} <= channels.keys():
                        channel_id = channels["/world/telemetry"]["id"]
                        subscribed[7] = "/world/telemetry"
                        subs = [{"id": 7, "channelId": channel_id}]
                        ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
                elif frame[0] == 1 and int.from_bytes(frame[1:5], "little") in subscribed:
                    received["telemetry"].append(json.loads(frame[13:]))
                    if len(received["telemetry"]) >= 200:
                        return

    thread = threading.Thread(target=client)
    thread.start()
    assert view.wait_for_client(10.0)
    log = tmp_path / "live.mcap"
    # 0.5 s in real time, into the live view and the file at once.
    run = ballbot.WorldLoop().run(4000, [0.3, 0.0, 0.0], log_path=log, live=view)
    thread.join(timeout=20)
    view.close()
    assert not thread.is_alive()
    assert received["channels"]["/scene"]["schemaName"] == "foxglove.SceneUpdate"
    assert received["channels"]["/world/telemetry"]["encoding"] == "json"
    telemetry = received["telemetry"]
    assert len(telemetry) >= 200
    # What the client saw is what the run recorded at those times.
    by_time = {round(t * 1e9): i for i, t in enumerate(run.time_secs)}
    for msg in telemetry:
        k = by_time[round(msg["time_secs"] * 1e9)]
        assert [w["normal_force_n"] for w in msg["wheels"]] == list(run.normal_force_n[k])
    assert ballbot.McapLog(log).channels()[0]["message_count"] == 4000


def test_a_live_view_needs_a_free_port() -> None:
    view = ballbot.LiveView(port=0)
    with pytest.raises(ballbot.BallbotError, match="live view"):
        ballbot.LiveView(port=view.port)
    view.close()


def test_a_live_view_alone_paces_a_run_to_real_time() -> None:
    # No file: the run goes to the live view only, and is held to the wall clock.
    view = ballbot.LiveView(port=0, realtime=True)
    assert view.realtime and view.client_count() == 0
    start = time.monotonic()
    run = ballbot.World().run(4000, live=view)  # 0.5 s simulated
    elapsed = time.monotonic() - start
    view.close()
    assert run.steps == 4000 and run.log_path is None
    assert elapsed >= 0.45, f"{elapsed:.3f} s of wall time for 0.5 s simulated"
