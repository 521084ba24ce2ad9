"""Status, mode and outcome enums of ``ballbot``.

Every member's value is its canonical snake_case name, the one the Rust crates print, log and
write to JSON (``FailureKind::as_str`` and friends). The classes mix in ``str``, so a member
also compares equal to its name: ``StepStatus.NOMINAL == "nominal"``.

Batch outputs (``step_many``, rollouts) keep step statuses as int8 codes for speed;
:meth:`StepStatus.from_code` and :meth:`StepStatus.decode` turn them into members, with the
code table read from the native module (``ballbot._core.STEP_STATUS_NAMES``), the one place
that defines it.
"""

from __future__ import annotations

import enum
from typing import Any

import numpy as np
import numpy.typing as npt

from ballbot import _core


class StepStatus(str, enum.Enum):
    """How a controller step went (``ballbot_core::control::StepStatus``)."""

    NOMINAL = "nominal"
    """Computed from valid inputs, within its limits."""
    SATURATED = "saturated"
    """Computed from valid inputs, clipped to its limit (``saturation_nm`` says by how much)."""
    INVALID_INPUT = "invalid_input"
    """A non-finite input or step length: zero torque, the controller state unchanged."""

    @property
    def code(self) -> int:
        """The int8 code of this status in batch outputs."""
        return _core.STEP_STATUS_NAMES.index(self.value)

    @classmethod
    def from_code(cls, code: int) -> StepStatus:
        """The status with the int8 ``code`` of a batch output (0 nominal, 1 saturated, 2
        invalid input); ``ValueError`` for an unknown code."""
        names = _core.STEP_STATUS_NAMES
        if not 0 <= int(code) < len(names):
            raise ValueError(f"unknown step status code {code}; known: 0..{len(names) - 1}")
        return cls(names[int(code)])

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


class Mode(str, enum.Enum):
    """The safety supervisor's mode (``ballbot_core::safety::Mode``)."""

    IDLE = "idle"
    """Not armed yet (before the first step)."""
    BALANCING = "balancing"
    """Balancing and following the command."""
    CONTROLLED_STOP = "controlled_stop"
    """Braking to rest after a stop request or a limit."""
    FAULT = "fault"
    """Motors off after a fault."""


class FailureKind(str, enum.Enum):
    """What made a world run fail (``ballbot_sim::world::FailureKind``)."""

    TILT = "tilt"
    """The body tilted beyond the failure limit."""
    BODY_TOUCHED_FLOOR = "body_touched_floor"
    """The chassis touched the floor."""
    SUSTAINED_SLIP = "sustained_slip"
    """An omniwheel slipped for longer than allowed."""
    LIFT_OFF = "lift_off"
    """An omniwheel lost contact with the ball."""
    DRIVER_TRIP = "driver_trip"
    """An omniwheel's motor driver disarmed (overspeed or current-limit violation)."""


class RiccatiStatus(str, enum.Enum):
    """How a Riccati solve ended (``ballbot_core::lqr::RiccatiStatus``)."""

    CONVERGED = "converged"
    """Converged; the closed loop is certified stable."""
    MAX_ITERATIONS = "max_iterations"
    """Stopped at the iteration limit; stable but not accurate to the tolerance."""
    NOT_STABILIZABLE = "not_stabilizable"
    """No stabilising solution exists."""
    NON_FINITE = "non_finite"
    """A non-finite number appeared."""


class SolveStatus(str, enum.Enum):
    """How a trajectory optimisation ended (``ballbot_sim::trajopt::SolveStatus``)."""

    SOLVED = "solved"
    """Solved; the trajectory is certified."""
    MAX_ITERATIONS = "max_iterations"
    """Stopped at the iteration limit."""
    INFEASIBLE = "infeasible"
    """The constraints cannot be met."""
    LINE_SEARCH_FAILED = "line_search_failed"
    """The line search could not reduce the merit function."""
    NUMERICAL_ERROR = "numerical_error"
    """The QP solver stopped without a solution or a certificate."""


class BrakingOutcome(str, enum.Enum):
    """How a braking run ended (``ballbot_sim::studies::world_braking::BrakingOutcome``)."""

    STOPPED = "stopped"
    """Came to rest as planned."""
    NO_TRAJECTORY = "no_trajectory"
    """No braking trajectory could be planned."""
    FAILED = "failed"
    """The world detected a failure."""
    NOT_AT_REST = "not_at_rest"
    """Survived but was not at rest at the end."""


class PushOutcome(str, enum.Enum):
    """How a push trial ended (``ballbot_sim::studies::push::PushOutcome``)."""

    RECOVERED = "recovered"
    """Recovered and came back to rest."""
    TILT_EXCEEDED = "tilt_exceeded"
    """The tilt exceeded the recovery limit."""
    FAILED = "failed"
    """The world detected a failure."""
    NOT_AT_REST = "not_at_rest"
    """Survived but was not at rest at the end."""


class Feedforward(str, enum.Enum):
    """The braking trajectory's feedforward (``TrajectoryFeedforward``)."""

    FULL = "full"
    """The plan as it is: the core feeds forward both terms (the default)."""
    CORE = "core"
    """Ablation: each sample's tilt shifted so the core's tilt-acceleration term cancels."""


__all__ = [
    "BrakingOutcome",
    "FailureKind",
    "Feedforward",
    "Mode",
    "PushOutcome",
    "RiccatiStatus",
    "SolveStatus",
    "StepStatus",
]
