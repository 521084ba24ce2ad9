"""What the native module's results look like from Python, pinned field by field: attribute
names, types (float or int, enum class, nested result class), numpy dtypes, shapes and
writability, and a few values, recorded in `result_layouts.json` from the hand-filled results
(`set_item`): a change of how the bindings convert a result must not change them."""

from __future__ import annotations

import dataclasses
import enum
import json
import math
import os
import pickle
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ballbot
from ballbot import _results

FAST_BRAKING = ballbot.BrakingSettings(approach_accel_m_per_s2=1.0, settle_secs=0.2, cruise_secs=1.0)
FAST_PUSH = ballbot.PushSettings(settle_secs=0.5, observe_secs=3.0, rest_within_secs=2.5)


def layout(value: Any) -> Any:
    """The type structure of a result: classes with their fields, arrays as
    ``(dtype, shape, writeable, c_contiguous)``, enums as their class, lists item by item,
    dicts key by key, scalars as their type's name."""
    if isinstance(value, _results._Result):
        fields = {f.name: layout(getattr(value, f.name)) for f in dataclasses.fields(value)}
        return (type(value).__name__, fields)
    if isinstance(value, np.ndarray):
        flags = value.flags
        # The number of rows depends on how long the run lasted: "n" (the values test checks
        # that the columns of a result agree).
        shape = ("n", *value.shape[1:]) if value.ndim else ()
        return ("ndarray", str(value.dtype), shape, flags.writeable, flags.c_contiguous)
    if isinstance(value, enum.Enum):
        return ("enum", type(value).__name__)
    if isinstance(value, list):
        return [layout(v) for v in value]
    if isinstance(value, tuple):
        return ("tuple", [layout(v) for v in value])
    if isinstance(value, dict):
        return {k: layout(v) for k, v in value.items()}
    return type(value).__name__

LAYOUTS = Path(__file__).with_name("result_layouts.json")


def _cases() -> dict[str, Any]:
    quick = ballbot.MaxSpeedSettings(
        quick=True,
        trial_headings_deg=(180.0,),
        map_headings_deg=(180.0,),
        accel_bracket_m_per_s2=(2.0, 2.4),
        accel_resolution_m_per_s2=0.2,
    )
    return {
        "braking_run_no_trajectory": lambda: ballbot.braking_run(
            heading_deg=180.0, duration_secs=0.3, settings=FAST_BRAKING
        ),
        "braking_study": lambda: ballbot.braking_study(
            heading_deg=180.0,
            durations_secs=[3.0, 1.0, 0.5],
            bisection_resolution_secs=1.0,
            settings=FAST_BRAKING,
        ),
        "push_trial": lambda: ballbot.push_trial(heading_deg=90.0, impulse_ns=5.0, settings=FAST_PUSH),
        "push_recovery_limit": lambda: ballbot.push_recovery_limit(
            heading_deg=90.0, upper_ns=160.0, resolution_ns=40.0, settings=FAST_PUSH
        ),
        "max_speed_ramp": lambda: ballbot.max_speed_ramp(heading_deg=90.0),
        "slow_ramp_trial": lambda: ballbot.slow_ramp_trial(heading_deg=180.0, seed=2),
        "failing_acceleration": lambda: ballbot.failing_acceleration(
            ballbot.WorldParams.preset("ideal_miapure_60kg"),
            heading_deg=0.0,
            accel_bracket_m_per_s2=(1.5, 2.0),
            accel_resolution_m_per_s2=0.25,
        ),
        "max_speed_study": lambda: ballbot.max_speed_study(settings=quick),
        "world_run": lambda: ballbot.World().run(200, [0.0, 0.0, 1.0], record_every=7),
        "world_run_failed": lambda: ballbot.World().run(
            40_000, [30.0, 0.0, 0.0], record_every=400, stop_on_failure=True
        ),
        "world_loop_run": lambda: ballbot.WorldLoop().run(800, [0.5, 0.0, 0.0], record_every=80),
        "world_loop_run_logged": _logged_world_loop_run,
        "scenario_run": lambda: ballbot.Scenario.from_toml(SCENARIO).run(),
        "scenario_run_logged": _logged_scenario_run,
        "traction_status": lambda: _traction_loop().traction,
        "traction_envelope": lambda: _traction_loop().traction_envelope(),
        "rollout_single": lambda: _rollout(np.array([0.1, 0.0, 0.0, 0.0])),
        "rollout_batch": lambda: _rollout(np.zeros((5, 4))),
        "gym_reset_info": lambda: _gym_episode()[0],
        "gym_step_info_with_events": lambda: _gym_episode()[1][12],
        "gym_step_info_at_the_end": lambda: _gym_episode()[1][-1],
    }


def _rollout(initial: Any) -> Any:
    wip = ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))
    lqr = ballbot.wip_lqr(wip, q=[100.0, 10.0, 1.0], r=0.1)
    controller = ballbot.LqrController(lqr.controller_gains(max_torque_nm=83.9))
    return ballbot.closed_loop_rollout(wip, controller, initial, n_steps=50)


def _gym_episode() -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The reset's info and every step's info of test_gym's lean-and-let-go episode: opposite
    torques on OW1 and OW2 for ten steps, then nothing, until it ends (contact events, a
    termination, the episode's events at the end)."""
    env = ballbot._core.GymEnv("balance")
    _, reset_info = env.reset(seed=0, options={"initial_tilt_rad": [0.0, 0.0]})
    lean = np.array([0.5, -0.5, 0.0], dtype=np.float32)
    infos = []
    for k in range(2000):
        _, _, term, trunc, info = env.step(lean if k < 10 else np.zeros(3, dtype=np.float32))
        infos.append(info)
        if term or trunc:
            break
    return reset_info, infos


def _traction_loop() -> ballbot.WorldLoop:
    loop = ballbot.WorldLoop()
    loop.run(800, [0.5, 0.0, 0.0])
    return loop


SCENARIO = 'seed = 3\nduration_secs = 0.5\n[controller]\nkind = "lqr_pi"'


def _logged_scenario_run() -> Any:
    with tempfile.TemporaryDirectory() as tmp:
        return ballbot.Scenario.from_toml(SCENARIO).run(log_path=Path(tmp) / "run.mcap")


def _logged_world_loop_run() -> Any:
    with tempfile.TemporaryDirectory() as tmp:
        return ballbot.WorldLoop().run(80, log_path=Path(tmp) / "run.mcap", record_every=8)


def _plain(value: Any) -> Any:
    """As JSON has it (tuples become lists), to compare with the recorded file."""
    return json.loads(json.dumps(value))


@pytest.mark.parametrize("name", list(_cases()))
def test_result_layout_is_unchanged(name: str) -> None:
    # BALLBOT_RECORD_LAYOUTS=1 rewrites the file from this build (only on purpose: a change
    # of a result's Python form is an API change for CHANGELOG.md).
    got = _plain(layout(_cases()[name]()))
    recorded = json.loads(LAYOUTS.read_text()) if LAYOUTS.exists() else {}
    if os.environ.get("BALLBOT_RECORD_LAYOUTS") == "1":
        recorded[name] = got
        lines = [f"{json.dumps(k)}: {json.dumps(v, sort_keys=True)}" for k, v in sorted(recorded.items())]
        LAYOUTS.write_text("{\n" + ",\n".join(lines) + "\n}\n")
    assert got == recorded[name]


def test_result_values_survive_the_conversion() -> None:
    none = ballbot.braking_run(heading_deg=180.0, duration_secs=0.3, settings=FAST_BRAKING)
    assert none.outcome is ballbot.BrakingOutcome.NO_TRAJECTORY
    assert none.solve_status is ballbot.SolveStatus.INFEASIBLE
    assert none.time_secs.shape == (0,) and none.cone_utilisation.shape == (0, 3)
    assert none.happened is None and none.failure is None
    study = ballbot.braking_study(
        heading_deg=180.0, durations_secs=[3.0, 1.0], bisection_resolution_secs=None, settings=FAST_BRAKING
    )
    ok, bad = study.descent
    assert ok.heading_deg == 180.0 and ok.duration_secs == 3.0 and study.bisection == []
    assert isinstance(ok.telemetry_hash, int) and ok.telemetry_hash > 0
    assert ok.peaks.cone_utilisation == [float(v) for v in ok.peaks.cone_utilisation]
    assert len(ok.peaks.min_normal_force_n) == 3
    assert 0.0 < ok.time_secs[0] < 0.01 and np.all(np.diff(ok.time_secs) > 0.0)
    assert ok.normal_force_n.shape == (ok.time_secs.size, 3)
    failure = bad.failure
    assert isinstance(failure, ballbot.Failure) and isinstance(failure.kind, ballbot.FailureKind)
    assert failure == pickle.loads(pickle.dumps(failure))
    push = ballbot.push_trial(heading_deg=90.0, impulse_ns=5.0, settings=FAST_PUSH)
    assert push.outcome is ballbot.PushOutcome.RECOVERED and push.failure is None
    assert push.time_secs[0] < 0.0 < push.time_secs[-1]
    assert isinstance(push.happened["events_dropped"], int)
    world = ballbot.World().run(40_000, [30.0, 0.0, 0.0], record_every=400, stop_on_failure=True)
    assert world.failure is not None and world.steps < 40_000
    assert world.time_secs.size in ((world.steps - 1) // 400 + 1, (world.steps - 1) // 400 + 2)
    assert world.slipping.dtype == np.bool_ and world.body_orientation.shape == (world.time_secs.size, 4)
    assert world.torque_nm[0].tolist() == [30.0, 0.0, 0.0] and world.log_path is None
    with tempfile.TemporaryDirectory() as tmp:
        logged = ballbot.WorldLoop().run(80, log_path=Path(tmp) / "run.mcap", record_every=8)
        assert logged.log_path == Path(tmp) / "run.mcap" and isinstance(logged.log_path, Path)
    assert logged.command.shape == (10, 3) and logged.steps == 80
    planar = ballbot.Scenario.from_toml(SCENARIO).run()
    assert planar.state.shape == (planar.time_secs.size, 4) and planar.command.shape[1] == 3
    assert set(np.unique(planar.saturated)) <= {0.0, 1.0} and planar.fault is None
    assert isinstance(planar.end_time_secs, float) and planar.log_path is None
    status = _traction_loop().traction
    assert status is not None and isinstance(status.slipping, tuple) and len(status.slipping) == 3
    assert status.slip_speed_m_per_s.shape == (3,) and isinstance(status.limited_steps, int)
    envelope = _traction_loop().traction_envelope()
    assert envelope is not None and envelope.heading_rad.shape == envelope.accel_m_per_s2.shape == (96,)
    trial = ballbot.slow_ramp_trial(heading_deg=180.0, seed=2)
    assert trial.outcome.seed == 2 and isinstance(trial.outcome.seed, int)
    assert trial.outcome.min_normal_force_n == float(np.min(trial.normal_force_n))
    assert trial.max_cone_utilisation.tolist() == np.max(trial.cone_utilisation, axis=1).tolist()



def test_non_finite_floats_stay_floats() -> None:
    # The conversion's rule (src/results.rs): an f64 is a Python float, NaN and inf included
    # (a JSON detour would make them None).
    nan, inf = float("nan"), float("inf")
    data = {
        "min_duration_secs": nan,
        "infeasible_below_secs": inf,
        "solution": None,
        "solves": 3,
    }
    found = _results._build("MinBrakingTime", data)
    assert isinstance(found, _results.MinBrakingTime)
    assert math.isnan(found.min_duration_secs or 0.0) and found.infeasible_below_secs == inf
    array = {"dtype": "f8", "shape": [2], "data": np.array([nan, -inf]).tobytes()}
    peaks = _results._build(
        "BrakingRun",
        {
            **{f: None for f in ("failure", "rest_speed_m_per_s", "solve_status", "plan_peak_tilt_rad",
                                 "plan_cost_n2m2s", "happened")},
            "heading_deg": 0.0, "duration_secs": 1.0, "outcome": "failed", "success": False,
            "brake_start_secs": 0.0, "telemetry_hash": 1,
            "peaks": {"cone_utilisation": [nan] * 3, "min_normal_force_n": [inf] * 3,
                      "actuator_utilisation": [0.0] * 3, "tilt_rad": nan, "speed_error_m_per_s": 0.0,
                      "slip_secs": 0.0},
            **{f: array for f in ("time_secs", "command_m_per_s", "speed_m_per_s", "command_tilt_rad",
                                   "tilt_rad")},
            **{f: {"dtype": "f8", "shape": [0, 3], "data": b""}
               for f in ("cone_utilisation", "normal_force_n", "actuator_utilisation")},
        },
    )
    assert isinstance(peaks, _results.BrakingRun) and peaks.outcome is ballbot.BrakingOutcome.FAILED
    assert math.isnan(peaks.peaks.tilt_rad) and peaks.peaks.min_normal_force_n == [inf] * 3
    assert math.isnan(peaks.time_secs[0]) and peaks.time_secs[1] == -inf
    assert peaks.time_secs.flags.writeable and peaks.cone_utilisation.shape == (0, 3)
