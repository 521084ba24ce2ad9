"""Traction-aware control from Python: ``WorldLoop(traction_control=True)`` (the default),
its per-step report (``WorldLoop.traction``) and its envelope
(``WorldLoop.traction_envelope()``)."""

from __future__ import annotations

import math

import numpy as np

import ballbot


def test_on_by_default_and_off_on_request() -> None:
    loop = ballbot.WorldLoop()
    loop.run(400)
    assert loop.traction is not None
    assert loop.traction_envelope() is not None
    paper = ballbot.WorldLoop(traction_control=False, balance_point=False)
    paper.run(400)
    assert paper.traction is None
    assert paper.traction_envelope() is None


def test_envelope_is_weakest_towards_ow1() -> None:
    loop = ballbot.WorldLoop(traction_control=True)
    env = loop.traction_envelope()
    assert env is not None
    assert env.heading_rad.shape == (96,) and env.accel_m_per_s2.shape == (96,)
    # Entry 0 is towards OW1 (0 rad), entry 48 away from it (pi).
    assert env.heading_rad[0] == 0.0 and math.isclose(env.heading_rad[48], math.pi)
    assert env.accel_m_per_s2[0] < env.accel_m_per_s2[48]
    assert np.all(env.accel_m_per_s2 > 0.5)


def test_a_hard_command_towards_ow1_is_limited_not_failed() -> None:
    # The user would allow 3 m/s^2; towards OW1 the envelope allows less, and the robot
    # follows the envelope without slipping.
    loop = ballbot.WorldLoop(
        max_speed_m_per_s=3.0,
        max_accel_m_per_s2=3.0,
        max_tilt_command_rad=0.5,
        max_tilt_rate_command_rad_per_s=5.0,
        traction_control=True,
    )
    env = loop.traction_envelope()
    assert env is not None
    run = loop.run(8 * 900, (2.0, 0.0, 0.0), record_every=80, stop_on_failure=True)
    assert run.failure is None
    status = loop.traction
    assert status is not None
    assert status.limited and status.limited_steps > 50
    assert status.accel_limit_m_per_s2 is not None
    assert math.isclose(status.accel_limit_m_per_s2, env.accel_m_per_s2[0], rel_tol=1e-9)
    assert status.slip_events == 0 and status.slipping == (False, False, False)
    assert status.slip_speed_m_per_s.shape == (3,)
    assert np.all(status.predicted_normal_force_n > 100.0)
    assert status.friction_estimate == 0.6 and status.accel_scale == 1.0
