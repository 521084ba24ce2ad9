//! The braking problem, its limits and solver options, validated once.

use super::drive::{Drive, DriveMap};
use super::error::{TrajoptError, invalid};
use super::interp::Trajectory;
use super::method::Method;
use ballbot_core::{ActuatorParams, DrivetrainParams, Wip, WipParams};

/// Path limits, each applied at every knot (torque bounds also at Hermite-Simpson midpoints).
/// `None` leaves a quantity free.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    /// `|theta| <=` this (rad).
    pub tilt_rad: Option<f64>,
    /// `|theta_dot| <=` this (rad/s).
    pub tilt_rate_rad_per_s: Option<f64>,
    /// `|r phi_dot| <=` this (m/s).
    pub ball_speed_m_per_s: Option<f64>,
    /// `|tau| <=` this (N m), the planar torque.
    pub torque_nm: Option<f64>,
    /// Motor-side limits: each actuator's peak torque, its torque-speed line (the torque
    /// that drives in the direction of motion falls linearly to 0 at the no-load speed), and
    /// the no-load speed itself, with torques and speeds mapped to every wheel.
    pub drive: Option<Drive>,
    /// Friction-aware limit: every omniwheel's traction `|F_i| <= mu N_i` (MODEL.md section
    /// 5), `mu` = the drivetrain's `wheel_ball_friction`. Needs [`Drive::Omniwheels`].
    pub traction: bool,
    /// Normal-force margin `N_min` of the traction limit (N): with it the cone becomes
    /// `|F_i| <= mu (N_i - N_min)`, which also keeps `N_i >= N_min`. It is the robust form of
    /// the cone when the plan's normal force may be `N_min` too high (a model that unloads a
    /// wheel less than the real robot does): the traction the plan uses stays inside the
    /// cone of any normal force within `N_min` below the planned one. Default 0 (the plain
    /// cone, the problem without a margin, bit-identical). Needs `traction`.
    pub normal_force_margin_n: f64,
}

impl Limits {
    /// No limits: the paper's problem ("input torque constraints were not included").
    pub fn none() -> Self {
        Self::default()
    }

    /// MiaPURE's actuators (43.2 N m peak, 62 rad/s no-load at each omniwheel) for travel at
    /// `heading_rad`; in the sagittal plane (0 or 180 deg) the planar torque capacity is
    /// 96.9 N m. No traction limit.
    pub fn miapure_actuators(heading_rad: f64) -> Self {
        Self {
            drive: Some(Drive::Omniwheels {
                params: DrivetrainParams::miapure(),
                heading_rad,
            }),
            ..Self::default()
        }
    }

    /// The PIPTB's actuator driving its wheel directly (assumed the MiaPURE actuator).
    pub fn piptb_actuator() -> Self {
        Self {
            drive: Some(Drive::Direct(ActuatorParams::miapure())),
            ..Self::default()
        }
    }

    fn validate(&self) -> Result<(), TrajoptError> {
        let positive = |v: Option<f64>, field| match v {
            Some(x) if !(x.is_finite() && x > 0.0) => Err(invalid(field, "must be finite and > 0")),
            _ => Ok(()),
        };
        positive(self.tilt_rad, "limits.tilt_rad")?;
        positive(self.tilt_rate_rad_per_s, "limits.tilt_rate_rad_per_s")?;
        positive(self.ball_speed_m_per_s, "limits.ball_speed_m_per_s")?;
        positive(self.torque_nm, "limits.torque_nm")?;
        match self.drive {
            Some(Drive::Direct(a)) => a.validate()?,
            Some(Drive::Omniwheels {
                params,
                heading_rad,
            }) => {
                params.validate()?;
                if !heading_rad.is_finite() {
                    return Err(invalid("limits.drive.heading_rad", "must be finite"));
                }
            }
            None => {}
        }
        if self.traction && !matches!(self.drive, Some(Drive::Omniwheels { .. })) {
            return Err(invalid(
                "limits.traction",
                "needs limits.drive = Drive::Omniwheels (the contact geometry)",
            ));
        }
        if !(self.normal_force_margin_n.is_finite() && self.normal_force_margin_n >= 0.0) {
            return Err(invalid(
                "limits.normal_force_margin_n",
                "must be finite and >= 0",
            ));
        }
        if self.normal_force_margin_n > 0.0 && !self.traction {
            return Err(invalid(
                "limits.normal_force_margin_n",
                "a margin > 0 needs limits.traction = true",
            ));
        }
        Ok(())
    }
}

/// Minimum-effort braking of one WIP plane: `min integral tau^2 dt` from cruise at
/// `initial_speed_m_per_s` upright (`theta = phi = theta_dot = 0`, `phi_dot = v0 / r`) to rest
/// upright (`theta = theta_dot = phi_dot = 0`, `phi` free) in exactly `duration_secs`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BrakingProblem {
    /// The plant.
    pub plane: WipParams<f64>,
    /// Cruise speed `v0` at the start (m/s); the ball rate is `v0 / r`.
    pub initial_speed_m_per_s: f64,
    /// Braking time `T` (s).
    pub duration_secs: f64,
    /// Number of collocation intervals `N` (knots `N + 1`).
    pub intervals: usize,
    /// The collocation scheme.
    pub method: Method,
    /// Pin `tau = 0` at both ends (the paper's `G` may include the input).
    pub zero_end_torques: bool,
    /// Path limits.
    pub limits: Limits,
}

impl BrakingProblem {
    /// The paper's MiaPURE problem (60 kg payload): 1.4 m/s to rest in 2 s, Hermite-Simpson
    /// with 100 intervals, free end torques, no limits.
    pub fn miapure() -> Self {
        Self {
            plane: WipParams::miapure_60kg(),
            initial_speed_m_per_s: 1.4,
            duration_secs: 2.0,
            intervals: 100,
            method: Method::HermiteSimpson,
            zero_end_torques: false,
            limits: Limits::none(),
        }
    }

    /// The PIPTB braking phase (MODEL.md section 7): 1 m/s to rest in 1.4 s.
    pub fn piptb() -> Self {
        Self {
            plane: WipParams::piptb(),
            initial_speed_m_per_s: 1.0,
            duration_secs: 1.4,
            ..Self::miapure()
        }
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), TrajoptError> {
        Wip::new(self.plane)?;
        if !self.initial_speed_m_per_s.is_finite() {
            return Err(invalid("initial_speed_m_per_s", "must be finite"));
        }
        if !(self.duration_secs.is_finite() && self.duration_secs > 0.0) {
            return Err(invalid("duration_secs", "must be finite and > 0"));
        }
        if !(2..=100_000).contains(&self.intervals) {
            return Err(invalid("intervals", "must be in 2..=100000"));
        }
        self.limits.validate()
    }

    pub(crate) fn drive_map(&self) -> Result<Option<DriveMap>, TrajoptError> {
        self.limits
            .drive
            .map(|d| DriveMap::new(&d, self.plane.ball_radius_m))
            .transpose()
    }
}

/// Where the solver starts.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum InitialGuess {
    /// The linear-quadratic optimum of the model linearised about upright (closed form, see
    /// [`super::LqBraking`]); a straight line if the modal decomposition fails.
    #[default]
    LinearQuadratic,
    /// A previous solution (any grid or duration: it is resampled, time-scaled to this
    /// problem's duration).
    Trajectory(Trajectory),
}

/// Solver settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveOptions {
    /// Maximum SQP iterations (QPs solved).
    pub max_iterations: usize,
    /// Converged when the largest constraint violation (defects in rad and rad/s, limits in
    /// their units) is at most this.
    pub primal_tolerance: f64,
    /// Converged when the stationarity residual `||grad J + J_c^T y||_inf` is at most this
    /// times `||grad J||_inf`.
    pub dual_tolerance: f64,
    /// Starting point.
    pub initial_guess: InitialGuess,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            max_iterations: 50,
            primal_tolerance: 1e-8,
            dual_tolerance: 1e-6,
            initial_guess: InitialGuess::LinearQuadratic,
        }
    }
}

impl SolveOptions {
    pub(crate) fn validate(&self) -> Result<(), TrajoptError> {
        if self.max_iterations == 0 {
            return Err(invalid("max_iterations", "must be >= 1"));
        }
        if !(self.primal_tolerance.is_finite() && self.primal_tolerance > 0.0) {
            return Err(invalid("primal_tolerance", "must be finite and > 0"));
        }
        if !(self.dual_tolerance.is_finite() && self.dual_tolerance > 0.0) {
            return Err(invalid("dual_tolerance", "must be finite and > 0"));
        }
        Ok(())
    }
}
