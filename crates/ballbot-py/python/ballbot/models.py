"""Robot models and their parameters.

The planar wheeled inverted pendulum (``Wip``) and spin axis (``Spin``), the omniwheel
kinematics (``OmniKinematics`` and the heading helpers), and the parameter records with
their presets (``WipParams.preset("miapure_60kg")`` ...).
"""

from ballbot._core import (
    ActuatorParams,
    BallbotParams,
    ContactForces,
    DrivetrainParams,
    OmniKinematics,
    PlanarRobotParams,
    Spin,
    SpinParams,
    Wip,
    WipParams,
    planar_torque_at_heading,
    relative_rate_at_heading,
    relative_rate_from_planar,
)

__all__ = [
    "ActuatorParams",
    "BallbotParams",
    "ContactForces",
    "DrivetrainParams",
    "OmniKinematics",
    "PlanarRobotParams",
    "Spin",
    "SpinParams",
    "Wip",
    "WipParams",
    "planar_torque_at_heading",
    "relative_rate_at_heading",
    "relative_rate_from_planar",
]
