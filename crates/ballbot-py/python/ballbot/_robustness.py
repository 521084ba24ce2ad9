"""Result classes of the reliability campaign (``ballbot.studies.robustness``): frozen
dataclasses built from the campaign's JSON, the same record ``ballbot robustness`` writes to
``robustness.json`` (fault-injection matrix, Monte Carlo; fuzzing)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Optional

from ballbot._results import _Result


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class CellLog(_Result):
    """The MCAP log of one faulted run, read back."""

    path: Path
    """The file."""
    messages: int
    """Messages written."""
    read_back_whole: bool
    """Whether it read back complete with every message written."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class FaultCell(_Result):
    """One cell of the fault-injection matrix: one fault, condition, heading and controller."""

    controller: str
    """``"paper"`` or ``"design"``."""
    fault: str
    """The fault class, e.g. ``"imu_stale"``."""
    condition: str
    """``"standing"``, ``"cruising"`` or ``"braking"``."""
    heading_deg: float
    """Direction of travel (deg)."""
    seed: int
    """Seed of the sensor noise (the cell re-runs from it)."""
    expected: str
    """The safe state the fault should end in (documented before the runs)."""
    observed: str
    """The one it ended in (``keeps_balancing``, ``controlled_stop``, ``protective_stop``,
    ``drifting`` or ``unsafe``)."""
    as_expected: bool
    """Whether ``observed == expected``."""
    fell: bool
    """Whether the body passed 25 deg from the vertical."""
    final_mode: str
    """The controller's mode at the end."""
    detected: list[str]
    """Faults raised after the injection, in the order first raised."""
    time_to_detect_ms: Optional[float]
    """From the injection to the first fault raised (ms)."""
    distance_m: float
    """The ball's path from the injection to the end or the fall (m)."""
    peak_tilt_deg: float
    """Largest tilt from the vertical after the injection (deg)."""
    speed_at_injection_m_per_s: float
    """Ball speed when the fault struck (m/s)."""
    final_speed_m_per_s: float
    """Ball speed at the end (m/s)."""
    final_command_error_m_per_s: float
    """Distance of the final ball velocity from the command's (m/s)."""
    faults_before_injection: list[str]
    """Faults raised before the injection (none in a healthy run)."""
    exercised: bool
    """Whether the fault could act (a bump ahead of a standing robot cannot)."""
    log: Optional[CellLog]
    """The run's MCAP log."""
    outcome: dict[str, Any]
    """How the run ended (``MonteCarloRun.outcome``'s form). The cell's world stops only on
    the tilt rule, its fall limit: ``ended_by_stop_rule`` with ``stop_rule`` ``tilt`` is a
    fall."""
    events: list[dict[str, Any]]
    """Slips, lift-offs, driver trips, controller faults and traction limits
    (``MonteCarloRun.events``' form)."""
    events_dropped: int
    """Events beyond the log's bound, not kept."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> FaultCell:
        log = d.get("log")
        fields = {k: v for k, v in d.items() if k not in ("class", "log")}
        return cls(
            fault=d["class"],
            log=None if log is None else CellLog(Path(log["path"]), log["messages"], log["read_back_whole"]),
            **fields,
        )


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class FaultMatrix(_Result):
    """The fault-injection matrix: counts and every cell."""

    cells: list[FaultCell]
    """Every cell (controller, then fault, condition and heading)."""
    as_expected: int
    """Cells in their expected safe state."""
    safe_but_other: int
    """Cells in another safe state."""
    unsafe_cells: int
    """Cells that fell undetected, drifted off the command or ended otherwise unsafe."""
    fell: int
    """Cells in which the body passed 25 deg."""
    not_exercised: int
    """Cells whose fault never acted."""
    logs_read_back_whole: int
    """Logs that read back whole (one per cell)."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> FaultMatrix:
        s = d["summary"]
        return cls(
            cells=[FaultCell._from_json(c) for c in d["cells"]],
            as_expected=s["as_expected"],
            safe_but_other=s["safe_but_other"],
            unsafe_cells=s["unsafe_cells"],
            fell=s["fell"],
            not_exercised=s["not_exercised"],
            logs_read_back_whole=s["logs_read_back_whole"],
        )


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class Mismatch(_Result):
    """How one Monte Carlo run's robot differs from the controller's model."""

    payload_mass: float
    """Factor on the payload mass."""
    com_height: float
    """Factor on the COM height."""
    body_inertia: float
    """Factor on the body inertia."""
    ball_inertia: float
    """Factor on the ball inertia."""
    roller_friction: float
    """Factor on the wheel-ball friction."""
    drive_friction: float
    """Factor on the drive friction (wheel damping)."""
    imu_noise: float
    """Factor on the IMU noise."""
    gyro_bias_rad_per_s: list[float]
    """Gyro bias ``[x, y, z]`` (rad/s)."""
    tilt_bias_rad: list[float]
    """Roll and pitch bias (rad)."""
    heading_deg: float
    """Push heading (deg)."""


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class MonteCarloRun(_Result):
    """One Monte Carlo run, re-runnable from its seed."""

    index: int
    """Index in the study."""
    seed: int
    """The run's seed."""
    mismatch: Mismatch
    """The sampled mismatch."""
    verdict: str
    """The protocol's verdict: ``recovered``, ``not_at_rest``, ``tilt_exceeded`` or
    ``failed``."""
    stayed_up: bool
    """No failure and tilt below 15 deg after the push."""
    recovered: bool
    """Also at rest within 3 s."""
    failure: Optional[str]
    """What failed, if anything."""
    peak_tilt_deg: float
    """Largest tilt from the vertical after the push (deg)."""
    rest_speed_m_per_s: float
    """Largest ball speed in the rest window (m/s)."""
    largest_recovered_ns: Optional[float]
    """Largest push it stays up after (N s), for the bisected runs."""
    outcome: dict[str, Any]
    """How the run ended: ``{"kind": "fell" | "ended_by_stop_rule" | "stopped" | "at_rest" |
    "recovered" | "unsettled", "time_secs": ...}`` (a stop rule adds ``stop_rule`` and
    ``wheel``)."""
    events: list[dict[str, Any]]
    """Slips, lift-offs, driver trips, controller faults and traction limits, each with
    ``kind``, ``onset_secs``, ``duration_secs``, ``ongoing`` and its peak."""
    events_dropped: int
    """Events beyond the log's bound, not kept."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> MonteCarloRun:
        fields = dict(d)
        fields["mismatch"] = Mismatch(**d["mismatch"])
        return cls(**fields)


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class MonteCarlo(_Result):
    """The Monte Carlo study of one controller."""

    controller: str
    """``"paper"`` or ``"design"``."""
    settings: dict[str, Any]
    """The settings it ran with."""
    runs: int
    """Runs."""
    stayed_up: int
    """Runs that stayed up after the push."""
    recovery_rate: float
    """``stayed_up / runs``."""
    recovery_rate_ci95: list[float]
    """95 % Wilson interval of the recovery rate."""
    at_rest: int
    """Runs that also came to rest within 3 s."""
    at_rest_rate: float
    """``at_rest / runs``."""
    at_rest_rate_ci95: list[float]
    """95 % Wilson interval of the at-rest rate."""
    outcomes: dict[str, int]
    """Runs by outcome."""
    worst: list[MonteCarloRun]
    """The runs that fell, then the largest peak tilts, up to 10."""
    limit_quantiles: Optional[dict[str, float]]
    """Quantiles of the largest push the bisected runs stay up after (N s)."""
    throughput: dict[str, float]
    """Runs per second on one thread and on all (this run's wall clock)."""
    all_runs: list[MonteCarloRun]
    """Every run, in index order."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> MonteCarlo:
        return cls(
            controller=d["settings"]["controller"],
            settings=d["settings"],
            runs=d["runs"],
            stayed_up=d["stayed_up"],
            recovery_rate=d["recovery_rate"],
            recovery_rate_ci95=d["recovery_rate_ci95"],
            at_rest=d["at_rest"],
            at_rest_rate=d["at_rest_rate"],
            at_rest_rate_ci95=d["at_rest_rate_ci95"],
            outcomes={o: n for o, n in d["outcomes"]},
            worst=[MonteCarloRun._from_json(r) for r in d["worst"]],
            limit_quantiles=d["limit_quantiles"],
            throughput=d["throughput"],
            all_runs=[MonteCarloRun._from_json(r) for r in d["all_runs"]],
        )


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class Fuzz(_Result):
    """The fuzz campaign of the core and the parsers."""

    seed: int
    """Base seed of the episodes."""
    steps: int
    """Controller steps executed (outer plus motor-loop)."""
    outer_steps: int
    """Outer (400 Hz) steps."""
    inner_steps: int
    """Motor-loop (8 kHz) steps."""
    planar_steps: int
    """Steps of the planar controllers (LQR, PI-PD, LQR-PI) fuzzed on their own."""
    simulated_hours: float
    """Simulated time (h)."""
    episodes: int
    """Episodes run."""
    traction_on_episodes: int
    """Episodes with traction-aware control and the balance point on (half of each kind)."""
    pushes: int
    """Pushes on the plant."""
    panics: int
    """Panics (must be 0)."""
    bad_commands: int
    """Motor commands that broke a hard invariant (must be 0)."""
    findings: int
    """Reported findings (see the docs)."""
    findings_by_what: dict[str, int]
    """Findings by what happened."""
    invariants: list[dict[str, Any]]
    """Every invariant: ``key``, ``item`` (the safe-by-default hardening item it checks, 0 for
    the campaign's first invariants), ``class`` (``"bad_command"`` or ``"finding"``), ``what``
    and ``breaks``."""
    violations: list[dict[str, Any]]
    """The first bad commands and findings, each with its episode seed."""
    faults_raised: dict[str, int]
    """Steps on which each fault class was raised."""
    single_sample_checks: int
    """Single corrupted samples compared against a clean twin."""
    parsers: dict[str, Any]
    """The parsers' tally (files, rejected, panics, errors naming the key)."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> Fuzz:
        fields = {k: v for k, v in d.items() if k != "settings"}
        return cls(seed=d["settings"]["seed"], **fields)


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class Robustness(_Result):
    """The reliability campaign (``ballbot.studies.robustness``, ``ballbot robustness``)."""

    quick: bool
    """Whether it was the CI-sized campaign."""
    seed: int
    """The base seed of every random input."""
    fuzz: Fuzz
    """The fuzz campaign."""
    fault_matrix: FaultMatrix
    """The fault-injection matrix in the 3D world."""
    monte_carlo: dict[str, MonteCarlo]
    """The Monte Carlo study per controller (``"paper"``, ``"design"``), counted by the
    world's stop rules (a wheel slipping for 0.1 s or off the ball for 20 ms fails a run)."""
    monte_carlo_by_falls: dict[str, MonteCarlo]
    """The same counted by falls only (the slip and lift-off stop rules relaxed)."""

    @classmethod
    def _from_json(cls, d: dict[str, Any]) -> Robustness:
        mc = d["monte_carlo"]["by_controller"]
        falls = d["monte_carlo"].get("by_falls", {})
        return cls(
            quick=d["quick"],
            seed=d["seed"],
            fuzz=Fuzz._from_json(d["fuzz"]),
            fault_matrix=FaultMatrix._from_json(d["fault_matrix"]),
            monte_carlo={k: MonteCarlo._from_json(v) for k, v in mc.items()},
            monte_carlo_by_falls={k: MonteCarlo._from_json(v) for k, v in falls.items()},
        )


__all__ = [
    "CellLog",
    "FaultCell",
    "FaultMatrix",
    "Fuzz",
    "Mismatch",
    "MonteCarlo",
    "MonteCarloRun",
    "Robustness",
]
