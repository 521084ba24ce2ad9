"""Settings of the paper's studies: one validated, documented parameter class per study.

Most fields default to ``None``, which means the protocol's own value (given in the field's
doc, from ``ballbot_sim``), exactly as the study functions' keyword arguments did; the others
(``quick``, ``threads``, ``feedforward`` and the ramp's fields) give their default. A field
that is set is checked here (finite numbers, positive counts; a ``ParameterError`` names the
field); most range checks that depend on other fields stay with the Rust protocol, which runs
them when the study starts and names the field too (the acceleration bracket's order is
checked here as well).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any, Optional, TypeVar, Union

from ballbot import _core
from ballbot._enums import Feedforward
from ballbot._errors import ParameterError

_S = TypeVar("_S", bound="_Settings")


def _check_number(name: str, value: Any, *, positive: bool = False) -> None:
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"invalid parameter `{name}`: must be a number, got {value!r}")
    if not math.isfinite(value) or (positive and value <= 0.0) or value < 0.0:
        bound = "> 0" if positive else ">= 0"
        raise ParameterError(f"invalid parameter `{name}`: must be finite and {bound}, got {value}")


def _check_count(name: str, value: Any, *, minimum: int) -> None:
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ParameterError(f"invalid parameter `{name}`: must be an integer >= {minimum}, got {value!r}")


def _check_list(name: str, values: Any) -> None:
    if values is None:
        return
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise ParameterError(f"invalid parameter `{name}`: must be finite numbers, got {values!r}")


def _check_stop_on(settings: Any) -> None:
    if not isinstance(settings.stop_on, str):
        raise ParameterError(f"`stop_on` must be a string, got {settings.stop_on!r}")
    canonical = _core.canonical_stop_rules(settings.stop_on)
    object.__setattr__(settings, "stop_on", canonical)


@dataclasses.dataclass(frozen=True)
class _Settings:
    """Base of the settings classes: ``replace``, ``to_dict``."""

    def replace(self: _S, **changes: Any) -> _S:
        """A copy with some fields replaced (validated); unknown names raise
        ``ParameterError`` listing the known ones."""
        known = [f.name for f in dataclasses.fields(self)]
        for key in changes:
            if key not in known:
                raise ParameterError(
                    f"unknown parameter `{key}` for {type(self).__name__}; known: {', '.join(known)}"
                )
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (enum members as their names), the keyword arguments of the
        native study function."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, Feedforward):
                value = value.value
            elif isinstance(value, tuple) and f.name != "accel_bracket_m_per_s2":
                value = list(value)
            out[f.name] = value
        return out


@dataclasses.dataclass(frozen=True)
class MaxSpeedSettings(_Settings):
    """Settings of the maximum-speed study (``ballbot_sim::studies::max_speed``); the lists are
    stored as tuples."""

    quick: bool = False
    """Start from the CI variant (one trial at 0 and 180 deg, a coarse search, no sensitivity)
    instead of the paper's (3 seeds at 0, 90, 180 deg, the map every 15 deg, mu 0.4/0.6/0.8,
    COM height 0.4/0.5/0.7 m)."""
    trial_headings_deg: Optional[Sequence[float]] = None
    """Headings of the seeded slow-ramp trials (deg, body frame; 0 towards OW1)."""
    seeds: Optional[Sequence[int]] = None
    """Sensor-noise seeds of the trials (at least one)."""
    map_headings_deg: Optional[Sequence[float]] = None
    """Headings of the capability map (deg)."""
    sensitivity_headings_deg: Optional[Sequence[float]] = None
    """Headings of the mu / COM-height sensitivity (deg)."""
    sensitivity_wheel_ball_friction: Optional[Sequence[float]] = None
    """Wheel-ball friction coefficients of the sensitivity."""
    sensitivity_com_height_m: Optional[Sequence[float]] = None
    """Centre-of-mass heights of the sensitivity (m)."""
    threads: int = 0
    """Rust worker threads (0: every core)."""
    fast_top_m_per_s: Optional[float] = None
    """Top speed of the fast ramps of the failing-acceleration search (m/s; protocol 3.0)."""
    accel_bracket_m_per_s2: Optional[tuple[float, float]] = None
    """Search bracket ``(low, high)`` of the ramp acceleration (m/s^2; protocol (0.5, 3.0));
    needs ``0 < low < high``."""
    accel_resolution_m_per_s2: Optional[float] = None
    """Grid of the search (m/s^2; protocol 0.05)."""

    def __post_init__(self) -> None:
        for name in (
            "trial_headings_deg",
            "seeds",
            "map_headings_deg",
            "sensitivity_headings_deg",
            "sensitivity_wheel_ball_friction",
            "sensitivity_com_height_m",
        ):
            value = getattr(self, name)
            if value is not None:
                _check_list(name, value)
                object.__setattr__(self, name, tuple(value))
        if self.seeds is not None:
            if not self.seeds:
                raise ParameterError("invalid parameter `seeds`: needs at least one seed")
            for seed in self.seeds:
                _check_count("seeds", seed, minimum=0)
        _check_count("threads", self.threads, minimum=0)
        _check_number("fast_top_m_per_s", self.fast_top_m_per_s, positive=True)
        _check_number("accel_resolution_m_per_s2", self.accel_resolution_m_per_s2, positive=True)
        if self.accel_bracket_m_per_s2 is not None:
            low, high = self.accel_bracket_m_per_s2
            if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
                raise ParameterError(
                    "invalid parameter `accel_bracket_m_per_s2`: need 0 < low < high, "
                    f"got ({low}, {high})"
                )
            object.__setattr__(self, "accel_bracket_m_per_s2", (float(low), float(high)))


@dataclasses.dataclass(frozen=True)
class BrakingSettings(_Settings):
    """The braking protocol (``ballbot_sim::studies::world_braking::BrakingParams``)."""

    cruise_speed_m_per_s: Optional[float] = None
    """Cruise speed before braking (m/s; protocol 1.4, the paper)."""
    approach_accel_m_per_s2: Optional[float] = None
    """Acceleration of the jerk-limited approach ramp (m/s^2; protocol 0.5)."""
    settle_secs: Optional[float] = None
    """Standing still before the ramp (s; protocol 0.5)."""
    cruise_secs: Optional[float] = None
    """Cruising before braking (s; protocol 2.5)."""
    trajectory_tilt_limit_rad: Optional[float] = None
    """Tilt bound of the planned braking trajectory (rad; protocol 15 deg)."""
    intervals: Optional[int] = None
    """Intervals of the braking trajectory's discretisation (protocol 100)."""
    sample_every_secs: Optional[float] = None
    """Sampling period of the returned series (s; protocol 0.01)."""
    feedforward: Union[Feedforward, str] = Feedforward.FULL
    """What the trajectory command feeds forward: ``FULL`` (the paper) or ``CORE``
    (ablation)."""
    stop_on: str = "all"
    """The world's stop rules: ``"all"`` (the paper protocol's), ``"none"``, or some of
    ``tilt,slip,lift-off,driver-trip``; ``"tilt,slip,driver-trip"`` is the summary's
    ``world_braking.lift_off_rule_relaxed``. Stored in canonical form."""

    def __post_init__(self) -> None:
        _check_stop_on(self)
        for name in ("cruise_speed_m_per_s", "approach_accel_m_per_s2", "sample_every_secs"):
            _check_number(name, getattr(self, name), positive=True)
        _check_number("trajectory_tilt_limit_rad", self.trajectory_tilt_limit_rad, positive=True)
        for name in ("settle_secs", "cruise_secs"):
            _check_number(name, getattr(self, name))
        _check_count("intervals", self.intervals, minimum=2)
        try:
            object.__setattr__(self, "feedforward", Feedforward(self.feedforward))
        except ValueError:
            raise ParameterError(
                f"unknown feedforward `{self.feedforward}`; known: full, core"
            ) from None


@dataclasses.dataclass(frozen=True)
class PushSettings(_Settings):
    """The push-recovery protocol (``ballbot_sim::studies::push::PushParams``)."""

    push_duration_secs: Optional[float] = None
    """How long the impulse is spread over (s, >= 0 and < ``observe_secs``; protocol 0.1)."""
    settle_secs: Optional[float] = None
    """Standing still before the push (s; protocol 1.0)."""
    observe_secs: Optional[float] = None
    """Watching after the push (s; protocol 4.0)."""
    rest_within_secs: Optional[float] = None
    """At rest from this long after the push on (s; protocol 3.0); below ``observe_secs``."""
    sample_every_secs: Optional[float] = None
    """Sampling period of the returned series (s; protocol 0.01)."""
    stop_on: str = "all"
    """The world's stop rules: ``"all"`` (the protocol's), ``"none"``, or some of
    ``tilt,slip,lift-off,driver-trip``; ``"tilt,driver-trip"`` is the summary's
    ``world_push.rules_relaxed``. Stored in canonical form."""

    def __post_init__(self) -> None:
        _check_stop_on(self)
        for name in ("observe_secs", "sample_every_secs"):
            _check_number(name, getattr(self, name), positive=True)
        for name in ("push_duration_secs", "settle_secs", "rest_within_secs"):
            _check_number(name, getattr(self, name))


@dataclasses.dataclass(frozen=True)
class RampSettings(_Settings):
    """One maximum-speed ramp in the 3D world (``max_speed_ramp``) and the controller's
    command-shaping overrides (``None`` keeps the designed cap: 1.0 m/s^2, 2.0 m/s^3, 0.2 rad,
    1.0 rad/s; the speed cap ``None`` is the ramp's top ``max_command_m_per_s``, not the
    designed 2.0 m/s, so that the ramp can find a speed above it)."""

    accel_m_per_s2: float = 0.25
    """Ramp acceleration (m/s^2)."""
    max_command_m_per_s: float = 3.5
    """Top of the ramp (m/s), then held for 1 s."""
    settle_secs: float = 0.5
    """Standing still before the ramp (s)."""
    sample_every_secs: float = 0.01
    """Sampling period of the returned series (s)."""
    max_speed_m_per_s: Optional[float] = None
    """The shaper's speed cap (m/s); ``None``: ``max_command_m_per_s``."""
    max_accel_m_per_s2: Optional[float] = None
    """The shaper's acceleration cap (m/s^2)."""
    max_jerk_m_per_s3: Optional[float] = None
    """The shaper's jerk cap (m/s^3)."""
    max_tilt_command_rad: Optional[float] = None
    """The shaper's tilt-command cap (rad)."""
    max_tilt_rate_command_rad_per_s: Optional[float] = None
    """The shaper's tilt-rate-command cap (rad/s)."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            if f.name != "settle_secs":
                _check_number(f.name, getattr(self, f.name), positive=True)
        _check_number("settle_secs", self.settle_secs)


__all__ = ["BrakingSettings", "MaxSpeedSettings", "PushSettings", "RampSettings"]
