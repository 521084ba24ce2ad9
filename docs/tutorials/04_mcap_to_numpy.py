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
