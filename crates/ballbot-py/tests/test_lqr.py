"""LQR synthesis from Python with the Rust tests' reference numbers (MODEL.md section 6)."""

import math

import numpy as np
import pytest

import ballbot


def test_wip_lqr_gains_and_poles_match_model_md(wip: ballbot.Wip) -> None:
    lqr = ballbot.wip_lqr(wip)
    assert lqr.reduced_gains() == pytest.approx([-234.8, -45.70, -3.162], rel=1e-3)
    assert lqr.paper_gains() == pytest.approx([-234.8, 0.0, -45.70, -3.162], rel=1e-3)
    poles = np.sort(lqr.closed_loop_eigenvalues().real)
    assert poles == pytest.approx([-19.5, -4.78, -2.06], rel=5e-3)
    assert lqr.dt_secs is None and lqr.residual < 1e-9
    # The same design through the generic single-input entry point.
    a, b = wip.linearize()
    keep = [0, 2, 3]
    generic = ballbot.Lqr.continuous(a[np.ix_(keep, keep)], b[keep], [100.0, 10.0, 1.0], 0.1)
    assert generic.gain == pytest.approx(lqr.gain, rel=1e-9)
    # A forward lean (reference upright) asks for a forward ball torque.
    assert lqr.control(np.zeros(3), [0.01, 0.0, 0.0]) > 0.0


def test_discrete_design_is_stable_and_close_to_continuous(wip: ballbot.Wip) -> None:
    cont = ballbot.wip_lqr(wip)
    disc = ballbot.wip_lqr_discrete(wip, dt_secs=1.0 / 400.0)
    assert disc.dt_secs == 1.0 / 400.0
    assert np.all(np.abs(disc.closed_loop_eigenvalues()) < 1.0)
    assert np.linalg.norm(disc.gain - cont.gain) < 0.05 * np.linalg.norm(cont.gain)
    gains = disc.controller_gains(83.9)
    assert gains.reduced() == pytest.approx(disc.gain)


def test_spin_lqr_heading_gain() -> None:
    spin = ballbot.Spin(ballbot.SpinParams.preset("miapure_60kg"))
    lqr = ballbot.spin_lqr(spin, [100.0, 1.0], 1.0)
    assert lqr.gain[0] == pytest.approx(10.0, rel=1e-9)
    disc = ballbot.spin_lqr_discrete(spin, np.diag([100.0, 1.0]), 1.0, 0.01)
    assert np.all(np.abs(disc.closed_loop_eigenvalues()) < 1.0)
    with pytest.raises(ballbot.ShapeError, match="paper_gains|reduced state|3"):
        lqr.paper_gains()


def test_riccati_solvers_on_the_double_integrator() -> None:
    a = np.array([[0.0, 1.0], [0.0, 0.0]])
    b = np.array([0.0, 1.0])
    care = ballbot.solve_care(a, b, np.eye(2), 1.0)
    assert care.status is ballbot.RiccatiStatus.CONVERGED and care.is_converged()
    assert care.gain == pytest.approx(np.array([[1.0, math.sqrt(3.0)]]), rel=1e-12)
    ad, bd = ballbot.zoh(a, b, 0.1)
    assert ad == pytest.approx(np.array([[1.0, 0.1], [0.0, 1.0]]), abs=1e-15)
    assert bd == pytest.approx([0.005, 0.1], abs=1e-15)
    dare = ballbot.solve_dare(ad, bd, np.eye(2), 1.0)
    assert dare.status is ballbot.RiccatiStatus.CONVERGED and dare.residual < 1e-12
    # Two inputs: full actuation.
    two = ballbot.solve_care(a, np.eye(2), np.eye(2), np.eye(2))
    assert two.gain.shape == (2, 2) and two.is_converged()
    assert ballbot.expm(np.zeros((3, 3))) == pytest.approx(np.eye(3))


def test_unstabilisable_plants_report_a_status_or_solver_error() -> None:
    a = np.diag([1.0, 2.0])
    b = np.array([1.0, 0.0])  # the mode at +2 cannot be moved
    sol = ballbot.solve_care(a, b, np.eye(2), 1.0)
    assert sol.status is ballbot.RiccatiStatus.NOT_STABILIZABLE
    with pytest.raises(ballbot.SolverError, match="no stabilising gain"):
        ballbot.Lqr.continuous(a, b, np.eye(2), 1.0)
    assert issubclass(ballbot.SolverError, ballbot.BallbotError)


def test_bad_lqr_input_raises_documented_errors(wip: ballbot.Wip) -> None:
    with pytest.raises(ballbot.ShapeError, match=r"`q` must have shape \(3,\)"):
        ballbot.wip_lqr(wip, q=np.eye(4))
    with pytest.raises(ballbot.ParameterError, match="`r`"):
        ballbot.wip_lqr(wip, r=0.0)
    with pytest.raises(ballbot.ParameterError, match="`r`"):
        ballbot.wip_lqr(wip, r=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="`q`"):
        ballbot.wip_lqr(wip, q=[100.0, -1.0, 1.0])
    with pytest.raises(ballbot.ParameterError, match="`dt_secs`"):
        ballbot.wip_lqr_discrete(wip, dt_secs=-1.0)
    with pytest.raises(ballbot.ShapeError, match=r"1 <= n <= 6"):
        ballbot.solve_care(np.eye(7), np.ones(7), np.eye(7), 1.0)
    with pytest.raises(ballbot.ShapeError, match=r"`b` must have shape \(2,\)"):
        ballbot.solve_dare(np.eye(2), np.ones(3), np.eye(2), 1.0)
    with pytest.raises(ballbot.ParameterError, match="`a`"):
        ballbot.solve_care(np.full((2, 2), np.nan), np.ones(2), np.eye(2), 1.0)
    with pytest.raises(ballbot.ShapeError):
        ballbot.Lqr.continuous(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 1.0)
