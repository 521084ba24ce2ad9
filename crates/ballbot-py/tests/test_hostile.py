"""Hostile input: NaN, infinities, empty and huge arrays, wrong dtypes. Nothing may crash the
interpreter; every call either returns (NaN in, NaN or a flagged zero out) or raises a
documented exception."""

import numpy as np
import pytest

import ballbot

NASTY = [np.nan, np.inf, -np.inf, 1e308, -1e308, 0.0]


def test_models_propagate_nan_without_crashing(wip: ballbot.Wip) -> None:
    states = np.array([[x, x, x, x] for x in NASTY])
    d = wip.derivative(states, np.array(NASTY))
    assert d.shape == (len(NASTY), 4)
    assert np.all(np.isfinite(d[-1]))
    assert np.isnan(d[0]).any()
    wip.energy_j(states)
    wip.accelerations(states, np.nan)
    traj = wip.rollout([np.nan, 0.0, 0.0, 0.0], dt_secs=1e-3, n_steps=10)
    assert traj.shape == (11, 4)
    a, b = wip.linearize([np.inf, 0.0, 0.0, 0.0], np.nan)
    assert a.shape == (4, 4)


def test_empty_batches_give_empty_results(wip: ballbot.Wip, kin: ballbot.OmniKinematics) -> None:
    assert wip.derivative(np.zeros((0, 4))).shape == (0, 4)
    assert wip.energy_j(np.zeros((0, 4))).shape == (0,)
    assert kin.wheel_torques_nm(np.zeros((0, 3))).shape == (0, 3)
    assert len(kin.wip_contact_forces(wip, np.zeros(0), np.zeros((0, 4)), np.zeros(0))) == 0
    lqr = ballbot.LqrController(ballbot.LqrGains.for_wip(wip, 83.9))
    out = lqr.step_many(np.zeros((0, 4)))
    assert out["torque_nm"].shape == (0,)
    run = ballbot.closed_loop_rollout(wip, lqr, np.zeros((0, 4)), n_steps=5)
    assert run.state.shape == (0, 6, 4)
    run = ballbot.closed_loop_rollout(wip, lqr, np.zeros(4), n_steps=0)
    assert run.state.shape == (1, 4) and run.torque_nm.shape == (0,)


def test_kinematics_with_non_finite_input(kin: ballbot.OmniKinematics, wip: ballbot.Wip) -> None:
    bad = np.array([[x, x, x] for x in NASTY])
    kin.wheel_speeds_rad_per_s(bad)
    kin.contact_forces(bad, bad)
    _, _, scale = kin.saturate_planar_torque(bad, bad)
    assert scale[0] == 0.0
    states = np.array([[x, x, x, x] for x in NASTY])
    kin.wip_actuator_torque_interval_nm(np.array(NASTY), states)
    kin.wip_contact_torque_interval_nm(wip, np.array(NASTY), states)


def test_controllers_flag_non_finite_input(wip: ballbot.Wip) -> None:
    lqr = ballbot.LqrController(ballbot.LqrGains.for_wip(wip, 83.9))
    pipd = ballbot.PiPdController(ballbot.PiPdGains.for_wip(wip, 83.9))
    inner = ballbot.SpeedPi(ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9))
    for x in NASTY[:3]:
        assert lqr.step([x, 0, 0, 0]).status == "invalid_input"
        assert pipd.step([0, 0, 0, 0], dt_secs=x).status == "invalid_input"
        out = inner.step(x, 1.0)
        assert out.torque_nm == 0.0 and out.status == "invalid_input"
    huge = lqr.step([1e308, 0, 0, 0])
    assert huge.status in ("saturated", "invalid_input") and np.isfinite(huge.torque_nm)
    # A diverging plant (no balance gain) keeps running and flags invalid steps, no crash.
    weak = ballbot.LqrController(
        ballbot.LqrGains(
            tilt_nm_per_rad=0.0,
            tilt_rate_nm_s_per_rad=0.0,
            ball_rate_nm_s_per_rad=0.0,
            max_torque_nm=1.0,
        )
    )
    run = ballbot.closed_loop_rollout(wip, weak, [0.1, 0, 0, 0], n_steps=2000, dt_secs=0.01)
    assert run.state.shape == (2001, 4)


def test_lqr_functions_with_hostile_matrices() -> None:
    statuses = {"converged", "max_iterations", "not_stabilizable", "non_finite"}
    for x in NASTY:
        a = np.array([[0.0, 1.0], [x, 0.0]])
        b = np.array([0.0, 1.0])
        for solve in (ballbot.solve_care, ballbot.solve_dare):
            try:
                assert solve(a, b, np.eye(2), 1.0).status in statuses
            except ballbot.ParameterError as e:
                assert "`a`" in str(e)
        try:
            ballbot.zoh(a, b, 1e300)
        except ballbot.ParameterError as e:
            assert "`a`" in str(e) or "`dt_secs`" in str(e)
    with pytest.raises(ballbot.ParameterError):
        ballbot.expm(np.full((2, 2), np.inf))


def test_wrong_dtypes_and_ranks(wip: ballbot.Wip) -> None:
    # Integer arrays are converted; strings and objects are rejected with a TypeError.
    assert wip.derivative(np.zeros(4, dtype=np.int64)).shape == (4,)
    with pytest.raises((TypeError, ValueError)):
        wip.derivative(np.array(["a", "b", "c", "d"]))
    with pytest.raises(ballbot.ShapeError):
        wip.derivative(np.zeros((2, 2, 4)))
    with pytest.raises(ballbot.ShapeError):
        wip.derivative(np.float64(1.0))


def test_huge_batches_work_or_raise_memory_error(wip: ballbot.Wip) -> None:
    states = np.zeros((1_000_000, 4))
    assert wip.derivative(states).shape == (1_000_000, 4)
    with pytest.raises(MemoryError):
        wip.rollout(np.zeros(4), dt_secs=1e-3, n_steps=1 << 62)
