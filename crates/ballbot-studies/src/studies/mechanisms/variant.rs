//! What the mechanism study varies: which contact/driver mechanism of the world is switched
//! on ([`Mechanism`]), and which controller drives the robot ([`ControllerVariant`]).

use crate::studies::max_speed::{self, MaxSpeedProtocol};
use ballbot_core::ballbot::{BallbotControllerConfig, WheelMapping};
use ballbot_core::command::AxisLimits;
use ballbot_world::world::{
    AxleLossParams, ContactParams, DriverParams, RollerParams, SensorParams, TransmissionParams,
    WorldError, WorldParams,
};

/// A world variant: the ideal world, the ideal world with one realistic mechanism added, or
/// every mechanism of the default world at once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mechanism {
    /// [`WorldParams::ideal`]: stiff continuous-rim contacts, no axle forces, the straight
    /// torque-speed line.
    Ideal,
    /// Roller gaps ([`RollerParams::miapure`]: 10 rollers, 4 mm gaps): the effective wheel
    /// radius dips once per roller pitch.
    RollerGaps,
    /// Roller rolling resistance and pin friction along the axle
    /// ([`AxleLossParams::miapure`], 0.042 of the load), under one friction cone with the
    /// traction.
    AxleLosses,
    /// The rubber coating's law over its whole range at the wheels
    /// ([`ContactParams::coating`]: 2.64 mm under the static load, tangent 3.2e5 N/m, the
    /// loss factor's damping).
    RubberCoating,
    /// The ODrive v3.6 at 45 V configured for the paper's 43.2 N m ([`DriverParams::miapure`]):
    /// current limit, back-EMF and modulation limit, overspeed trip.
    MotorDriver,
    /// The drivetrain between motor and wheel ([`TransmissionParams::miapure`]): gearbox
    /// stiction (0.37 N m breakaway), an elastomeric coupling (3e3 N m/rad) and 0.22 deg of
    /// backlash, with the encoders on the motor side.
    Drivetrain,
    /// The sensors as the robot has them ([`SensorParams::miapure`]): the VN-100's
    /// accelerometer-aided attitude filter with its bias and delay, and the 1 ms link to the
    /// drivers. Not (yet) part of [`Self::All`], the default world (docs/world-sensing.md).
    Sensing,
    /// Every mechanism of the default world, [`WorldParams::realistic`] (all but
    /// [`Self::Sensing`]).
    All,
}

impl Mechanism {
    /// Every variant, the ideal world first and all mechanisms together last.
    pub const ALL: [Self; 8] = [
        Self::Ideal,
        Self::RollerGaps,
        Self::AxleLosses,
        Self::RubberCoating,
        Self::MotorDriver,
        Self::Drivetrain,
        Self::Sensing,
        Self::All,
    ];

    /// The canonical (snake_case) name, used as the summary's key.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Ideal => "ideal",
            Self::RollerGaps => "roller_gaps",
            Self::AxleLosses => "axle_losses",
            Self::RubberCoating => "rubber_coating",
            Self::MotorDriver => "motor_driver",
            Self::Drivetrain => "drivetrain",
            Self::Sensing => "sensing",
            Self::All => "all",
        }
    }

    /// A short description for tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Self::Ideal => "ideal contact and drive",
            Self::RollerGaps => "+ roller gaps",
            Self::AxleLosses => "+ roller losses along the axle",
            Self::RubberCoating => "+ rubber coating's law at the wheels",
            Self::MotorDriver => "+ ODrive v3.6 driver limits",
            Self::Drivetrain => "+ gearbox stiction, coupling and backlash",
            Self::Sensing => "+ VN-100 attitude filter and link latency",
            Self::All => "all mechanisms (the default world)",
        }
    }

    /// The world of this variant for `robot`: [`WorldParams::ideal`] with the mechanism's
    /// realistic parameters switched on.
    pub fn params(self, robot: ballbot_core::BallbotParams<f64>) -> WorldParams {
        let mut p = WorldParams::ideal(robot);
        match self {
            Self::Ideal => {}
            Self::RollerGaps => p.contact.rollers = RollerParams::miapure(),
            Self::AxleLosses => p.contact.axle_loss = AxleLossParams::miapure(),
            Self::RubberCoating => {
                p.contact = ContactParams::coating();
            }
            Self::MotorDriver => p.driver = DriverParams::miapure(),
            Self::Drivetrain => p.transmission = TransmissionParams::miapure(),
            Self::Sensing => p.sensors = SensorParams::miapure(),
            Self::All => p = WorldParams::realistic(robot),
        }
        p
    }
}

/// The controller a run uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ControllerVariant {
    /// The core's designed controller in the paper's configuration
    /// ([`BallbotControllerConfig::paper`]: wheel mapping with the lean term, jerk-limited
    /// command, no traction-aware control), with the protocol's shaper caps lifted
    /// ([`max_speed::controller`]).
    Corrected,
    /// The paper's robot as an ablation: the same controller and caps with the upright wheel
    /// mapping (no lean term, [`WheelMapping::Upright`]) and no jerk limit on the command
    /// (the paper's ramps are plain velocity ramps), as in
    /// [`BallbotControllerConfig::with_paper_ablation`].
    Paper,
}

impl ControllerVariant {
    /// Every variant.
    pub const ALL: [Self; 2] = [Self::Corrected, Self::Paper];

    /// The canonical (snake_case) name, used as the summary's key.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Corrected => "corrected",
            Self::Paper => "paper",
        }
    }

    /// A short description for tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Self::Corrected => "corrected controller",
            Self::Paper => "paper's controller (upright mapping, no jerk limit)",
        }
    }

    /// The controller configuration for `params` under `protocol`.
    pub fn config(
        self,
        params: &WorldParams,
        protocol: &MaxSpeedProtocol,
    ) -> Result<BallbotControllerConfig<f64>, WorldError> {
        let mut config = max_speed::controller(params, protocol)?;
        match self {
            Self::Corrected => {}
            Self::Paper => {
                config.wheel_mapping = WheelMapping::Upright;
                config.shaping.translation.max_jerk_per_s2 =
                    AxisLimits::<f64>::unlimited_jerk_per_s2();
            }
        }
        Ok(config)
    }
}
