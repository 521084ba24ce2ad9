"""``ControllerConfig``: the 3D controller's configuration as a controller file, from Python.

The presets are the command line's (``ballbot params show --kind controller``), a file round
trips through Python unchanged, every bad value names its dotted key as ``ballbot params check``
does, and ``WorldLoop``/``max_speed_ramp`` run it (``controller=``)."""

from __future__ import annotations

import os
import pickle
import subprocess
from pathlib import Path
from typing import Optional

import numpy as np
import pytest

import ballbot

REPO = Path(__file__).resolve().parents[3]


def _ballbot_binary() -> Optional[Path]:
    """The newest built ``ballbot`` command that knows controller files, if any."""
    dirs = [Path(d) for d in (os.environ.get("CARGO_TARGET_DIR"),) if d] + [REPO / "target"]
    found = [d / p / "ballbot" for d in dirs for p in ("debug", "release")]
    found = sorted((b for b in found if b.is_file()), key=lambda b: b.stat().st_mtime, reverse=True)
    for binary in found:
        done = subprocess.run(
            [str(binary), "params", "show", "--kind", "controller", "--preset", "design"],
            capture_output=True,
            text=True,
        )
        if done.returncode == 0:
            return binary
    return None


def _body(text: str) -> str:
    """A commented file without its header (the comment lines before the first blank line)."""
    return text.split("\n\n", 1)[1]


def test_design_and_paper_are_the_presets() -> None:
    design, paper = ballbot.ControllerConfig.design(), ballbot.ControllerConfig.paper()
    assert ballbot.ControllerConfig.presets() == ["design", "paper"]
    assert design == ballbot.ControllerConfig.preset("design") == ballbot.ControllerConfig()
    assert paper == ballbot.ControllerConfig.preset("paper")
    assert design.traction_control and design.balance_point
    assert not paper.traction_control and not paper.balance_point
    assert design.traction_safety_factor == 2.0 and design.outer_dt_secs == 0.0025
    assert design.robot == ballbot.BallbotParams.preset("miapure_60kg")
    assert design.wheel_mapping == "rolling_ball"
    # Designed for another robot: its model and its gains.
    unloaded = ballbot.BallbotParams.preset("miapure_unloaded")
    light = ballbot.ControllerConfig.design(unloaded)
    assert light.robot == unloaded and light != design
    with pytest.raises(ballbot.ParameterError, match="unknown preset `fast`.*design, paper"):
        ballbot.ControllerConfig.preset("fast")  # type: ignore[arg-type]


def test_to_toml_reads_back_and_is_what_the_cli_writes(tmp_path: Path) -> None:
    design = ballbot.ControllerConfig.design()
    text = design.to_toml()
    assert "friction_safety_factor = 2.0" in text and "[traction]" in text
    assert ballbot.ControllerConfig.from_toml(text) == design
    binary = _ballbot_binary()
    if binary is None:
        pytest.skip("no built `ballbot` command with controller files")
    for name in ("design", "paper"):
        cli = subprocess.run(
            [str(binary), "params", "show", "--kind", "controller", "--preset", name],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        config = ballbot.ControllerConfig.preset(name)
        assert ballbot.ControllerConfig.from_toml(cli) == config
        # The same file but for the header: every key, comment and value.
        assert _body(config.to_toml()) == _body(cli)
    # And the command line reads what Python writes.
    mine = tmp_path / "mine.toml"
    design.with_traction_safety_factor(3.0).save(mine)
    checked = subprocess.run(
        [str(binary), "params", "check", str(mine)], capture_output=True, text=True
    )
    assert checked.returncode == 0, checked.stderr
    assert "valid controller file" in checked.stdout


def test_a_file_round_trips_through_python(tmp_path: Path) -> None:
    first = tmp_path / "design.toml"
    first.write_text(ballbot.ControllerConfig.design().to_toml())
    edited = first.read_text().replace(
        "friction_safety_factor = 2.0", "friction_safety_factor = 3.0"
    )
    first.write_text(edited)
    config = ballbot.ControllerConfig.from_file(first)
    assert config.traction_safety_factor == 3.0
    assert config == ballbot.ControllerConfig.load(first)
    second = tmp_path / "again.toml"
    config.save(second)
    assert second.read_text() == config.to_toml() == edited
    assert ballbot.ControllerConfig.from_file(second) == config


def test_a_bad_safety_factor_names_its_key(tmp_path: Path) -> None:
    key = r"`traction.friction_safety_factor` must be finite and >= 1"
    text = ballbot.ControllerConfig.design().to_toml()
    bad = text.replace("friction_safety_factor = 2.0", "friction_safety_factor = 0.5")
    with pytest.raises(ballbot.ParameterError, match=key):
        ballbot.ControllerConfig.from_toml(bad)
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    with pytest.raises(ballbot.ParameterError, match=f"bad.toml: {key}"):
        ballbot.ControllerConfig.from_file(path)
    design = ballbot.ControllerConfig.design()
    with pytest.raises(ballbot.ParameterError, match=key):
        design.with_traction_safety_factor(0.5)
    with pytest.raises(ballbot.ParameterError, match=key):
        design.replace({"traction.friction_safety_factor": 0.5})
    with pytest.raises(ballbot.ParameterError, match=key):
        design.replace(traction={"friction_safety_factor": float("nan")})


def test_other_bad_files_and_values_name_their_key(tmp_path: Path) -> None:
    text = ballbot.ControllerConfig.design().to_toml()
    with pytest.raises(ballbot.ParameterError, match="`traction.nope`"):
        ballbot.ControllerConfig.from_toml(text.replace("[traction]\n", "[traction]\nnope = 1\n"))
    with pytest.raises(ballbot.ParameterError, match="`outer_dt_secs`"):
        ballbot.ControllerConfig.from_toml(text.replace("outer_dt_secs = 0.0025", ""))
    with pytest.raises(ballbot.ParameterError, match="`shaping.translation.max_value`"):
        ballbot.ControllerConfig.design().replace({"shaping.translation.max_value": -1.0})
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `traction.nope`"):
        ballbot.ControllerConfig.design().replace({"traction.nope": 1.0})
    with pytest.raises(ballbot.ParameterError, match="`traction.enabled` must be a bool"):
        ballbot.ControllerConfig.design().replace({"traction.enabled": 1})
    with pytest.raises(ballbot.ParameterError, match="balancing"):
        ballbot.ControllerConfig.design().replace(balancing="pid")
    missing = r"`balancing\.pi_pd\.frontal\.\w+`: missing field"
    with pytest.raises(ballbot.ParameterError, match=missing) as e:
        ballbot.ControllerConfig.design().replace(balancing={"pi_pd": {"frontal": {}}})
    assert "line" not in str(e.value), "no line of a text the caller never saw"
    with pytest.raises(ballbot.FileError, match="not a TOML file"):
        path = tmp_path / "broken.toml"
        path.write_text("[traction\n")
        ballbot.ControllerConfig.from_file(path)
    with pytest.raises(ballbot.FileError, match="missing.toml"):
        ballbot.ControllerConfig.from_file(tmp_path / "missing.toml")


def test_replace_takes_dotted_keys_dicts_and_keywords() -> None:
    design = ballbot.ControllerConfig.design()
    a = design.replace({"traction.friction_safety_factor": 6.0})
    b = design.replace(**{"traction.friction_safety_factor": 6.0})
    c = design.replace(traction={"friction_safety_factor": 6.0})
    d = design.with_traction_safety_factor(6.0)
    assert a == b == c == d and a.traction_safety_factor == 6.0
    assert design.traction_safety_factor == 2.0, "frozen: replace copies"
    assert a.to_dict()["traction"]["friction_safety_factor"] == 6.0
    off = design.replace({"traction.enabled": False}, **{"balance_point.enabled": False})
    assert not off.traction_control and not off.balance_point
    assert design.replace(balancing="lqr_pi") == design
    heavy = ballbot.BallbotParams.preset("miapure_60kg").replace(
        **{"sagittal.body_mass_kg": 70.0}
    )
    assert design.replace(robot=heavy).robot == heavy
    # from_dict / to_dict round trip.
    assert ballbot.ControllerConfig.from_dict(off.to_dict()) == off


def test_the_pi_pd_balancing_law_is_set_whole_or_by_key() -> None:
    paper = ballbot.ControllerConfig.paper()
    robot = paper.robot
    frontal = ballbot.PiPdGains.for_wip(ballbot.Wip(robot.frontal), 83.9).to_dict()
    sagittal = ballbot.PiPdGains.for_wip(ballbot.Wip(robot.sagittal), 96.9).to_dict()
    pi_pd = paper.replace(balancing={"pi_pd": {"frontal": frontal, "sagittal": sagittal}})
    assert pi_pd.to_dict()["balancing"]["pi_pd"]["sagittal"] == sagittal
    assert ballbot.ControllerConfig.from_toml(pi_pd.to_toml()) == pi_pd
    assert pickle.loads(pickle.dumps(pi_pd)) == pi_pd
    stiffer = pi_pd.replace({"balancing.pi_pd.frontal.tilt_p_nm_per_rad": -300.0})
    assert stiffer.to_dict()["balancing"]["pi_pd"]["frontal"]["tilt_p_nm_per_rad"] == -300.0
    assert stiffer.replace(balancing="lqr_pi") == paper
    loop = ballbot.WorldLoop(controller=pi_pd)
    loop.run(400)
    assert loop.mode is ballbot.Mode.BALANCING


def test_equality_repr_and_pickle() -> None:
    design = ballbot.ControllerConfig.design()
    six = design.with_traction_safety_factor(6.0)
    assert design != six and design == ballbot.ControllerConfig.design()
    text = repr(six)
    assert text.startswith("ControllerConfig(") and "traction_safety_factor=6.0" in text
    assert "traction_control=True" in text
    # An unlimited jerk (inf) survives too: the pickle is the file's TOML.
    unlimited = six.replace({"shaping.translation.max_jerk_per_s2": float("inf")})
    for config in (design, six, ballbot.ControllerConfig.paper(), unlimited):
        again = pickle.loads(pickle.dumps(config))
        assert again == config and type(again) is ballbot.ControllerConfig


def test_world_loop_runs_the_controller_given() -> None:
    ramp = np.zeros((800, 3))
    ramp[:, 0] = 0.5 * np.arange(800) / 8000
    default = ballbot.WorldLoop().run(800, ramp)
    given = ballbot.WorldLoop(controller=ballbot.ControllerConfig.design()).run(800, ramp)
    assert np.array_equal(default.body_rate_rad_per_s, given.body_rate_rad_per_s)
    paper = ballbot.WorldLoop(controller=ballbot.ControllerConfig.paper())
    paper_run = paper.run(800, ramp)
    assert paper.traction is None and paper.traction_envelope() is None
    same = ballbot.WorldLoop(traction_control=False, balance_point=False).run(800, ramp)
    assert np.array_equal(paper_run.body_rate_rad_per_s, same.body_rate_rad_per_s)
    with pytest.raises(ballbot.ParameterError, match="`traction_control` and `balance_point`"):
        ballbot.WorldLoop(controller=ballbot.ControllerConfig.design(), traction_control=False)
    with pytest.raises(ballbot.ParameterError, match="`traction_control` and `balance_point`"):
        ballbot.WorldLoop(controller=ballbot.ControllerConfig.paper(), balance_point=True)
    # The shaping keywords still apply on top of it.
    with pytest.raises(ballbot.ParameterError, match="max_speed_m_per_s"):
        ballbot.WorldLoop(controller=ballbot.ControllerConfig.design(), max_speed_m_per_s=-1.0)


def test_a_larger_traction_safety_factor_holds_a_ramp_slower() -> None:
    # `ballbot world --heading-deg 120 --accel-m-per-s2 2 --top-speed-m-per-s 2
    # --duration-secs 2.5 [--traction-safety-factor 6]`: 1.95 m/s with factor 2, 0.77 with 6.
    # The same ramp here: 0.5 s settle, 1 s to 2 m/s, 1 s held; the caps of
    # `CommandShaperParams::admitting_ramp(2, 2)` (the CLI's).
    design = ballbot.ControllerConfig.design()

    def top(config: ballbot.ControllerConfig) -> float:
        run = ballbot.max_speed_ramp(
            heading_deg=120.0,
            controller=config,
            accel_m_per_s2=2.0,
            max_command_m_per_s=2.0,
            max_accel_m_per_s2=2.0,
            max_tilt_command_rad=0.5,
            max_tilt_rate_command_rad_per_s=5.0,
        )
        return run.max_speed_m_per_s

    two, six = top(design), top(design.with_traction_safety_factor(6.0))
    assert six < two - 0.5
    assert two == pytest.approx(1.95, abs=0.05)
    assert six == pytest.approx(0.77, abs=0.05)
