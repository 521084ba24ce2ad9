"""The hand-written part of ``ballbot._enums``: ``StepStatus``'s int8 code table.

Batch outputs (``step_many``, rollouts) keep step statuses as int8 codes for speed;
``StepStatus.from_code`` and ``StepStatus.decode`` turn them into members, with the code table
read from the native module (``ballbot._core.STEP_STATUS_NAMES``), the one place that defines
it.
"""

from __future__ import annotations

from typing import Any, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ballbot import _core

_S = TypeVar("_S", bound="StepStatusCodes")


class StepStatusCodes:
    """The int8 codes of ``StepStatus`` (mixed into the generated enum)."""

    @property
    def code(self) -> int:
        """The int8 code of this status in batch outputs."""
        value: str = getattr(self, "value")
        return _core.STEP_STATUS_NAMES.index(value)

    @classmethod
    def from_code(cls: type[_S], code: int) -> _S:
        """The status with the int8 ``code`` of a batch output (0 nominal, 1 saturated, 2
        invalid input); ``ValueError`` for an unknown code."""
        names = _core.STEP_STATUS_NAMES
        if not 0 <= int(code) < len(names):
            raise ValueError(f"unknown step status code {code}; known: 0..{len(names) - 1}")
        member: _S = cast(Any, cls)(names[int(code)])
        return member

    @classmethod
    def decode(cls, codes: npt.ArrayLike) -> npt.NDArray[Any]:
        """An array of int8 codes as an object array of members, same shape."""
        array = np.asarray(codes)
        # An object array: numpy would turn a list of str members into a str array.
        members = np.empty(len(_core.STEP_STATUS_NAMES), dtype=object)
        members[:] = [cls.from_code(i) for i in range(len(members))]
        if array.size and (array.min() < 0 or array.max() >= len(members)):
            raise ValueError("unknown step status code in the array")
        out: npt.NDArray[Any] = members[array.astype(np.intp)]
        return out
