//! The motor driver between the controller's torque command and the wheel: which torque an
//! ODrive v3.6 can actually put on a wheel at a given wheel speed, and when it disarms.
//!
//! Two models ([`DriverModel`]):
//!
//! * `Ideal`: the actuator's straight torque-speed line
//!   ([`ActuatorParams::clamp_torque_nm`]): the paper's 43.2 N m at rest, 0 at 62 rad/s,
//!   full peak for braking. The ideal world's driver ([`crate::world::WorldParams::ideal`]);
//!   bit-identical to the world before this model.
//! * `Odrive`: field-oriented control of a surface PM motor as the ODrive firmware 0.5.x does
//!   it, in steady state (the current loop's 1000 rad/s bandwidth, firmware default
//!   `current_control_bandwidth`, is taken as instantaneous against the 400 Hz outer loop;
//!   inductance and `I_d` are neglected). Per step and wheel, at rotor speed
//!   `w_m = N w` (gear ratio `N`, wheel speed `w`):
//!   1. overspeed trip: `|w_m| / 2 pi > vel_limit_tolerance * vel_limit` disarms the axis
//!      (firmware `Controller::update`, `ERROR_OVERSPEED`); from then on zero current;
//!   2. torque-mode velocity limiter: the rotor torque is clamped to
//!      `[(-v_lim - v) g, (v_lim - v) g]` with `v = w_m / 2 pi` (turn/s) and `g = vel_gain`
//!      (firmware `limitVel`);
//!   3. current limit: `|T_m| <= K_t I_lim`, `I_lim = min(current_lim, hardware range)`
//!      (firmware `max_available_torque`, `effective_current_lim`);
//!   4. voltage (modulation) limit: the q-axis voltage `V_q = R I_q + k_e w_m` cannot exceed
//!      `V_max = m V_bus / sqrt 3`, so `I_q` stays in `[(-V_max - k_e w_m) / R,
//!      (V_max - k_e w_m) / R]` (firmware `FieldOrientedController`: the modulation vector is
//!      scaled to `0.80 * sqrt(3) / 2` of `2/3 V_bus`, i.e. `m = 0.8`). Beyond the back-EMF
//!      speed `V_max / k_e` the interval excludes 0: the motor brakes whatever is commanded.
//!      A current forced beyond `I_lim + current_lim_margin` also disarms
//!      (`ERROR_CURRENT_LIMIT_VIOLATION`).
//!
//! Constants (amplitude-invariant dq frame, as the firmware): `K_t = 8.27 / KV` (N m/A, KV in
//! rpm/V; exactly `(sqrt 3 / 2) 60 / (2 pi KV)`), back-EMF `k_e = 2/3 K_t` (V s/rad, phase
//! peak), so that the no-load speed at full modulation is `KV V_bus`; electrical power
//! `3/2 V_q I_q` = mechanical `K_t I_q w_m` + copper `3/2 R I_q^2`. Wheel torque `N K_t I_q`.
//!
//! Sources: ODrive firmware fw-v0.5.6 (github.com/odriverobotics/ODrive):
//! `Firmware/MotorControl/controller.hpp` (defaults `vel_limit = 2` turn/s,
//! `vel_limit_tolerance = 1.2`, `vel_gain = 1/6` N m/(turn/s), `enable_overspeed_error` and
//! `enable_torque_mode_vel_limit` true), `controller.cpp` (`limitVel`, the overspeed check, the
//! limiter acting only below velocity control), `motor.hpp` (`current_lim = 10` A,
//! `current_lim_margin = 8` A, `requested_current_range = 60` A), `motor.cpp` (hardware
//! current range `0.9 * 1.35 V / R_shunt / gain`), `Board/v3/Inc/board.h` (shunt 500 uOhm on
//! v3.5+), `Drivers/DRV8301/drv8301.cpp` (gains 10, 20, 40, 80 V/V, snapped down), `foc.cpp`
//! (modulation limit); `docs/getting-started.rst` (`torque_constant = 8.27 / KV`, current
//! limits above 60 A need `requested_current_range`).

use super::WorldError;
use ballbot_core::ActuatorParams;
use core::f64::consts::{PI, TAU};

/// ODrive v3.6 factory `motor.config.current_lim` (A).
pub const ODRIVE_CURRENT_LIM_A: f64 = 10.0;
/// ODrive factory `motor.config.current_lim_margin` (A): the measured current may exceed the
/// limit by this much before the axis disarms.
pub const ODRIVE_CURRENT_LIM_MARGIN_A: f64 = 8.0;
/// ODrive factory `motor.config.requested_current_range` (A).
pub const ODRIVE_REQUESTED_CURRENT_RANGE_A: f64 = 60.0;
/// ODrive factory `controller.config.vel_limit` (turn/s of the rotor).
pub const ODRIVE_VEL_LIMIT_TURN_PER_S: f64 = 2.0;
/// ODrive factory `controller.config.vel_limit_tolerance` (ratio to `vel_limit`).
pub const ODRIVE_VEL_LIMIT_TOLERANCE: f64 = 1.2;
/// ODrive factory `controller.config.vel_gain` (N m per turn/s, at the rotor).
pub const ODRIVE_VEL_GAIN_NM_S_PER_TURN: f64 = 1.0 / 6.0;
/// The ODrive 0.5.x modulation limit: 0.8 of the linear space-vector range (`foc.cpp`, not
/// configurable in that firmware).
pub const ODRIVE_MAX_MODULATION: f64 = 0.8;
/// ODrive v3.6 current-sense shunt (Ohm; v3.5 and later).
pub const ODRIVE_V36_SHUNT_OHM: f64 = 500.0e-6;
/// MiaPURE's bus voltage (V): the paper's 45 V source.
pub const MIAPURE_BUS_VOLTAGE_V: f64 = 45.0;

/// Which model turns a torque command into the wheel torque.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum DriverModel {
    /// The actuator's straight torque-speed line ([`ActuatorParams::clamp_torque_nm`]); the
    /// other [`DriverParams`] fields only scale the reported current.
    Ideal,
    /// The ODrive firmware's limits (see the [module](self) doc).
    Odrive,
}

/// One motor driver's configuration (the same for the three wheels).
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct DriverParams {
    /// The model. Default `Ideal`.
    pub model: DriverModel,
    /// DC bus voltage (V). Default 45 (paper).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub bus_voltage_v: f64,
    /// Largest modulation as a fraction of the linear space-vector range (phase peak voltage
    /// `m V_bus / sqrt 3`), in (0, 1]. ODrive 0.5.x: 0.8.
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub max_modulation: f64,
    /// Motor velocity constant KV (rpm/V, at the rotor). Default 98.68: the paper's 62 rad/s
    /// at the wheel times the ratio 7.5 at 45 V.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub motor_kv_rpm_per_v: f64,
    /// Phase resistance (Ohm). Default [`Self::straight_line_phase_resistance_ohm`] (an
    /// assumption, see there).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub phase_resistance_ohm: f64,
    /// `motor.config.current_lim` (A, q-axis).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub current_limit_a: f64,
    /// `motor.config.current_lim_margin` (A).
    #[schemars(range(min = 0))]
    pub current_limit_margin_a: f64,
    /// `motor.config.requested_current_range` (A): sets the current-sense gain and so the
    /// hardware current limit ([`Self::hardware_current_limit_a`]).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub requested_current_range_a: f64,
    /// `controller.config.vel_limit` (turn/s of the rotor).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub vel_limit_turn_per_s: f64,
    /// `controller.config.vel_limit_tolerance` (ratio to the velocity limit, >= 1).
    #[schemars(range(min = 1))]
    pub vel_limit_tolerance: f64,
    /// `controller.config.vel_gain` (N m per turn/s at the rotor): the torque-mode velocity
    /// limiter's slope.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub vel_gain_nm_s_per_turn: f64,
    /// `controller.config.enable_torque_mode_vel_limit`.
    pub enable_torque_mode_vel_limit: bool,
    /// `controller.config.enable_overspeed_error`.
    pub enable_overspeed_error: bool,
}

impl DriverParams {
    /// The ideal driver: the straight torque-speed line; the remaining fields as in
    /// [`Self::miapure`]. The ideal world's driver and the serde default.
    pub fn ideal() -> Self {
        Self {
            model: DriverModel::Ideal,
            ..Self::miapure()
        }
    }

    /// An ODrive v3.6 with its factory configuration (the `ODRIVE_*` constants) driving
    /// MiaPURE's motor at 45 V: 10 A, `vel_limit` 2 turn/s (1.68 rad/s at the wheel), the
    /// torque-mode limiter on. (It cannot balance the robot; it shows what the defaults do.)
    pub fn odrive_v36_factory() -> Self {
        let actuator = ActuatorParams::<f64>::miapure();
        let kv = miapure_kv_rpm_per_v(&actuator);
        Self {
            model: DriverModel::Odrive,
            bus_voltage_v: MIAPURE_BUS_VOLTAGE_V,
            max_modulation: ODRIVE_MAX_MODULATION,
            motor_kv_rpm_per_v: kv,
            phase_resistance_ohm: Self::straight_line_phase_resistance_ohm(
                &actuator,
                MIAPURE_BUS_VOLTAGE_V,
                kv,
            ),
            current_limit_a: ODRIVE_CURRENT_LIM_A,
            current_limit_margin_a: ODRIVE_CURRENT_LIM_MARGIN_A,
            requested_current_range_a: ODRIVE_REQUESTED_CURRENT_RANGE_A,
            vel_limit_turn_per_s: ODRIVE_VEL_LIMIT_TURN_PER_S,
            vel_limit_tolerance: ODRIVE_VEL_LIMIT_TOLERANCE,
            vel_gain_nm_s_per_turn: ODRIVE_VEL_GAIN_NM_S_PER_TURN,
            enable_torque_mode_vel_limit: true,
            enable_overspeed_error: true,
        }
    }

    /// The ODrive as MiaPURE must have been configured to deliver the paper's 43.2 N m and
    /// 62 rad/s: `current_lim` = 43.2 N m / (7.5 K_t) = 68.7 A, which needs
    /// `requested_current_range` above 60 A (90 A, the firmware docs' example: 121.5 A
    /// hardware range); `vel_limit` = the no-load speed, 62 rad/s at the wheel = 74.0 turn/s
    /// of the rotor (assumption); tolerance 1.2 (factory). The torque-mode limiter is off
    /// (assumption: the paper ran the speed PI in the driver, velocity control, where the
    /// firmware does not apply it). Modulation 0.8: not configurable in firmware 0.5.x.
    pub fn miapure() -> Self {
        let actuator = ActuatorParams::<f64>::miapure();
        let kv = miapure_kv_rpm_per_v(&actuator);
        let kt = torque_constant_nm_per_a(kv);
        Self {
            current_limit_a: actuator.peak_torque_nm / (actuator.gear_ratio * kt),
            requested_current_range_a: 90.0,
            vel_limit_turn_per_s: actuator.no_load_speed_rad_per_s * actuator.gear_ratio / TAU,
            enable_torque_mode_vel_limit: false,
            ..Self::odrive_v36_factory()
        }
    }

    /// The phase resistance (Ohm) that makes the paper's straight line the motor's own
    /// voltage-limited line at `bus_voltage_v` and full modulation: the stall current
    /// `V_bus / sqrt 3 / R` gives the actuator's peak torque. An assumption (no datasheet of
    /// the customised T-motor motor is public): the paper states its 43.2 N m and 62 rad/s
    /// "without considering the efficiency of the motor driver". With it the `Odrive` model at
    /// modulation 1, `current_limit_a` at the stall current and no limiter reproduces
    /// [`ActuatorParams::torque_bounds_nm`] below the no-load speed. MiaPURE: 0.378 Ohm.
    pub fn straight_line_phase_resistance_ohm(
        actuator: &ActuatorParams<f64>,
        bus_voltage_v: f64,
        kv_rpm_per_v: f64,
    ) -> f64 {
        let kt = torque_constant_nm_per_a(kv_rpm_per_v);
        let stall_current_a = actuator.peak_torque_nm / (actuator.gear_ratio * kt);
        bus_voltage_v / 3.0_f64.sqrt() / stall_current_a
    }

    /// Torque constant `K_t = (sqrt 3 / 2) 60 / (2 pi KV)` (N m/A at the rotor; the ODrive's
    /// `8.27 / KV`).
    pub fn torque_constant_nm_per_a(&self) -> f64 {
        torque_constant_nm_per_a(self.motor_kv_rpm_per_v)
    }

    /// Back-EMF constant `k_e = 2/3 K_t` (phase peak V per rad/s of the rotor).
    pub fn back_emf_v_s_per_rad(&self) -> f64 {
        2.0 / 3.0 * self.torque_constant_nm_per_a()
    }

    /// Largest phase peak voltage `m V_bus / sqrt 3` (V).
    pub fn max_phase_voltage_v(&self) -> f64 {
        self.max_modulation * self.bus_voltage_v / 3.0_f64.sqrt()
    }

    /// The hardware current limit of an ODrive v3.6 axis (A): `0.9 * 1.35 V / R_shunt`
    /// divided by the DRV8301 gain, the largest of 10, 20, 40, 80 V/V not above the one
    /// `requested_current_range_a` asks for (10 if none). 60 A (factory) gives 60.75 A,
    /// 90 A gives 121.5 A.
    pub fn hardware_current_limit_a(&self) -> f64 {
        let unity_gain_current_a = 0.9 * 1.35 / ODRIVE_V36_SHUNT_OHM;
        let requested_gain = unity_gain_current_a / self.requested_current_range_a;
        let gain = [80.0, 40.0, 20.0]
            .into_iter()
            .find(|&g| g <= requested_gain)
            .unwrap_or(10.0);
        unity_gain_current_a / gain
    }

    /// The q-axis current limit in force: `min(current_limit_a, hardware limit)` (A).
    pub fn effective_current_limit_a(&self) -> f64 {
        self.current_limit_a.min(self.hardware_current_limit_a())
    }

    /// The wheel speed beyond which the driver trips (rad/s), infinite when the overspeed
    /// error is disabled.
    pub fn trip_speed_rad_per_s(&self, gear_ratio: f64) -> f64 {
        if self.enable_overspeed_error {
            self.vel_limit_tolerance * self.vel_limit_turn_per_s * TAU / gear_ratio
        } else {
            f64::INFINITY
        }
    }

    /// Checks every field; the error names the first one out of range (`driver.<field>`).
    pub fn validate(&self) -> Result<(), WorldError> {
        let positive = [
            (self.bus_voltage_v, "driver.bus_voltage_v"),
            (self.motor_kv_rpm_per_v, "driver.motor_kv_rpm_per_v"),
            (self.phase_resistance_ohm, "driver.phase_resistance_ohm"),
            (self.current_limit_a, "driver.current_limit_a"),
            (
                self.requested_current_range_a,
                "driver.requested_current_range_a",
            ),
            (self.vel_limit_turn_per_s, "driver.vel_limit_turn_per_s"),
        ];
        for (value, field) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(field, "must be finite and > 0"));
            }
        }
        if !(self.max_modulation > 0.0 && self.max_modulation <= 1.0) {
            return Err(invalid("driver.max_modulation", "must be in (0, 1]"));
        }
        let m = self.current_limit_margin_a;
        if !(m.is_finite() && m >= 0.0) {
            return Err(invalid(
                "driver.current_limit_margin_a",
                "must be finite and >= 0",
            ));
        }
        let tol = self.vel_limit_tolerance;
        if !(tol.is_finite() && tol >= 1.0) {
            return Err(invalid(
                "driver.vel_limit_tolerance",
                "must be finite and >= 1",
            ));
        }
        let g = self.vel_gain_nm_s_per_turn;
        if !(g.is_finite() && g > 0.0) {
            return Err(invalid(
                "driver.vel_gain_nm_s_per_turn",
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

impl Default for DriverParams {
    fn default() -> Self {
        Self::ideal()
    }
}

fn invalid(field: &'static str, requirement: &'static str) -> WorldError {
    WorldError::InvalidParameter { field, requirement }
}

fn torque_constant_nm_per_a(kv_rpm_per_v: f64) -> f64 {
    3.0_f64.sqrt() / 2.0 * 60.0 / (2.0 * PI * kv_rpm_per_v)
}

/// KV (rpm/V) from the paper: no-load wheel speed times the ratio, per 45 V.
fn miapure_kv_rpm_per_v(actuator: &ActuatorParams<f64>) -> f64 {
    actuator.no_load_speed_rad_per_s * actuator.gear_ratio * 60.0 / TAU / MIAPURE_BUS_VOLTAGE_V
}

/// Which limit shaped a step's torque (the first that cut the command, in the firmware's
/// order; `Voltage` wins when the back-EMF leaves less than the current limit).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum DriverLimit {
    /// The command passed unchanged.
    #[default]
    None,
    /// The current limit (the ideal model: the peak torque).
    Current,
    /// The voltage limit: back-EMF and resistance (the ideal model: the straight line).
    Voltage,
    /// The torque-mode velocity limiter.
    VelocityLimiter,
    /// The driver has disarmed: no torque.
    Disarmed,
}

impl DriverLimit {
    /// The canonical (snake_case) name, as serde writes it: `none`, `current`, `voltage`,
    /// `velocity_limiter` or `disarmed`.
    ///
    /// ```
    /// use ballbot_world::world::DriverLimit;
    /// assert_eq!(DriverLimit::VelocityLimiter.as_str(), "velocity_limiter");
    /// ```
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Current => "current",
            Self::Voltage => "voltage",
            Self::VelocityLimiter => "velocity_limiter",
            Self::Disarmed => "disarmed",
        }
    }
}

/// Why a driver disarmed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriverFault {
    /// `|speed| > vel_limit_tolerance * vel_limit` (`ERROR_OVERSPEED`).
    Overspeed,
    /// The current exceeded `current_limit + current_limit_margin`
    /// (`ERROR_CURRENT_LIMIT_VIOLATION`).
    CurrentLimitViolation,
}

/// What the driver delivered in one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriverOutput {
    /// Torque at the wheel (N m).
    pub torque_nm: f64,
    /// q-axis current (A); the ideal model: torque over `N K_t`.
    pub current_a: f64,
    /// Which limit shaped the torque.
    pub limit: DriverLimit,
}

/// One wheel's driver: the configuration and whether it is still armed.
///
/// ```
/// use ballbot_core::ActuatorParams;
/// use ballbot_world::world::driver::{DriverLimit, DriverParams, MotorDriver};
/// let mut d = MotorDriver::new(DriverParams::miapure(), ActuatorParams::miapure());
/// // At rest the 0.8 modulation limit leaves 0.8 of the stall torque: 34.56 N m.
/// let out = d.step(60.0, 0.0);
/// approx::assert_relative_eq!(out.torque_nm, 34.56, epsilon = 1e-9);
/// assert_eq!(out.limit, DriverLimit::Voltage);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct MotorDriver {
    params: DriverParams,
    actuator: ActuatorParams<f64>,
    fault: Option<DriverFault>,
    /// The constants the step uses, derived once from `params` and `actuator`.
    resolved: Resolved,
}

/// [`DriverParams`]' derived constants, resolved at construction so that a step does no
/// unit conversion or table lookup.
#[derive(Clone, Copy, Debug)]
struct Resolved {
    /// `K_t` (N m/A at the rotor).
    kt_nm_per_a: f64,
    /// `k_e` (V s/rad at the rotor).
    ke_v_s_per_rad: f64,
    /// Largest phase peak voltage (V).
    max_phase_voltage_v: f64,
    /// The q-axis current limit in force (A).
    current_limit_a: f64,
    /// The wheel speed beyond which the driver trips (rad/s).
    trip_speed_rad_per_s: f64,
}

impl MotorDriver {
    /// An armed driver.
    pub fn new(params: DriverParams, actuator: ActuatorParams<f64>) -> Self {
        let resolved = Resolved {
            kt_nm_per_a: params.torque_constant_nm_per_a(),
            ke_v_s_per_rad: params.back_emf_v_s_per_rad(),
            max_phase_voltage_v: params.max_phase_voltage_v(),
            current_limit_a: params.effective_current_limit_a(),
            trip_speed_rad_per_s: params.trip_speed_rad_per_s(actuator.gear_ratio),
        };
        Self {
            params,
            actuator,
            fault: None,
            resolved,
        }
    }

    /// The configuration.
    pub fn params(&self) -> &DriverParams {
        &self.params
    }

    /// Why the driver disarmed, if it has.
    pub fn fault(&self) -> Option<DriverFault> {
        self.fault
    }

    /// One step: the wheel torque for the command `torque_nm` (N m at the wheel; non-finite
    /// gives 0) at wheel speed `speed_rad_per_s`. Checks the trips first (the ODrive model);
    /// a disarmed driver gives nothing.
    #[inline]
    pub fn step(&mut self, torque_nm: f64, speed_rad_per_s: f64) -> DriverOutput {
        if self.params.model == DriverModel::Odrive
            && self.fault.is_none()
            && speed_rad_per_s.abs() > self.resolved.trip_speed_rad_per_s
        {
            self.fault = Some(DriverFault::Overspeed);
        }
        if self.fault.is_some() {
            return DriverOutput {
                torque_nm: 0.0,
                current_a: 0.0,
                limit: DriverLimit::Disarmed,
            };
        }
        let out = self.envelope(torque_nm, speed_rad_per_s);
        let p = &self.params;
        if p.model == DriverModel::Odrive
            && out.current_a.abs() > self.resolved.current_limit_a + p.current_limit_margin_a
        {
            self.fault = Some(DriverFault::CurrentLimitViolation);
        }
        out
    }

    /// The torque an armed driver delivers for `torque_nm` at `speed_rad_per_s` (no trips).
    #[inline]
    pub fn envelope(&self, torque_nm: f64, speed_rad_per_s: f64) -> DriverOutput {
        let n = self.actuator.gear_ratio;
        let kt = self.resolved.kt_nm_per_a;
        if !torque_nm.is_finite() {
            return DriverOutput {
                torque_nm: 0.0,
                current_a: 0.0,
                limit: DriverLimit::None,
            };
        }
        match self.params.model {
            DriverModel::Ideal => {
                let tau = self.actuator.clamp_torque_nm(torque_nm, speed_rad_per_s);
                let limit = if tau == torque_nm {
                    DriverLimit::None
                } else if tau.abs() == self.actuator.peak_torque_nm {
                    DriverLimit::Current
                } else {
                    DriverLimit::Voltage
                };
                DriverOutput {
                    torque_nm: tau,
                    current_a: tau / (n * kt),
                    limit,
                }
            }
            DriverModel::Odrive => self.odrive(torque_nm / n, n * speed_rad_per_s),
        }
    }

    /// The firmware's chain on the rotor torque `t_m` (N m) at rotor speed `w_m` (rad/s).
    fn odrive(&self, t_m: f64, w_m: f64) -> DriverOutput {
        let p = &self.params;
        let n = self.actuator.gear_ratio;
        let kt = self.resolved.kt_nm_per_a;
        let mut limit = DriverLimit::None;
        let mut t = t_m;
        if p.enable_torque_mode_vel_limit {
            let v = w_m / TAU;
            let g = p.vel_gain_nm_s_per_turn;
            let lo = (-p.vel_limit_turn_per_s - v) * g;
            let hi = (p.vel_limit_turn_per_s - v) * g;
            let limited = t.clamp(lo, hi);
            if limited != t {
                limit = DriverLimit::VelocityLimiter;
                t = limited;
            }
        }
        let i_lim = self.resolved.current_limit_a;
        let mut i = t / kt;
        if i.abs() > i_lim {
            i = i.clamp(-i_lim, i_lim);
            if limit == DriverLimit::None {
                limit = DriverLimit::Current;
            }
        }
        let (i_lo, i_hi) = self.voltage_current_bounds_a(w_m);
        if i > i_hi || i < i_lo {
            i = if i > i_hi { i_hi } else { i_lo };
            limit = DriverLimit::Voltage;
        }
        DriverOutput {
            torque_nm: n * kt * i,
            current_a: i,
            limit,
        }
    }

    /// The q-axis currents (A) the voltage allows at rotor speed `w_m` (rad/s).
    fn voltage_current_bounds_a(&self, w_m: f64) -> (f64, f64) {
        let v_max = self.resolved.max_phase_voltage_v;
        let emf = self.resolved.ke_v_s_per_rad * w_m;
        let r = self.params.phase_resistance_ohm;
        ((-v_max - emf) / r, (v_max - emf) / r)
    }

    /// The wheel torque range `(min, max)` (N m) an armed driver can deliver at
    /// `speed_rad_per_s`.
    pub fn torque_bounds_nm(&self, speed_rad_per_s: f64) -> (f64, f64) {
        (
            self.envelope(-f64::MAX, speed_rad_per_s).torque_nm,
            self.envelope(f64::MAX, speed_rad_per_s).torque_nm,
        )
    }

    /// Electrical power drawn by the motor, `3/2 V_q I_q` with `V_q = R I_q + k_e w_m` (W;
    /// negative: regeneration into the bus), for q-axis current `current_a` at wheel speed
    /// `speed_rad_per_s`.
    pub fn electrical_power_w(&self, current_a: f64, speed_rad_per_s: f64) -> f64 {
        let p = &self.params;
        let w_m = self.actuator.gear_ratio * speed_rad_per_s;
        let v_q = p.phase_resistance_ohm * current_a + self.resolved.ke_v_s_per_rad * w_m;
        1.5 * v_q * current_a
    }

    /// Copper loss `3/2 R I_q^2` (W) at q-axis current `current_a`.
    pub fn copper_loss_w(&self, current_a: f64) -> f64 {
        1.5 * self.params.phase_resistance_ohm * current_a * current_a
    }
}
