"""Trajectory optimisation from Python with the Rust tests' reference numbers (MODEL.md
section 7, crates/ballbot-sim/tests/trajopt.rs)."""

import math

import numpy as np
import pytest

import ballbot


def test_miapure_braking_optimum_matches_the_rust_tests() -> None:
    sol = ballbot.BrakingProblem.miapure().solve()
    assert sol.status is ballbot.SolveStatus.SOLVED and sol.is_solved()
    # MODEL.md: about 114 N^2 m^2 s; the Rust tests pin 113.558 (converged in N).
    assert sol.cost_n2m2s == pytest.approx(113.558, abs=0.05)
    states = sol.knot_states
    assert states.shape == (101, 4) and sol.knot_times_secs.shape == (101,)
    # The body leans back about 7 deg; the ball first speeds up to about 1.6 m/s.
    assert -8.0 < math.degrees(states[:, 0].min()) < -6.0
    assert 1.55 < (0.1145 * states[:, 3]).max() < 1.65
    # Ends at rest upright; the interpolant is available at any time.
    assert sol.state_at(2.0)[[0, 2, 3]] == pytest.approx([0.0, 0.0, 0.0], abs=1e-9)
    assert sol.state_at(np.array([0.0, 1.0])).shape == (2, 4)
    assert sol.torque_at(np.linspace(0.0, 2.0, 5)).shape == (5,)
    sampled = sol.sample(0.01)
    assert sampled["state"].shape == (201, 4)
    # A warm start from the solution converges at once.
    again = sol.problem.solve(initial_guess=sol)
    assert again.is_solved() and again.iterations <= sol.iterations


def test_piptb_braking_costs_0_83() -> None:
    sol = ballbot.BrakingProblem.piptb().solve()
    assert sol.cost_n2m2s == pytest.approx(0.8301, abs=5e-4)


def test_limits_and_infeasibility() -> None:
    limits = ballbot.BrakingLimits(torque_nm=20.0, tilt_rad=0.2)
    short = ballbot.BrakingProblem(duration_secs=0.3, intervals=50, limits=limits)
    assert short.solve().status is ballbot.SolveStatus.INFEASIBLE
    traction = ballbot.BrakingLimits(drivetrain=ballbot.DrivetrainParams(), traction=True)
    sol = ballbot.BrakingProblem(intervals=40, limits=traction).solve()
    assert sol.normal_force_n.shape == (41, 3)
    assert ballbot.BrakingProblem(intervals=40).solve().normal_force_n.shape == (0, 3)


def test_minimum_braking_time_brackets_the_boundary() -> None:
    p = ballbot.BrakingProblem(
        intervals=40, limits=ballbot.BrakingLimits.miapure_actuators(math.pi)
    )
    r = ballbot.min_braking_time(p, lower_secs=0.1, upper_secs=3.0, resolution_secs=0.02)
    t_min, t_bad = r.min_duration_secs, r.infeasible_below_secs
    assert t_min is not None and t_bad is not None
    assert 0.0 < t_min - t_bad <= 0.02
    assert 0.3 < t_min < 0.6
    assert r.solution.is_solved()
    assert np.abs(r.solution.knot_torques_nm).max() > 90.0


def test_bad_problems_raise_parameter_error() -> None:
    with pytest.raises(ballbot.ParameterError, match="duration_secs"):
        ballbot.BrakingProblem(duration_secs=-1.0)
    with pytest.raises(ballbot.ParameterError, match="intervals"):
        ballbot.BrakingProblem(intervals=1)
    with pytest.raises(ballbot.ParameterError, match="initial_speed_m_per_s"):
        ballbot.BrakingProblem(initial_speed_m_per_s=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="unknown method `euler`"):
        ballbot.BrakingProblem(method="euler")  # type: ignore[arg-type]
    with pytest.raises(ballbot.ParameterError, match="traction"):
        ballbot.BrakingLimits(traction=True)
    with pytest.raises(ballbot.ParameterError, match="torque_nm"):
        ballbot.BrakingLimits(torque_nm=float("inf"))
    with pytest.raises(ballbot.ParameterError, match="min_time"):
        ballbot.min_braking_time(ballbot.BrakingProblem.miapure(), lower_secs=5.0, upper_secs=1.0)
