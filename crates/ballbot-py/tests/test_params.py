"""Parameter classes: presets, keyword construction, nested structs, dict and TOML round trips,
and the errors bad input raises."""

import math
from pathlib import Path

import numpy as np
import pytest

import ballbot


def test_drivetrain_preset_is_miapure() -> None:
    d = ballbot.DrivetrainParams.preset("miapure")
    assert np.degrees(d.wheel_azimuths_rad) == pytest.approx([0.0, 120.0, 240.0])
    assert math.degrees(d.contact_angle_rad) == pytest.approx(45.0)
    assert d.wheel_radius_m == 0.0625
    assert d.actuator == ballbot.ActuatorParams.preset("miapure")
    assert d.actuator.peak_torque_nm == 43.2
    assert ballbot.DrivetrainParams() == d


def test_ballbot_params_nest_the_planes_and_drivetrain() -> None:
    p = ballbot.BallbotParams.preset("miapure_60kg")
    assert p.sagittal == ballbot.WipParams.preset("miapure_60kg")
    assert p.frontal == p.sagittal
    assert p.spin == ballbot.SpinParams.preset("miapure_60kg")
    assert p.ball_radius_m == pytest.approx(0.1145)
    unloaded = ballbot.BallbotParams.preset("miapure_unloaded")
    assert unloaded.sagittal.body_mass_kg < p.sagittal.body_mass_kg
    assert ballbot.PlanarRobotParams.preset("piptb").plane == ballbot.WipParams.preset("piptb")


def test_nested_fields_accept_objects_and_partial_dicts() -> None:
    p = ballbot.BallbotParams(drivetrain={"contact_angle_rad": math.radians(50.0)})
    assert math.degrees(p.drivetrain.contact_angle_rad) == pytest.approx(50.0)
    # The rest of the drivetrain keeps the default preset's values.
    assert p.drivetrain.wheel_radius_m == 0.0625
    heavy = ballbot.WipParams.preset("miapure_60kg").replace(body_mass_kg=90.0)
    q = p.replace(sagittal=heavy, frontal=heavy)
    assert q.sagittal.body_mass_kg == 90.0 and q.frontal == heavy
    d = ballbot.DrivetrainParams(wheel_azimuths_rad=np.radians([10.0, 130.0, 250.0]))
    assert np.degrees(d.wheel_azimuths_rad) == pytest.approx([10.0, 130.0, 250.0])


def test_replace_accepts_the_dotted_keys_of_sweeps() -> None:
    w = ballbot.WorldParams.preset("miapure_60kg")
    dotted = w.replace(
        **{"robot.drivetrain.wheel_ball_friction": 0.5, "contact.rollers.count": 8},
        wheel_inertia_kg_m2=1.1e-3,
    )
    nested = w.replace(
        robot={"drivetrain": {"wheel_ball_friction": 0.5}},
        contact={"rollers": {"count": 8}},
        wheel_inertia_kg_m2=1.1e-3,
    )
    assert dotted == nested
    assert dotted.robot.drivetrain.wheel_ball_friction == 0.5
    assert dotted.contact.rollers.count == 8
    assert dotted.robot.drivetrain.wheel_radius_m == w.robot.drivetrain.wheel_radius_m
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `robot.drivetrain.nope`"):
        w.replace(**{"robot.drivetrain.nope": 1.0})
    with pytest.raises(ballbot.ParameterError, match="`wheel_inertia_kg_m2` is not a nested"):
        w.replace(**{"wheel_inertia_kg_m2.x": 1.0})
    with pytest.raises(ballbot.ParameterError, match="wheel_ball_friction"):
        w.replace(**{"robot.drivetrain.wheel_ball_friction": -1.0})


def test_nested_roundtrip_through_dict_and_toml(tmp_path: Path) -> None:
    p = ballbot.BallbotParams.preset("miapure_unloaded").replace(
        spin={"damping_nm_s_per_rad": 2.5}
    )
    d = p.to_dict()
    assert isinstance(d["drivetrain"]["wheel_azimuths_rad"], list)
    assert d["spin"]["damping_nm_s_per_rad"] == 2.5
    assert ballbot.BallbotParams.from_dict(d) == p
    path = tmp_path / "robot.toml"
    p.save(path)
    assert ballbot.BallbotParams.load(path) == p
    assert ballbot.BallbotParams.load(str(path)) == p
    r = ballbot.PlanarRobotParams.preset("piptb")
    r.save(tmp_path / "piptb.toml")
    assert ballbot.PlanarRobotParams.load(tmp_path / "piptb.toml") == r


def test_unknown_presets_and_fields_name_the_alternatives() -> None:
    with pytest.raises(ballbot.ParameterError, match="unknown preset `segway`.*miapure_60kg"):
        ballbot.BallbotParams.preset("segway")
    with pytest.raises(ballbot.ParameterError, match="unknown preset `x`.*miapure"):
        ballbot.DrivetrainParams.preset("x")
    with pytest.raises(ballbot.ParameterError, match=r"unknown parameter `drivetrain.wheels`"):
        ballbot.BallbotParams(drivetrain={"wheels": 4})
    with pytest.raises(ValueError, match="unknown parameter `mass`.*body_mass_kg"):
        ballbot.WipParams(mass=3.0)


def test_invalid_values_raise_parameter_error_naming_the_field() -> None:
    with pytest.raises(ballbot.ParameterError, match="contact_angle_rad"):
        ballbot.DrivetrainParams(contact_angle_rad=math.radians(95.0))
    with pytest.raises(ballbot.ParameterError, match="wheel_azimuths_rad"):
        ballbot.DrivetrainParams(wheel_azimuths_rad=[0.0, 0.0, 1.0])
    with pytest.raises(ballbot.ParameterError, match="wheel_azimuths_rad"):
        ballbot.DrivetrainParams(wheel_azimuths_rad=[0.0, float("nan"), 1.0])
    with pytest.raises(ballbot.ParameterError, match=r"sequence of 3 numbers"):
        ballbot.DrivetrainParams(wheel_azimuths_rad=[0.0, 1.0])
    with pytest.raises(ballbot.ParameterError, match="must be a number"):
        ballbot.WipParams(body_mass_kg="heavy")
    with pytest.raises(ballbot.ParameterError, match="must be a number"):
        ballbot.WipParams(body_mass_kg=True)
    with pytest.raises(ballbot.ParameterError, match="peak_torque_nm"):
        ballbot.ActuatorParams(peak_torque_nm=float("inf"))
    with pytest.raises(ballbot.ParameterError, match="ball_radius_m"):
        # The two planes must share one ball.
        ballbot.BallbotParams(frontal={"ball_radius_m": 0.2})
    with pytest.raises(ballbot.ParameterError, match="`sagittal` must be"):
        ballbot.BallbotParams(sagittal=ballbot.SpinParams())


def test_a_toml_file_with_a_bad_value_is_a_parameter_error(tmp_path: Path) -> None:
    path = tmp_path / "nan.toml"
    ballbot.WipParams().save(path)
    text = path.read_text().replace("body_mass_kg = 74.3", "body_mass_kg = nan")
    path.write_text(text)
    with pytest.raises(ballbot.ParameterError, match="nan.toml.*body_mass_kg"):
        ballbot.WipParams.load(path)


def test_unreadable_files_raise_file_error(tmp_path: Path) -> None:
    with pytest.raises(ballbot.FileError, match="missing.toml"):
        ballbot.BallbotParams.load(tmp_path / "missing.toml")
    (tmp_path / "binary.toml").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(ballbot.FileError, match="binary.toml"):
        ballbot.DrivetrainParams.load(tmp_path / "binary.toml")
    with pytest.raises(ballbot.FileError):
        ballbot.WipParams().save(tmp_path / "no" / "such" / "dir.toml")
    with pytest.raises(ballbot.FileError):
        ballbot.WipParams.load(tmp_path)  # a directory


def test_actuator_torque_speed_line() -> None:
    a = ballbot.ActuatorParams.preset("miapure")
    assert a.torque_bounds_nm(0.0) == pytest.approx((-43.2, 43.2))
    lo, hi = a.torque_bounds_nm(a.no_load_speed_rad_per_s)
    assert hi == pytest.approx(0.0, abs=1e-9) and lo == pytest.approx(-43.2)
    assert a.clamp_torque_nm(100.0, 0.0) == pytest.approx(43.2)
