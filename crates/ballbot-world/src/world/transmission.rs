//! The drivetrain between each motor and its omniwheel: gearbox friction with stiction, an
//! elastomeric coupling, backlash and the rotor's reflected inertia.
//!
//! All angles, speeds and torques are at the gearbox output (the wheel's axle): the motor's
//! angle is the rotor's divided by the gear ratio `n`, so its encoder and the wheel read the
//! same number when the drivetrain is rigid.
//!
//! # Two inertias and what joins them
//!
//! The motor side carries the rotor's inertia reflected through the gearbox, `J_m = n^2 I_r`,
//! the wheel side the omniwheel's `I_w`. Between them sits the coupling: a torsional spring
//! `k` with damping `c` behind a dead band of `backlash_rad` (the free play of gear mesh and
//! coupling together). With `delta = theta_m - theta_w` and the dead band's half-width
//! `b = backlash_rad / 2`,
//!
//! ```text
//! e     = delta - b sign(delta)   if |delta| > b, else 0 (the teeth are apart)
//! tau_c = k e + c (w_m - w_w)      while e != 0, never of the opposite sign to e
//! J_m dw_m/dt = tau_motor - tau_c - b_v w_m - tau_f
//! I_w dw_w/dt = tau_c - r F + tau_gap
//! ```
//!
//! (an elastomer in a jaw coupling pushes; it does not pull the jaws back together, so the
//! damping term cannot make `tau_c` change sign while the teeth are in mesh). `b_v` is the
//! world's `wheel_damping_nm_s_per_rad`, on the motor side where the gearbox is.
//!
//! With `coupling_stiffness_nm_per_rad = 0` the drivetrain is rigid: one inertia
//! `J_m + I_w` on one angle, the world of the earlier releases ([`TransmissionParams::rigid`]).
//!
//! # Gearbox friction: the Karnopp model
//!
//! `tau_f` is the gearbox's Coulomb friction with stiction, on the motor side's speed (the
//! whole inertia's when rigid). Outside the window `|w_m| >= w` the gearbox slides with
//! `tau_f = T_c sign(w_m)`. Inside it, the gearbox is held by the torque that makes
//! `dw_m/dt = -w_m / t_settle` (it stops and does not creep), `tau_hold = tau_other + J w_m /
//! t_settle`, as long as `|tau_hold| <= T_s`; beyond that it breaks away against
//! `T_s sign(tau_hold)`. The window must be wide enough that friction alone cannot carry the
//! speed across it in one step, `w >= (T_s + T_c) dt / J` ([`TransmissionParams::validate`]).
//!
//! The spin momentum that the body feels is `n I_r w_m + I_w w_w` (the rotor turns at `n`
//! times the motor side's speed): the body takes `-(n I_r dw_m/dt + I_w dw_w/dt)` about the
//! axle, and every torque inside the drivetrain (friction, coupling, motor) cancels in it.

use super::WorldError;
use super::check::non_negative;

/// The drivetrain of one omniwheel, the same for all three (module documentation).
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct TransmissionParams {
    /// Breakaway torque `T_s` of the gearbox at its output (N m): the largest torque a stuck
    /// gearbox holds. 0 with [`Self::coulomb_torque_nm`] 0: no gearbox friction.
    #[schemars(range(min = 0))]
    pub stiction_torque_nm: f64,
    /// Sliding (Coulomb) torque `T_c` of the gearbox at its output (N m), `<= T_s`.
    #[schemars(range(min = 0))]
    pub coulomb_torque_nm: f64,
    /// Half-width `w` of the Karnopp stick window on the motor side's speed (rad/s at the
    /// output).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub stick_window_rad_per_s: f64,
    /// Time constant with which a stuck gearbox's residual speed is pulled to zero (s), at
    /// least one world step.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub stick_settle_time_secs: f64,
    /// Torsional stiffness `k` of the coupling between gearbox output and omniwheel
    /// (N m/rad). 0: a rigid drivetrain (one inertia; backlash and coupling damping must
    /// then be 0).
    #[schemars(range(min = 0))]
    pub coupling_stiffness_nm_per_rad: f64,
    /// Damping `c` of the coupling (N m s/rad).
    #[schemars(range(min = 0))]
    pub coupling_damping_nm_s_per_rad: f64,
    /// Total free play between motor side and wheel, gear mesh and coupling together (rad at
    /// the output): the dead band is `+-backlash_rad / 2`.
    #[schemars(range(min = 0))]
    pub backlash_rad: f64,
}

impl Default for TransmissionParams {
    /// The rigid drivetrain ([`TransmissionParams::rigid`]): also what a world file without a
    /// `transmission` table gets.
    fn default() -> Self {
        Self::rigid()
    }
}

impl TransmissionParams {
    /// The drivetrain of the earlier releases: motor and wheel one rigid inertia, no gearbox
    /// friction beyond the world's viscous `wheel_damping_nm_s_per_rad`.
    pub fn rigid() -> Self {
        Self {
            stiction_torque_nm: 0.0,
            coulomb_torque_nm: 0.0,
            stick_window_rad_per_s: 0.02,
            stick_settle_time_secs: 1e-3,
            coupling_stiffness_nm_per_rad: 0.0,
            coupling_damping_nm_s_per_rad: 0.0,
            backlash_rad: 0.0,
        }
    }

    /// MiaPURE's drivetrain as we estimate it from a comparable actuator and coupling
    /// (docs/world-drivetrain.md, "Drivetrain"): a single-stage planetary
    /// quasi-direct-drive actuator with the breakaway torque and backlash measured on the
    /// PULSE115-60 (0.37 N m, +-0.11 deg), a Coulomb torque of 0.7 times the breakaway
    /// (estimate), and a jaw coupling of the size rated for the 43.2 N m peak (KTR ROTEX GS 24,
    /// 98 Sh A spider: 60 N m rated) whose stiffness, 3e3 N m/rad, is our estimate from the
    /// spider's geometry and modulus (not a catalogue value), with the spider's relative
    /// damping 0.45 (a loss factor of 0.072) as 0.13 N m s/rad at the coupling's mode.
    pub fn miapure() -> Self {
        Self {
            stiction_torque_nm: 0.37,
            coulomb_torque_nm: 0.26,
            stick_window_rad_per_s: 0.02,
            stick_settle_time_secs: 1e-3,
            coupling_stiffness_nm_per_rad: 3.0e3,
            coupling_damping_nm_s_per_rad: 0.13,
            backlash_rad: 0.22_f64.to_radians(),
        }
    }

    /// `true` when motor and wheel are one rigid inertia.
    pub fn is_rigid(&self) -> bool {
        self.coupling_stiffness_nm_per_rad == 0.0
    }

    /// `true` when the gearbox has no Coulomb friction or stiction.
    pub fn is_frictionless(&self) -> bool {
        self.stiction_torque_nm == 0.0 && self.coulomb_torque_nm == 0.0
    }

    /// The narrowest stick window (rad/s) for a stuck inertia `inertia_kg_m2` at the world
    /// step `dt_secs`: `(T_s + T_c) dt / J`.
    pub fn min_stick_window_rad_per_s(&self, inertia_kg_m2: f64, dt_secs: f64) -> f64 {
        (self.stiction_torque_nm + self.coulomb_torque_nm) * dt_secs / inertia_kg_m2
    }

    /// Checks every field; `stuck_inertia_kg_m2` is the inertia the friction acts on (the
    /// motor side's, or the whole drivetrain's when rigid) and `dt_secs` the world step. The
    /// error names the field (`transmission.backlash_rad`).
    pub fn validate(&self, stuck_inertia_kg_m2: f64, dt_secs: f64) -> Result<(), WorldError> {
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        non_negative(self.stiction_torque_nm, "transmission.stiction_torque_nm")?;
        non_negative(self.coulomb_torque_nm, "transmission.coulomb_torque_nm")?;
        if self.coulomb_torque_nm > self.stiction_torque_nm {
            return invalid(
                "transmission.coulomb_torque_nm",
                "must not exceed transmission.stiction_torque_nm",
            );
        }
        non_negative(
            self.coupling_stiffness_nm_per_rad,
            "transmission.coupling_stiffness_nm_per_rad",
        )?;
        non_negative(
            self.coupling_damping_nm_s_per_rad,
            "transmission.coupling_damping_nm_s_per_rad",
        )?;
        non_negative(self.backlash_rad, "transmission.backlash_rad")?;
        if self.is_rigid() && (self.backlash_rad > 0.0 || self.coupling_damping_nm_s_per_rad > 0.0)
        {
            return invalid(
                "transmission.coupling_stiffness_nm_per_rad",
                "must be > 0 when transmission.backlash_rad or \
                 transmission.coupling_damping_nm_s_per_rad is > 0 (0 is the rigid drivetrain)",
            );
        }
        if !(self.stick_settle_time_secs.is_finite() && self.stick_settle_time_secs >= dt_secs) {
            return invalid(
                "transmission.stick_settle_time_secs",
                "must be finite and at least one world step (dt_secs)",
            );
        }
        let w = self.stick_window_rad_per_s;
        if !(w.is_finite() && w > 0.0) {
            return invalid(
                "transmission.stick_window_rad_per_s",
                "must be finite and > 0",
            );
        }
        if w < self.min_stick_window_rad_per_s(stuck_inertia_kg_m2, dt_secs) {
            return invalid(
                "transmission.stick_window_rad_per_s",
                "must be >= (stiction_torque_nm + coulomb_torque_nm) * dt_secs / J, J the \
                 inertia the gearbox friction holds (TransmissionParams::min_stick_window_rad_per_s)",
            );
        }
        Ok(())
    }
}

/// What the gearbox friction did in one step.
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
pub enum GearboxMode {
    /// No gearbox friction is modelled.
    #[default]
    Free,
    /// Sliding: Coulomb friction against the motor side's speed.
    Sliding,
    /// Held by stiction.
    Stuck,
    /// Inside the stick window, but the holding torque would exceed the breakaway torque.
    BreakingAway,
}

/// The spin state of one drivetrain, relative to the body (output-side units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DrivetrainState {
    /// Motor side: the rotor's angle over the gear ratio (rad).
    pub motor_angle_rad: f64,
    /// Motor side's speed (rad/s).
    pub motor_speed_rad_per_s: f64,
    /// The omniwheel's angle (rad).
    pub wheel_angle_rad: f64,
    /// The omniwheel's speed (rad/s).
    pub wheel_speed_rad_per_s: f64,
}

/// The torques on one drivetrain in one step, at the output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrivetrainLoads {
    /// The motor's torque after its driver (N m).
    pub motor_nm: f64,
    /// The contact's traction torque on the wheel, `r F` (N m; it opposes the wheel).
    pub traction_nm: f64,
    /// The roller gap's torque on the wheel, `N d(dip)/d(psi)` (N m).
    pub gap_nm: f64,
}

/// What one step of a drivetrain produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrivetrainStep {
    /// Rate of change of the spin momentum the body feels about the axle,
    /// `n I_r dw_m/dt + I_w dw_w/dt` (N m): the body takes minus this.
    pub spin_momentum_rate_nm: f64,
    /// Torque through the coupling from motor side to wheel (N m); when rigid, the torque the
    /// motor side passes to the wheel, `I_w dw/dt - (tau_gap - r F)`.
    pub coupling_torque_nm: f64,
    /// Gearbox friction torque on the motor side (N m, opposing positive speed when > 0).
    pub friction_torque_nm: f64,
    /// Which branch of the friction model acted.
    pub mode: GearboxMode,
}

/// One omniwheel's drivetrain: its parameters and inertias, stepped by the world.
#[derive(Clone, Copy, Debug)]
pub struct Drivetrain {
    params: TransmissionParams,
    /// `n^2 I_r` (kg m^2).
    motor_inertia_kg_m2: f64,
    /// `I_w` (kg m^2).
    wheel_inertia_kg_m2: f64,
    /// `n I_r` (kg m^2): the rotor's spin momentum per unit of the motor side's speed.
    rotor_momentum_kg_m2: f64,
    /// `n I_r` over `n^2 I_r`: `1 / n` (0 without a rotor).
    rotor_momentum_share: f64,
    /// `(I_w + n I_r) / (I_w + n^2 I_r)`, the rigid drivetrain's spin momentum per unit of
    /// its accelerating torque.
    rigid_spin_share: f64,
    /// Viscous friction on the motor side's speed (N m s/rad).
    viscous_nm_s_per_rad: f64,
    /// Precomputed per step: rigid, frictionless, the dead band's half-width (rad) and the
    /// inertias' reciprocals (1/(kg m^2)).
    rigid: bool,
    frictionless: bool,
    half_backlash_rad: f64,
    inv_motor_inertia: f64,
    inv_wheel_inertia: f64,
}

impl Drivetrain {
    /// The drivetrain with gear ratio `gear_ratio`, rotor inertia `rotor_inertia_kg_m2` (at
    /// the rotor), wheel inertia `wheel_inertia_kg_m2` and viscous friction
    /// `viscous_nm_s_per_rad` on the motor side.
    pub fn new(
        params: TransmissionParams,
        gear_ratio: f64,
        rotor_inertia_kg_m2: f64,
        wheel_inertia_kg_m2: f64,
        viscous_nm_s_per_rad: f64,
    ) -> Self {
        let motor = rotor_inertia_kg_m2 * gear_ratio * gear_ratio;
        let momentum = rotor_inertia_kg_m2 * gear_ratio;
        Self {
            params,
            motor_inertia_kg_m2: motor,
            wheel_inertia_kg_m2,
            rotor_momentum_kg_m2: momentum,
            rotor_momentum_share: if motor > 0.0 { momentum / motor } else { 0.0 },
            rigid_spin_share: (wheel_inertia_kg_m2 + momentum) / (wheel_inertia_kg_m2 + motor),
            viscous_nm_s_per_rad,
            rigid: params.is_rigid(),
            frictionless: params.is_frictionless(),
            half_backlash_rad: 0.5 * params.backlash_rad,
            inv_motor_inertia: if motor > 0.0 { 1.0 / motor } else { 0.0 },
            inv_wheel_inertia: 1.0 / wheel_inertia_kg_m2,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &TransmissionParams {
        &self.params
    }

    /// The inertia that the gearbox friction holds (kg m^2): the motor side's, or motor and
    /// wheel together when rigid.
    pub fn stuck_inertia_kg_m2(&self) -> f64 {
        if self.params.is_rigid() {
            self.wheel_inertia_kg_m2 + self.motor_inertia_kg_m2
        } else {
            self.motor_inertia_kg_m2
        }
    }

    /// The coupling's torque at the current state (N m, 0 when rigid or inside the
    /// backlash).
    #[inline]
    pub fn coupling_torque_nm(&self, s: &DrivetrainState) -> f64 {
        let p = &self.params;
        if self.rigid {
            return 0.0;
        }
        let half = self.half_backlash_rad;
        let delta = s.motor_angle_rad - s.wheel_angle_rad;
        let e = if delta > half {
            delta - half
        } else if delta < -half {
            delta + half
        } else {
            return 0.0;
        };
        let rate = s.motor_speed_rad_per_s - s.wheel_speed_rad_per_s;
        let tau = p.coupling_stiffness_nm_per_rad * e + p.coupling_damping_nm_s_per_rad * rate;
        if e > 0.0 { tau.max(0.0) } else { tau.min(0.0) }
    }

    /// Elastic energy in the coupling (J).
    pub fn coupling_energy_j(&self, s: &DrivetrainState) -> f64 {
        let p = &self.params;
        if p.is_rigid() {
            return 0.0;
        }
        let e = ((s.motor_angle_rad - s.wheel_angle_rad).abs() - 0.5 * p.backlash_rad).max(0.0);
        0.5 * p.coupling_stiffness_nm_per_rad * e * e
    }

    /// Kinetic energy of the spins (J): `J_m w_m^2 / 2 + I_w w_w^2 / 2`.
    pub fn kinetic_energy_j(&self, s: &DrivetrainState) -> f64 {
        if self.params.is_rigid() {
            let j = self.wheel_inertia_kg_m2 + self.motor_inertia_kg_m2;
            return 0.5 * j * s.wheel_speed_rad_per_s * s.wheel_speed_rad_per_s;
        }
        0.5 * self.motor_inertia_kg_m2 * s.motor_speed_rad_per_s * s.motor_speed_rad_per_s
            + 0.5 * self.wheel_inertia_kg_m2 * s.wheel_speed_rad_per_s * s.wheel_speed_rad_per_s
    }

    /// The spin angular momentum about the axle (N m s): `n I_r w_m + I_w w_w`.
    pub fn spin_momentum_nms(&self, s: &DrivetrainState) -> f64 {
        if self.params.is_rigid() {
            let i_spin = self.wheel_inertia_kg_m2 + self.rotor_momentum_kg_m2;
            return i_spin * s.wheel_speed_rad_per_s;
        }
        self.rotor_momentum_kg_m2 * s.motor_speed_rad_per_s
            + self.wheel_inertia_kg_m2 * s.wheel_speed_rad_per_s
    }

    /// Gearbox friction on an inertia `inertia_kg_m2` turning at `speed` under the other
    /// torques `other_nm` (module documentation).
    #[inline]
    fn friction(&self, other_nm: f64, speed: f64, inertia_kg_m2: f64) -> (f64, GearboxMode) {
        let p = &self.params;
        if self.frictionless {
            return (0.0, GearboxMode::Free);
        }
        if speed.abs() >= p.stick_window_rad_per_s {
            return (p.coulomb_torque_nm * speed.signum(), GearboxMode::Sliding);
        }
        let hold = other_nm + inertia_kg_m2 * speed / p.stick_settle_time_secs;
        if hold.abs() <= p.stiction_torque_nm {
            (hold, GearboxMode::Stuck)
        } else {
            (
                p.stiction_torque_nm * hold.signum(),
                GearboxMode::BreakingAway,
            )
        }
    }

    /// Advances `s` by one step of `dt_secs` under `loads` (semi-implicit Euler: speeds, then
    /// angles from the new speeds).
    #[inline]
    pub fn step(
        &self,
        s: &mut DrivetrainState,
        loads: &DrivetrainLoads,
        dt_secs: f64,
    ) -> DrivetrainStep {
        if self.rigid {
            return self.step_rigid(s, loads, dt_secs);
        }
        let tau_c = self.coupling_torque_nm(s);
        let other = loads.motor_nm - tau_c - self.viscous_nm_s_per_rad * s.motor_speed_rad_per_s;
        let j_m = self.motor_inertia_kg_m2;
        let (friction, mode) = self.friction(other, s.motor_speed_rad_per_s, j_m);
        let motor_net = other - friction;
        let wheel_net = tau_c - loads.traction_nm + loads.gap_nm;
        let motor_accel = motor_net * self.inv_motor_inertia;
        let wheel_accel = wheel_net * self.inv_wheel_inertia;
        s.motor_speed_rad_per_s += dt_secs * motor_accel;
        s.wheel_speed_rad_per_s += dt_secs * wheel_accel;
        s.motor_angle_rad += dt_secs * s.motor_speed_rad_per_s;
        s.wheel_angle_rad += dt_secs * s.wheel_speed_rad_per_s;
        DrivetrainStep {
            spin_momentum_rate_nm: self.rotor_momentum_share * motor_net + wheel_net,
            coupling_torque_nm: tau_c,
            friction_torque_nm: friction,
            mode,
        }
    }

    /// The rigid drivetrain: one inertia, in the earlier releases' order of operations.
    fn step_rigid(
        &self,
        s: &mut DrivetrainState,
        loads: &DrivetrainLoads,
        dt_secs: f64,
    ) -> DrivetrainStep {
        let j = self.wheel_inertia_kg_m2 + self.motor_inertia_kg_m2;
        let speed = s.wheel_speed_rad_per_s;
        let spin = loads.motor_nm - loads.traction_nm - self.viscous_nm_s_per_rad * speed;
        let other = spin + loads.gap_nm;
        let (friction, mode) = self.friction(other, speed, j);
        let net = other - friction;
        s.wheel_speed_rad_per_s += dt_secs * net / j;
        s.wheel_angle_rad += dt_secs * s.wheel_speed_rad_per_s;
        s.motor_speed_rad_per_s = s.wheel_speed_rad_per_s;
        s.motor_angle_rad = s.wheel_angle_rad;
        let wheel_loads = loads.gap_nm - loads.traction_nm;
        DrivetrainStep {
            spin_momentum_rate_nm: self.rigid_spin_share * net,
            coupling_torque_nm: self.wheel_inertia_kg_m2 * net / j - wheel_loads,
            friction_torque_nm: friction,
            mode,
        }
    }
}

#[cfg(test)]
mod tests;
