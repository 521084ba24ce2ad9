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
# # A Gymnasium environment
#
# `import ballbot.gym` (the `gym` extra) registers `ballbot/Balance-v0` (wheel torques as the
# action) and `ballbot/Velocity-v0` (a residual torque on the core's LQR-PI, which tracks random
# velocity commands). Here the residual is zero: the shipped controller alone, on the rapier3d
# world with seeded domain randomisation.

# %%
import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import ballbot.gym  # noqa: F401  (registers the environments)

env = gym.make("ballbot/Velocity-v0")
obs, info = env.reset(seed=7)
rewards, tilts = [], []
for _ in range(800):  # 2 s at 400 Hz
    obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    rewards.append(reward)
    tilts.append(float(np.hypot(obs[0], obs[1])))
    if terminated or truncated:
        break
print(f"{len(rewards)} steps, return {sum(rewards):.1f}, terminated {terminated}")
env.close()

# %%
fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(np.arange(len(tilts)) / 400.0, np.degrees(tilts))
ax.set_xlabel("time (s)")
ax.set_ylabel("|tilt| (deg), from the observation")
ax.grid(True)
plt.show()
