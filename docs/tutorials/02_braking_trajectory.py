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
# # The braking trajectory
#
# Minimum effort `integral tau^2 dt` from 1.4 m/s to rest in 2 s on the nonlinear WIP (paper
# Sec. III-D), solved by clarabel in an SQP loop; then with MiaPURE's actuator limits and the
# omniwheels' friction cones at 180 deg, and the shortest braking time those limits allow on
# the planar model (about 0.5 s: the planner's bound; tracking it in the 3D world with the
# core's controller takes longer, and `ballbot reproduce` measures that, 2 s as on the paper's
# hardware).

# %%
import math

import matplotlib.pyplot as plt
import numpy as np

import ballbot

free = ballbot.BrakingProblem.miapure().solve()
print(free.status, f"J = {free.cost_n2m2s:.2f} N^2 m^2 s, {free.iterations} SQP iterations")

# %%
r = free.problem.plane.ball_radius_m
t = free.knot_times_secs
fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
axes[0].plot(t, r * free.knot_states[:, 3])
axes[0].set_ylabel("ball speed (m/s)")
axes[1].plot(t, np.degrees(free.knot_states[:, 0]))
axes[1].set_ylabel("tilt (deg)")
axes[2].plot(t, free.knot_torques_nm)
axes[2].set_ylabel("torque (N m)")
axes[2].set_xlabel("time (s)")
for ax in axes:
    ax.grid(True)
plt.show()

# %%
limits = ballbot.BrakingLimits(
    drivetrain=ballbot.DrivetrainParams.preset("miapure"), heading_rad=math.pi, traction=True
)
search = ballbot.min_braking_time(
    ballbot.BrakingProblem(intervals=30, limits=limits),
    lower_secs=0.5,
    upper_secs=4.0,
    resolution_secs=0.05,
)
print("minimum braking time at 180 deg:", search.min_duration_secs, "s")
