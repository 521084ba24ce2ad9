"""The hand-written part of ``ballbot._settings``: the settings classes' base (``replace``,
``to_dict``) and the checks the generated classes name per field (``x-python-check`` in the
schema of the Rust settings structs, ``crates/ballbot-py/src/studies/settings.rs``).

A field that is set is checked here (finite numbers, positive counts; a ``ParameterError``
names the field); most range checks that depend on other fields stay with the Rust protocol,
which runs them when the study starts and names the field too (the acceleration bracket's
order is checked here as well).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

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


def _numbers(settings: Any, name: str) -> None:
    """A list of finite numbers, stored as a tuple."""
    value = getattr(settings, name)
    if value is not None:
        _check_list(name, value)
        object.__setattr__(settings, name, tuple(value))


def _seeds(settings: Any, name: str) -> None:
    """At least one seed, each an integer >= 0, stored as a tuple."""
    _numbers(settings, name)
    seeds = getattr(settings, name)
    if seeds is not None:
        if not seeds:
            raise ParameterError(f"invalid parameter `{name}`: needs at least one seed")
        for seed in seeds:
            _check_count(name, seed, minimum=0)


def _bracket(settings: Any, name: str) -> None:
    """``(low, high)`` with ``0 < low < high``, stored as floats."""
    value = getattr(settings, name)
    if value is None:
        return
    low, high = value
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
        raise ParameterError(f"invalid parameter `{name}`: need 0 < low < high, got ({low}, {high})")
    object.__setattr__(settings, name, (float(low), float(high)))


def _stop_on(settings: Any, name: str) -> None:
    """The world's stop rules, stored in canonical form (the native module's parser)."""
    value = getattr(settings, name)
    if not isinstance(value, str):
        raise ParameterError(f"`{name}` must be a string, got {value!r}")
    object.__setattr__(settings, name, _core.canonical_stop_rules(value))


def _feedforward(settings: Any, name: str) -> None:
    """A ``Feedforward`` member or its name, stored as the member."""
    value = getattr(settings, name)
    try:
        object.__setattr__(settings, name, Feedforward(value))
    except ValueError:
        known = ", ".join(m.value for m in Feedforward)
        raise ParameterError(f"unknown {name} `{value}`; known: {known}") from None


_CHECKS: dict[str, Callable[[Any, str], None]] = {
    "positive": lambda s, n: _check_number(n, getattr(s, n), positive=True),
    "non_negative": lambda s, n: _check_number(n, getattr(s, n)),
    "count_from_0": lambda s, n: _check_count(n, getattr(s, n), minimum=0),
    "count_from_2": lambda s, n: _check_count(n, getattr(s, n), minimum=2),
    "numbers": _numbers,
    "seeds": _seeds,
    "bracket": _bracket,
    "stop_on": _stop_on,
    "feedforward": _feedforward,
}


def _check(settings: Any, checks: Sequence[tuple[str, str]]) -> None:
    """Runs each ``(field, check)``: the stop rules first (they canonicalise), then the
    others in field order."""
    for name, check in sorted(checks, key=lambda c: c[1] != "stop_on"):
        _CHECKS[check](settings, name)


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
