"""ballbot: ballbot drivetrain models, controllers and simulators.

A thin, typed mirror of the Rust crates ``ballbot-core`` and ``ballbot-sim``: the same names,
keyword arguments with units in their names, numpy arrays in and out. Heavy work (rollouts,
simulations, optimisation) runs in Rust without the GIL.

>>> import ballbot
>>> wip = ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))
>>> round(wip.upright_unstable_pole_rad_per_s(), 2)
8.04
"""

from ballbot._core import (
    ActuatorParams,
    Spin,
    SpinParams,
    Wip,
    WipParams,
    __version__,
)
from ballbot._errors import BallbotError, FileError, ParameterError, ShapeError

__all__ = [
    "ActuatorParams",
    "BallbotError",
    "FileError",
    "ParameterError",
    "ShapeError",
    "Spin",
    "SpinParams",
    "Wip",
    "WipParams",
    "__version__",
]
