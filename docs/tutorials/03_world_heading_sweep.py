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
# # The 3D world: a heading sweep
#
# The rapier3d world with compliant, friction-cone-limited omniwheel contacts and the core's
# cascaded LQR-PI in the loop. At each heading the robot follows a steep velocity ramp until an
# omniwheel slips, lifts off or the robot falls (`ballbot.max_speed_ramp`). Towards omniwheel 1
# (0 deg) the driving wheels OW2 and OW3 are unloaded, the paper's direction dependence. Each
# ramp runs in Rust without the GIL, so threads run headings in parallel.

# %%
import concurrent.futures

import matplotlib.pyplot as plt
import numpy as np

import ballbot


def ramp(heading_deg: float) -> ballbot.RampRun:
    return ballbot.max_speed_ramp(
        heading_deg=heading_deg,
        accel_m_per_s2=1.9,
        max_command_m_per_s=2.0,
        settle_secs=0.5,
        max_speed_m_per_s=5.0,
        max_accel_m_per_s2=20.0,
        max_tilt_command_rad=0.5,
        max_tilt_rate_command_rad_per_s=5.0,
    )


headings = np.arange(0.0, 360.0, 60.0)
with concurrent.futures.ThreadPoolExecutor() as pool:
    runs = list(pool.map(ramp, headings))
for r in runs:
    outcome = "completed" if r.failure is None else f"{r.failure.kind.value} at {r.failure.time_secs:.2f} s"
    print(f"{r.heading_deg:5.0f} deg: max speed {r.max_speed_m_per_s:.2f} m/s, {outcome}")

# %%
fig, ax = plt.subplots(figsize=(7, 4))
for r in runs:
    ax.plot(r.time_secs, r.normal_force_n[:, 1], label=f"OW2 at {r.heading_deg:.0f} deg")
ax.set_xlabel("time (s)")
ax.set_ylabel("OW2 normal force (N)")
ax.grid(True)
ax.legend(fontsize=7)
plt.show()
