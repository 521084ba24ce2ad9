"""The typed surface: submodules, status enums with their one code table, frozen result
classes with `to_dict`, study settings classes, the loop rates."""

import dataclasses
import importlib

import numpy as np
import pytest

import ballbot
from ballbot import _core


@pytest.mark.parametrize("name", ["models", "control", "world", "studies", "trajopt", "log"])
def test_submodules_export_what_they_list_and_the_top_level_has_it_too(name: str) -> None:
    module = importlib.import_module(f"ballbot.{name}")
    assert module.__doc__
    for item in module.__all__:
        assert getattr(module, item) is getattr(ballbot, item), item
    assert set(module.__all__) <= set(ballbot.__all__)


def test_loop_rates_come_from_the_core() -> None:
    assert ballbot.OUTER_LOOP_DT_SECS == 0.0025 == 1.0 / ballbot.OUTER_LOOP_RATE_HZ
    assert ballbot.INNER_LOOP_DT_SECS == 0.000125 == 1.0 / ballbot.INNER_LOOP_RATE_HZ
    assert ballbot.control.OUTER_LOOP_DT_SECS is ballbot.OUTER_LOOP_DT_SECS


def test_enums_use_the_rust_names_and_one_code_table(wip: ballbot.Wip) -> None:
    assert [k.value for k in ballbot.FailureKind] == _core.FAILURE_KIND_NAMES
    assert [s.value for s in ballbot.StepStatus] == _core.STEP_STATUS_NAMES
    assert [ballbot.StepStatus.from_code(c) for c in range(3)] == list(ballbot.StepStatus)
    assert ballbot.StepStatus.SATURATED.code == 1
    with pytest.raises(ValueError, match="unknown step status code 3"):
        ballbot.StepStatus.from_code(3)
    # The batch codes decode to what `step` reports one at a time.
    gains = ballbot.LqrGains.for_wip(wip, 83.9)
    measured = np.array([[0.01, 0, 0, 0], [1.0, 0, 0, 0], [np.nan, 0, 0, 0]])
    batch = ballbot.LqrController(gains).step_many(measured)
    one = ballbot.LqrController(gains)
    assert list(ballbot.StepStatus.decode(batch["status"])) == [one.step(m).status for m in measured]
    # Members are also their names, so string comparisons keep working.
    assert ballbot.StepStatus.NOMINAL == "nominal" and ballbot.Mode("fault") is ballbot.Mode.FAULT  # type: ignore[comparison-overlap]


def test_results_are_frozen_typed_and_convert_to_dicts(wip: ballbot.Wip) -> None:
    controller = ballbot.LqrController(ballbot.LqrGains.for_wip(wip, 83.9))
    run = ballbot.closed_loop_rollout(wip, controller, [0.1, 0, 0, 0], n_steps=40)
    assert isinstance(run, ballbot.Rollout) and run.state.shape == (41, 4)
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.compute_secs = 0.0  # type: ignore[misc]
    d = run.to_dict()
    assert set(d) == {"time_secs", "state", "torque_nm", "status", "compute_secs"}
    assert d["state"] is run.state
    assert "state=array(shape=(41, 4)" in repr(run)
    world = ballbot.World().run(8)
    assert isinstance(world, ballbot.WorldRun) and world.torque_nm.shape == (8, 3)
    assert world.to_dict()["failure"] is None and world.steps == 8


def test_failures_name_their_wheel() -> None:
    world = ballbot.World()
    world.translate_robot([0.0, 0.0, 0.05])
    run = world.run(400, stop_on_failure=True)
    failure = run.failure
    assert failure is not None and failure.kind is ballbot.FailureKind.LIFT_OFF
    assert failure.wheel == "OW1" and failure.wheel_index == 0
    assert "FailureKind.LIFT_OFF" in repr(failure) and "'OW1'" not in repr(failure.kind)


def test_settings_validate_and_name_the_field() -> None:
    s = ballbot.BrakingSettings(cruise_speed_m_per_s=1.0, feedforward="core")
    assert s.feedforward is ballbot.Feedforward.CORE and s.settle_secs is None
    assert s.replace(settle_secs=0.2).settle_secs == 0.2 and s.settle_secs is None
    assert s.to_dict()["feedforward"] == "core"
    with pytest.raises(ballbot.ParameterError, match="cruise_speed_m_per_s"):
        ballbot.BrakingSettings(cruise_speed_m_per_s=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="intervals"):
        ballbot.BrakingSettings(intervals=1)  # the Rust protocol needs >= 2 as well
    # The Python checks accept what the Rust protocol accepts: an instantaneous push is valid.
    assert ballbot.PushSettings(push_duration_secs=0.0).push_duration_secs == 0.0
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `cruise`.*cruise_secs"):
        s.replace(cruise=1.0)
    with pytest.raises(ballbot.ParameterError, match="observe_secs"):
        ballbot.PushSettings(observe_secs=-1.0)
    with pytest.raises(ballbot.ParameterError, match="accel_bracket_m_per_s2"):
        ballbot.MaxSpeedSettings(accel_bracket_m_per_s2=(2.0, 1.0))
    with pytest.raises(ballbot.ParameterError, match="max_jerk_m_per_s3"):
        ballbot.RampSettings(max_jerk_m_per_s3=0.0)
    assert ballbot.RampSettings().to_dict()["accel_m_per_s2"] == 0.25
    m = ballbot.MaxSpeedSettings(trial_headings_deg=[0.0, 90.0])
    assert m.trial_headings_deg == (0.0, 90.0)
    with pytest.raises(TypeError, match="BrakingSettings"):
        ballbot.braking_run(duration_secs=1.0, settings=ballbot.PushSettings())  # type: ignore[arg-type]
