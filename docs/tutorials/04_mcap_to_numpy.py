# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Reading an MCAP log into numpy
#
# Every world run can write an MCAP log (telemetry at 8 kHz, the controller at 400 Hz, a
# Foxglove 3D scene). `ballbot.log.McapLog` reads it back; `numeric_series` gives one numpy
# column per numeric field of a topic.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import ballbot
from ballbot.log import McapLog

path = Path(tempfile.mkdtemp()) / "drive.mcap"
sim = ballbot.WorldLoop()
sim.run(8000, [0.0, 0.0, 0.0])  # 1 s standing, unlogged
run = sim.run(16_000, [0.6, 0.2, 0.0], log_path=path, log_compact=True)
log = McapLog(path)
print(log.is_complete, log.message_count, "messages")
print(log.topics())

# %%
series = McapLog(path).numeric_series("/world/telemetry")
print(sorted(series)[:12], "...")
t = series["time_secs"]
fig, ax = plt.subplots(figsize=(7, 3.5))
for i in range(3):
    key = f"wheels[{i}].normal_force_n"
    if key in series:
        ax.plot(t, series[key], label=f"OW{i + 1}")
ax.set_xlabel("time (s)")
ax.set_ylabel("normal force (N)")
ax.grid(True)
ax.legend()
plt.show()

# %% [markdown]
# The 3D scene, the frame transforms, the wheel joints and the event log are Foxglove's own
# messages (protobuf, from the official Foxglove SDK). `McapLog` decodes them too, with
# Foxglove's field names, so the wheel angles come out as columns of `/joint_states`:

# %%
joints = log.numeric_series("/joint_states")
print(sorted(joints))
print(np.allclose(joints["joints[0].position"][-1], run.wheel_angle_rad[-1, 0], atol=0.5))

# %% [markdown]
# Any MCAP tool reads the file as well. With `pip install "ballbot[mcap]"`, the `mcap` package
# and `mcap-protobuf-support` decode the same messages from the schemas the file carries:

# %%
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

with open(path, "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    angles = np.array(
        [
            [j.position for j in msg.joints]
            for _, _, _, msg in reader.iter_decoded_messages(topics=["/joint_states"])
        ]
    )
print(angles.shape, "wheel angles at 100 Hz")
print(np.array_equal(angles[:, 0], joints["joints[0].position"]))
