"""The 3D world (rapier3d).

``World`` is the ballbot driven by wheel torques, ``WorldLoop`` the world with the core's
controller in the loop (``mode`` is a ``Mode``). Their parameters (``WorldParams`` and its
parts), per-step records (``StepTelemetry``, ``WheelTelemetry``, ``Measurement``), failures
(``Failure`` with a ``FailureKind``; wheels named ``"OW1"``..``"OW3"``) and run results
(``WorldRun``, ``WorldLoopRun``); traction-aware control's report and envelope
(``TractionStatus``, ``TractionEnvelope``; on by default, ``WorldLoop(traction_control=False)``
turns it off); the world's robot as MJCF (MuJoCo) or URDF (``export``); pictures of it
(``SceneRenderer``, the frames of the Gymnasium environments and of ``ballbot world --video``).
"""

from ballbot._core import (
    AxleLossParams,
    ContactParams,
    DriverParams,
    Failure,
    FailureParams,
    ImuParams,
    LiveView,
    Measurement,
    RollerParams,
    SceneRenderer,
    SensorParams,
    StepTelemetry,
    TransmissionParams,
    FloorParams,
    WheelTelemetry,
    World,
    WorldLoop,
    WorldParams,
    export,
)
from ballbot._enums import FailureKind, Mode
from ballbot._results import TractionEnvelope, TractionStatus, WorldLoopRun, WorldRun

__all__ = [
    "AxleLossParams",
    "ContactParams",
    "DriverParams",
    "Failure",
    "FailureKind",
    "FailureParams",
    "ImuParams",
    "LiveView",
    "Measurement",
    "RollerParams",
    "Mode",
    "SceneRenderer",
    "SensorParams",
    "StepTelemetry",
    "TractionEnvelope",
    "TractionStatus",
    "TransmissionParams",
    "FloorParams",
    "WheelTelemetry",
    "World",
    "WorldLoop",
    "WorldLoopRun",
    "WorldParams",
    "WorldRun",
    "export",
]
