//! Parameters of the 3D world that the core's [`BallbotParams`] does not carry: the compliant
//! omniwheel contact, wheel and rotor inertia, floor friction, sensors, failure limits.
//!
//! Every number that is not in the paper is an estimate and says so.

use super::WorldError;
use super::axle_loss::AxleLossParams;
use super::check::{non_negative, positive};
use super::contact::NormalLaw;
use super::driver::DriverParams;
use super::floor::FloorParams;
use super::imu::ImuParams;
use super::rollers::{MIAPURE_ROLLER_RADIUS_M, RollerParams};
use super::rubber::{CoatingLaw, RubberLayer};
use super::transmission::{Drivetrain, TransmissionParams};
use ballbot_core::BallbotParams;
use ballbot_core::rates::INNER_LOOP_DT_SECS;

/// The largest [`WorldParams::rigid_step_ratio`]: 40 world steps, a 5 ms rigid step at 8 kHz.
pub const MAX_RIGID_STEP_RATIO: u32 = 40;

/// The default world's [`WorldParams::rigid_step_ratio`] ([`WorldParams::realistic`]): the
/// rigid bodies at 800 Hz, twice per 400 Hz control period, while contacts, wheels and drivers
/// run at 8 kHz (docs/world-speed.md, "Multi-rate world": within the trajectory spread of a changed
/// sensor-noise seed, five times faster). Capped by [`WorldParams::max_rigid_step_ratio`].
pub const DEFAULT_RIGID_STEP_RATIO: u32 = 10;

/// The largest `omega_B T` allowed for the rigid step `T`, with `omega_B` the ball's vertical
/// frequency on its three omniwheel contacts ([`WorldParams::ball_contact_frequency_rad_per_s`]).
/// Measured on the 10 s drive cycle of `benches/world_step` (docs/world-speed.md,
/// "Multi-rate world") when the floor's force on the ball was held at the last rigid step's
/// average, a lag of one rigid step on that mode: stable at 1.14 (ideal world, 1.25 ms) and
/// 0.94 (default world, 2.5 ms), diverging at 1.83 (ideal, 2 ms) and 1.87 (default, 5 ms). The
/// floor has since become the coating's compliant contact on the 8 kHz path; the bound is
/// kept, not re-measured.
pub const MAX_BALL_CONTACT_PHASE_RAD: f64 = 1.2;

/// MiaPURE's link latency from the 400 Hz loop's sample to the drivers acting on its output
/// (s): the CAN frames between the roboRIO and the two ODrives (docs/world-sensing.md;
/// an estimate from the bus's frame times, not a measurement).
pub const MIAPURE_LINK_LATENCY_SECS: f64 = 1.0e-3;

fn default_roller_radius_m() -> f64 {
    MIAPURE_ROLLER_RADIUS_M
}

fn default_rigid_step_ratio() -> u32 {
    1
}

/// How the omniwheel contact's normal force follows its penetration
/// ([`crate::world::contact::NormalLaw`]).
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
pub enum ContactNormalLaw {
    /// The linear spring-damper of `normal_stiffness_n_per_m` and `normal_damping_n_s_per_m`
    /// (the ideal world's; the default when missing from a file).
    #[default]
    Linear,
    /// The ball coating's force-deflection law over its whole range
    /// ([`crate::world::rubber::CoatingLaw`], Hertz plus the thin bonded layer) pressed by a
    /// roller of the wheel's rim radius in the wheel plane and `roller_radius_m` across it,
    /// with the loss factor's damping at the ball-against-body mode (the default world's).
    /// The coating is the floor's ([`WorldParams::floor`]: one layer on one ball); the two
    /// linear fields are not used.
    Coating,
}

/// The compliant omniwheel-ball contact (see [`crate::world::contact`] for the model).
///
/// The default is the ideal contact ([`ContactParams::ideal`]): a stiff normal spring, a
/// continuous rim and free rollers. The realistic mechanisms switch on one at a time:
/// [`RollerParams::miapure`] (roller gaps), [`AxleLossParams::miapure`] (roller losses along
/// the axle) and [`ContactParams::rubber_coated`] (stiffness and damping of the rubber
/// coating); docs/world-contacts.md, "Contact realism: parameters and sources".
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct ContactParams {
    /// The normal force's law: `linear` (default) or `coating`.
    #[serde(default)]
    pub normal_law: ContactNormalLaw,
    /// Radius of the roller across the wheel plane at the contact (m), the coating law's
    /// second curvature. Default 0.011 (estimate, [`MIAPURE_ROLLER_RADIUS_M`]).
    #[serde(default = "default_roller_radius_m")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub roller_radius_m: f64,
    /// Normal stiffness of one omniwheel contact under the `linear` law (N/m). Default 2e6:
    /// the static 344 N load compresses it by 0.17 mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub normal_stiffness_n_per_m: f64,
    /// Normal damping of one omniwheel contact under the `linear` law (N s/m). Default 3.5e3 (damping ratio about
    /// 0.7 of the ball-against-body mode).
    #[schemars(range(min = 0))]
    pub normal_damping_n_s_per_m: f64,
    /// Tangential (stick) stiffness along the rolling direction (N/m). Default 5e5: the
    /// elastic creep of tyre and roller before gross slip.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub traction_stiffness_n_per_m: f64,
    /// Tangential (stick) damping along the rolling direction (N s/m). Default 1.2e3.
    #[schemars(range(min = 0))]
    pub traction_damping_n_s_per_m: f64,
    /// Kinetic over static friction coefficient while slipping (dimensionless, in (0, 1]).
    /// Default 0.85 (estimate; TPU on rubber).
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 1))]
    pub kinetic_friction_ratio: f64,
    /// Roller gaps of the omniwheels. Default [`RollerParams::none`] (a continuous rim).
    #[serde(default)]
    pub rollers: RollerParams,
    /// Roller losses along the axles. Default [`AxleLossParams::none`] (free rollers).
    #[serde(default)]
    pub axle_loss: AxleLossParams,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            normal_law: ContactNormalLaw::Linear,
            roller_radius_m: MIAPURE_ROLLER_RADIUS_M,
            normal_stiffness_n_per_m: 2.0e6,
            normal_damping_n_s_per_m: 3.5e3,
            traction_stiffness_n_per_m: 5.0e5,
            traction_damping_n_s_per_m: 1.2e3,
            kinetic_friction_ratio: 0.85,
            rollers: RollerParams::none(),
            axle_loss: AxleLossParams::none(),
        }
    }
}

impl ContactParams {
    /// The ideal contact (today's world, equal to [`ContactParams::default`]): stiff normal
    /// spring, no roller gaps, no axle losses.
    pub fn ideal() -> Self {
        Self::default()
    }

    /// The ideal contact with the ball coating's whole-range law
    /// ([`ContactNormalLaw::Coating`], the default world's normal law); gaps and axle losses
    /// stay as in [`ContactParams::ideal`].
    pub fn coating() -> Self {
        Self {
            normal_law: ContactNormalLaw::Coating,
            ..Self::ideal()
        }
    }

    /// The ideal contact with the `linear` law fitted to `layer`'s thin-layer law at the
    /// static load on `robot` ([`crate::world::rubber`], items 4 and 5: 3.4e5 N/m and
    /// 88 N s/m for MiaPURE with 60 kg); gaps and axle losses stay as in
    /// [`ContactParams::ideal`]. The default world's contact before the whole-range law
    /// ([`ContactParams::coating`]), kept as a named variant: it keeps the static force but
    /// not the static deflection (1.0 mm against the law's 2.6 mm), so it lifts off early.
    pub fn rubber_coated(robot: &BallbotParams<f64>, layer: &RubberLayer) -> Self {
        let wip = &robot.sagittal;
        let dt = &robot.drivetrain;
        let cos_a = dt.contact_angle_rad.cos();
        let load_n = wip.body_mass_kg * wip.gravity_m_per_s2 / (3.0 * cos_a);
        let r = robot.ball_radius_m();
        let k = layer.stiffness_n_per_m(load_n, dt.wheel_radius_m, r);
        let m_eff = wip.ball_mass_kg * wip.body_mass_kg / (wip.ball_mass_kg + wip.body_mass_kg);
        let omega = (3.0 * k * cos_a * cos_a / m_eff).sqrt();
        Self {
            normal_stiffness_n_per_m: k,
            normal_damping_n_s_per_m: layer.damping_n_s_per_m(k, omega),
            ..Self::ideal()
        }
    }
}

/// Sensor noise and resolution. Noise is Gaussian, drawn from a seeded generator.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct SensorParams {
    /// Seed of the noise generator.
    pub seed: u64,
    /// Standard deviation of the IMU tilt (roll, pitch) angles (rad) of the `truth` IMU
    /// model ([`ImuModel::Truth`](crate::world::ImuModel::Truth)). Default 1e-3.
    #[schemars(range(min = 0))]
    pub tilt_noise_rad: f64,
    /// Standard deviation of the gyro rates (rad/s) of the `truth` IMU model. Default 5e-3.
    #[schemars(range(min = 0))]
    pub gyro_noise_rad_per_s: f64,
    /// Encoder counts per motor-rotor turn. Default 16384 (14 bit); the wheel resolution is
    /// this times the gear ratio.
    #[schemars(range(min = 1))]
    pub encoder_counts_per_rev: u32,
    /// The IMU: [`ImuParams::truth`] (the true attitude plus white noise) in the ideal and
    /// the default world and when missing from a file; [`ImuParams::vn100`] (an
    /// accelerometer-aided attitude filter, gyro bias, output delay) in
    /// [`SensorParams::miapure`].
    #[serde(default)]
    pub imu: ImuParams,
    /// Time from the 400 Hz loop's sensor sample to the motor drivers acting on the output
    /// computed from it (s): the link to the drivers both ways (the encoder speeds up, the
    /// speed and torque references down) and the computation. Below one control period;
    /// rounded to whole world steps; applied by the rig that runs the shipped loop
    /// ([`WorldRobot`](crate::rig::WorldRobot)). 0 in the ideal and the default world and when missing
    /// from a file; docs/world-sensing.md.
    #[serde(default)]
    #[schemars(range(min = 0))]
    pub link_latency_secs: f64,
}

impl Default for SensorParams {
    /// The ideal (and the default) world's sensors: the `truth` IMU, no link latency.
    fn default() -> Self {
        Self {
            seed: 0,
            tilt_noise_rad: 1.0e-3,
            gyro_noise_rad_per_s: 5.0e-3,
            encoder_counts_per_rev: 16_384,
            imu: ImuParams::truth(),
            link_latency_secs: 0.0,
        }
    }
}

impl SensorParams {
    /// MiaPURE's sensors as the robot has them: the VN-100 ([`ImuParams::vn100`]) and the
    /// roboRIO-to-ODrive CAN link ([`MIAPURE_LINK_LATENCY_SECS`]), the 14-bit encoders. The
    /// mechanism study's `sensing` variant; not yet in the default world.
    pub fn miapure() -> Self {
        Self {
            imu: ImuParams::vn100(),
            link_latency_secs: MIAPURE_LINK_LATENCY_SECS,
            ..Self::default()
        }
    }
}

/// When a run counts as failed.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct FailureParams {
    /// Body tilt (angle between body axis and vertical) beyond which the robot has fallen
    /// (rad). Default 25 deg.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub max_tilt_rad: f64,
    /// A wheel slipping faster than this counts as slipping (m/s). Default 0.05.
    #[schemars(range(min = 0))]
    pub slip_speed_threshold_m_per_s: f64,
    /// Slip of any wheel lasting longer than this is a failure (s). Default 0.1.
    #[schemars(range(min = 0))]
    pub max_slip_duration_secs: f64,
    /// Normal force below which a wheel has lifted off (N). Default 1.
    #[schemars(range(min = 0))]
    pub lift_off_force_n: f64,
    /// Lift-off lasting longer than this is a failure (s). Default 0.02.
    #[schemars(range(min = 0))]
    pub max_lift_off_duration_secs: f64,
}

impl Default for FailureParams {
    fn default() -> Self {
        Self {
            max_tilt_rad: 25.0_f64.to_radians(),
            slip_speed_threshold_m_per_s: 0.05,
            max_slip_duration_secs: 0.1,
            lift_off_force_n: 1.0,
            max_lift_off_duration_secs: 0.02,
        }
    }
}

/// Everything the world needs: the core's robot parameters plus the world's own.
#[derive(
    Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(deny_unknown_fields)]
pub struct WorldParams {
    /// The robot (masses, inertias, COM height, drivetrain, friction coefficients).
    ///
    /// The body uses `sagittal.body_mass_kg`, `sagittal.com_height_m`, the principal
    /// inertias `frontal.body_inertia_kg_m2` (about x), `sagittal.body_inertia_kg_m2` (about
    /// y) and `spin.inertia_kg_m2` (about z).
    pub robot: BallbotParams<f64>,
    /// Omniwheel contact model.
    pub contact: ContactParams,
    /// Inertia of one omniwheel about its axle (kg m^2). Default 1.2e-3 (estimate: 0.6 kg,
    /// 62.5 mm radius disc).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub wheel_inertia_kg_m2: f64,
    /// Motor rotor inertia (kg m^2). It resists the wheel's acceleration through the gear ratio
    /// squared ([`Self::reflected_wheel_inertia_kg_m2`]) but carries angular momentum through
    /// the ratio once, the rotor spinning at `n` times the wheel's speed
    /// ([`Self::wheel_spin_momentum_inertia_kg_m2`]): the body feels the difference. Default
    /// 1.5e-4 (estimate for a QDD pancake motor).
    #[schemars(range(min = 0))]
    pub rotor_inertia_kg_m2: f64,
    /// Viscous friction of each wheel's drivetrain (N m s/rad): on the motor side's speed, where
    /// the gearbox is ([`Self::transmission`]; the wheel's speed when the drivetrain is
    /// rigid). Default 0.02.
    #[schemars(range(min = 0))]
    pub wheel_damping_nm_s_per_rad: f64,
    /// The floor and the ball coating's contact on it ([`crate::world::floor`]):
    /// [`FloorParams::miapure`] (level) in both worlds and when missing from a file.
    #[serde(default)]
    pub floor: FloorParams,
    /// Rolling resistance coefficient of the rubber ball on the floor (dimensionless, force
    /// over load). Default 0.015 (estimate).
    #[schemars(range(min = 0))]
    pub rolling_resistance: f64,
    /// Torsional friction at the ball-floor contact: the largest spin torque is this times
    /// the floor load (N m per N, i.e. an effective patch radius, m). Default 0.01.
    #[schemars(range(min = 0))]
    pub spin_friction_m: f64,
    /// Chassis half-width (m): the body touches the floor when a corner of its square
    /// footprint, at the ball centre's height in the body frame, reaches the floor.
    /// Default 0.18 (0.36 m footprint).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub chassis_half_width_m: f64,
    /// Chassis height above the ball centre (m). Default 0.45.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub chassis_height_m: f64,
    /// Physics step (s). Default 1/8000: the motor loop rate.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub dt_secs: f64,
    /// World steps per rapier step (dimensionless, 1 to 40, [`MAX_RIGID_STEP_RATIO`]): the
    /// rigid bodies' orientations step at `rigid_step_ratio * dt_secs`; the omniwheel and floor
    /// contacts, wheels, motor drivers and sensors at `dt_secs`, with the ball's and body's
    /// motion predicted in between (module `world::rigid`). Default 1 (one rate, when missing
    /// from a file too); docs/world-speed.md, "Multi-rate world", measures the accuracy and speed
    /// of larger ratios.
    #[serde(default = "default_rigid_step_ratio")]
    #[schemars(range(min = 1, max = 40))]
    pub rigid_step_ratio: u32,
    /// Sensors.
    pub sensors: SensorParams,
    /// Failure limits.
    pub failure: FailureParams,
    /// The motor driver between torque command and wheel: [`DriverParams::miapure`] in the
    /// default world, [`DriverParams::ideal`] (the actuator's straight torque-speed line) in
    /// the ideal one and when missing from a file.
    #[serde(default)]
    pub driver: DriverParams,
    /// The drivetrain between each motor and its omniwheel: gearbox stiction, elastomeric
    /// coupling, backlash ([`crate::world::transmission`]). [`TransmissionParams::miapure`] in
    /// the default world, [`TransmissionParams::rigid`] (one inertia, no gearbox friction) in
    /// the ideal one and when missing from a file. Values and their sources:
    /// docs/world-drivetrain.md, "Drivetrain".
    #[serde(default)]
    pub transmission: TransmissionParams,
}

impl WorldParams {
    /// MiaPURE with a 60 kg payload in the default world ([`WorldParams::realistic`]).
    pub fn miapure_60kg() -> Self {
        Self::with_robot(BallbotParams::miapure_60kg())
    }

    /// The given robot in the ideal world: stiff continuous-rim omniwheel contacts without
    /// forces along the axle, and the actuator's straight torque-speed line (the world of the
    /// first releases; every mechanism of the realistic world switched off).
    pub fn ideal(robot: BallbotParams<f64>) -> Self {
        Self {
            robot,
            contact: ContactParams::ideal(),
            wheel_inertia_kg_m2: 1.2e-3,
            rotor_inertia_kg_m2: 1.5e-4,
            wheel_damping_nm_s_per_rad: 0.02,
            floor: FloorParams::miapure(),
            rolling_resistance: 0.015,
            spin_friction_m: 0.01,
            chassis_half_width_m: 0.18,
            chassis_height_m: 0.45,
            dt_secs: INNER_LOOP_DT_SECS,
            rigid_step_ratio: 1,
            sensors: SensorParams::default(),
            failure: FailureParams::default(),
            driver: DriverParams::ideal(),
            transmission: TransmissionParams::rigid(),
        }
    }

    /// The given robot in the most realistic world we can defend: roller gaps
    /// ([`RollerParams::miapure`]), roller losses along the axle ([`AxleLossParams::miapure`])
    /// and the rubber coating's stiffness and damping ([`ContactParams::rubber_coated`] of
    /// [`RubberLayer::miapure`]), the ODrive v3.6 motor driver at 45 V
    /// ([`DriverParams::miapure`]) and the drivetrain with gearbox stiction, an elastomeric
    /// coupling and backlash ([`TransmissionParams::miapure`]); docs/world-contacts.md and
    /// docs/world-drivetrain.md. Its sensors are the
    /// ideal world's; [`SensorParams::miapure`] (the VN-100's attitude filter and the link
    /// latency) is not in it yet: docs/world-sensing.md says why.
    pub fn realistic(robot: BallbotParams<f64>) -> Self {
        let mut p = Self::ideal(robot);
        p.driver = DriverParams::miapure();
        p.transmission = TransmissionParams::miapure();
        p.contact = ContactParams {
            rollers: RollerParams::miapure(),
            axle_loss: AxleLossParams::miapure(),
            ..ContactParams::coating()
        };
        p.rigid_step_ratio = DEFAULT_RIGID_STEP_RATIO.min(p.max_rigid_step_ratio());
        p
    }

    /// The given robot in the default world: [`WorldParams::realistic`].
    pub fn with_robot(robot: BallbotParams<f64>) -> Self {
        Self::realistic(robot)
    }

    /// The static load of one omniwheel contact, `m_U g / (3 cos alpha)` (N).
    pub fn static_wheel_load_n(&self) -> f64 {
        let wip = &self.robot.sagittal;
        wip.body_mass_kg * wip.gravity_m_per_s2
            / (3.0 * self.robot.drivetrain.contact_angle_rad.cos())
    }

    /// The omniwheel contact's normal law as the world evaluates it: the `linear`
    /// spring-damper, or the coating's law of [`Self::floor`]'s layer pressed by the roller
    /// with the damping `eta / omega_0`, `omega_0` the ball-against-body mode
    /// `sqrt(3 k_0 cos^2(alpha) / m_eff)` on the law's tangent `k_0` at the static load
    /// (`m_eff = m_B m_U / (m_B + m_U)`; [`crate::world::rubber`], item 5).
    pub fn wheel_normal_law(&self) -> NormalLaw {
        let c = &self.contact;
        match c.normal_law {
            ContactNormalLaw::Linear => NormalLaw::Linear {
                stiffness_n_per_m: c.normal_stiffness_n_per_m,
                damping_n_s_per_m: c.normal_damping_n_s_per_m,
            },
            ContactNormalLaw::Coating => {
                let layer = RubberLayer {
                    roller_radius_m: c.roller_radius_m,
                    ..self.floor.coating()
                };
                let r_e = layer.equivalent_radius_m(
                    self.robot.drivetrain.wheel_radius_m,
                    self.robot.ball_radius_m(),
                );
                let law = CoatingLaw::new(&layer, r_e);
                let k_0 = law
                    .evaluate(law.deflection_m(self.static_wheel_load_n()))
                    .stiffness_n_per_m;
                let wip = &self.robot.sagittal;
                let m_eff =
                    wip.ball_mass_kg * wip.body_mass_kg / (wip.ball_mass_kg + wip.body_mass_kg);
                let cos_a = self.robot.drivetrain.contact_angle_rad.cos();
                let omega = (3.0 * k_0 * cos_a * cos_a / m_eff).sqrt();
                NormalLaw::Coating {
                    law,
                    damping_secs: if omega > 0.0 {
                        layer.loss_factor / omega
                    } else {
                        0.0
                    },
                }
            }
        }
    }

    /// The ball's vertical frequency on its three omniwheel contacts,
    /// `sqrt(3 k cos^2(alpha) / m_B)` (rad/s), with `k` the contact's normal stiffness (the
    /// tangent at the static load, [`Self::static_wheel_load_n`]) and `alpha` the contact
    /// angle: about 910 rad/s in the ideal world, 365 in the default one.
    pub fn ball_contact_frequency_rad_per_s(&self) -> f64 {
        let cos_a = self.robot.drivetrain.contact_angle_rad.cos();
        let k = self
            .wheel_normal_law()
            .stiffness_n_per_m(self.static_wheel_load_n());
        (3.0 * k * cos_a * cos_a / self.robot.sagittal.ball_mass_kg).sqrt()
    }

    /// The largest [`WorldParams::rigid_step_ratio`] these parameters allow: at most
    /// [`MAX_RIGID_STEP_RATIO`], and the rigid step's phase on the ball's contact mode at most
    /// [`MAX_BALL_CONTACT_PHASE_RAD`]; at least 1.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// use ballbot_world::world::WorldParams;
    /// assert_eq!(WorldParams::ideal(BallbotParams::miapure_60kg()).max_rigid_step_ratio(), 10);
    /// assert_eq!(WorldParams::miapure_60kg().max_rigid_step_ratio(), 26);
    /// ```
    pub fn max_rigid_step_ratio(&self) -> u32 {
        let phase_per_step = self.ball_contact_frequency_rad_per_s() * self.dt_secs;
        let ratio = (MAX_BALL_CONTACT_PHASE_RAD / phase_per_step).floor();
        if ratio.is_finite() {
            (ratio as u32).clamp(1, MAX_RIGID_STEP_RATIO)
        } else {
            1
        }
    }

    /// The rigid bodies' step, `rigid_step_ratio * dt_secs` (s).
    pub fn rigid_step_secs(&self) -> f64 {
        self.dt_secs * f64::from(self.rigid_step_ratio)
    }

    /// Reflected inertia of one wheel: wheel plus rotor times gear ratio squared (kg m^2).
    pub fn reflected_wheel_inertia_kg_m2(&self) -> f64 {
        let n = self.robot.drivetrain.actuator.gear_ratio;
        self.wheel_inertia_kg_m2 + self.rotor_inertia_kg_m2 * n * n
    }

    /// The inertia that turns one wheel's speed into the spin angular momentum of its wheel and
    /// rotor: `I_w + n I_r` (kg m^2), the rotor turning at `n` times the wheel's speed about a
    /// parallel axis in the same sense (a planetary stage). Smaller than
    /// [`Self::reflected_wheel_inertia_kg_m2`] (`I_w + n^2 I_r`) whenever `n > 1`: the gear
    /// train takes the rest of the motor's reaction.
    pub fn wheel_spin_momentum_inertia_kg_m2(&self) -> f64 {
        let n = self.robot.drivetrain.actuator.gear_ratio;
        self.wheel_inertia_kg_m2 + self.rotor_inertia_kg_m2 * n
    }

    /// One omniwheel's drivetrain with these parameters ([`crate::world::transmission`]).
    pub fn drivetrain(&self) -> Drivetrain {
        Drivetrain::new(
            self.transmission,
            self.robot.drivetrain.actuator.gear_ratio,
            self.rotor_inertia_kg_m2,
            self.wheel_inertia_kg_m2,
            self.wheel_damping_nm_s_per_rad,
        )
    }

    /// Checks every field; the error names the first one out of range.
    pub fn validate(&self) -> Result<(), WorldError> {
        self.robot.validate()?;
        let c = &self.contact;
        positive(c.roller_radius_m, "contact.roller_radius_m")?;
        positive(
            c.normal_stiffness_n_per_m,
            "contact.normal_stiffness_n_per_m",
        )?;
        non_negative(
            c.normal_damping_n_s_per_m,
            "contact.normal_damping_n_s_per_m",
        )?;
        positive(
            c.traction_stiffness_n_per_m,
            "contact.traction_stiffness_n_per_m",
        )?;
        non_negative(
            c.traction_damping_n_s_per_m,
            "contact.traction_damping_n_s_per_m",
        )?;
        if !(c.kinetic_friction_ratio > 0.0 && c.kinetic_friction_ratio <= 1.0) {
            return Err(WorldError::InvalidParameter {
                field: "contact.kinetic_friction_ratio",
                requirement: "must be in (0, 1]",
            });
        }
        c.rollers.validate(self.robot.drivetrain.wheel_radius_m)?;
        c.axle_loss.validate()?;
        positive(self.wheel_inertia_kg_m2, "wheel_inertia_kg_m2")?;
        non_negative(self.rotor_inertia_kg_m2, "rotor_inertia_kg_m2")?;
        non_negative(
            self.wheel_damping_nm_s_per_rad,
            "wheel_damping_nm_s_per_rad",
        )?;
        self.floor.validate()?;
        non_negative(self.rolling_resistance, "rolling_resistance")?;
        non_negative(self.spin_friction_m, "spin_friction_m")?;
        positive(self.chassis_half_width_m, "chassis_half_width_m")?;
        positive(self.chassis_height_m, "chassis_height_m")?;
        positive(self.dt_secs, "dt_secs")?;
        if !(1..=MAX_RIGID_STEP_RATIO).contains(&self.rigid_step_ratio) {
            return Err(WorldError::InvalidParameter {
                field: "rigid_step_ratio",
                requirement: "must be in 1..=40",
            });
        }
        if self.rigid_step_ratio > self.max_rigid_step_ratio() {
            return Err(WorldError::InvalidParameter {
                field: "rigid_step_ratio",
                requirement: "must keep ball_contact_frequency_rad_per_s * rigid_step_ratio * \
                              dt_secs <= 1.2 (MAX_BALL_CONTACT_PHASE_RAD; \
                              WorldParams::max_rigid_step_ratio gives the largest)",
            });
        }
        positive(self.failure.max_tilt_rad, "failure.max_tilt_rad")?;
        let f = &self.failure;
        non_negative(
            f.slip_speed_threshold_m_per_s,
            "failure.slip_speed_threshold_m_per_s",
        )?;
        non_negative(f.max_slip_duration_secs, "failure.max_slip_duration_secs")?;
        non_negative(f.lift_off_force_n, "failure.lift_off_force_n")?;
        non_negative(
            f.max_lift_off_duration_secs,
            "failure.max_lift_off_duration_secs",
        )?;
        self.driver.validate()?;
        if !self.transmission.is_rigid() && self.rotor_inertia_kg_m2 <= 0.0 {
            return Err(WorldError::InvalidParameter {
                field: "rotor_inertia_kg_m2",
                requirement: "must be > 0 when the drivetrain is compliant \
                              (transmission.coupling_stiffness_nm_per_rad > 0): the motor side \
                              needs an inertia",
            });
        }
        self.transmission
            .validate(self.drivetrain().stuck_inertia_kg_m2(), self.dt_secs)?;
        non_negative(self.sensors.tilt_noise_rad, "sensors.tilt_noise_rad")?;
        non_negative(
            self.sensors.gyro_noise_rad_per_s,
            "sensors.gyro_noise_rad_per_s",
        )?;
        if self.sensors.encoder_counts_per_rev == 0 {
            return Err(WorldError::InvalidParameter {
                field: "sensors.encoder_counts_per_rev",
                requirement: "must be > 0",
            });
        }
        non_negative(self.sensors.link_latency_secs, "sensors.link_latency_secs")?;
        self.sensors.imu.validate(self.dt_secs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn miapure_coating_is_soft_and_lightly_damped() {
        let robot = BallbotParams::miapure_60kg();
        let c = ContactParams::rubber_coated(&robot, &RubberLayer::miapure());
        assert!(
            (c.normal_stiffness_n_per_m - 3.37e5).abs() < 0.01e5,
            "{c:?}"
        );
        assert!((c.normal_damping_n_s_per_m - 87.8).abs() < 0.5, "{c:?}");
        // Damping ratio of the vertical mode is eta / 2.
        let m_eff = 3.6 * 74.3 / (3.6 + 74.3);
        let k_v = 1.5 * c.normal_stiffness_n_per_m;
        let zeta = 1.5 * c.normal_damping_n_s_per_m / (2.0 * (k_v * m_eff).sqrt());
        assert!((zeta - 0.05).abs() < 1e-9, "{zeta}");
        assert_eq!(
            c.traction_stiffness_n_per_m,
            ContactParams::ideal().traction_stiffness_n_per_m
        );
    }

    #[test]
    fn the_default_worlds_wheel_contact_is_the_coatings_whole_range_law() {
        let p = WorldParams::miapure_60kg();
        assert_eq!(p.contact.normal_law, ContactNormalLaw::Coating);
        let NormalLaw::Coating { law, damping_secs } = p.wheel_normal_law() else {
            panic!("{:?}", p.wheel_normal_law());
        };
        // 343.6 N per wheel; 2.64 mm under the roller (module rubber, item 6), against the
        // linear fit's 1.0 mm.
        let load = p.static_wheel_load_n();
        assert!((load - 343.6).abs() < 0.1, "{load}");
        let d = law.deflection_m(load);
        assert!((d - 2.64e-3).abs() < 0.01e-3, "{d}");
        assert!((law.evaluate(d).force_n - load).abs() < 1e-9);
        let linear = ContactParams::rubber_coated(&p.robot, &RubberLayer::miapure());
        assert!(load / linear.normal_stiffness_n_per_m < 1.05e-3);
        // The damping is the loss factor's at the ball-against-body mode on the tangent:
        // damping ratio eta / 2 there.
        let k = law.evaluate(d).stiffness_n_per_m;
        let m_eff = 3.6 * 74.3 / (3.6 + 74.3);
        let (k_v, c_v) = (1.5 * k, 1.5 * damping_secs * k);
        let zeta = c_v / (2.0 * (k_v * m_eff).sqrt());
        assert!((zeta - 0.05).abs() < 1e-9, "{zeta}");
        // The ideal world keeps its linear spring.
        let ideal = WorldParams::ideal(p.robot);
        assert!(matches!(ideal.wheel_normal_law(), NormalLaw::Linear { .. }));
    }
}
