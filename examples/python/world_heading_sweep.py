"""Sweep the direction of travel of MiaPURE (60 kg) in the 3D world, in parallel threads: at
each heading the core's 3D controller follows a steep velocity ramp until an omniwheel slips,
lifts off or the robot falls (`ballbot.max_speed_ramp`).

The paper (Sec. V) explains why MiaPURE is slower towards omniwheel 1 (0 deg) than away from
it (180 deg): accelerating towards OW1 tilts the body forward and unloads OW2 and OW3, the
wheels that must drive. In the world this is the full rapier3d simulation with compliant,
friction-cone-limited omniwheel contacts, the cascaded LQR-PI at 400 Hz and the motor PIs at
8 kHz (unlike `heading_sweep.py`, which checks the planar model's contact forces). The command
shaper's speed and acceleration caps are lifted so that the ramp sets the acceleration. Each
ramp runs in Rust with the GIL released, so a `ThreadPoolExecutor` runs headings on all cores.

Usage: python examples/python/world_heading_sweep.py [--step-deg 30] [--accel 1.9] [--top 3.0]
       [--workers N]
"""

import argparse
import concurrent.futures
import time

import numpy as np

import ballbot


def ramp(heading_deg: float, accel_m_per_s2: float, top_m_per_s: float) -> ballbot.RampRun:
    """One ramp at `heading_deg` with the shaper's caps lifted (its jerk limit is kept)."""
    return ballbot.max_speed_ramp(
        heading_deg=heading_deg,
        accel_m_per_s2=accel_m_per_s2,
        max_command_m_per_s=top_m_per_s,
        settle_secs=0.5,
        sample_every_secs=0.0025,
        max_speed_m_per_s=5.0,
        max_accel_m_per_s2=20.0,
        max_tilt_command_rad=0.5,
        max_tilt_rate_command_rad_per_s=5.0,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step-deg", type=float, default=30.0, help="heading step (deg)")
    parser.add_argument("--accel", type=float, default=1.9, help="ramp acceleration (m/s^2)")
    parser.add_argument("--top", type=float, default=3.0, help="ramp end speed (m/s)")
    parser.add_argument("--workers", type=int, default=None, help="threads (default: CPUs)")
    args = parser.parse_args()
    headings = np.arange(0.0, 360.0, args.step_deg)
    start = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(lambda h: ramp(h, args.accel, args.top), headings))
    elapsed = time.perf_counter() - start
    print(f"ramp {args.accel} m/s^2 to {args.top} m/s, core controller, shaper caps lifted")
    print("heading  max speed  min N(OW2, OW3)  peak cone use  outcome")
    for r in results:
        failure = r.failure
        outcome = "ramp completed"
        if failure is not None:
            wheel = "" if failure.wheel is None else f" {failure.wheel}"
            outcome = f"{failure.kind.value}{wheel} at {failure.time_secs:.2f} s"
        min_n = float(np.min(r.normal_force_n[:, 1:])) if r.time_secs.size else float("nan")
        peak_u = float(np.max(r.max_cone_utilisation, initial=0.0))
        print(
            f"{r.heading_deg:5.0f} deg {r.max_speed_m_per_s:6.2f} m/s {min_n:10.1f} N "
            f"{peak_u:14.2f}  {outcome}"
        )
    print(f"{len(headings)} headings in {elapsed:.2f} s")


if __name__ == "__main__":
    main()
