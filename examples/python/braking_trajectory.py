"""Optimise MiaPURE's braking trajectory (paper Sec. III-D) and find its minimum braking time.

Minimum effort integral tau^2 dt from 1.4 m/s to rest in 2 s on the nonlinear WIP (MODEL.md:
about 114 N^2 m^2 s, the body leans back about 7 deg, the ball first speeds up to about
1.6 m/s); then the same with MiaPURE's actuator limits at 180 deg and the omniwheels' friction
cones, and the shortest braking time those limits allow (the paper's hardware reached 2 s).

Usage: python examples/python/braking_trajectory.py
"""

import math

import numpy as np

import ballbot


def describe(name: str, sol: ballbot.BrakingSolution) -> None:
    states = sol.knot_states
    speed = sol.problem.plane.ball_radius_m * states[:, 3]
    print(
        f"{name}: {sol.status}, J = {sol.cost_n2m2s:.2f} N^2 m^2 s, lean back "
        f"{math.degrees(-states[:, 0].min()):.1f} deg, peak speed {speed.max():.2f} m/s, "
        f"peak torque {np.abs(sol.knot_torques_nm).max():.1f} N m "
        f"({sol.iterations} SQP iterations, {sol.solve_time_secs * 1e3:.0f} ms)"
    )


def main() -> None:
    free = ballbot.BrakingProblem.miapure().solve()
    describe("free, 2 s", free)
    pinned = ballbot.BrakingProblem(zero_end_torques=True).solve()
    describe("tau = 0 at both ends", pinned)

    drivetrain = ballbot.DrivetrainParams.preset("miapure")
    limits = ballbot.BrakingLimits(drivetrain=drivetrain, heading_rad=math.pi, traction=True)
    limited = ballbot.BrakingProblem(limits=limits).solve(initial_guess=free)
    describe("actuators + friction cones at 180 deg", limited)
    if limited.normal_force_n.size:
        print(f"  smallest omniwheel normal force {limited.normal_force_n.min():.0f} N")

    search = ballbot.min_braking_time(
        ballbot.BrakingProblem(intervals=50, limits=limits),
        lower_secs=0.2,
        upper_secs=5.0,
        resolution_secs=0.02,
    )
    t_min = search.min_duration_secs
    if t_min is None:
        print("no feasible braking time up to 5 s under these limits")
    else:
        print(
            f"minimum braking time from 1.4 m/s at 180 deg: {t_min:.2f} s "
            f"({search.solves} solves; infeasible below {search.infeasible_below_secs})"
        )


if __name__ == "__main__":
    main()
