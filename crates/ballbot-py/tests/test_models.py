"""The Python mirror gives the same numbers as the Rust tests (MODEL.md section 6)."""

import math

import numpy as np
import pytest

import ballbot


def test_open_loop_poles_match_model_md(wip: ballbot.Wip) -> None:
    assert wip.upright_unstable_pole_rad_per_s() == pytest.approx(8.04, abs=5e-3)
    poles = np.sort(wip.open_loop_poles().real)
    assert poles == pytest.approx([-8.04, 0.0, 0.0, 8.04], abs=5e-3)


def test_linearisation_matches_model_md(wip: ballbot.Wip) -> None:
    a, b = wip.linearize()
    assert a.shape == (4, 4) and b.shape == (4,)
    assert a[2, 0] == pytest.approx(64.64, rel=1e-3)
    assert a[3, 0] == pytest.approx(-257.39, rel=1e-3)
    assert b[2] == pytest.approx(-0.8836, rel=1e-3)
    assert b[3] == pytest.approx(4.4545, rel=1e-3)


def test_vectorised_derivative_matches_single_rows(wip: ballbot.Wip) -> None:
    rng = np.random.default_rng(7)
    states = rng.normal(size=(50, 4))
    torques = rng.normal(scale=20.0, size=50)
    batch = wip.derivative(states, torques)
    assert batch.shape == (50, 4)
    for s, t, row in zip(states, torques, batch):
        assert wip.derivative(s, t) == pytest.approx(row, rel=1e-12, abs=1e-12)


def test_rollout_conserves_energy(wip: ballbot.Wip) -> None:
    traj = wip.rollout(np.array([math.radians(20.0), 0, 0, 0]), dt_secs=1e-3, n_steps=10_000)
    assert traj.shape == (10_001, 4)
    energy = wip.energy_j(traj)
    assert np.max(np.abs(energy - energy[0]) / energy[0]) < 2e-8


def test_parameters_roundtrip_through_dict_and_toml(tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = ballbot.WipParams.preset("piptb").replace(com_height_m=0.3)
    assert ballbot.WipParams.from_dict(p.to_dict()) == p
    path = tmp_path / "plane.toml"
    p.save(path)
    assert ballbot.WipParams.load(path) == p
    assert ballbot.WipParams(com_height_m=0.3).com_height_m == 0.3


def test_bad_parameters_raise_parameter_error() -> None:
    with pytest.raises(ballbot.ParameterError, match="body_mass_kg"):
        ballbot.WipParams(body_mass_kg=-1.0)
    with pytest.raises(ValueError, match="com_height_m"):
        ballbot.WipParams(com_height_m=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `mass`"):
        ballbot.WipParams(mass=3.0)
    with pytest.raises(ballbot.ParameterError, match="unknown preset `segway`.*piptb"):
        ballbot.WipParams.preset("segway")


def test_bad_shapes_raise_shape_error(wip: ballbot.Wip) -> None:
    with pytest.raises(ballbot.ShapeError, match=r"shape \(4,\) or \(n, 4\)"):
        wip.derivative(np.zeros(3))
    with pytest.raises(ValueError, match="torque_nm"):
        wip.derivative(np.zeros((5, 4)), np.zeros(4))


def test_unreadable_files_raise_file_error(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ballbot.FileError, match="missing.toml"):
        ballbot.WipParams.load(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("ball_radius_m = 0.1\nwheels = 3\n")
    with pytest.raises(ballbot.FileError, match="bad.toml"):
        ballbot.WipParams.load(bad)
    with pytest.raises(OSError):
        ballbot.WipParams.load(tmp_path / "missing.toml")
