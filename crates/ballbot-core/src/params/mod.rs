//! Physical parameters, validated once, and the presets of the paper's robots.
//!
//! Every field carries its unit in its name. Values labelled *estimate* in the docs are
//! engineering estimates standing in for the paper's missing parameter table (see
//! `docs/model.md`); they are parameters, never hidden constants.

use crate::Error;
use crate::check::{finite, lit, non_negative, positive};
use nalgebra::RealField;

/// One plane of the wheeled inverted pendulum (WIP): ball plus upper body.
///
/// The upper body is everything but the ball (chassis, omniwheels, payload).
///
/// ```
/// use ballbot_core::{Wip, WipParams};
/// // A variant of a preset: MiaPURE with a lighter, 40 kg payload.
/// let params = WipParams {
///     body_mass_kg: 54.3,
///     ..WipParams::<f64>::miapure_60kg()
/// };
/// params.validate()?;
/// // A lighter body falls more slowly.
/// let light = Wip::new(params)?.upright_unstable_pole_rad_per_s();
/// assert!(light < Wip::new(WipParams::miapure_60kg())?.upright_unstable_pole_rad_per_s());
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct WipParams<T> {
    /// Ball radius `r` (m). For the PIPTB, the wheel radius.
    pub ball_radius_m: T,
    /// Ball mass `m_S` (kg).
    pub ball_mass_kg: T,
    /// Ball moment of inertia about its centre `I_S` (kg m^2).
    pub ball_inertia_kg_m2: T,
    /// Upper-body mass `m_U` (kg), payload included.
    pub body_mass_kg: T,
    /// Distance `l` from the ball centre to the upper body's centre of mass (m).
    pub com_height_m: T,
    /// Upper-body moment of inertia about its own centre of mass, about the plane's
    /// horizontal axis, `I_U` (kg m^2).
    pub body_inertia_kg_m2: T,
    /// Omniwheel plus rotor inertia reflected onto the relative rate `phi_dot - theta_dot`,
    /// `I_W` (kg m^2); 0 neglects it.
    pub wheel_inertia_kg_m2: T,
    /// Viscous friction between ball and floor, on `phi_dot`, `b_k` (N m s/rad).
    pub ball_damping_nm_s_per_rad: T,
    /// Viscous drivetrain friction on the relative rate `phi_dot - theta_dot`, `b_m`
    /// (N m s/rad).
    pub drive_damping_nm_s_per_rad: T,
    /// Gravitational acceleration `g` (m/s^2).
    pub gravity_m_per_s2: T,
}

impl<T: RealField + Copy> WipParams<T> {
    /// MiaPURE carrying a 60 kg payload (one plane; sagittal and frontal are alike).
    ///
    /// Ball: 22.9 cm, 3.6 kg, 0.047 kg m^2 (paper). Upper body 74.3 kg = 17.9 - 3.6 + 60
    /// (derived). COM height 0.50 m and body inertia 4.0 kg m^2 are estimates (seated-human
    /// COM with the chassis). Frictions and wheel inertia are 0: the nominal design model.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let params = WipParams::<f64>::miapure_60kg();
    /// // Robot (17.9 kg) plus payload (60 kg), ball included.
    /// approx::assert_relative_eq!(
    ///     params.ball_mass_kg + params.body_mass_kg,
    ///     77.9,
    ///     epsilon = 1e-12
    /// );
    /// // MODEL.md section 6: open-loop poles 0, 0, +-8.04 rad/s.
    /// approx::assert_relative_eq!(
    ///     Wip::new(params)?.upright_unstable_pole_rad_per_s(),
    ///     8.04,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            ball_radius_m: lit(0.1145),
            ball_mass_kg: lit(3.6),
            ball_inertia_kg_m2: lit(0.047),
            body_mass_kg: lit(74.3),
            com_height_m: lit(0.50),
            body_inertia_kg_m2: lit(4.0),
            wheel_inertia_kg_m2: T::zero(),
            ball_damping_nm_s_per_rad: T::zero(),
            drive_damping_nm_s_per_rad: T::zero(),
            gravity_m_per_s2: lit(9.81),
        }
    }

    /// MiaPURE without payload: the 14.3 kg drivetrain chassis alone.
    ///
    /// COM height 0.20 m and body inertia 0.40 kg m^2 are estimates (a 14.3 kg,
    /// 0.45 x 0.36 x 0.36 m box whose centre sits 0.2 m above the ball centre).
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let params = WipParams::<f64>::miapure_unloaded();
    /// // The 14.3 kg chassis on the same 3.6 kg ball.
    /// assert_eq!(params.body_mass_kg, 14.3);
    /// assert_eq!(
    ///     params.ball_radius_m,
    ///     WipParams::<f64>::miapure_60kg().ball_radius_m
    /// );
    /// // Lower COM, lighter body: the upright falls more slowly than with payload (6.89 rad/s).
    /// approx::assert_relative_eq!(
    ///     Wip::new(params)?.upright_unstable_pole_rad_per_s(),
    ///     6.89,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            body_mass_kg: lit(14.3),
            com_height_m: lit(0.20),
            body_inertia_kg_m2: lit(0.40),
            ..Self::miapure_60kg()
        }
    }

    /// The planar inverted-pendulum testbed (PIPTB).
    ///
    /// The paper gives only "half the size, one fifth of the weight of MiaPURE with payload";
    /// every number here is an estimate: wheel 0.0573 m, 0.9 kg, inertia 0.5 m r^2; body
    /// 14.7 kg, COM 0.25 m, 0.25 kg m^2.
    ///
    /// ```
    /// use ballbot_core::{Wip, WipParams};
    /// let piptb = WipParams::<f64>::piptb();
    /// let mia = WipParams::<f64>::miapure_60kg();
    /// // "One fifth of the weight of MiaPURE with payload" and half its ball size.
    /// let mass_ratio =
    ///     (piptb.ball_mass_kg + piptb.body_mass_kg) / (mia.ball_mass_kg + mia.body_mass_kg);
    /// approx::assert_relative_eq!(mass_ratio, 0.2, epsilon = 0.001);
    /// approx::assert_relative_eq!(
    ///     piptb.ball_radius_m / mia.ball_radius_m,
    ///     0.5,
    ///     epsilon = 0.001
    /// );
    /// // The smaller pendulum falls faster: 10.50 rad/s.
    /// approx::assert_relative_eq!(
    ///     Wip::new(piptb)?.upright_unstable_pole_rad_per_s(),
    ///     10.50,
    ///     epsilon = 0.005
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn piptb() -> Self {
        let wheel_radius_m: T = lit(0.0573);
        let wheel_mass_kg: T = lit(0.9);
        Self {
            ball_radius_m: wheel_radius_m,
            ball_mass_kg: wheel_mass_kg,
            ball_inertia_kg_m2: lit::<T>(0.5) * wheel_mass_kg * wheel_radius_m * wheel_radius_m,
            body_mass_kg: lit(14.7),
            com_height_m: lit(0.25),
            body_inertia_kg_m2: lit(0.25),
            wheel_inertia_kg_m2: T::zero(),
            ball_damping_nm_s_per_rad: T::zero(),
            drive_damping_nm_s_per_rad: T::zero(),
            gravity_m_per_s2: lit(9.81),
        }
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{Error, WipParams};
    /// assert_eq!(WipParams::<f64>::piptb().validate(), Ok(()));
    /// // Friction may be zero but not negative; the error names the field.
    /// let params = WipParams {
    ///     ball_damping_nm_s_per_rad: -0.1,
    ///     ..WipParams::<f64>::piptb()
    /// };
    /// assert_eq!(
    ///     params.validate(),
    ///     Err(Error::invalid(
    ///         "ball_damping_nm_s_per_rad",
    ///         "must be finite and >= 0"
    ///     ))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.ball_radius_m, "ball_radius_m")?;
        positive(self.ball_mass_kg, "ball_mass_kg")?;
        positive(self.ball_inertia_kg_m2, "ball_inertia_kg_m2")?;
        positive(self.body_mass_kg, "body_mass_kg")?;
        positive(self.com_height_m, "com_height_m")?;
        positive(self.body_inertia_kg_m2, "body_inertia_kg_m2")?;
        non_negative(self.wheel_inertia_kg_m2, "wheel_inertia_kg_m2")?;
        non_negative(self.ball_damping_nm_s_per_rad, "ball_damping_nm_s_per_rad")?;
        non_negative(
            self.drive_damping_nm_s_per_rad,
            "drive_damping_nm_s_per_rad",
        )?;
        positive(self.gravity_m_per_s2, "gravity_m_per_s2")?;
        Ok(())
    }
}

/// The spin (yaw) model: `I_z theta_z_ddot + D_z theta_z_dot = tau_z`.
///
/// ```
/// use ballbot_core::{Spin, SpinParams};
/// // A heavier, better-lubricated variant.
/// let spin = Spin::new(SpinParams {
///     inertia_kg_m2: 2.5,
///     damping_nm_s_per_rad: 0.5,
/// })?;
/// // The yaw rate of a coasting robot decays with time constant I_z / D_z = 5 s.
/// let (a, _) = spin.state_space();
/// approx::assert_relative_eq!(-1.0 / a[(1, 1)], 5.0, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct SpinParams<T> {
    /// Lumped yaw inertia of upper body and omniwheels `I_z` (kg m^2).
    pub inertia_kg_m2: T,
    /// Viscous yaw friction `D_z` (N m s/rad).
    pub damping_nm_s_per_rad: T,
}

impl<T: RealField + Copy> SpinParams<T> {
    /// MiaPURE with 60 kg payload: I_z 1.8 kg m^2, D_z 1.0 N m s/rad (both estimates).
    ///
    /// ```
    /// use ballbot_core::SpinParams;
    /// let spin = SpinParams::<f64>::miapure_60kg();
    /// assert_eq!((spin.inertia_kg_m2, spin.damping_nm_s_per_rad), (1.8, 1.0));
    /// // The payload dominates the yaw inertia: about 5 times the unloaded chassis's.
    /// assert!(spin.inertia_kg_m2 > 5.0 * SpinParams::<f64>::miapure_unloaded().inertia_kg_m2);
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            inertia_kg_m2: lit(1.8),
            damping_nm_s_per_rad: lit(1.0),
        }
    }

    /// MiaPURE without payload: I_z 0.35 kg m^2 (estimate: chassis box plus wheels),
    /// D_z 1.0 N m s/rad (estimate).
    ///
    /// ```
    /// use ballbot_core::SpinParams;
    /// let spin = SpinParams::<f32>::miapure_unloaded();
    /// assert_eq!(spin.inertia_kg_m2, 0.35);
    /// assert_eq!(spin.validate(), Ok(()));
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            inertia_kg_m2: lit(0.35),
            damping_nm_s_per_rad: lit(1.0),
        }
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{Error, SpinParams};
    /// let spin = SpinParams {
    ///     inertia_kg_m2: f64::NAN,
    ///     damping_nm_s_per_rad: 1.0,
    /// };
    /// assert_eq!(
    ///     spin.validate(),
    ///     Err(Error::invalid("inertia_kg_m2", "must be finite and > 0"))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.inertia_kg_m2, "inertia_kg_m2")?;
        non_negative(self.damping_nm_s_per_rad, "damping_nm_s_per_rad")?;
        Ok(())
    }
}

/// One actuator (motor plus gearbox), its limits stated at the output (the omniwheel).
///
/// ```
/// use ballbot_core::ActuatorParams;
/// // A weaker actuator: 20 N m peak, 80 rad/s no-load at the wheel.
/// let weak = ActuatorParams {
///     peak_torque_nm: 20.0,
///     no_load_speed_rad_per_s: 80.0,
///     ..ActuatorParams::<f64>::miapure()
/// };
/// weak.validate()?;
/// // At half the no-load speed, half the peak is left for motoring, all of it for braking.
/// assert_eq!(weak.torque_bounds_nm(40.0), (-20.0, 10.0));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ActuatorParams<T> {
    /// Gear ratio, rotor turns per output turn (dimensionless).
    pub gear_ratio: T,
    /// Peak torque at the output (N m).
    pub peak_torque_nm: T,
    /// No-load speed at the output (rad/s); the available torque falls linearly to zero there.
    pub no_load_speed_rad_per_s: T,
}

impl<T: RealField + Copy> ActuatorParams<T> {
    /// The T-motor QDD actuator of MiaPURE: ratio 7.5, 43.2 N m peak, 62 rad/s no-load at
    /// 45 V (paper). The PIPTB uses similar hardware (paper); we assume the same actuator.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// assert_eq!(
    ///     (
    ///         qdd.gear_ratio,
    ///         qdd.peak_torque_nm,
    ///         qdd.no_load_speed_rad_per_s
    ///     ),
    ///     (7.5, 43.2, 62.0)
    /// );
    /// // The rotor's peak torque is the output's divided by the ratio: 5.76 N m.
    /// approx::assert_relative_eq!(qdd.peak_torque_nm / qdd.gear_ratio, 5.76, epsilon = 1e-12);
    /// ```
    pub fn miapure() -> Self {
        Self {
            gear_ratio: lit(7.5),
            peak_torque_nm: lit(43.2),
            no_load_speed_rad_per_s: lit(62.0),
        }
    }

    /// The output torque range `(min, max)` (N m) available at output speed
    /// `speed_rad_per_s`: the current limit `peak_torque_nm`, and, when the torque drives in
    /// the direction of motion, the line from the peak at rest to 0 at the no-load speed.
    /// Torque against the motion (braking) may use the full peak.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// // At rest: the full 43.2 N m either way.
    /// assert_eq!(qdd.torque_bounds_nm(0.0), (-43.2, 43.2));
    /// // Turning forward at half the no-load speed (31 rad/s): 21.6 N m left to speed up,
    /// // the full peak to brake; mirrored when turning backwards.
    /// let (lo, hi) = qdd.torque_bounds_nm(31.0);
    /// approx::assert_relative_eq!(hi, 21.6, epsilon = 1e-12);
    /// assert_eq!(lo, -43.2);
    /// assert_eq!(qdd.torque_bounds_nm(-31.0), (-hi, 43.2));
    /// // Beyond the no-load speed nothing is left for motoring.
    /// assert_eq!(qdd.torque_bounds_nm(70.0).1, 0.0);
    /// ```
    pub fn torque_bounds_nm(&self, speed_rad_per_s: T) -> (T, T) {
        let peak = self.peak_torque_nm;
        let line = peak * (T::one() - speed_rad_per_s.abs() / self.no_load_speed_rad_per_s);
        let motoring = line.max(T::zero()).min(peak);
        if speed_rad_per_s > T::zero() {
            (-peak, motoring)
        } else if speed_rad_per_s < T::zero() {
            (-motoring, peak)
        } else {
            (-peak, peak)
        }
    }

    /// `torque_nm` clamped to [`Self::torque_bounds_nm`] at `speed_rad_per_s`; a non-finite
    /// request gives 0.
    ///
    /// ```
    /// use ballbot_core::ActuatorParams;
    /// let qdd = ActuatorParams::<f64>::miapure();
    /// // 30 N m asked at 31 rad/s forward: only 21.6 N m can drive, braking passes in full.
    /// approx::assert_relative_eq!(qdd.clamp_torque_nm(30.0, 31.0), 21.6, epsilon = 1e-12);
    /// assert_eq!(qdd.clamp_torque_nm(-30.0, 31.0), -30.0);
    /// // A non-finite request (a failed computation upstream) gives no torque.
    /// assert_eq!(qdd.clamp_torque_nm(f64::NAN, 0.0), 0.0);
    /// ```
    pub fn clamp_torque_nm(&self, torque_nm: T, speed_rad_per_s: T) -> T {
        if !torque_nm.is_finite() {
            return T::zero();
        }
        let (lo, hi) = self.torque_bounds_nm(speed_rad_per_s);
        torque_nm.max(lo).min(hi)
    }

    /// Checks every field; the error names the first field out of range.
    ///
    /// ```
    /// use ballbot_core::{ActuatorParams, Error};
    /// let no_gearbox = ActuatorParams {
    ///     gear_ratio: 0.0,
    ///     ..ActuatorParams::<f64>::miapure()
    /// };
    /// assert_eq!(
    ///     no_gearbox.validate(),
    ///     Err(Error::invalid("gear_ratio", "must be finite and > 0"))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.gear_ratio, "gear_ratio")?;
        positive(self.peak_torque_nm, "peak_torque_nm")?;
        positive(self.no_load_speed_rad_per_s, "no_load_speed_rad_per_s")?;
        Ok(())
    }
}

/// Number of omniwheels. The kinematics and the controllers are written for three.
///
/// ```
/// use ballbot_core::{DrivetrainParams, WHEEL_COUNT};
/// assert_eq!(
///     DrivetrainParams::<f64>::miapure().wheel_azimuths_rad.len(),
///     WHEEL_COUNT
/// );
/// ```
pub const WHEEL_COUNT: usize = 3;

/// The omniwheel drivetrain geometry (MODEL.md section 1) and its actuators.
///
/// ```
/// use ballbot_core::{DrivetrainParams, OmniKinematics};
/// // MiaPURE's drivetrain with the contacts nearer the top of the ball (40 deg from the vertical).
/// let steep = DrivetrainParams {
///     contact_angle_rad: 40f64.to_radians(),
///     ..DrivetrainParams::miapure()
/// };
/// let kin = OmniKinematics::new(steep, 0.1145)?;
/// let nominal = OmniKinematics::new(DrivetrainParams::miapure(), 0.1145)?;
/// // That trades yaw torque capacity for tilt torque capacity.
/// let (cap, cap0) = (
///     kin.planar_torque_capacity_nm(),
///     nominal.planar_torque_capacity_nm(),
/// );
/// assert!(cap[1] > cap0[1] && cap[2] < cap0[2]);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct DrivetrainParams<T> {
    /// Azimuth `beta_i` of each omniwheel's contact, counter-clockwise from the body x axis
    /// seen from above (rad). MiaPURE: 0, 120, 240 deg.
    pub wheel_azimuths_rad: [T; WHEEL_COUNT],
    /// Contact angle `alpha` between the vertical and the line from the ball centre to each
    /// contact (rad), in (0, pi/2). MiaPURE: 45 deg.
    pub contact_angle_rad: T,
    /// Omniwheel radius `r_W` (m).
    pub wheel_radius_m: T,
    /// Each omniwheel's actuator.
    pub actuator: ActuatorParams<T>,
    /// Friction coefficient between omniwheel rollers and ball (estimate 0.6: TPU on rubber).
    pub wheel_ball_friction: T,
    /// Friction coefficient between ball and floor (estimate 0.9).
    pub ball_floor_friction: T,
}

impl<T: RealField + Copy> DrivetrainParams<T> {
    /// MiaPURE: wheels at 0, 120, 240 deg, 45 deg contact angle, 125 mm omniwheels, the QDD
    /// actuator (paper); friction coefficients are estimates.
    ///
    /// ```
    /// use ballbot_core::DrivetrainParams;
    /// let d = DrivetrainParams::<f64>::miapure();
    /// // Wheels 120 deg apart, contacts 45 deg from the vertical, 125 mm omniwheels.
    /// approx::assert_relative_eq!(
    ///     d.wheel_azimuths_rad[2] - d.wheel_azimuths_rad[1],
    ///     120f64.to_radians()
    /// );
    /// approx::assert_relative_eq!(d.contact_angle_rad, std::f64::consts::FRAC_PI_4);
    /// assert_eq!(2.0 * d.wheel_radius_m, 0.125);
    /// ```
    pub fn miapure() -> Self {
        let deg = T::pi() / lit(180.0);
        Self {
            wheel_azimuths_rad: [T::zero(), lit::<T>(120.0) * deg, lit::<T>(240.0) * deg],
            contact_angle_rad: lit::<T>(45.0) * deg,
            wheel_radius_m: lit(0.0625),
            actuator: ActuatorParams::miapure(),
            wheel_ball_friction: lit(0.6),
            ball_floor_friction: lit(0.9),
        }
    }

    /// Checks every field, including that the three wheels span all three rotation axes
    /// (a singular layout, e.g. two wheels at the same azimuth, is rejected).
    ///
    /// ```
    /// use ballbot_core::{DrivetrainParams, Error};
    /// let mut d = DrivetrainParams::<f64>::miapure();
    /// d.validate()?;
    /// // Two wheels at the same azimuth cannot drive all three axes.
    /// d.wheel_azimuths_rad[2] = d.wheel_azimuths_rad[1];
    /// assert!(matches!(
    ///     d.validate(),
    ///     Err(Error::InvalidParameter {
    ///         field: "wheel_azimuths_rad",
    ///         ..
    ///     })
    /// ));
    /// // A contact at 90 deg from the vertical cannot carry the robot's weight.
    /// let flat = DrivetrainParams {
    ///     contact_angle_rad: std::f64::consts::FRAC_PI_2,
    ///     ..DrivetrainParams::miapure()
    /// };
    /// assert!(matches!(
    ///     flat.validate(),
    ///     Err(Error::InvalidParameter {
    ///         field: "contact_angle_rad",
    ///         ..
    ///     })
    /// ));
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        for beta in self.wheel_azimuths_rad {
            finite(beta, "wheel_azimuths_rad")?;
        }
        let a = self.contact_angle_rad;
        if !(a.is_finite() && a > T::zero() && a < T::frac_pi_2()) {
            return Err(Error::invalid(
                "contact_angle_rad",
                "must be in (0, pi/2) rad, i.e. (0, 90) deg",
            ));
        }
        positive(self.wheel_radius_m, "wheel_radius_m")?;
        self.actuator.validate()?;
        positive(self.wheel_ball_friction, "wheel_ball_friction")?;
        positive(self.ball_floor_friction, "ball_floor_friction")?;
        // The rows u_i = [-cos a cos b_i, -cos a sin b_i, sin a] must be independent. The
        // determinant is cos^2 a sin a times a purely azimuthal factor; compare that factor
        // with the best layout's (3 sqrt 3 / 2, wheels 120 deg apart).
        let [b1, b2, b3] = self.wheel_azimuths_rad;
        let azimuthal = (b2 - b1).sin() + (b3 - b2).sin() + (b1 - b3).sin();
        if azimuthal.abs() < lit(1e-3) {
            return Err(Error::invalid(
                "wheel_azimuths_rad",
                "wheel layout is singular: no two wheels may share an azimuth",
            ));
        }
        Ok(())
    }
}

/// A complete 3D ballbot: sagittal and frontal planes, spin, drivetrain.
///
/// ```
/// use ballbot_core::{BallbotParams, WipParams};
/// // MiaPURE carrying 60 kg, its payload's COM 10 cm higher in the frontal plane only.
/// let mut params = BallbotParams::<f64>::miapure_60kg();
/// params.frontal = WipParams {
///     com_height_m: 0.60,
///     ..params.frontal
/// };
/// params.validate()?;
/// assert_ne!(params.sagittal, params.frontal);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BallbotParams<T> {
    /// The sagittal plane (subscript y: travel along body x, rotation about y).
    pub sagittal: WipParams<T>,
    /// The frontal plane (subscript x: travel along body y, rotation about x).
    pub frontal: WipParams<T>,
    /// The spin model about the vertical.
    pub spin: SpinParams<T>,
    /// The omniwheel drivetrain.
    pub drivetrain: DrivetrainParams<T>,
}

impl<T: RealField + Copy> BallbotParams<T> {
    /// MiaPURE carrying a 60 kg payload.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, WipParams};
    /// let params = BallbotParams::<f64>::miapure_60kg();
    /// // The two planes are alike (a symmetric robot), and total 77.9 kg with the ball.
    /// assert_eq!(params.sagittal, params.frontal);
    /// assert_eq!(params.sagittal, WipParams::miapure_60kg());
    /// approx::assert_relative_eq!(
    ///     params.sagittal.body_mass_kg + params.sagittal.ball_mass_kg,
    ///     77.9
    /// );
    /// ```
    pub fn miapure_60kg() -> Self {
        Self {
            sagittal: WipParams::miapure_60kg(),
            frontal: WipParams::miapure_60kg(),
            spin: SpinParams::miapure_60kg(),
            drivetrain: DrivetrainParams::miapure(),
        }
    }

    /// MiaPURE without payload.
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// let empty = BallbotParams::<f64>::miapure_unloaded();
    /// let loaded = BallbotParams::<f64>::miapure_60kg();
    /// // Same drivetrain and ball, 60 kg less on top.
    /// assert_eq!(empty.drivetrain, loaded.drivetrain);
    /// approx::assert_relative_eq!(
    ///     loaded.frontal.body_mass_kg - empty.frontal.body_mass_kg,
    ///     60.0,
    ///     epsilon = 1e-12
    /// );
    /// ```
    pub fn miapure_unloaded() -> Self {
        Self {
            sagittal: WipParams::miapure_unloaded(),
            frontal: WipParams::miapure_unloaded(),
            spin: SpinParams::miapure_unloaded(),
            drivetrain: DrivetrainParams::miapure(),
        }
    }

    /// The ball radius shared by both planes (m).
    ///
    /// ```
    /// use ballbot_core::BallbotParams;
    /// // MiaPURE's ball is 22.9 cm across.
    /// assert_eq!(BallbotParams::<f64>::miapure_60kg().ball_radius_m(), 0.1145);
    /// ```
    pub fn ball_radius_m(&self) -> T {
        self.sagittal.ball_radius_m
    }

    /// Checks every part and that both planes agree on the ball.
    ///
    /// ```
    /// use ballbot_core::{BallbotParams, Error};
    /// // One ball: both planes must agree on its radius.
    /// let mut params = BallbotParams::<f64>::miapure_60kg();
    /// params.frontal.ball_radius_m = 0.12;
    /// assert_eq!(
    ///     params.validate(),
    ///     Err(Error::invalid(
    ///         "frontal.ball_radius_m",
    ///         "must equal sagittal.ball_radius_m (one ball)"
    ///     ))
    /// );
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.sagittal.validate()?;
        self.frontal.validate()?;
        self.spin.validate()?;
        self.drivetrain.validate()?;
        if self.sagittal.ball_radius_m != self.frontal.ball_radius_m {
            return Err(Error::invalid(
                "frontal.ball_radius_m",
                "must equal sagittal.ball_radius_m (one ball)",
            ));
        }
        Ok(())
    }
}

/// A planar robot (the PIPTB): one WIP plane driven by one actuator.
///
/// ```
/// use ballbot_core::{ActuatorParams, PlanarRobotParams};
/// // The PIPTB with an actuator of half the peak torque.
/// let actuator = ActuatorParams {
///     peak_torque_nm: 21.6,
///     ..ActuatorParams::<f64>::miapure()
/// };
/// let robot = PlanarRobotParams {
///     actuator,
///     ..PlanarRobotParams::piptb()
/// };
/// robot.validate()?;
/// assert_eq!(robot.actuator.torque_bounds_nm(0.0), (-21.6, 21.6));
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PlanarRobotParams<T> {
    /// The WIP plane.
    pub plane: WipParams<T>,
    /// The actuator driving the wheel directly (limits at the wheel).
    pub actuator: ActuatorParams<T>,
}

impl<T: RealField + Copy> PlanarRobotParams<T> {
    /// The PIPTB testbed (estimates, see [`WipParams::piptb`]).
    ///
    /// ```
    /// use ballbot_core::{ActuatorParams, PlanarRobotParams, WipParams};
    /// let robot = PlanarRobotParams::<f64>::piptb();
    /// assert_eq!(robot.plane, WipParams::piptb());
    /// assert_eq!(robot.actuator, ActuatorParams::miapure());
    /// // At the testbed's 1 m/s cruise the wheel turns at 17.5 rad/s, well below the 62 rad/s
    /// // no-load speed: 31 N m of the 43.2 N m peak is left to accelerate.
    /// let wheel_rate_rad_per_s = 1.0 / robot.plane.ball_radius_m;
    /// approx::assert_relative_eq!(wheel_rate_rad_per_s, 17.45, epsilon = 0.01);
    /// approx::assert_relative_eq!(
    ///     robot.actuator.torque_bounds_nm(wheel_rate_rad_per_s).1,
    ///     31.04,
    ///     epsilon = 0.01
    /// );
    /// ```
    pub fn piptb() -> Self {
        Self {
            plane: WipParams::piptb(),
            actuator: ActuatorParams::miapure(),
        }
    }

    /// Checks every part.
    ///
    /// ```
    /// use ballbot_core::{Error, PlanarRobotParams};
    /// let mut robot = PlanarRobotParams::<f64>::piptb();
    /// robot.validate()?;
    /// robot.actuator.no_load_speed_rad_per_s = f64::INFINITY;
    /// assert_eq!(
    ///     robot.validate(),
    ///     Err(Error::invalid(
    ///         "no_load_speed_rad_per_s",
    ///         "must be finite and > 0"
    ///     ))
    /// );
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        self.plane.validate()?;
        self.actuator.validate()
    }
}
