"""Control: LQR design, the planar controllers and batch closed-loop rollouts.

LQR design (``wip_lqr``, the Riccati solvers, ``expm``/``zoh`` discretisation); the planar
controllers with ``step``/``step_many`` (``LqrController``, ``PiPdController``, the cascaded
``LqrPiOuter`` + ``SpeedPi``), their gains and per-step outputs (``status`` is a
``StepStatus``); ``closed_loop_rollout`` runs batches in Rust and returns a ``Rollout``.
``ControllerConfig`` is the 3D controller's configuration, a controller file as data
(``WorldLoop(controller=...)`` and ``max_speed_ramp(controller=...)`` run it).

``OUTER_LOOP_DT_SECS`` (1/400 s) and ``INNER_LOOP_DT_SECS`` (1/8000 s) are the robot's two
rates (``ballbot_core::rates``) and the controllers' default step lengths.
"""

from ballbot._core import (
    INNER_LOOP_DT_SECS,
    INNER_LOOP_RATE_HZ,
    OUTER_LOOP_DT_SECS,
    OUTER_LOOP_RATE_HZ,
    ControllerConfig,
    Lqr,
    LqrController,
    LqrGains,
    LqrOutput,
    LqrPiOuter,
    LqrPiOuterConfig,
    LqrPiOuterOutput,
    PiPdController,
    PiPdGains,
    PiPdOutput,
    RiccatiSolution,
    SpeedPi,
    SpeedPiGains,
    SpeedPiOutput,
    accelerating_command,
    closed_loop_rollout,
    expm,
    solve_care,
    solve_dare,
    spin_lqr,
    spin_lqr_discrete,
    wip_lqr,
    wip_lqr_discrete,
    zoh,
)
from ballbot._enums import RiccatiStatus, StepStatus
from ballbot._results import Rollout

__all__ = [
    "INNER_LOOP_DT_SECS",
    "INNER_LOOP_RATE_HZ",
    "OUTER_LOOP_DT_SECS",
    "OUTER_LOOP_RATE_HZ",
    "ControllerConfig",
    "Lqr",
    "LqrController",
    "LqrGains",
    "LqrOutput",
    "LqrPiOuter",
    "LqrPiOuterConfig",
    "LqrPiOuterOutput",
    "PiPdController",
    "PiPdGains",
    "PiPdOutput",
    "RiccatiSolution",
    "RiccatiStatus",
    "Rollout",
    "SpeedPi",
    "SpeedPiGains",
    "SpeedPiOutput",
    "StepStatus",
    "accelerating_command",
    "closed_loop_rollout",
    "expm",
    "solve_care",
    "solve_dare",
    "spin_lqr",
    "spin_lqr_discrete",
    "wip_lqr",
    "wip_lqr_discrete",
    "zoh",
]
