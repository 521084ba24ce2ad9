"""Trajectory optimisation: the optimal braking problem (``BrakingProblem`` under
``BrakingLimits``), its ``BrakingSolution`` (``status`` is a ``SolveStatus``) and the shortest
feasible braking time (``min_braking_time`` -> ``MinBrakingTime``).
"""

from ballbot._core import BrakingLimits, BrakingProblem, BrakingSolution, min_braking_time
from ballbot._enums import SolveStatus
from ballbot._results import MinBrakingTime

__all__ = [
    "BrakingLimits",
    "BrakingProblem",
    "BrakingSolution",
    "MinBrakingTime",
    "SolveStatus",
    "min_braking_time",
]
