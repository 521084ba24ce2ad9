"""Simulated seconds per wall second: our rapier3d world against a MuJoCo roller-omniwheel
ballbot, in one run (docs/world.md, "Speed against MuJoCo"). Run it through
``benches/mujoco/run.sh``, which makes the venv.

Both simulate the same robot (MiaPURE with 60 kg, the default world's parameters from
``world_speed params``) balancing under a controller at 400 Hz while driving a cycle of velocity
commands, without logging, on one thread, each warmed up for 1 s before the clock starts:

* ours: ``world_speed run SECONDS RATIO``, the world with the core's controller in the loop (the
  shipped robot loop, motor PIs at 8 kHz), once at the default ``rigid_step_ratio`` and once at
  1 (the single-rate world);
* MuJoCo: ``roller_ballbot.py``'s model at a 1 ms step with a Python LQR (the core's continuous
  LQR gains per plane, the core's wheel torque map, a yaw PD; ``mj_step`` with ``nstep`` between
  updates); and the part of that run's wall time spent inside ``mj_step`` (the engine alone).

Repetitions alternate between the two, and the table reports medians and the ratio of the
medians. ``--json FILE`` writes everything measured.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import mujoco

sys.path.insert(0, str(Path(__file__).resolve().parent))
from roller_ballbot import mjcf  # noqa: E402

#: Velocity commands (vx, vy in m/s), each held 2 s: the world bench's cycle without yaw.
DRIVE_CYCLE = [(0.8, -0.3), (0.0, 0.0), (0.6, 0.5), (1.2, 0.0), (0.0, 0.0)]
CONTROL_DT_S = 1.0 / 400.0
WARM_UP_S = 1.0
#: Yaw PD on the body (N m per rad, N m s per rad).
YAW_KP, YAW_KD = 20.0, 8.0


class MujocoBallbot:
    """The roller model with its Python controller."""

    def __init__(self, params: dict[str, Any]) -> None:
        self.p = params
        self.model = mujoco.MjModel.from_xml_string(mjcf(params))
        self.data = mujoco.MjData(self.model)
        self.ball = self.model.body("ball").id
        self.body = self.model.body("body").id
        self.k_sag = [float(k) for k in params["gains_sagittal"]]
        self.k_fro = [float(k) for k in params["gains_frontal"]]
        self.torque_map = [[float(x) for x in row] for row in params["wheel_torque_matrix"]]
        self.peak = params["peak_wheel_torque_nm"]
        self.max_tilt_rad = 0.0
        #: Wall time spent inside mj_step (s).
        self.step_wall_secs = 0.0
        mujoco.mj_forward(self.model, self.data)

    def state(self) -> tuple[float, float, tuple[float, float], tuple[float, float], tuple[float, float]]:
        """Yaw and yaw rate, planar tilts and rates in the yaw frame, and the ball's velocity
        there (plain floats: a few numpy calls on 3-vectors would cost more than the step)."""
        d = self.data
        r00, _, r02, r10, _, r12, _, _, r22 = d.xmat[self.body]
        yaw = math.atan2(r10, r00)
        c, s = math.cos(yaw), math.sin(yaw)
        zx, zy = c * r02 + s * r12, -s * r02 + c * r12
        tilt = (math.atan2(-zy, r22), math.atan2(zx, r22))
        # The body's free joint: qvel[6:9] is its linear, qvel[9:12] its angular velocity in
        # the body frame; the ball's qvel[0:3] is its centre's velocity, world axes.
        wx, wy, wz = d.qvel[9:12]
        vx, vy, _ = d.qvel[0:3]
        v_yaw = (c * vx + s * vy, -s * vx + c * vy)
        return yaw, wz, tilt, (wx, wy), v_yaw

    def control(self, command: tuple[float, float]) -> None:
        yaw, yaw_rate, tilt, rates, v = self.state()
        r = self.p["ball_radius_m"]
        ks, kf = self.k_sag, self.k_fro
        # Reduced WIP states [theta, theta_dot, phi_dot] (MODEL.md sections 1, 2): sagittal
        # about y (travel +x, phi_dot = vx / r), frontal about x (travel -y, phi_dot = -vy / r);
        # u = k . (s_ref - s).
        tau_y = -ks[0] * tilt[1] - ks[1] * rates[1] + ks[2] * (command[0] - v[0]) / r
        tau_x = -kf[0] * tilt[0] - kf[1] * rates[0] + kf[2] * (v[1] - command[1]) / r
        tau_z = -(YAW_KP * yaw + YAW_KD * yaw_rate)
        m, peak = self.torque_map, self.peak
        self.data.ctrl[:] = [
            min(max(m[i][0] * tau_x + m[i][1] * tau_y + m[i][2] * tau_z, -peak), peak)
            for i in range(3)
        ]
        self.max_tilt_rad = max(self.max_tilt_rad, abs(tilt[0]), abs(tilt[1]))

    def run(self, seconds: float, t0: float = 0.0) -> None:
        """Simulates ``seconds`` with the controller at 400 Hz (the cycle's phase from ``t0``):
        a control update, then ``mj_step`` with ``nstep`` up to the next update (2 or 3 steps of
        1 ms, alternating)."""
        d, m = self.data, self.model
        dt = m.opt.timestep
        steps = int(round(seconds / dt))
        start = int(round(d.time / dt))
        done = 0
        while done < steps:
            k = start + done
            phase = int((k * dt - t0) / 2.0) % len(DRIVE_CYCLE)
            self.control(DRIVE_CYCLE[phase])
            # Steps up to the next multiple of 2.5 ms.
            next_control = math.floor(k * dt / CONTROL_DT_S + 1.0 + 1e-9) * CONTROL_DT_S
            n = min(max(int(round(next_control / dt)) - k, 1), steps - done)
            t = time.perf_counter()
            mujoco.mj_step(m, d, nstep=n)
            self.step_wall_secs += time.perf_counter() - t
            done += n



def time_mujoco(params: dict[str, Any], seconds: float) -> dict[str, Any]:
    bot = MujocoBallbot(params)
    bot.run(WARM_UP_S)
    bot.max_tilt_rad = 0.0
    bot.step_wall_secs = 0.0
    start = time.perf_counter()
    bot.run(seconds, t0=WARM_UP_S)
    controlled = time.perf_counter() - start
    upright = bot.max_tilt_rad < 0.3
    max_tilt = bot.max_tilt_rad
    bare = bot.step_wall_secs
    return {
        "controlled_wall_secs": controlled,
        "controlled_sim_secs_per_wall_sec": seconds / controlled,
        "bare_wall_secs": bare,
        "bare_sim_secs_per_wall_sec": seconds / bare,
        "max_tilt_rad": max_tilt,
        "stayed_upright": upright,
        "dofs": int(bot.model.nv),
    }


def time_ours(world_speed: str, seconds: float, ratio: str) -> dict[str, Any]:
    out = subprocess.run(
        [world_speed, "run", str(seconds), ratio], check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--world-speed", required=True, help="path of the world_speed example binary")
    ap.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run (10)")
    ap.add_argument("--repeats", type=int, default=5, help="repetitions of each (5)")
    ap.add_argument("--json", type=Path, help="write every measurement to this file")
    args = ap.parse_args()
    params = json.loads(
        subprocess.run([args.world_speed, "params"], check=True, capture_output=True, text=True).stdout
    )
    runs: dict[str, list[dict[str, Any]]] = {"ours_default": [], "ours_single_rate": [], "mujoco": []}
    for i in range(args.repeats):
        runs["ours_default"].append(time_ours(args.world_speed, args.seconds, "default"))
        runs["mujoco"].append(time_mujoco(params, args.seconds))
        runs["ours_single_rate"].append(time_ours(args.world_speed, args.seconds, "1"))
        print(f"repetition {i + 1}/{args.repeats} done", file=sys.stderr, flush=True)

    def med(name: str, key: str) -> float:
        return statistics.median(r[key] for r in runs[name])

    ours = med("ours_default", "sim_secs_per_wall_sec")
    single = med("ours_single_rate", "sim_secs_per_wall_sec")
    mj = med("mujoco", "controlled_sim_secs_per_wall_sec")
    mj_bare = med("mujoco", "bare_sim_secs_per_wall_sec")
    ratio = runs["ours_default"][0]["rigid_step_ratio"]
    upright = all(r["stayed_upright"] for r in runs["mujoco"])
    restarts = sum(r["restarts"] for k in ("ours_default", "ours_single_rate") for r in runs[k])
    rows = [
        (f"ours, default world (rigid_step_ratio {ratio}), core controller", ours),
        ("ours, single-rate world (rigid_step_ratio 1), core controller", single),
        (f"MuJoCo roller omniwheels ({runs['mujoco'][0]['dofs']} DoF), Python LQR", mj),
        ("MuJoCo roller omniwheels, time inside mj_step alone", mj_bare),
    ]
    print(f"\nsimulated s per wall s, median of {args.repeats}, {args.seconds:g} s each")
    for name, value in rows:
        print(f"  {name:<66} {value:8.1f}")
    print(f"  ratio ours / MuJoCo (controlled): {ours / mj:.2f}x (single-rate: {single / mj:.2f}x)")
    print(f"  ratio ours / MuJoCo mj_step alone: {ours / mj_bare:.2f}x")
    print(
        f"  MuJoCo robot upright in every run: {upright} "
        f"(largest tilt {max(r['max_tilt_rad'] for r in runs['mujoco']):.3f} rad); "
        f"our robot failed {restarts} times"
    )
    if args.json:
        summary = {
            "seconds": args.seconds,
            "repeats": args.repeats,
            "median_sim_secs_per_wall_sec": {
                "ours_default": ours,
                "ours_single_rate": single,
                "mujoco_controlled": mj,
                "mujoco_bare": mj_bare,
            },
            "ratio_ours_over_mujoco": ours / mj,
            "runs": runs,
            "params": params,
        }
        args.json.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    return 0 if upright and restarts == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
