"""Controllers with `step`, log replay with `step_many`, and closed-loop rollouts in Rust."""

import math
from typing import Any, Callable

import numpy as np
import pytest

import ballbot


@pytest.fixture
def lqr(wip: ballbot.Wip) -> ballbot.LqrController:
    return ballbot.LqrController(ballbot.LqrGains.for_wip(wip, 83.9))


def test_lqr_step_matches_the_rust_doc_example(lqr: ballbot.LqrController) -> None:
    out = lqr.step(np.array([0.1, 0.0, 0.0, 0.0]), np.zeros(4), 0.0025)
    assert out.torque_nm == pytest.approx(23.48, rel=1e-3)
    assert out.status is ballbot.StepStatus.NOMINAL
    assert out.tilt_term_nm == pytest.approx(out.torque_nm)
    # Lists and tuples work too; the command defaults to upright at rest.
    assert lqr.step([0.1, 0.0, 0.0, 0.0]).torque_nm == out.torque_nm
    sat = lqr.step((1.0, 0.0, 0.0, 0.0))
    assert sat.status is ballbot.StepStatus.SATURATED and sat.torque_nm == pytest.approx(83.9)
    assert sat.saturation_nm == pytest.approx(83.9 - 234.8, rel=1e-3)
    bad = lqr.step([float("nan"), 0.0, 0.0, 0.0])
    assert (bad.torque_nm, bad.status) == (0.0, ballbot.StepStatus.INVALID_INPUT)
    assert lqr.step([float("inf"), 0.0, 0.0, 0.0]).status is ballbot.StepStatus.INVALID_INPUT
    assert out.to_dict()["status"] is ballbot.StepStatus.NOMINAL


def test_gains_classes(wip: ballbot.Wip) -> None:
    g = ballbot.LqrGains.from_reduced((-234.8, -45.70, -3.162), 83.9)
    assert g.full() == pytest.approx([-234.8, 0.0, -45.70, -3.162])
    assert g.replace(max_torque_nm=40.0).max_torque_nm == 40.0
    designed = ballbot.LqrGains.design(wip, 83.9, q=[100.0, 10.0, 1.0], r=0.1)
    assert designed.reduced() == pytest.approx([-234.8, -45.70, -3.162], rel=1e-3)
    assert ballbot.LqrGains.design(wip, 83.9, dt_secs=0.0025) != designed
    with pytest.raises(ballbot.ParameterError, match="max_torque_nm"):
        ballbot.LqrGains(
            tilt_nm_per_rad=-1.0,
            tilt_rate_nm_s_per_rad=-1.0,
            ball_rate_nm_s_per_rad=-1.0,
            max_torque_nm=-5.0,
        )
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `kp`"):
        g.replace(kp=1.0)
    pipd = ballbot.PiPdGains.for_wip(wip, 83.9)
    assert pipd.tilt_p_nm_per_rad < 0.0 and pipd.speed_i_rad_per_rad > 0.0
    with pytest.raises(ballbot.ParameterError, match="poles_rad_per_s"):
        ballbot.PiPdGains.design(wip, (1.0, -1.0, -2.0, -3.0), 0.2, 83.9)
    inner = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    assert inner.proportional_nm_s_per_rad == pytest.approx(60.0 / 4.4545, rel=1e-3)
    config = ballbot.LqrPiOuterConfig.for_inner(g, inner)
    assert config.max_speed_error_rad_per_s == pytest.approx(
        83.9 / inner.proportional_nm_s_per_rad
    )


def test_step_many_equals_a_python_loop_of_step(wip: ballbot.Wip) -> None:
    rng = np.random.default_rng(11)
    measured = rng.normal(scale=0.1, size=(100, 4))
    a = ballbot.PiPdController(ballbot.PiPdGains.for_wip(wip, 83.9))
    b = ballbot.PiPdController(ballbot.PiPdGains.for_wip(wip, 83.9))
    batch = a.step_many(measured, [0.0, 0.0, 0.0, 1.0])
    loop = [b.step(m, [0.0, 0.0, 0.0, 1.0]).torque_nm for m in measured]
    assert batch["torque_nm"] == pytest.approx(loop, rel=0, abs=0)
    assert a.speed_error_integral_rad == b.speed_error_integral_rad != 0.0
    assert batch["status"].dtype == np.int8
    a.reset()
    assert a.speed_error_integral_rad == 0.0


def test_every_step_many_has_a_column_per_term_and_equals_its_step(wip: ballbot.Wip) -> None:
    rng = np.random.default_rng(12)
    measured = rng.normal(scale=0.05, size=(50, 4))
    command = [0.0, 0.0, 0.0, 1.0]
    gains = ballbot.LqrGains.for_wip(wip, 83.9)
    inner_gains = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    config = ballbot.LqrPiOuterConfig.for_inner(gains, inner_gains)
    makers: list[Callable[[], Any]] = [
        lambda: ballbot.LqrController(gains),
        lambda: ballbot.PiPdController(ballbot.PiPdGains.for_wip(wip, 83.9)),
        lambda: ballbot.LqrPiOuter(wip, config),
    ]
    for make in makers:
        batched, looped = make(), make()
        batch = batched.step_many(measured, command)
        steps = [looped.step(m, command).to_dict() for m in measured]
        assert set(batch) == set(steps[0]), type(batched).__name__
        for name in steps[0]:
            if name == "status":
                continue
            column = [s[name] for s in steps]
            assert batch[name] == pytest.approx(column, rel=0, abs=0), name


def test_every_controller_recovers_from_a_ten_degree_lean(wip: ballbot.Wip) -> None:
    tilt = math.radians(10.0)
    gains = ballbot.LqrGains.for_wip(wip, 83.9)
    inner_gains = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    outer = ballbot.LqrPiOuter(wip, ballbot.LqrPiOuterConfig.for_inner(gains, inner_gains))
    cases = [
        (ballbot.LqrController(gains), None),
        (ballbot.PiPdController(ballbot.PiPdGains.for_wip(wip, 83.9)), None),
        (outer, ballbot.SpeedPi(inner_gains)),
    ]
    for controller, inner in cases:
        run = ballbot.closed_loop_rollout(
            wip, controller, [tilt, 0.0, 0.0, 0.0], n_steps=4000, inner=inner, substeps=20
        )
        state = run.state
        assert state.shape == (4001, 4) and run.torque_nm.shape == (4000,)
        assert run.time_secs[-1] == pytest.approx(10.0)
        assert abs(state[-1, 0]) < 1e-3, type(controller).__name__
        assert abs(state[-1, 3]) < 1e-2, type(controller).__name__
        assert np.all(run.status != ballbot.StepStatus.INVALID_INPUT.code)
    # The rollout copies the controller: the caller's outer loop was not stepped.
    assert outer.reference_ball_rate_rad_per_s is None


def test_lqr_pi_without_disturbance_is_the_lqr(wip: ballbot.Wip) -> None:
    gains = ballbot.LqrGains.for_wip(wip, 83.9)
    inner_gains = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    outer = ballbot.LqrPiOuter(wip, ballbot.LqrPiOuterConfig.for_inner(gains, inner_gains))
    s0 = [0.05, 0.0, 0.0, 0.0]
    lqr = ballbot.closed_loop_rollout(
        wip, ballbot.LqrController(gains), s0, n_steps=800, substeps=20
    )
    pi = ballbot.closed_loop_rollout(
        wip, outer, s0, n_steps=800, substeps=20, inner=ballbot.SpeedPi(inner_gains)
    )
    assert np.max(np.abs(pi.state[:, 0] - lqr.state[:, 0])) < 2e-3


def test_batch_rollout_equals_single_rollouts(lqr: ballbot.LqrController, wip: ballbot.Wip) -> None:
    rng = np.random.default_rng(5)
    s0 = rng.normal(scale=0.05, size=(8, 4))
    command = np.tile([0.0, 0.0, 0.0, 2.0], (2000, 1))
    batch = ballbot.closed_loop_rollout(wip, lqr, s0, n_steps=2000, command=command)
    assert batch.state.shape == (8, 2001, 4) and batch.torque_nm.shape == (8, 2000)
    for i in (0, 7):
        one = ballbot.closed_loop_rollout(wip, lqr, s0[i], n_steps=2000, command=command)
        assert one.state == pytest.approx(batch.state[i], rel=0, abs=0)
    # Tracking a ball-rate command: the ball ends up rolling at about 2 rad/s.
    assert np.all(np.abs(batch.state[:, -1, 3] - 2.0) < 1e-3)


def test_bad_controller_input(lqr: ballbot.LqrController, wip: ballbot.Wip) -> None:
    with pytest.raises(ballbot.ShapeError, match=r"`measured` must have shape \(4,\)"):
        lqr.step(np.zeros(3))
    with pytest.raises(ballbot.ShapeError, match="`command`"):
        lqr.step(np.zeros(4), [1.0, 2.0])
    with pytest.raises(ValueError, match="sequence of 4 numbers"):
        lqr.step("abcd")
    with pytest.raises(ballbot.ShapeError, match=r"\(n_steps, 4\) = \(10, 4\)"):
        ballbot.closed_loop_rollout(wip, lqr, np.zeros(4), n_steps=10, command=np.zeros((9, 4)))
    with pytest.raises(ballbot.ParameterError, match="dt_secs"):
        ballbot.closed_loop_rollout(wip, lqr, np.zeros(4), n_steps=10, dt_secs=0.0)
    with pytest.raises(ballbot.ParameterError, match="substeps"):
        ballbot.closed_loop_rollout(wip, lqr, np.zeros(4), n_steps=10, substeps=0)
    with pytest.raises(TypeError, match="controller"):
        ballbot.closed_loop_rollout(wip, "lqr", np.zeros(4), n_steps=10)  # type: ignore[arg-type]
    g = ballbot.LqrGains.for_wip(wip, 83.9)
    inner = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    outer = ballbot.LqrPiOuter(wip, ballbot.LqrPiOuterConfig.for_inner(g, inner))
    with pytest.raises(ballbot.ParameterError, match="inner"):
        ballbot.closed_loop_rollout(wip, outer, np.zeros(4), n_steps=10)
    with pytest.raises(MemoryError):
        ballbot.closed_loop_rollout(wip, lqr, np.zeros((1 << 20, 4)), n_steps=1 << 40)


def test_accelerating_command_holds_the_acceleration(wip: ballbot.Wip) -> None:
    r = wip.params.ball_radius_m
    found = ballbot.accelerating_command(wip, 0.5 / r, 0.5 / r)
    assert found is not None
    state, torque_nm = found
    assert state[0] > 0.0
    assert wip.accelerations(state, torque_nm) == pytest.approx([0.0, 0.5 / r], abs=1e-9)
    assert ballbot.accelerating_command(wip, 0.0, 1e6) is None
    assert ballbot.accelerating_command(wip, float("nan"), 0.0) is None
