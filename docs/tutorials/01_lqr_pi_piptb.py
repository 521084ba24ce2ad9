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
# # Design an LQR and simulate the PIPTB
#
# The planar wheeled inverted pendulum (MODEL.md section 2) of MiaPURE carrying 60 kg, an LQR on
# the reduced state `[theta, theta_dot, phi_dot]` (the paper does not feed back the ball's
# angle), then the paper's testbed experiment (Sec. IV-C): accelerate to 1 m/s, hold, brake
# along the optimal trajectory in 1.4 s, with stiction in the transmission, for the three
# controllers.

# %%
import matplotlib.pyplot as plt
import numpy as np

import ballbot

wip = ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))
print("open-loop poles (rad/s):", np.round(wip.open_loop_poles(), 3))
lqr = ballbot.wip_lqr(wip, q=[100.0, 10.0, 1.0], r=0.1)
print("reduced gains [k_theta, k_theta_dot, k_phi_dot]:", np.round(lqr.reduced_gains(), 2))
print("closed-loop poles:", np.round(lqr.closed_loop_eigenvalues(), 2))

# %% [markdown]
# The PIPTB experiment with its seeded trials (`quick=True`: one trial per controller, so the
# page builds fast; `ballbot reproduce` runs the full set). Every controller runs on the same
# planar robot loop that a robot binary runs.

# %%
result = ballbot.piptb_experiment(quick=True)
for key, c in result.controllers.items():
    paper = c["paper_j_p_n2mm2s"]
    print(f"{key:7s} J_P = {c['j_p_n2mm2s']:.3g} N^2 mm^2 s (paper: {paper}), "
          f"stopped: {c['stopped_all']}, torque jitter {c['torque_jitter_nm']:.3f} N m")

# %%
fig, axes = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
for key, c in result.controllers.items():
    s = c["trials"][0]["series"]
    axes[0].plot(s["time_secs"], s["speed_m_per_s"], label=key)
    axes[1].plot(s["time_secs"], s["torque_nm"], label=key, linewidth=0.8)
for ax in axes:
    ax.axvspan(result.brake_start_secs, result.brake_end_secs, color="0.9")
    ax.grid(True)
axes[0].set_ylabel("speed (m/s)")
axes[1].set_ylabel("torque (N m)")
axes[1].set_xlabel("time (s)")
axes[0].legend()
plt.show()
