"""The paper's experiments, run in Rust without the GIL.

In the 3D world: the maximum-speed ramp and study (``max_speed_ramp`` with ``RampSettings``,
``slow_ramp_trial``, ``failing_acceleration``, ``max_speed_study`` with ``MaxSpeedSettings``),
braking (``braking_run``, ``braking_study`` with ``BrakingSettings``) and push recovery
(``push_trial``, ``push_recovery_limit`` with ``PushSettings``). On the planar simulator: the
PIPTB controller comparison (``piptb_experiment``) and TOML scenarios (``Scenario``). The
reliability campaign (fuzzing, fault injection, Monte Carlo): ``robustness``.

Each study takes its settings as one parameter class; the settings' fields may also be given
as keyword arguments (they map one to one onto the class and override ``settings``).
Results are frozen classes (``MaxSpeedStudy``, ``BrakingRun``, ...) with ``to_dict()``.
"""

from __future__ import annotations

import json
import os
from typing import Any, Optional, TypeVar

from ballbot import _core
from ballbot._core import (
    ControllerConfig,
    Scenario,
    WorldParams,
    piptb_experiment,
    slow_ramp_trial,
)
from ballbot._enums import BrakingOutcome, Feedforward, PushOutcome
from ballbot._results import (
    BrakingPeaks,
    BrakingRun,
    BrakingStudy,
    FailingAcceleration,
    MaxSpeedStudy,
    PiptbExperiment,
    PushRecovery,
    PushTrial,
    RampRun,
    ScenarioRun,
    SlowRampTrial,
    TrialOutcome,
)
from ballbot._robustness import (
    CellLog,
    FaultCell,
    FaultMatrix,
    Fuzz,
    Mismatch,
    MonteCarlo,
    MonteCarloRun,
    Robustness,
)
from ballbot._settings import (
    BrakingSettings,
    MaxSpeedSettings,
    PushSettings,
    RampSettings,
    _Settings,
)

_S = TypeVar("_S", bound=_Settings)


def _settings(cls: type[_S], settings: Optional[_S], overrides: dict[str, Any]) -> _S:
    base = cls() if settings is None else settings
    if not isinstance(base, cls):
        raise TypeError(f"`settings` must be a {cls.__name__}, got {type(base).__name__}")
    return base.replace(**overrides) if overrides else base


def _search(settings: MaxSpeedSettings) -> dict[str, Any]:
    return {
        "fast_top_m_per_s": settings.fast_top_m_per_s,
        "accel_bracket_m_per_s2": settings.accel_bracket_m_per_s2,
        "accel_resolution_m_per_s2": settings.accel_resolution_m_per_s2,
    }


def max_speed_ramp(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    settings: Optional[RampSettings] = None,
    controller: Optional[ControllerConfig] = None,
    **overrides: Any,
) -> RampRun:
    """The maximum-speed experiment of the paper's Sec. V: the core's controller follows a
    velocity ramp towards ``heading_deg`` (body frame; 0 towards OW1) until the world detects a
    failure or the top speed has been held for 1 s. The controller is the paper's
    configuration unless ``controller`` (a ``ControllerConfig``) is given; the settings' caps
    apply on top of either."""
    s = _settings(RampSettings, settings, overrides)
    return _core.max_speed_ramp(
        params, heading_deg=heading_deg, controller=controller, **s.to_dict()
    )


def failing_acceleration(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    seed: int = 0,
    settings: Optional[MaxSpeedSettings] = None,
    **overrides: Any,
) -> FailingAcceleration:
    """The failing-acceleration search at ``heading_deg``: bisection for the largest ramp
    acceleration whose ramp to ``settings.fast_top_m_per_s`` (and 1 s hold) survives, on the
    grid of ``accel_resolution_m_per_s2`` inside ``accel_bracket_m_per_s2`` (only the search
    fields of ``MaxSpeedSettings`` are used)."""
    s = _settings(MaxSpeedSettings, settings, overrides)
    return _core.failing_acceleration(params, heading_deg=heading_deg, seed=seed, **_search(s))


def max_speed_study(
    params: Optional[WorldParams] = None,
    settings: Optional[MaxSpeedSettings] = None,
    **overrides: Any,
) -> MaxSpeedStudy:
    """The whole maximum-speed study as ``ballbot reproduce`` runs it, on Rust worker threads
    (the paper's variant by default; a few minutes on two cores)."""
    s = _settings(MaxSpeedSettings, settings, overrides)
    return _core.max_speed_study(params, **s.to_dict())


def braking_run(
    params: Optional[WorldParams] = None,
    *,
    duration_secs: float,
    heading_deg: float = 0.0,
    settings: Optional[BrakingSettings] = None,
    **overrides: Any,
) -> BrakingRun:
    """One braking run: settle, ramp to the cruise speed along ``heading_deg``, cruise, then
    the optimal braking trajectory to rest in ``duration_secs``, flown by the core's
    controller."""
    s = _settings(BrakingSettings, settings, overrides)
    return _core.braking_run(params, duration_secs=duration_secs, heading_deg=heading_deg, **s.to_dict())


def braking_study(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    durations_secs: Optional[list[float]] = None,
    bisection_resolution_secs: Optional[float] = 0.05,
    settings: Optional[BrakingSettings] = None,
    **overrides: Any,
) -> BrakingStudy:
    """The minimum braking time at ``heading_deg``: the descent over ``durations_secs`` (the
    paper's from 5 s) and the bisection to ``bisection_resolution_secs`` (``None`` skips it)."""
    s = _settings(BrakingSettings, settings, overrides)
    return _core.braking_study(
        params,
        heading_deg=heading_deg,
        durations_secs=durations_secs,
        bisection_resolution_secs=bisection_resolution_secs,
        **s.to_dict(),
    )


def push_trial(
    params: Optional[WorldParams] = None,
    *,
    impulse_ns: float,
    heading_deg: float = 0.0,
    settings: Optional[PushSettings] = None,
    **overrides: Any,
) -> PushTrial:
    """One push-recovery trial: an impulse ``impulse_ns`` towards ``heading_deg`` on the
    standing robot, watched for recovery."""
    s = _settings(PushSettings, settings, overrides)
    return _core.push_trial(params, impulse_ns=impulse_ns, heading_deg=heading_deg, **s.to_dict())


def push_recovery_limit(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    upper_ns: float = 100.0,
    resolution_ns: float = 0.5,
    settings: Optional[PushSettings] = None,
    **overrides: Any,
) -> PushRecovery:
    """The largest impulse towards ``heading_deg`` the robot recovers from, bisected to
    ``resolution_ns`` below ``upper_ns``."""
    s = _settings(PushSettings, settings, overrides)
    return _core.push_recovery_limit(
        params,
        heading_deg=heading_deg,
        upper_ns=upper_ns,
        resolution_ns=resolution_ns,
        **s.to_dict(),
    )


def robustness(
    out: str | os.PathLike[str],
    *,
    quick: bool = False,
    seed: int = 1,
    threads: int = 0,
) -> Robustness:
    """The reliability campaign of ``ballbot robustness`` (without its figures): fuzzing the
    core and the parsers, the fault-injection matrix in the 3D world and the Monte Carlo pushes
    on mismatched robots, on
    ``threads`` threads (0: every core) without the GIL. Writes ``out/robustness.json`` and each faulted run's MCAP log under
    ``out/logs/``; ``quick`` is the CI-sized campaign; ``seed`` seeds every random input."""
    text = _core.robustness_json(os.fspath(out), quick=quick, seed=seed, threads=threads)
    return Robustness._from_json(json.loads(text))


__all__ = [
    "BrakingOutcome",
    "BrakingPeaks",
    "BrakingRun",
    "BrakingSettings",
    "BrakingStudy",
    "CellLog",
    "FailingAcceleration",
    "FaultCell",
    "FaultMatrix",
    "Feedforward",
    "Fuzz",
    "MaxSpeedSettings",
    "MaxSpeedStudy",
    "Mismatch",
    "MonteCarlo",
    "MonteCarloRun",
    "PiptbExperiment",
    "PushOutcome",
    "PushRecovery",
    "PushSettings",
    "PushTrial",
    "RampRun",
    "RampSettings",
    "Robustness",
    "Scenario",
    "ScenarioRun",
    "SlowRampTrial",
    "TrialOutcome",
    "braking_run",
    "braking_study",
    "failing_acceleration",
    "max_speed_ramp",
    "max_speed_study",
    "piptb_experiment",
    "push_recovery_limit",
    "push_trial",
    "robustness",
    "slow_ramp_trial",
]
