//! The edge between the simulator and a planar controller: what the controller measures, what
//! it is commanded, and what it sends to the motor drive.
//!
//! A controller has two parts, driven at their own rates exactly as on the robot:
//! the main controller ([`PlanarController::outer_step`], e.g. 400 Hz on the sbRIO) and the
//! motor drive's loop ([`PlanarController::drive_step`], e.g. 8 kHz). A torque-mode controller
//! (LQR, PI-PD) leaves the drive step at its default, which passes the torque through; the
//! cascaded LQR-PI runs its inner speed PI there.

/// The command state `s_c` without the ball angle (the paper commands no position).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PlanarCommand {
    /// Commanded tilt `theta_c` (rad).
    pub tilt_rad: f64,
    /// Commanded tilt rate `theta_dot_c` (rad/s).
    pub tilt_rate_rad_per_s: f64,
    /// Commanded ball (wheel) rate `phi_dot_c` (rad/s).
    pub ball_rate_rad_per_s: f64,
}

/// What the main controller reads at its own rate: IMU and motor encoder, converted into the
/// WIP's state.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct OuterMeasurement {
    /// Time of the sample (s).
    pub time_secs: f64,
    /// Measured tilt `theta` (rad), from the IMU.
    pub tilt_rad: f64,
    /// Measured tilt rate `theta_dot` (rad/s), from the gyro.
    pub tilt_rate_rad_per_s: f64,
    /// Measured ball angle `phi = (phi - theta)_encoder + theta_imu` (rad).
    pub ball_angle_rad: f64,
    /// Measured ball rate `phi_dot = (phi_dot - theta_dot)_encoder + theta_dot_imu` (rad/s).
    pub ball_rate_rad_per_s: f64,
    /// Measured joint (motor) rate `phi_dot - theta_dot` at the wheel (rad/s), from the encoder.
    pub joint_rate_rad_per_s: f64,
    /// Torque the actuator delivered in the last plant step (N m), as the drive reports it.
    pub applied_torque_nm: f64,
}

/// What the main controller sends to the motor drive each outer period.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct DriveSetpoint {
    /// Torque to apply (N m): the whole command in torque mode, the feedforward `tau_r` when a
    /// speed reference is given.
    pub torque_nm: f64,
    /// Joint-rate reference for the drive's speed loop (rad/s at the wheel), if any.
    pub joint_rate_rad_per_s: Option<f64>,
}

/// What the motor drive reads at its own rate: its encoder only.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct DriveMeasurement {
    /// Time of the sample (s).
    pub time_secs: f64,
    /// Encoder joint angle `phi - theta` (rad at the wheel), quantised.
    pub joint_angle_rad: f64,
    /// Estimated joint rate (rad/s at the wheel).
    pub joint_rate_rad_per_s: f64,
    /// Torque the actuator delivered in the last plant step (N m).
    pub applied_torque_nm: f64,
}

/// A planar controller the simulator can drive. Implementations must be deterministic.
pub trait PlanarController {
    /// A short name for logs (`"lqr"`, `"pi_pd"`, `"lqr_pi"`, ...).
    fn name(&self) -> &str;

    /// One period of the main controller.
    fn outer_step(
        &mut self,
        measured: &OuterMeasurement,
        command: &PlanarCommand,
        dt_secs: f64,
    ) -> DriveSetpoint;

    /// One period of the motor drive: the torque to request from the actuator (N m). The
    /// default is torque mode: pass the setpoint's torque through.
    fn drive_step(
        &mut self,
        measured: &DriveMeasurement,
        setpoint: &DriveSetpoint,
        dt_secs: f64,
    ) -> f64 {
        let _ = (measured, dt_secs);
        setpoint.torque_nm
    }

    /// Appends the per-term contributions of the latest steps (name, value) for logging, e.g.
    /// `("tau_r_nm", ..)`, `("tau_e_nm", ..)`. The names must be the same at every call.
    fn terms(&self, out: &mut Vec<(&'static str, f64)>) {
        let _ = out;
    }

    /// Clears every internal state (integrators, filters, references).
    fn reset(&mut self);
}

impl<C: PlanarController + ?Sized> PlanarController for Box<C> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn outer_step(
        &mut self,
        measured: &OuterMeasurement,
        command: &PlanarCommand,
        dt_secs: f64,
    ) -> DriveSetpoint {
        (**self).outer_step(measured, command, dt_secs)
    }
    fn drive_step(
        &mut self,
        measured: &DriveMeasurement,
        setpoint: &DriveSetpoint,
        dt_secs: f64,
    ) -> f64 {
        (**self).drive_step(measured, setpoint, dt_secs)
    }
    fn terms(&self, out: &mut Vec<(&'static str, f64)>) {
        (**self).terms(out)
    }
    fn reset(&mut self) {
        (**self).reset()
    }
}

/// A command as a function of time.
pub trait CommandProfile {
    /// The command at `time_secs`.
    fn command(&self, time_secs: f64) -> PlanarCommand;
}

impl<F: Fn(f64) -> PlanarCommand> CommandProfile for F {
    fn command(&self, time_secs: f64) -> PlanarCommand {
        self(time_secs)
    }
}
