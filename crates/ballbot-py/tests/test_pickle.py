"""Pickle round trips of the classes a user sends to another process (a Dask or multiprocessing
sweep): every parameter class and preset, the gains, the braking problem, scenarios and the
records and results of world runs."""

import copy
import inspect
import pickle

import numpy as np
import pytest

import ballbot
from ballbot import _core

PARAM_CLASSES = [
    c for c in vars(_core).values() if inspect.isclass(c) and hasattr(c, "presets")
]


def roundtrip(obj: object) -> object:
    return pickle.loads(pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


def test_there_are_parameter_classes_to_check() -> None:
    names = {c.__name__ for c in PARAM_CLASSES}
    assert {"WorldParams", "BallbotParams", "WipParams", "ContactParams"} <= names


@pytest.mark.parametrize("cls", PARAM_CLASSES, ids=lambda c: c.__name__)
def test_every_preset_of_every_parameter_class_round_trips(cls: type) -> None:
    for name in cls.presets():  # type: ignore[attr-defined]
        p = cls.preset(name)  # type: ignore[attr-defined]
        for proto in (2, pickle.HIGHEST_PROTOCOL):
            back = pickle.loads(pickle.dumps(p, protocol=proto))
            assert back == p and type(back) is cls
            assert back.to_dict() == p.to_dict()
        assert copy.deepcopy(p) == p


def test_a_changed_parameter_keeps_its_exact_value() -> None:
    p = ballbot.WorldParams().replace(dt_secs=1.0 / 7919.0, robot={"drivetrain": {"wheel_ball_friction": 0.1 + 0.2}})
    back = roundtrip(p)
    assert back == p
    assert back.dt_secs == 1.0 / 7919.0
    assert back.robot.drivetrain.wheel_ball_friction == 0.1 + 0.2


def test_gains_and_configurations_round_trip(wip: ballbot.Wip) -> None:
    lqr = ballbot.LqrGains.design(wip, 83.9, q=[100.0, 10.0, 1.0], r=0.1)
    pipd = ballbot.PiPdGains.for_wip(wip, 83.9)
    inner = ballbot.SpeedPiGains.for_wip_ball_rate(wip, 30.0, 83.9)
    config = ballbot.LqrPiOuterConfig.for_inner(lqr, inner)
    for obj in (lqr, pipd, inner, config):
        assert roundtrip(obj) == obj


def test_problems_limits_and_scenarios_round_trip() -> None:
    limits = ballbot.BrakingLimits.miapure_actuators(0.3)
    assert roundtrip(limits) == limits
    problem = ballbot.BrakingProblem.miapure().with_duration(1.7)
    assert roundtrip(problem) == problem
    scenario = ballbot.Scenario.from_toml('seed = 3\nduration_secs = 0.5\n[controller]\nkind = "lqr_pi"')
    back = roundtrip(scenario)
    a, b = scenario.run(), back.run()  # type: ignore[attr-defined]
    assert np.array_equal(a.state, b.state) and len(a.state) > 100
    assert np.array_equal(roundtrip(a).state, a.state)


def test_world_records_and_results_round_trip_exactly() -> None:
    world = ballbot.World()
    world.tilt_body((0.0, 0.2))
    run = world.run(4000, stop_on_failure=True)
    assert run.failure is not None
    back = roundtrip(run)
    assert type(back) is ballbot.WorldRun
    assert back.failure == run.failure
    assert np.array_equal(back.tilt_rad, run.tilt_rad)
    t = world.telemetry
    tb = roundtrip(t)
    assert np.array_equal(tb.body_orientation, t.body_orientation)
    assert [w.normal_force_n for w in tb.wheels] == [w.normal_force_n for w in t.wheels]
    wheel = roundtrip(t.wheels[1])
    assert wheel.slip_speed_m_per_s == t.wheels[1].slip_speed_m_per_s
    m = world.measure()
    mb = roundtrip(m)
    assert np.array_equal(mb.tilt_rad, m.tilt_rad) and mb.yaw_rad == m.yaw_rad
    for f in [run.failure]:
        assert roundtrip(f) == f


def test_stateful_simulators_do_not_pickle_silently() -> None:
    # A world holds a rapier pipeline: sending one is a mistake; it must fail loudly.
    with pytest.raises(TypeError):
        pickle.dumps(ballbot.World())
