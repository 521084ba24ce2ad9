"""Sweep the direction of travel of MiaPURE (60 kg) in parallel threads: how hard can it
accelerate at each heading before an omniwheel slips or lifts off?

The paper (Sec. V) explains why MiaPURE is slower towards omniwheel 1 (0 deg) than away from
it (180 deg): accelerating towards wheel 1 unloads wheels 2 and 3, the two that must drive.
Here each heading runs the planar model of that direction on the nonlinear WIP in Rust: the
LQR, limited to the drivetrain's torque capacity at that heading, follows a smooth speed ramp
to 1.4 m/s with the model's steady lean for the ramp's acceleration as feedforward; every state of the trajectory is checked against the friction cones and lift-off of
the three contacts (`OmniKinematics.wip_contact_forces`), and a bisection finds the steepest
ramp that keeps every contact. The rollouts release the GIL, so a `ThreadPoolExecutor` runs
the headings on all cores.

Usage: python examples/python/heading_sweep.py [--workers N] [--step-deg 15]
"""

import argparse
import concurrent.futures
import math
import time

import numpy as np

import ballbot

TOP_SPEED_M_PER_S = 1.4
JERK_SECS = 0.5  # the acceleration rises and falls smoothly over this time
SETTLE_SECS = 1.0  # simulated after reaching the top speed
DT_SECS = 1.0 / 400.0
BISECTION_STEPS = 12


def acceleration_profile(accel_m_per_s2: float) -> np.ndarray:
    """Ball acceleration (m/s^2) every DT_SECS: a smooth rise to `accel_m_per_s2`, a hold and a
    smooth fall, reaching TOP_SPEED_M_PER_S, then SETTLE_SECS at that speed."""
    rise = min(JERK_SECS, TOP_SPEED_M_PER_S / accel_m_per_s2)
    hold = TOP_SPEED_M_PER_S / accel_m_per_s2 - rise
    t = np.arange(0.0, 2 * rise + hold + SETTLE_SECS, DT_SECS)
    x_up = np.clip(t / rise, 0.0, 1.0)
    x_down = np.clip((2 * rise + hold - t) / rise, 0.0, 1.0)
    smooth = lambda x: 3 * x**2 - 2 * x**3  # noqa: E731
    return accel_m_per_s2 * np.minimum(smooth(x_up), smooth(x_down))


def ramp_holds(heading_rad: float, accel_m_per_s2: float) -> bool:
    """Whether every contact holds while following the ramp at `accel_m_per_s2`."""
    params = ballbot.BallbotParams.preset("miapure_60kg")
    kin = ballbot.OmniKinematics.from_ballbot(params)
    wip = ballbot.Wip(params.sagittal)
    r = params.ball_radius_m
    # Torque capacity along this heading: a large request scaled down to the wheel limits.
    _, _, scale = kin.saturate_planar_torque(ballbot.planar_torque_at_heading(heading_rad, 1e4))
    controller = ballbot.LqrController(ballbot.LqrGains.for_wip(wip, float(scale) * 1e4))
    # The command: the ball speed of the profile, and as feedforward the model's steady lean
    # for the profile's acceleration (proportional to it, to first order).
    lean = ballbot.accelerating_command(wip, 0.0, accel_m_per_s2 / r)
    if lean is None:
        return False  # no lean holds this acceleration at all
    accel = acceleration_profile(accel_m_per_s2)
    command = np.zeros((accel.size, 4))
    command[:, 0] = lean[0][0] * accel / accel_m_per_s2
    command[:, 2] = np.gradient(command[:, 0], DT_SECS)
    command[:, 3] = np.cumsum(accel) * DT_SECS / r
    run = ballbot.closed_loop_rollout(
        wip, controller, np.zeros(4), n_steps=accel.size, command=command
    )
    contacts = kin.wip_contact_forces(wip, heading_rad, run.state[:-1], run.torque_nm)
    return bool(np.all(contacts.all_hold == 1.0))


def max_accel_at(heading_deg: float) -> tuple[float, float]:
    """(heading, the steepest ramp in m/s^2 that keeps every contact), by bisection."""
    heading = math.radians(heading_deg)
    lo, hi = 0.05, 10.0
    if not ramp_holds(heading, lo):
        return heading_deg, 0.0
    for _ in range(BISECTION_STEPS):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if ramp_holds(heading, mid) else (lo, mid)
    return heading_deg, lo


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=None, help="threads (default: CPUs)")
    parser.add_argument("--step-deg", type=float, default=15.0, help="heading step (deg)")
    args = parser.parse_args()
    headings = np.arange(0.0, 360.0, args.step_deg)
    start = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(max_accel_at, headings))
    elapsed = time.perf_counter() - start
    print("heading  steepest ramp keeping every contact")
    for heading_deg, accel in results:
        print(f"{heading_deg:5.0f} deg {accel:6.2f} m/s^2  {'#' * int(round(accel * 10))}")
    runs = len(headings) * (BISECTION_STEPS + 1)
    print(f"{len(headings)} headings, {runs} closed-loop rollouts in {elapsed:.2f} s")


if __name__ == "__main__":
    main()
