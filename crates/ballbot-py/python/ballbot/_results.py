"""Result classes: what rollouts, world runs and the paper's studies return.

Frozen dataclasses with typed attributes (numpy arrays, floats, nested results), built by the
native module from the Rust result. ``to_dict()`` gives the plain dict (nested results become
dicts too) for users who want one; ``repr`` shows scalars and the shapes of arrays.

The native module converts a result in one way (``src/results.rs``): the Rust result's serde
form, as plain Python objects (``pythonize``), goes to :func:`_build`, which converts each
field by its annotation here: arrays from their ``{"dtype", "shape", "data"}`` form, nested
result classes, enums from their canonical names, ``Failure`` from its parts, paths.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import sys
import typing
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np
import numpy.typing as npt

from ballbot._core import BrakingSolution, Failure
from ballbot._enums import BrakingOutcome, PushOutcome, SolveStatus

_F64 = npt.NDArray[np.float64]


def _plain(value: Any) -> Any:
    if isinstance(value, _Result):
        return value.to_dict()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"array(shape={value.shape}, dtype={value.dtype})"
    if isinstance(value, list):
        return f"[{len(value)} items]"
    if isinstance(value, dict):
        return f"{{{len(value)} entries}}"
    if isinstance(value, str) and "\n" in value:
        return f"<{len(value.splitlines())} lines>"
    return repr(value)


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class _Result:
    """Base of the result classes: ``to_dict`` and a short ``repr``."""

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested results as dicts; arrays are not copied)."""
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __repr__(self) -> str:
        fields = ", ".join(
            f"{f.name}={_short(getattr(self, f.name))}" for f in dataclasses.fields(self)
        )
        return f"{type(self).__name__}({fields})"


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class Rollout(_Result):
    """Closed-loop rollouts (``closed_loop_rollout``): one trajectory or a batch."""

    time_secs: _F64
    """Time of each state (s), ``(n_steps + 1,)``."""
    state: _F64
    """States ``[theta, phi, theta_dot, phi_dot]``, ``(n_steps + 1, 4)`` or
    ``(n, n_steps + 1, 4)``."""
    torque_nm: _F64
    """Mean torque applied over each period (N m), ``(n_steps,)`` or ``(n, n_steps)``."""
    status: npt.NDArray[np.int8]
    """Step status codes (``StepStatus.from_code``/``decode``), shaped as ``torque_nm``."""
    compute_secs: float
    """Time spent in the Rust loop (s)."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class _WorldTrace(_Result):
    """Per-step columns of a world run, one row per recorded step."""

    time_secs: _F64
    """Simulated time (s), ``(n,)``."""
    normal_force_n: _F64
    """Wheel normal forces (N), ``(n, 3)``."""
    traction_n: _F64
    """Wheel tractions along the rolling direction (N), ``(n, 3)``."""
    traction_demand_n: _F64
    """Traction each contact needed to stick (N), ``(n, 3)``."""
    axle_force_n: _F64
    """Roller losses along each wheel's axle (N), ``(n, 3)``; 0 with free rollers."""
    cone_utilisation: _F64
    """``|(F, F_a)| / (mu N)`` per wheel, ``(n, 3)``."""
    slip_speed_m_per_s: _F64
    """Slip speed per wheel (m/s), ``(n, 3)``."""
    slipping: npt.NDArray[np.bool_]
    """Whether each contact slides, ``(n, 3)``."""
    motor_torque_nm: _F64
    """Torque each actuator delivered (N m), ``(n, 3)``."""
    wheel_speed_rad_per_s: _F64
    """Wheel speeds relative to the body (rad/s), ``(n, 3)``."""
    wheel_angle_rad: _F64
    """Wheel angles relative to the body (rad), ``(n, 3)``."""
    ball_position_m: _F64
    """Ball centre (m), ``(n, 3)``."""
    ball_velocity_m_per_s: _F64
    """Ball velocity (m/s), ``(n, 3)``."""
    ball_angular_velocity_rad_per_s: _F64
    """Ball angular velocity (rad/s), ``(n, 3)``."""
    body_position_m: _F64
    """Body frame origin (m), ``(n, 3)``."""
    body_orientation: _F64
    """Body orientation ``(x, y, z, w)``, ``(n, 4)``."""
    body_rate_rad_per_s: _F64
    """Body angular velocity in the body frame (rad/s), ``(n, 3)``."""
    tilt_rad: _F64
    """Body tilt ``(theta_x, theta_y)`` (rad), ``(n, 2)``."""
    tilt_from_vertical_rad: _F64
    """Angle between the body axis and the vertical (rad), ``(n,)``."""
    yaw_rad: _F64
    """Body yaw (rad), ``(n,)``."""
    floor_force_n: _F64
    """Normal force of the floor on the ball (N), ``(n,)``."""
    steps: int
    """Steps run (fewer than asked when stopped on a failure)."""
    failure: Optional[Failure]
    """The first failure detected, or ``None``."""
    log_path: Optional[Path]
    """The MCAP log written, or ``None``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class WorldRun(_WorldTrace):
    """A ``World.run``: the trace plus the wheel torque commands."""

    torque_nm: _F64
    """Wheel torque commands (N m), ``(n, 3)``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class WorldLoopRun(_WorldTrace):
    """A ``WorldLoop.run``: the trace plus the velocity commands."""

    command: _F64
    """Velocity commands ``(vx_m_per_s, vy_m_per_s, yaw_rate_rad_per_s)``, ``(n, 3)``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class TractionStatus(_Result):
    """Traction-aware control's report of one outer step (``WorldLoop.traction``)."""

    accel_limit_m_per_s2: Optional[float]
    """The acceleration limit along the direction the command wanted to accelerate in
    (m/s^2): envelope, actuators, slip reaction and braking floor; ``None`` when the command
    did not ask to accelerate."""
    limited: bool
    """Whether the envelope held the command back in this step."""
    limited_steps: int
    """Outer steps with a limited command so far."""
    slip_speed_m_per_s: _F64
    """Each omniwheel's estimated slip speed at the rim (m/s), ``(3,)``."""
    slipping: tuple[bool, bool, bool]
    """Which omniwheels slip (estimated slip speed above the threshold)."""
    predicted_normal_force_n: _F64
    """The contact model's normal forces for the measured state and the reference torque
    (N), ``(3,)``."""
    lift_off_imminent: bool
    """Whether a predicted normal force is below the envelope's minimum."""
    accel_scale: float
    """The factor on the envelope after a slip or an imminent lift-off (1 when quiet)."""
    friction_estimate: float
    """The wheel-ball friction the envelope uses now."""
    slip_events: int
    """Slip events so far."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class TractionEnvelope(_Result):
    """The controller's traction envelope (``WorldLoop.traction_envelope()``): the largest
    acceleration that keeps every omniwheel inside its margin, per direction."""

    heading_rad: _F64
    """Table headings (rad, body frame, 0 towards OW1, in (-pi, pi]), ``(96,)``."""
    accel_m_per_s2: _F64
    """Largest acceleration towards each heading (m/s^2), ``(96,)``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class RampRun(_Result):
    """A maximum-speed ramp in the 3D world (``max_speed_ramp``)."""

    heading_deg: float
    """Ramp heading in the body frame (deg; 0 towards OW1)."""
    max_speed_m_per_s: float
    """Highest ball speed along the heading before failure (m/s)."""
    failure: Optional[Failure]
    """The failure that ended the ramp, or ``None``."""
    supervisor_stop_secs: Optional[float]
    """When the safety supervisor stopped balancing (s), or ``None``."""
    time_secs: _F64
    """Sample times (s), ``(n,)``."""
    command_m_per_s: _F64
    """The ramp (m/s), ``(n,)``."""
    shaped_command_m_per_s: _F64
    """The command after the controller's shaper (m/s), ``(n,)``."""
    speed_m_per_s: _F64
    """Ball speed along the heading (m/s), ``(n,)``."""
    tilt_rad: _F64
    """Tilt from the vertical (rad), ``(n,)``."""
    max_cone_utilisation: _F64
    """Largest cone utilisation of the three wheels, ``(n,)``."""
    normal_force_n: _F64
    """Wheel normal forces (N), ``(n, 3)``."""
    cone_utilisation: _F64
    """Cone utilisation per wheel, ``(n, 3)``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class TrialOutcome(_Result):
    """The summary of one slow-ramp or fast-ramp trial of the maximum-speed study."""

    heading_deg: float
    """Heading (deg)."""
    seed: int
    """Sensor-noise seed."""
    accel_m_per_s2: float
    """Ramp acceleration (m/s^2)."""
    max_speed_m_per_s: float
    """Highest ball speed along the heading (m/s)."""
    censored: bool
    """No failure: the speed is only a lower bound."""
    failure: Optional[Failure]
    """The failure, or ``None``."""
    peak_cone_utilisation: float
    """Peak cone utilisation."""
    min_normal_force_n: float
    """Smallest wheel normal force (N)."""
    peak_tilt_rad: float
    """Peak tilt from the vertical (rad)."""
    supervisor_stop_secs: Optional[float]
    """When the safety supervisor stopped balancing (s), or ``None``."""
    happened: dict[str, Any]
    """How the run ended and its contact events (``BrakingRun.happened``'s form); a ramp
    ends at the world's first failure, so a failed trial's outcome is ``ended_by_stop_rule``
    or ``fell``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class SlowRampTrial(RampRun):
    """One slow-ramp trial (``slow_ramp_trial``): the ramp and its outcome."""

    outcome: TrialOutcome
    """The trial's summary."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class FailingAcceleration(_Result):
    """The failing-acceleration search at one heading (``failing_acceleration``)."""

    heading_deg: float
    """Heading (deg)."""
    largest_surviving_m_per_s2: Optional[float]
    """Largest surviving ramp acceleration, ``None`` if the bracket's low end failed."""
    smallest_failing_m_per_s2: Optional[float]
    """Smallest failing ramp acceleration, ``None`` if the high end survived."""
    censored: bool
    """The bracket's high end survived."""
    text: str
    """As the table prints it: ``1.75``, ``>= 3.00``, ``< 0.50``."""
    runs: int
    """Ramps run."""
    failing: Optional[TrialOutcome]
    """The failing run's outcome."""
    surviving: Optional[TrialOutcome]
    """The surviving run's outcome."""
    failing_run: Optional[RampRun]
    """The failing ramp's series."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class MaxSpeedStudy(_Result):
    """The whole maximum-speed study (``max_speed_study``); the JSON-shaped fields are the
    ``max_speed_study`` entry of ``summary.json``."""

    protocol: dict[str, Any]
    """The protocol (ramps, search)."""
    wheel_ball_friction: float
    """Wheel-ball friction coefficient."""
    com_height_m: float
    """Centre-of-mass height (m)."""
    trials: list[dict[str, Any]]
    """Per trial heading: mean and spread of the slow-ramp maximum speed, the trials."""
    failing_accel_by_heading: dict[str, Any]
    """The failing acceleration per heading."""
    map: list[dict[str, Any]]
    """The capability map."""
    sensitivity: list[dict[str, Any]]
    """The mu / COM-height sensitivity."""
    paper: list[dict[str, Any]]
    """The paper's numbers."""
    max_speed_by_heading: dict[str, Any]
    """Mean slow-ramp maximum speed per heading."""
    table: str
    """The text table ``reproduce`` prints."""
    first_runs: dict[float, RampRun]
    """Per trial heading, the first trial's ramp."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class BrakingPeaks(_Result):
    """Peaks over a braking run."""

    cone_utilisation: list[float]
    """Peak cone utilisation per wheel."""
    min_normal_force_n: list[float]
    """Smallest normal force per wheel (N)."""
    actuator_utilisation: list[float]
    """Peak actuator utilisation per wheel."""
    tilt_rad: float
    """Peak tilt (rad)."""
    speed_error_m_per_s: float
    """Peak speed error against the plan (m/s)."""
    slip_secs: float
    """Time spent slipping (s)."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class BrakingRun(_Result):
    """One braking run in the 3D world (``braking_run``)."""

    heading_deg: float
    """Heading (deg)."""
    duration_secs: float
    """Planned braking duration (s)."""
    outcome: BrakingOutcome
    """How the run ended."""
    success: bool
    """Stopped within the criterion."""
    failure: Optional[Failure]
    """The failure, for ``BrakingOutcome.FAILED``."""
    rest_speed_m_per_s: Optional[float]
    """Speed at the end (m/s), when the run survived."""
    solve_status: Optional[SolveStatus]
    """The optimiser's status, for ``BrakingOutcome.NO_TRAJECTORY``."""
    brake_start_secs: float
    """When braking started (s)."""
    plan_peak_tilt_rad: Optional[float]
    """Peak tilt of the plan (rad)."""
    plan_cost_n2m2s: Optional[float]
    """Cost of the plan (N^2 m^2 s)."""
    peaks: BrakingPeaks
    """Peaks over the run."""
    time_secs: _F64
    """Sample times (s), ``(n,)``."""
    command_m_per_s: _F64
    """Commanded speed (m/s), ``(n,)``."""
    speed_m_per_s: _F64
    """Ball speed along the heading (m/s), ``(n,)``."""
    command_tilt_rad: _F64
    """Commanded tilt (rad), ``(n,)``."""
    tilt_rad: _F64
    """Tilt (rad), ``(n,)``."""
    cone_utilisation: _F64
    """Cone utilisation per wheel, ``(n, 3)``."""
    normal_force_n: _F64
    """Normal force per wheel (N), ``(n, 3)``."""
    actuator_utilisation: _F64
    """Actuator utilisation per wheel, ``(n, 3)``."""
    telemetry_hash: int
    """Hash of the run's telemetry (determinism checks)."""
    happened: Optional[dict[str, Any]]
    """How the flown run ended and its contact events, whatever the stop rules:
    ``{"outcome": {"kind": "at_rest", "time_secs": ...}, "events": [...], "events_dropped": 0}``
    (kinds ``fell``, ``ended_by_stop_rule``, ``stopped``, ``at_rest``, ``recovered``,
    ``unsettled``); ``None`` when no trajectory was flown."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class BrakingStudy(_Result):
    """The braking-time study at one heading (``braking_study``)."""

    heading_deg: float
    """Heading (deg)."""
    shortest_success_secs: Optional[float]
    """Shortest successful duration of the descent (s)."""
    first_failure_secs: Optional[float]
    """First failing duration of the descent (s)."""
    limit_secs: Optional[float]
    """The bisected limit (s)."""
    limit_failure_secs: Optional[float]
    """The failing duration next to the limit (s)."""
    descent: list[BrakingRun]
    """The runs of the descent."""
    bisection: list[BrakingRun]
    """The runs of the bisection."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class PushTrial(_Result):
    """One push-recovery trial (``push_trial``)."""

    heading_deg: float
    """Push heading (deg)."""
    impulse_ns: float
    """Impulse (N s)."""
    outcome: PushOutcome
    """How the trial ended."""
    recovered: bool
    """Whether it recovered."""
    failure: Optional[Failure]
    """The failure, for ``PushOutcome.FAILED``."""
    peak_tilt_rad: float
    """Peak tilt (rad)."""
    peak_speed_m_per_s: float
    """Peak ball speed (m/s)."""
    rest_speed_m_per_s: float
    """Ball speed at the end (m/s)."""
    time_secs: _F64
    """Sample times (s), ``(n,)``."""
    tilt_rad: _F64
    """Tilt from the vertical (rad), ``(n,)``."""
    speed_m_per_s: _F64
    """Ball speed (m/s), ``(n,)``."""
    max_cone_utilisation: _F64
    """Largest cone utilisation, ``(n,)``."""
    ball_velocity_m_per_s: _F64
    """Horizontal ball velocity (m/s), ``(n, 2)``."""
    telemetry_hash: int
    """Hash of the run's telemetry (determinism checks)."""
    happened: dict[str, Any]
    """How the run ended and its contact events, whatever the stop rules (the form of
    ``BrakingRun.happened``)."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class PushRecovery(_Result):
    """The push-recovery limit at one heading (``push_recovery_limit``)."""

    heading_deg: float
    """Heading (deg)."""
    largest_recovered_ns: float
    """Largest impulse recovered (N s)."""
    smallest_failing_ns: Optional[float]
    """Smallest impulse not recovered (N s), ``None`` if the upper end recovered."""
    trials: list[PushTrial]
    """The trials of the search."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class MinBrakingTime(_Result):
    """The shortest feasible braking time (``min_braking_time``)."""

    min_duration_secs: Optional[float]
    """Shortest feasible duration (s), ``None`` if none in the bracket."""
    infeasible_below_secs: Optional[float]
    """Longest infeasible duration below it (s)."""
    solution: BrakingSolution
    """The ``BrakingSolution`` at ``min_duration_secs``."""
    solves: int
    """Solves run."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class ScenarioRun(_Result):
    """A planar scenario's run (``Scenario.run``), sampled at the main controller's ticks."""

    time_secs: _F64
    """Tick times (s), ``(n,)``."""
    state: _F64
    """True ``[theta, phi, theta_dot, phi_dot]``, ``(n, 4)``."""
    command: _F64
    """``[theta_c, theta_dot_c, phi_dot_c]``, ``(n, 3)``."""
    requested_torque_nm: _F64
    """Torque the controller requested (N m), ``(n,)``."""
    torque_nm: _F64
    """Torque delivered (N m), ``(n,)``."""
    friction_torque_nm: _F64
    """Transmission friction torque (N m), ``(n,)``."""
    saturated: _F64
    """1.0 when saturated, else 0.0, ``(n,)``."""
    end_time_secs: float
    """When the run ended (s)."""
    fault: Optional[str]
    """Why the run stopped early, or ``None``."""
    log_path: Optional[Path]
    """The MCAP log written, or ``None``."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class PiptbExperiment(_Result):
    """The PIPTB controller comparison (``piptb_experiment``)."""

    brake_start_secs: float
    """When braking starts (s)."""
    brake_end_secs: float
    """When braking ends (s)."""
    reference: dict[str, Any]
    """The braking reference: effort, peak tilt, duration, source."""
    controllers: dict[str, dict[str, Any]]
    """Per controller key: the metrics and the trials (each with ``series``), braking phase
    ``[t2, t2 + 1.4 s]`` (the fixed window)."""
    controllers_until_stopped: dict[str, dict[str, Any]]
    """The same shape, braking phase ``[t2, t3]`` with ``t3`` when the testbed stopped (the
    speed within the stop band for the stop hold; ``t3_capped`` when it never did)."""


@functools.lru_cache(maxsize=None)
def _hints(cls: type) -> dict[str, Any]:
    module = sys.modules[cls.__module__]
    return typing.get_type_hints(cls, vars(module))


def _decode(hint: Any, value: Any) -> Any:
    """``value`` (plain Python objects from the native module) as the annotation ``hint``
    says: the one place where the serde form becomes numpy arrays, result classes, enums and
    ``Failure``s."""
    if value is None:
        return None
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin is Union:
        (inner,) = [a for a in args if a is not type(None)]
        return _decode(inner, value)
    if origin is np.ndarray:
        flat = np.frombuffer(value["data"], dtype=np.dtype(value["dtype"]))
        return flat.reshape(value["shape"]).copy()
    if origin is list:
        return [_decode(args[0], v) for v in value]
    if origin is tuple:
        return tuple(_decode(a, v) for a, v in zip(args, value))
    if origin is dict:
        return {_decode(args[0], k): _decode(args[1], v) for k, v in value.items()}
    if isinstance(hint, type):
        if issubclass(hint, _Result):
            return _build(hint.__name__, value)
        if issubclass(hint, enum.Enum):
            return hint(value)
        if hint is Failure:
            return Failure._from_parts(**value)
        if hint is Path:
            return Path(value)
    return value


def _build(class_name: str, data: dict[str, Any]) -> _Result:
    """The result class ``class_name`` from the native module's plain form of it (a dict
    with one entry per field, no other)."""
    cls = globals()[class_name]
    hints = _hints(cls)
    fields = {f.name: _decode(hints[f.name], data[f.name]) for f in dataclasses.fields(cls)}
    extra = data.keys() - fields.keys()
    if extra:
        raise TypeError(f"{class_name}: unexpected fields {sorted(extra)}")
    result: _Result = cls(**fields)
    return result


__all__ = [
    "BrakingPeaks",
    "BrakingRun",
    "BrakingStudy",
    "FailingAcceleration",
    "MaxSpeedStudy",
    "MinBrakingTime",
    "PiptbExperiment",
    "PushRecovery",
    "PushTrial",
    "RampRun",
    "Rollout",
    "ScenarioRun",
    "SlowRampTrial",
    "TractionEnvelope",
    "TractionStatus",
    "TrialOutcome",
    "WorldLoopRun",
    "WorldRun",
]
