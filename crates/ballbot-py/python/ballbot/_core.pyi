"""Type stubs of the native module ``ballbot._core`` (checked by ``mypy.stubtest``)."""

from os import PathLike
from pathlib import Path
from typing import Any, Literal, Optional, TypedDict, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "ActuatorParams",
    "BallbotParams",
    "BrakingLimits",
    "BrakingProblem",
    "BrakingSolution",
    "ContactForces",
    "DrivetrainParams",
    "Lqr",
    "LqrController",
    "LqrGains",
    "LqrOutput",
    "LqrPiOuter",
    "LqrPiOuterConfig",
    "LqrPiOuterOutput",
    "McapLog",
    "OmniKinematics",
    "PiPdController",
    "PiPdGains",
    "PiPdOutput",
    "PlanarRobotParams",
    "RiccatiSolution",
    "Scenario",
    "SpeedPi",
    "SpeedPiGains",
    "SpeedPiOutput",
    "Spin",
    "SpinParams",
    "Wip",
    "WipParams",
    "closed_loop_rollout",
    "expm",
    "min_braking_time",
    "piptb_experiment",
    "planar_torque_at_heading",
    "relative_rate_at_heading",
    "relative_rate_from_planar",
    "solve_care",
    "solve_dare",
    "spin_lqr",
    "spin_lqr_discrete",
    "wip_lqr",
    "wip_lqr_discrete",
    "zoh",
    "__version__",
    "accelerating_command",
    "ContactParams",
    "Failure",
    "FailureParams",
    "Measurement",
    "SensorParams",
    "StepTelemetry",
    "WheelTelemetry",
    "World",
    "WorldLoop",
    "WorldParams",
    "max_speed_ramp",
    "failing_acceleration",
    "max_speed_study",
    "slow_ramp_trial",
    "braking_run",
    "braking_study",
    "push_trial",
    "push_recovery_limit",
]

__version__: str

_Floats = Union[float, npt.ArrayLike]
_Path = Union[str, "PathLike[str]"]
_F64 = npt.NDArray[np.float64]
_Status = Literal["nominal", "saturated", "invalid_input"]
_RiccatiStatus = Literal["converged", "max_iterations", "not_stabilizable", "non_finite"]

@final
class WipParams:
    """One plane of the wheeled inverted pendulum; defaults are MiaPURE with 60 kg."""

    def __new__(
        cls,
        *,
        ball_radius_m: float = ...,
        ball_mass_kg: float = ...,
        ball_inertia_kg_m2: float = ...,
        body_mass_kg: float = ...,
        com_height_m: float = ...,
        body_inertia_kg_m2: float = ...,
        wheel_inertia_kg_m2: float = ...,
        ball_damping_nm_s_per_rad: float = ...,
        drive_damping_nm_s_per_rad: float = ...,
        gravity_m_per_s2: float = ...,
    ) -> WipParams: ...
    @staticmethod
    def preset(name: str) -> WipParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: float) -> WipParams: ...
    def to_dict(self) -> dict[str, float]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> WipParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> WipParams: ...
    @property
    def ball_radius_m(self) -> float: ...
    @property
    def ball_mass_kg(self) -> float: ...
    @property
    def ball_inertia_kg_m2(self) -> float: ...
    @property
    def body_mass_kg(self) -> float: ...
    @property
    def com_height_m(self) -> float: ...
    @property
    def body_inertia_kg_m2(self) -> float: ...
    @property
    def wheel_inertia_kg_m2(self) -> float: ...
    @property
    def ball_damping_nm_s_per_rad(self) -> float: ...
    @property
    def drive_damping_nm_s_per_rad(self) -> float: ...
    @property
    def gravity_m_per_s2(self) -> float: ...

@final
class SpinParams:
    """The spin model; defaults are MiaPURE with 60 kg."""

    def __new__(
        cls, *, inertia_kg_m2: float = ..., damping_nm_s_per_rad: float = ...
    ) -> SpinParams: ...
    @staticmethod
    def preset(name: str) -> SpinParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: float) -> SpinParams: ...
    def to_dict(self) -> dict[str, float]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> SpinParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> SpinParams: ...
    @property
    def inertia_kg_m2(self) -> float: ...
    @property
    def damping_nm_s_per_rad(self) -> float: ...

@final
class ActuatorParams:
    """One actuator, limits at the output; defaults are MiaPURE's QDD actuator."""

    def __new__(
        cls,
        *,
        gear_ratio: float = ...,
        peak_torque_nm: float = ...,
        no_load_speed_rad_per_s: float = ...,
    ) -> ActuatorParams: ...
    @staticmethod
    def preset(name: str) -> ActuatorParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: float) -> ActuatorParams: ...
    def to_dict(self) -> dict[str, float]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> ActuatorParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> ActuatorParams: ...
    @property
    def gear_ratio(self) -> float: ...
    @property
    def peak_torque_nm(self) -> float: ...
    @property
    def no_load_speed_rad_per_s(self) -> float: ...
    def torque_bounds_nm(self, speed_rad_per_s: float) -> tuple[float, float]: ...
    def clamp_torque_nm(self, torque_nm: float, speed_rad_per_s: float) -> float: ...

@final
class DrivetrainParams:
    """The omniwheel drivetrain: wheel azimuths, contact angle, wheel radius, actuator,
    friction coefficients; defaults are MiaPURE's."""

    def __new__(
        cls,
        *,
        wheel_azimuths_rad: npt.ArrayLike = ...,
        contact_angle_rad: float = ...,
        wheel_radius_m: float = ...,
        actuator: Union[ActuatorParams, dict[str, Any]] = ...,
        wheel_ball_friction: float = ...,
        ball_floor_friction: float = ...,
    ) -> DrivetrainParams: ...
    @staticmethod
    def preset(name: str) -> DrivetrainParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> DrivetrainParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> DrivetrainParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> DrivetrainParams: ...
    @property
    def wheel_azimuths_rad(self) -> _F64: ...
    @property
    def contact_angle_rad(self) -> float: ...
    @property
    def wheel_radius_m(self) -> float: ...
    @property
    def actuator(self) -> ActuatorParams: ...
    @property
    def wheel_ball_friction(self) -> float: ...
    @property
    def ball_floor_friction(self) -> float: ...

@final
class BallbotParams:
    """A complete 3D ballbot: sagittal and frontal planes, spin, drivetrain; defaults are
    MiaPURE with 60 kg."""

    def __new__(
        cls,
        *,
        sagittal: Union[WipParams, dict[str, Any]] = ...,
        frontal: Union[WipParams, dict[str, Any]] = ...,
        spin: Union[SpinParams, dict[str, Any]] = ...,
        drivetrain: Union[DrivetrainParams, dict[str, Any]] = ...,
    ) -> BallbotParams: ...
    @staticmethod
    def preset(name: str) -> BallbotParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> BallbotParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> BallbotParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> BallbotParams: ...
    @property
    def sagittal(self) -> WipParams: ...
    @property
    def frontal(self) -> WipParams: ...
    @property
    def spin(self) -> SpinParams: ...
    @property
    def drivetrain(self) -> DrivetrainParams: ...
    @property
    def ball_radius_m(self) -> float: ...

@final
class PlanarRobotParams:
    """A planar robot: one WIP plane driven by one actuator; defaults are the PIPTB's."""

    def __new__(
        cls,
        *,
        plane: Union[WipParams, dict[str, Any]] = ...,
        actuator: Union[ActuatorParams, dict[str, Any]] = ...,
    ) -> PlanarRobotParams: ...
    @staticmethod
    def preset(name: str) -> PlanarRobotParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> PlanarRobotParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> PlanarRobotParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> PlanarRobotParams: ...
    @property
    def plane(self) -> WipParams: ...
    @property
    def actuator(self) -> ActuatorParams: ...

@final
class Wip:
    """The planar wheeled inverted pendulum, vectorised over states (4,) or (n, 4)."""

    def __new__(cls, params: WipParams) -> Wip: ...
    @property
    def params(self) -> WipParams: ...
    def accelerations(
        self, state: npt.ArrayLike, torque_nm: Optional[_Floats] = None
    ) -> npt.NDArray[np.float64]: ...
    def derivative(
        self, state: npt.ArrayLike, torque_nm: Optional[_Floats] = None
    ) -> npt.NDArray[np.float64]: ...
    def energy_j(self, state: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def linearize(
        self, state: Optional[npt.ArrayLike] = None, torque_nm: float = 0.0
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def upright_unstable_pole_rad_per_s(self) -> float: ...
    def open_loop_poles(self) -> npt.NDArray[np.complex128]: ...
    def rollout(
        self,
        state: npt.ArrayLike,
        dt_secs: float,
        n_steps: int,
        torque_nm: float = 0.0,
    ) -> npt.NDArray[np.float64]: ...

@final
class Spin:
    """The spin model ``I_z theta_z_ddot + D_z theta_z_dot = tau_z``."""

    def __new__(cls, params: SpinParams) -> Spin: ...
    def derivative(
        self, state: npt.ArrayLike, torque_nm: float
    ) -> npt.NDArray[np.float64]: ...
    def state_space(
        self,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

# ---- kinematics ---------------------------------------------------------------------------

@final
class ContactForces:
    """Forces at the three omniwheel contacts: per-wheel arrays of shape (3,) for one case or
    (n, 3) for a batch; per-case values are 0-d or (n,)."""

    @property
    def normal_force_n(self) -> _F64: ...
    @property
    def traction_n(self) -> _F64: ...
    @property
    def friction_utilisation(self) -> _F64: ...
    @property
    def lifted_off(self) -> _F64: ...
    @property
    def max_friction_utilisation(self) -> _F64: ...
    @property
    def all_hold(self) -> _F64: ...
    def __len__(self) -> int: ...

@final
class OmniKinematics:
    """Omniwheel kinematics and statics; every map takes (3,) or (n, 3) rows."""

    def __new__(cls, drivetrain: DrivetrainParams, ball_radius_m: float) -> OmniKinematics: ...
    @staticmethod
    def from_ballbot(params: BallbotParams) -> OmniKinematics: ...
    @property
    def drivetrain(self) -> DrivetrainParams: ...
    @property
    def ball_radius_m(self) -> float: ...
    @property
    def contact_normals(self) -> _F64: ...
    @property
    def rolling_directions(self) -> _F64: ...
    @property
    def axle_directions(self) -> _F64: ...
    @property
    def contact_points_m(self) -> _F64: ...
    def wheel_speeds_rad_per_s(self, relative_rate_rad_per_s: npt.ArrayLike) -> _F64: ...
    def relative_rate_rad_per_s(self, wheel_speeds_rad_per_s: npt.ArrayLike) -> _F64: ...
    def motor_speeds_rad_per_s(self, relative_rate_rad_per_s: npt.ArrayLike) -> _F64: ...
    def relative_rate_from_motor_speeds_rad_per_s(
        self, motor_speeds_rad_per_s: npt.ArrayLike
    ) -> _F64: ...
    def wheel_torques_nm(self, planar_torque_nm: npt.ArrayLike) -> _F64: ...
    def planar_torque_nm(self, wheel_torques_nm: npt.ArrayLike) -> _F64: ...
    def motor_torques_nm(self, planar_torque_nm: npt.ArrayLike) -> _F64: ...
    def planar_torque_from_motor_torques_nm(self, motor_torques_nm: npt.ArrayLike) -> _F64: ...
    def wheel_speed_matrix(self) -> _F64: ...
    def wheel_torque_matrix(self) -> _F64: ...
    def reflected_wheel_inertia_kg_m2(
        self, wheel_inertia_kg_m2: float, rotor_inertia_kg_m2: float
    ) -> _F64: ...
    def planar_torque_capacity_nm(self) -> _F64: ...
    def saturate_planar_torque(
        self,
        planar_torque_nm: npt.ArrayLike,
        wheel_speeds_rad_per_s: Optional[npt.ArrayLike] = None,
    ) -> tuple[_F64, _F64, _F64]: ...
    def normal_forces_n(
        self, support_force_n: npt.ArrayLike, wheel_torques_nm: npt.ArrayLike
    ) -> _F64: ...
    def contact_forces(
        self, support_force_n: npt.ArrayLike, wheel_torques_nm: npt.ArrayLike
    ) -> ContactForces: ...
    def wip_contact_forces(
        self, wip: Wip, heading_rad: _Floats, state: npt.ArrayLike, torque_nm: _Floats
    ) -> ContactForces: ...
    def decoupled_contact_forces(
        self,
        sagittal: Wip,
        sagittal_state: npt.ArrayLike,
        frontal: Wip,
        frontal_state: npt.ArrayLike,
        planar_torque_nm: npt.ArrayLike,
    ) -> ContactForces: ...
    def wip_actuator_torque_interval_nm(
        self, heading_rad: _Floats, state: npt.ArrayLike
    ) -> _F64: ...
    def wip_contact_torque_interval_nm(
        self, wip: Wip, heading_rad: _Floats, state: npt.ArrayLike
    ) -> _F64: ...

def relative_rate_from_planar(
    ball_rate_rad_per_s: npt.ArrayLike,
    tilt_rate_rad_per_s: npt.ArrayLike,
    yaw_rate_rad_per_s: Optional[_Floats] = None,
) -> _F64: ...
def relative_rate_at_heading(
    heading_rad: _Floats, ball_rate_rad_per_s: _Floats, tilt_rate_rad_per_s: _Floats
) -> _F64: ...
def planar_torque_at_heading(heading_rad: _Floats, torque_nm: _Floats) -> _F64: ...

# ---- LQR ----------------------------------------------------------------------------------

@final
class Lqr:
    """A single-input LQR design: gain k for u = k . (s_c - s), closed loop, cost-to-go."""

    @staticmethod
    def continuous(
        a: npt.ArrayLike, b: npt.ArrayLike, q: npt.ArrayLike, r: float
    ) -> Lqr: ...
    @staticmethod
    def discrete(
        a: npt.ArrayLike, b: npt.ArrayLike, q: npt.ArrayLike, r: float, dt_secs: float
    ) -> Lqr: ...
    @property
    def gain(self) -> _F64: ...
    @property
    def closed_loop(self) -> _F64: ...
    @property
    def cost_to_go(self) -> _F64: ...
    @property
    def dt_secs(self) -> Optional[float]: ...
    @property
    def iterations(self) -> int: ...
    @property
    def residual(self) -> float: ...
    def closed_loop_eigenvalues(self) -> npt.NDArray[np.complex128]: ...
    def control(self, reference: npt.ArrayLike, measured: npt.ArrayLike) -> float: ...
    def reduced_gains(self) -> _F64: ...
    def paper_gains(self) -> _F64: ...
    def controller_gains(self, max_torque_nm: float) -> LqrGains: ...

@final
class RiccatiSolution:
    """The result of a Riccati solve; use x and gain only when converged."""

    @property
    def x(self) -> _F64: ...
    @property
    def gain(self) -> _F64: ...
    @property
    def status(self) -> _RiccatiStatus: ...
    @property
    def iterations(self) -> int: ...
    @property
    def residual(self) -> float: ...
    def is_converged(self) -> bool: ...

def wip_lqr(wip: Wip, q: Optional[npt.ArrayLike] = None, r: float = 0.1) -> Lqr: ...
def wip_lqr_discrete(
    wip: Wip, dt_secs: float = 0.0025, q: Optional[npt.ArrayLike] = None, r: float = 0.1
) -> Lqr: ...
def spin_lqr(spin: Spin, q: npt.ArrayLike, r: float) -> Lqr: ...
def spin_lqr_discrete(spin: Spin, q: npt.ArrayLike, r: float, dt_secs: float) -> Lqr: ...
def solve_care(
    a: npt.ArrayLike, b: npt.ArrayLike, q: npt.ArrayLike, r: _Floats
) -> RiccatiSolution: ...
def solve_dare(
    a: npt.ArrayLike, b: npt.ArrayLike, q: npt.ArrayLike, r: _Floats
) -> RiccatiSolution: ...
def expm(a: npt.ArrayLike) -> _F64: ...
def zoh(a: npt.ArrayLike, b: npt.ArrayLike, dt_secs: float) -> tuple[_F64, _F64]: ...

# ---- controllers --------------------------------------------------------------------------

@final
class LqrGains:
    """Gains and torque limit of the LQR controller, tau = k (s_c - s)."""

    def __new__(
        cls,
        *,
        tilt_nm_per_rad: float,
        tilt_rate_nm_s_per_rad: float,
        ball_rate_nm_s_per_rad: float,
        max_torque_nm: float,
    ) -> LqrGains: ...
    @staticmethod
    def from_reduced(k: tuple[float, float, float], max_torque_nm: float) -> LqrGains: ...
    @staticmethod
    def design(
        wip: Wip,
        max_torque_nm: float,
        q: Optional[npt.ArrayLike] = None,
        r: float = 0.1,
        dt_secs: Optional[float] = None,
    ) -> LqrGains: ...
    @staticmethod
    def for_wip(wip: Wip, max_torque_nm: float) -> LqrGains: ...
    def reduced(self) -> _F64: ...
    def full(self) -> _F64: ...
    def replace(self, **kwargs: float) -> LqrGains: ...
    def to_dict(self) -> dict[str, float]: ...
    @property
    def tilt_nm_per_rad(self) -> float: ...
    @property
    def tilt_rate_nm_s_per_rad(self) -> float: ...
    @property
    def ball_rate_nm_s_per_rad(self) -> float: ...
    @property
    def max_torque_nm(self) -> float: ...

@final
class PiPdGains:
    """Gains and limits of the cascaded PI-PD controller."""

    def __new__(
        cls,
        *,
        speed_p_secs: float,
        speed_i_rad_per_rad: float,
        tilt_p_nm_per_rad: float,
        tilt_d_nm_s_per_rad: float,
        max_tilt_rad: float,
        max_torque_nm: float,
    ) -> PiPdGains: ...
    @staticmethod
    def design(
        wip: Wip,
        poles_rad_per_s: tuple[float, float, float, float],
        max_tilt_rad: float,
        max_torque_nm: float,
    ) -> PiPdGains: ...
    @staticmethod
    def for_wip(wip: Wip, max_torque_nm: float) -> PiPdGains: ...
    def replace(self, **kwargs: float) -> PiPdGains: ...
    def to_dict(self) -> dict[str, float]: ...
    @property
    def speed_p_secs(self) -> float: ...
    @property
    def speed_i_rad_per_rad(self) -> float: ...
    @property
    def tilt_p_nm_per_rad(self) -> float: ...
    @property
    def tilt_d_nm_s_per_rad(self) -> float: ...
    @property
    def max_tilt_rad(self) -> float: ...
    @property
    def max_torque_nm(self) -> float: ...

@final
class SpeedPiGains:
    """Gains and limit of the inner speed PI."""

    def __new__(
        cls,
        *,
        proportional_nm_s_per_rad: float,
        integral_nm_per_rad: float,
        anti_windup_per_s: float,
        max_torque_nm: float,
    ) -> SpeedPiGains: ...
    @staticmethod
    def from_bandwidth(
        accel_per_torque: float, bandwidth_rad_per_s: float, max_torque_nm: float
    ) -> SpeedPiGains: ...
    @staticmethod
    def for_wip_ball_rate(
        wip: Wip, bandwidth_rad_per_s: float, max_torque_nm: float
    ) -> SpeedPiGains: ...
    def replace(self, **kwargs: float) -> SpeedPiGains: ...
    def to_dict(self) -> dict[str, float]: ...
    @property
    def proportional_nm_s_per_rad(self) -> float: ...
    @property
    def integral_nm_per_rad(self) -> float: ...
    @property
    def anti_windup_per_s(self) -> float: ...
    @property
    def max_torque_nm(self) -> float: ...

@final
class LqrPiOuterConfig:
    """The LQR-PI outer loop's LQR gains and reference-integrator anchor band."""

    def __new__(
        cls, *, lqr: LqrGains, max_speed_error_rad_per_s: float
    ) -> LqrPiOuterConfig: ...
    @staticmethod
    def for_inner(lqr: LqrGains, inner: SpeedPiGains) -> LqrPiOuterConfig: ...
    @property
    def lqr(self) -> LqrGains: ...
    @property
    def max_speed_error_rad_per_s(self) -> float: ...

@final
class LqrOutput:
    """One LQR step's result, with each term."""

    @property
    def torque_nm(self) -> float: ...
    @property
    def tilt_term_nm(self) -> float: ...
    @property
    def tilt_rate_term_nm(self) -> float: ...
    @property
    def ball_rate_term_nm(self) -> float: ...
    @property
    def saturation_nm(self) -> float: ...
    @property
    def status(self) -> _Status: ...
    def to_dict(self) -> dict[str, Any]: ...

@final
class PiPdOutput:
    """One PI-PD step's result, with each term."""

    @property
    def torque_nm(self) -> float: ...
    @property
    def reference_tilt_rad(self) -> float: ...
    @property
    def tilt_feedforward_rad(self) -> float: ...
    @property
    def speed_p_term_rad(self) -> float: ...
    @property
    def speed_i_term_rad(self) -> float: ...
    @property
    def tilt_limit_rad(self) -> float: ...
    @property
    def tilt_p_term_nm(self) -> float: ...
    @property
    def tilt_d_term_nm(self) -> float: ...
    @property
    def saturation_nm(self) -> float: ...
    @property
    def status(self) -> _Status: ...
    def to_dict(self) -> dict[str, Any]: ...

@final
class LqrPiOuterOutput:
    """One LQR-PI outer step's result: references for the inner loop, and each term."""

    @property
    def reference_torque_nm(self) -> float: ...
    @property
    def reference_ball_rate_rad_per_s(self) -> float: ...
    @property
    def reference_ball_accel_rad_per_s2(self) -> float: ...
    @property
    def tilt_term_nm(self) -> float: ...
    @property
    def tilt_rate_term_nm(self) -> float: ...
    @property
    def ball_rate_term_nm(self) -> float: ...
    @property
    def saturation_nm(self) -> float: ...
    @property
    def anchor_correction_rad_per_s(self) -> float: ...
    @property
    def status(self) -> _Status: ...
    def to_dict(self) -> dict[str, Any]: ...

@final
class SpeedPiOutput:
    """One speed-PI step's result, with each term."""

    @property
    def torque_nm(self) -> float: ...
    @property
    def feedforward_nm(self) -> float: ...
    @property
    def proportional_nm(self) -> float: ...
    @property
    def integral_nm(self) -> float: ...
    @property
    def saturation_nm(self) -> float: ...
    @property
    def speed_error_rad_per_s(self) -> float: ...
    @property
    def status(self) -> _Status: ...
    def to_dict(self) -> dict[str, Any]: ...

@final
class LqrController:
    """The paper's LQR torque controller, tau = k (s_c - s), saturated."""

    def __new__(cls, gains: LqrGains) -> LqrController: ...
    @property
    def gains(self) -> LqrGains: ...
    def reset(self) -> None: ...
    def step(
        self,
        measured: npt.ArrayLike,
        command: Optional[npt.ArrayLike] = None,
        dt_secs: float = 0.0025,
    ) -> LqrOutput: ...
    def step_many(
        self,
        measured: npt.ArrayLike,
        command: Optional[npt.ArrayLike] = None,
        dt_secs: float = 0.0025,
    ) -> dict[str, npt.NDArray[Any]]: ...

@final
class PiPdController:
    """The cascaded PI-PD controller: outer PI on ball rate, inner PD on tilt."""

    def __new__(cls, gains: PiPdGains) -> PiPdController: ...
    @property
    def gains(self) -> PiPdGains: ...
    @property
    def speed_error_integral_rad(self) -> float: ...
    def reset(self) -> None: ...
    def step(
        self,
        measured: npt.ArrayLike,
        command: Optional[npt.ArrayLike] = None,
        dt_secs: float = 0.0025,
    ) -> PiPdOutput: ...
    def step_many(
        self,
        measured: npt.ArrayLike,
        command: Optional[npt.ArrayLike] = None,
        dt_secs: float = 0.0025,
    ) -> dict[str, npt.NDArray[Any]]: ...

@final
class LqrPiOuter:
    """The outer part of the cascaded LQR-PI controller."""

    def __new__(cls, model: Wip, config: LqrPiOuterConfig) -> LqrPiOuter: ...
    @property
    def config(self) -> LqrPiOuterConfig: ...
    @property
    def reference_ball_rate_rad_per_s(self) -> Optional[float]: ...
    def reset(self) -> None: ...
    def step(
        self,
        measured: npt.ArrayLike,
        command: Optional[npt.ArrayLike] = None,
        dt_secs: float = 0.0025,
    ) -> LqrPiOuterOutput: ...

@final
class SpeedPi:
    """The inner speed PI with feedforward and back-calculation anti-windup."""

    def __new__(cls, gains: SpeedPiGains) -> SpeedPi: ...
    @property
    def gains(self) -> SpeedPiGains: ...
    @property
    def integral_nm(self) -> float: ...
    def reset(self) -> None: ...
    def step(
        self,
        measured_speed_rad_per_s: float,
        speed_rad_per_s: float,
        feedforward_torque_nm: float = 0.0,
        dt_secs: float = 0.000125,
        lower_nm: Optional[float] = None,
        upper_nm: Optional[float] = None,
    ) -> SpeedPiOutput: ...

def accelerating_command(
    wip: Wip, ball_rate_rad_per_s: float, ball_accel_rad_per_s2: float
) -> Optional[tuple[_F64, float]]: ...

class _Rollout(TypedDict):
    time_secs: _F64
    state: _F64
    torque_nm: _F64
    status: npt.NDArray[np.int8]
    compute_secs: float

def closed_loop_rollout(
    plant: Wip,
    controller: Union[LqrController, PiPdController, LqrPiOuter],
    initial_state: npt.ArrayLike,
    *,
    n_steps: int,
    dt_secs: float = 0.0025,
    command: Optional[npt.ArrayLike] = None,
    inner: Optional[SpeedPi] = None,
    substeps: int = 1,
) -> _Rollout: ...

# ---- logs ---------------------------------------------------------------------------------

@final
class McapLog:
    """An MCAP log read into memory (complete, or recovered from a killed writer)."""

    def __new__(cls, path: _Path) -> McapLog: ...
    @property
    def path(self) -> Path: ...
    @property
    def is_complete(self) -> bool: ...
    @property
    def stop_reason(self) -> Optional[str]: ...
    @property
    def message_count(self) -> int: ...
    def topics(self) -> list[str]: ...
    def channels(self) -> list[dict[str, Any]]: ...
    def numeric_series(self, topic: str) -> dict[str, _F64]: ...
    def messages(self, topic: str) -> tuple[_F64, list[Any]]: ...

# ---- trajectory optimisation --------------------------------------------------------------

_Method = Literal["hermite_simpson", "trapezoidal"]
_SolveStatus = Literal[
    "solved", "max_iterations", "infeasible", "line_search_failed", "numerical_error"
]

@final
class BrakingLimits:
    """Path limits of a braking problem; None leaves a quantity free."""

    def __new__(
        cls,
        *,
        tilt_rad: Optional[float] = None,
        tilt_rate_rad_per_s: Optional[float] = None,
        ball_speed_m_per_s: Optional[float] = None,
        torque_nm: Optional[float] = None,
        actuator: Optional[ActuatorParams] = None,
        drivetrain: Optional[DrivetrainParams] = None,
        heading_rad: float = 0.0,
        traction: bool = False,
    ) -> BrakingLimits: ...
    @staticmethod
    def miapure_actuators(heading_rad: float) -> BrakingLimits: ...
    @staticmethod
    def piptb_actuator() -> BrakingLimits: ...
    @property
    def tilt_rad(self) -> Optional[float]: ...
    @property
    def tilt_rate_rad_per_s(self) -> Optional[float]: ...
    @property
    def ball_speed_m_per_s(self) -> Optional[float]: ...
    @property
    def torque_nm(self) -> Optional[float]: ...
    @property
    def traction(self) -> bool: ...

@final
class BrakingProblem:
    """Minimum-effort braking of one WIP plane by direct collocation."""

    def __new__(
        cls,
        *,
        plane: Optional[WipParams] = None,
        initial_speed_m_per_s: float = 1.4,
        duration_secs: float = 2.0,
        intervals: int = 100,
        method: _Method = "hermite_simpson",
        zero_end_torques: bool = False,
        limits: Optional[BrakingLimits] = None,
    ) -> BrakingProblem: ...
    @staticmethod
    def miapure() -> BrakingProblem: ...
    @staticmethod
    def piptb() -> BrakingProblem: ...
    def with_duration(self, duration_secs: float) -> BrakingProblem: ...
    @property
    def plane(self) -> WipParams: ...
    @property
    def initial_speed_m_per_s(self) -> float: ...
    @property
    def duration_secs(self) -> float: ...
    @property
    def intervals(self) -> int: ...
    @property
    def method(self) -> _Method: ...
    @property
    def zero_end_torques(self) -> bool: ...
    @property
    def limits(self) -> BrakingLimits: ...
    def solve(
        self,
        *,
        max_iterations: int = 50,
        primal_tolerance: float = 1e-8,
        dual_tolerance: float = 1e-6,
        initial_guess: Optional[BrakingSolution] = None,
    ) -> BrakingSolution: ...

@final
class BrakingSolution:
    """The result of a braking solve; only status "solved" certifies the trajectory."""

    @property
    def status(self) -> _SolveStatus: ...
    def is_solved(self) -> bool: ...
    @property
    def problem(self) -> BrakingProblem: ...
    @property
    def cost_n2m2s(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def primal_residual(self) -> float: ...
    @property
    def dual_residual(self) -> float: ...
    @property
    def solve_time_secs(self) -> float: ...
    @property
    def peak_tilt_rad(self) -> float: ...
    @property
    def knot_times_secs(self) -> _F64: ...
    @property
    def knot_states(self) -> _F64: ...
    @property
    def knot_torques_nm(self) -> _F64: ...
    @property
    def mid_torques_nm(self) -> _F64: ...
    @property
    def normal_force_n(self) -> _F64: ...
    @property
    def traction_n(self) -> _F64: ...
    def state_at(self, t_secs: _Floats) -> _F64: ...
    def torque_at(self, t_secs: _Floats) -> _F64: ...
    def sample(self, dt_secs: float) -> dict[str, _F64]: ...

class _MinTime(TypedDict):
    min_duration_secs: Optional[float]
    infeasible_below_secs: Optional[float]
    solution: BrakingSolution
    solves: int

def min_braking_time(
    problem: BrakingProblem,
    *,
    lower_secs: float = 0.1,
    upper_secs: float = 10.0,
    resolution_secs: float = 0.01,
    max_iterations: int = 50,
    primal_tolerance: float = 1e-8,
    dual_tolerance: float = 1e-6,
) -> _MinTime: ...

# ---- planar simulator ---------------------------------------------------------------------

@final
class Scenario:
    """A planar simulation scenario (robot, friction, sensors, rates, controller, command)."""

    @staticmethod
    def from_toml(text: str) -> Scenario: ...
    @staticmethod
    def load(path: _Path) -> Scenario: ...
    @property
    def seed(self) -> int: ...
    @property
    def duration_secs(self) -> float: ...
    @property
    def controller(self) -> Literal["lqr", "pi_pd", "lqr_pi"]: ...
    def run(self, log_path: Optional[_Path] = None) -> dict[str, Any]: ...

def piptb_experiment(
    *,
    quick: bool = False,
    trials: Optional[int] = None,
    base_seed: Optional[int] = None,
    controllers: Optional[list[str]] = None,
    log_dir: Optional[_Path] = None,
) -> dict[str, Any]: ...

# ---- 3D world -----------------------------------------------------------------------------

_Vec3 = Union[npt.ArrayLike, tuple[float, float, float], list[float]]

@final
class ContactParams:
    """The compliant omniwheel-ball contact of the 3D world: normal and tangential (stick)
    spring-dampers, kinetic over static friction while slipping; defaults are estimates."""

    def __new__(
        cls,
        *,
        normal_stiffness_n_per_m: float = ...,
        normal_damping_n_s_per_m: float = ...,
        traction_stiffness_n_per_m: float = ...,
        traction_damping_n_s_per_m: float = ...,
        kinetic_friction_ratio: float = ...,
    ) -> ContactParams: ...
    @staticmethod
    def preset(name: str) -> ContactParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> ContactParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> ContactParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> ContactParams: ...
    @property
    def normal_stiffness_n_per_m(self) -> float: ...
    @property
    def normal_damping_n_s_per_m(self) -> float: ...
    @property
    def traction_stiffness_n_per_m(self) -> float: ...
    @property
    def traction_damping_n_s_per_m(self) -> float: ...
    @property
    def kinetic_friction_ratio(self) -> float: ...

@final
class SensorParams:
    """Sensor noise and resolution of the 3D world: seeded Gaussian IMU noise, quantised
    encoders."""

    def __new__(
        cls,
        *,
        seed: int = ...,
        tilt_noise_rad: float = ...,
        gyro_noise_rad_per_s: float = ...,
        encoder_counts_per_rev: int = ...,
    ) -> SensorParams: ...
    @staticmethod
    def preset(name: str) -> SensorParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> SensorParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> SensorParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> SensorParams: ...
    @property
    def seed(self) -> int: ...
    @property
    def tilt_noise_rad(self) -> float: ...
    @property
    def gyro_noise_rad_per_s(self) -> float: ...
    @property
    def encoder_counts_per_rev(self) -> int: ...

@final
class FailureParams:
    """When a 3D world run counts as failed: tilt, sustained slip, lift-off."""

    def __new__(
        cls,
        *,
        max_tilt_rad: float = ...,
        slip_speed_threshold_m_per_s: float = ...,
        max_slip_duration_s: float = ...,
        lift_off_force_n: float = ...,
        max_lift_off_duration_s: float = ...,
    ) -> FailureParams: ...
    @staticmethod
    def preset(name: str) -> FailureParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    def replace(self, **kwargs: Any) -> FailureParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> FailureParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> FailureParams: ...
    @property
    def max_tilt_rad(self) -> float: ...
    @property
    def slip_speed_threshold_m_per_s(self) -> float: ...
    @property
    def max_slip_duration_s(self) -> float: ...
    @property
    def lift_off_force_n(self) -> float: ...
    @property
    def max_lift_off_duration_s(self) -> float: ...

@final
class WorldParams:
    """Everything the 3D world needs: the robot plus contact, wheel and rotor inertia, floor
    friction, chassis, physics step, sensors, failure limits; defaults are MiaPURE with 60 kg."""

    def __new__(
        cls,
        *,
        robot: Union[BallbotParams, dict[str, Any]] = ...,
        contact: Union[ContactParams, dict[str, Any]] = ...,
        wheel_inertia_kg_m2: float = ...,
        rotor_inertia_kg_m2: float = ...,
        wheel_damping_nm_s_per_rad: float = ...,
        rolling_resistance: float = ...,
        spin_friction_m: float = ...,
        chassis_half_width_m: float = ...,
        chassis_height_m: float = ...,
        dt_secs: float = ...,
        sensors: Union[SensorParams, dict[str, Any]] = ...,
        failure: Union[FailureParams, dict[str, Any]] = ...,
    ) -> WorldParams: ...
    @staticmethod
    def preset(name: str) -> WorldParams: ...
    @staticmethod
    def presets() -> list[str]: ...
    @staticmethod
    def with_robot(robot: BallbotParams) -> WorldParams: ...
    def replace(self, **kwargs: Any) -> WorldParams: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(fields: dict[str, Any]) -> WorldParams: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> WorldParams: ...
    def reflected_wheel_inertia_kg_m2(self) -> float: ...
    @property
    def robot(self) -> BallbotParams: ...
    @property
    def contact(self) -> ContactParams: ...
    @property
    def wheel_inertia_kg_m2(self) -> float: ...
    @property
    def rotor_inertia_kg_m2(self) -> float: ...
    @property
    def wheel_damping_nm_s_per_rad(self) -> float: ...
    @property
    def rolling_resistance(self) -> float: ...
    @property
    def spin_friction_m(self) -> float: ...
    @property
    def chassis_half_width_m(self) -> float: ...
    @property
    def chassis_height_m(self) -> float: ...
    @property
    def dt_secs(self) -> float: ...
    @property
    def sensors(self) -> SensorParams: ...
    @property
    def failure(self) -> FailureParams: ...

@final
class WheelTelemetry:
    """One omniwheel in one step."""

    @property
    def normal_force_n(self) -> float: ...
    @property
    def traction_n(self) -> float: ...
    @property
    def traction_demand_n(self) -> float: ...
    @property
    def cone_utilisation(self) -> float: ...
    @property
    def slip_speed_m_per_s(self) -> float: ...
    @property
    def slipping(self) -> bool: ...
    @property
    def motor_torque_nm(self) -> float: ...
    @property
    def speed_rad_per_s(self) -> float: ...
    @property
    def angle_rad(self) -> float: ...

@final
class StepTelemetry:
    """Everything the world reports after one step (world frame, z up; quaternions
    ``(x, y, z, w)``)."""

    @property
    def time_s(self) -> float: ...
    @property
    def wheels(self) -> list[WheelTelemetry]: ...
    @property
    def ball_position_m(self) -> _F64: ...
    @property
    def ball_orientation(self) -> _F64: ...
    @property
    def ball_velocity_m_per_s(self) -> _F64: ...
    @property
    def ball_angular_velocity_rad_per_s(self) -> _F64: ...
    @property
    def body_position_m(self) -> _F64: ...
    @property
    def body_orientation(self) -> _F64: ...
    @property
    def body_rate_rad_per_s(self) -> _F64: ...
    @property
    def tilt_rad(self) -> _F64: ...
    @property
    def tilt_from_vertical_rad(self) -> float: ...
    @property
    def floor_force_n(self) -> float: ...

@final
class Measurement:
    """One sample of every sensor: IMU (ZYX Euler tilt, yaw, gyro) and encoders."""

    @property
    def time_s(self) -> float: ...
    @property
    def tilt_rad(self) -> _F64: ...
    @property
    def yaw_rad(self) -> float: ...
    @property
    def body_rate_rad_per_s(self) -> _F64: ...
    @property
    def wheel_angle_rad(self) -> _F64: ...
    @property
    def wheel_speed_rad_per_s(self) -> _F64: ...

_FailureKind = Literal["tilt", "body_touched_floor", "sustained_slip", "lift_off"]

@final
class Failure:
    """A detected failure: what (``kind``), when, which wheel (slip, lift-off) or how far it
    tilted."""

    @property
    def kind(self) -> _FailureKind: ...
    @property
    def time_s(self) -> float: ...
    @property
    def wheel(self) -> Optional[int]: ...
    @property
    def tilt_rad(self) -> Optional[float]: ...

class _WorldTrace(TypedDict):
    time_s: _F64
    normal_force_n: _F64
    traction_n: _F64
    traction_demand_n: _F64
    cone_utilisation: _F64
    slip_speed_m_per_s: _F64
    slipping: npt.NDArray[np.bool_]
    motor_torque_nm: _F64
    wheel_speed_rad_per_s: _F64
    wheel_angle_rad: _F64
    ball_position_m: _F64
    ball_velocity_m_per_s: _F64
    ball_angular_velocity_rad_per_s: _F64
    body_position_m: _F64
    body_orientation: _F64
    body_rate_rad_per_s: _F64
    tilt_rad: _F64
    tilt_from_vertical_rad: _F64
    yaw_rad: _F64
    floor_force_n: _F64
    steps: int
    failure: Optional[Failure]
    log_path: Optional[Path]

class _WorldRun(_WorldTrace):
    torque_nm: _F64

class _WorldLoopRun(_WorldTrace):
    command: _F64

@final
class World:
    """The simulated 3D ballbot driven directly by wheel torques (rapier3d; friction-cone
    omniwheel contacts)."""

    def __new__(cls, params: Optional[WorldParams] = None) -> World: ...
    def step(self, torque_nm: _Vec3) -> StepTelemetry: ...
    def run(
        self,
        n_steps: int,
        torque_nm: Optional[npt.ArrayLike] = None,
        *,
        record_every: int = 1,
        stop_on_failure: bool = False,
        log_path: Optional[_Path] = None,
        log_compact: bool = False,
    ) -> _WorldRun: ...
    @property
    def params(self) -> WorldParams: ...
    @property
    def time_s(self) -> float: ...
    @property
    def telemetry(self) -> StepTelemetry: ...
    @property
    def failure(self) -> Optional[Failure]: ...
    def measure(self) -> Measurement: ...
    def encoder_speeds_rad_per_s(self) -> _F64: ...
    def push_body(self, impulse_ns: _Vec3) -> None: ...
    def set_body_velocity(
        self, linear_m_per_s: _Vec3, angular_rad_per_s: Optional[_Vec3] = None
    ) -> None: ...
    def set_ball_velocity(
        self, linear_m_per_s: _Vec3, angular_rad_per_s: Optional[_Vec3] = None
    ) -> None: ...
    def tilt_body(self, tilt_rad: tuple[float, float]) -> None: ...
    def translate_robot(self, offset_m: _Vec3) -> None: ...
    def set_gravity_m_per_s2(self, gravity_m_per_s2: float) -> None: ...
    def set_floor_friction(self, friction: float) -> None: ...
    def set_wheel_friction(self, friction: float) -> None: ...
    def set_ball_fixed(self, fixed: bool) -> None: ...
    def set_body_fixed(self, fixed: bool) -> None: ...
    def kinetic_energy_j(self) -> float: ...
    def potential_energy_j(self) -> float: ...
    def contact_energy_j(self) -> float: ...
    def linear_momentum_ns(self) -> _F64: ...
    def angular_momentum_nms(self) -> _F64: ...
    def chassis_clearance_m(self) -> float: ...

_Mode = Literal["idle", "balancing", "controlled_stop", "fault"]

@final
class WorldLoop:
    """The 3D world with the core's cascaded LQR-PI controller in the loop (400 Hz outer,
    8 kHz motor PIs)."""

    def __new__(
        cls,
        params: Optional[WorldParams] = None,
        *,
        max_speed_m_per_s: Optional[float] = None,
        max_accel_m_per_s2: Optional[float] = None,
        max_jerk_m_per_s3: Optional[float] = None,
        max_tilt_command_rad: Optional[float] = None,
        max_tilt_rate_command_rad_per_s: Optional[float] = None,
    ) -> WorldLoop: ...
    @property
    def mode(self) -> _Mode: ...
    def step(
        self,
        vx_m_per_s: float = 0.0,
        vy_m_per_s: float = 0.0,
        yaw_rate_rad_per_s: float = 0.0,
    ) -> StepTelemetry: ...
    def run(
        self,
        n_steps: int,
        command: Optional[npt.ArrayLike] = None,
        *,
        record_every: int = 1,
        stop_on_failure: bool = False,
        log_path: Optional[_Path] = None,
        log_compact: bool = False,
    ) -> _WorldLoopRun: ...
    @property
    def params(self) -> WorldParams: ...
    @property
    def time_s(self) -> float: ...
    @property
    def telemetry(self) -> StepTelemetry: ...
    @property
    def failure(self) -> Optional[Failure]: ...
    def measure(self) -> Measurement: ...
    def encoder_speeds_rad_per_s(self) -> _F64: ...
    def push_body(self, impulse_ns: _Vec3) -> None: ...
    def set_body_velocity(
        self, linear_m_per_s: _Vec3, angular_rad_per_s: Optional[_Vec3] = None
    ) -> None: ...
    def set_ball_velocity(
        self, linear_m_per_s: _Vec3, angular_rad_per_s: Optional[_Vec3] = None
    ) -> None: ...
    def tilt_body(self, tilt_rad: tuple[float, float]) -> None: ...
    def translate_robot(self, offset_m: _Vec3) -> None: ...
    def set_gravity_m_per_s2(self, gravity_m_per_s2: float) -> None: ...
    def set_floor_friction(self, friction: float) -> None: ...
    def set_wheel_friction(self, friction: float) -> None: ...
    def set_ball_fixed(self, fixed: bool) -> None: ...
    def set_body_fixed(self, fixed: bool) -> None: ...
    def kinetic_energy_j(self) -> float: ...
    def potential_energy_j(self) -> float: ...
    def contact_energy_j(self) -> float: ...
    def linear_momentum_ns(self) -> _F64: ...
    def angular_momentum_nms(self) -> _F64: ...
    def chassis_clearance_m(self) -> float: ...

class _Ramp(TypedDict):
    heading_deg: float
    max_speed_m_per_s: float
    failure: Optional[Failure]
    supervisor_stop_s: Optional[float]
    time_s: _F64
    command_m_per_s: _F64
    shaped_command_m_per_s: _F64
    speed_m_per_s: _F64
    tilt_rad: _F64
    max_cone_utilisation: _F64
    normal_force_n: _F64
    cone_utilisation: _F64

def max_speed_ramp(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    accel_m_per_s2: float = 0.25,
    max_command_m_per_s: float = 3.5,
    settle_s: float = 0.5,
    sample_every_s: float = 0.01,
    max_speed_m_per_s: Optional[float] = None,
    max_accel_m_per_s2: Optional[float] = None,
    max_jerk_m_per_s3: Optional[float] = None,
    max_tilt_command_rad: Optional[float] = None,
    max_tilt_rate_command_rad_per_s: Optional[float] = None,
) -> _Ramp: ...

class _TrialOutcome(TypedDict):
    heading_deg: float
    seed: int
    accel_m_per_s2: float
    max_speed_m_per_s: float
    censored: bool
    failure: Optional[Failure]
    peak_cone_utilisation: float
    min_normal_force_n: float
    peak_tilt_rad: float
    supervisor_stop_s: Optional[float]

class _Trial(_Ramp):
    outcome: _TrialOutcome

def slow_ramp_trial(
    params: Optional[WorldParams] = None, *, heading_deg: float = 0.0, seed: int = 1
) -> _Trial: ...

class _FailingAccel(TypedDict):
    heading_deg: float
    largest_surviving_m_per_s2: Optional[float]
    smallest_failing_m_per_s2: Optional[float]
    censored: bool
    text: str
    runs: int
    failing: Optional[_TrialOutcome]
    surviving: Optional[_TrialOutcome]
    failing_run: Optional[_Ramp]

def failing_acceleration(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    seed: int = 0,
    fast_top_m_per_s: Optional[float] = None,
    accel_bracket_m_per_s2: Optional[tuple[float, float]] = None,
    accel_resolution_m_per_s2: Optional[float] = None,
) -> _FailingAccel: ...
def max_speed_study(
    params: Optional[WorldParams] = None,
    *,
    quick: bool = False,
    trial_headings_deg: Optional[list[float]] = None,
    seeds: Optional[list[int]] = None,
    map_headings_deg: Optional[list[float]] = None,
    sensitivity_headings_deg: Optional[list[float]] = None,
    sensitivity_mu: Optional[list[float]] = None,
    sensitivity_com_height_m: Optional[list[float]] = None,
    threads: int = 0,
    fast_top_m_per_s: Optional[float] = None,
    accel_bracket_m_per_s2: Optional[tuple[float, float]] = None,
    accel_resolution_m_per_s2: Optional[float] = None,
) -> dict[str, Any]: ...

_BrakingOutcome = Literal["stopped", "no_trajectory", "failed", "not_at_rest"]

class _BrakingRun(TypedDict):
    heading_deg: float
    duration_s: float
    outcome: _BrakingOutcome
    success: bool
    failure: Optional[Failure]
    rest_speed_m_per_s: Optional[float]
    solve_status: Optional[str]
    brake_start_s: float
    plan_peak_tilt_rad: Optional[float]
    plan_cost_n2m2s: Optional[float]
    peaks: dict[str, Any]
    time_s: _F64
    command_m_per_s: _F64
    speed_m_per_s: _F64
    command_tilt_rad: _F64
    tilt_rad: _F64
    cone_utilisation: _F64
    normal_force_n: _F64
    actuator_utilisation: _F64
    telemetry_hash: int

def braking_run(
    params: Optional[WorldParams] = None,
    *,
    duration_s: float,
    heading_deg: float = 0.0,
    cruise_speed_m_per_s: Optional[float] = None,
    approach_accel_m_per_s2: Optional[float] = None,
    settle_s: Optional[float] = None,
    cruise_s: Optional[float] = None,
    trajectory_tilt_limit_rad: Optional[float] = None,
    intervals: Optional[int] = None,
    sample_every_s: Optional[float] = None,
    feedforward: Literal["full", "core"] = "full",
) -> _BrakingRun: ...

class _BrakingStudy(TypedDict):
    heading_deg: float
    shortest_success_s: Optional[float]
    first_failure_s: Optional[float]
    limit_s: Optional[float]
    limit_failure_s: Optional[float]
    descent: list[_BrakingRun]
    bisection: list[_BrakingRun]

def braking_study(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    durations_s: Optional[list[float]] = None,
    bisection_resolution_s: Optional[float] = ...,  # 0.05; None skips the bisection
    cruise_speed_m_per_s: Optional[float] = None,
    approach_accel_m_per_s2: Optional[float] = None,
    settle_s: Optional[float] = None,
    cruise_s: Optional[float] = None,
    trajectory_tilt_limit_rad: Optional[float] = None,
    intervals: Optional[int] = None,
    sample_every_s: Optional[float] = None,
    feedforward: Literal["full", "core"] = "full",
) -> _BrakingStudy: ...

class _PushTrial(TypedDict):
    heading_deg: float
    impulse_ns: float
    outcome: Literal["recovered", "tilt_exceeded", "failed", "not_at_rest"]
    recovered: bool
    failure: Optional[Failure]
    peak_tilt_rad: float
    peak_speed_m_per_s: float
    rest_speed_m_per_s: float
    time_s: _F64
    tilt_rad: _F64
    speed_m_per_s: _F64
    max_cone_utilisation: _F64
    ball_velocity_m_per_s: _F64
    telemetry_hash: int

def push_trial(
    params: Optional[WorldParams] = None,
    *,
    impulse_ns: float,
    heading_deg: float = 0.0,
    push_duration_s: Optional[float] = None,
    settle_s: Optional[float] = None,
    observe_s: Optional[float] = None,
    rest_within_s: Optional[float] = None,
    sample_every_s: Optional[float] = None,
) -> _PushTrial: ...

class _PushRecovery(TypedDict):
    heading_deg: float
    largest_recovered_ns: float
    smallest_failing_ns: Optional[float]
    trials: list[_PushTrial]

def push_recovery_limit(
    params: Optional[WorldParams] = None,
    *,
    heading_deg: float = 0.0,
    upper_ns: float = 100.0,
    resolution_ns: float = 0.5,
    push_duration_s: Optional[float] = None,
    settle_s: Optional[float] = None,
    observe_s: Optional[float] = None,
    rest_within_s: Optional[float] = None,
    sample_every_s: Optional[float] = None,
) -> _PushRecovery: ...
