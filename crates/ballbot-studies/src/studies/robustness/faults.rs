//! The fault classes of the fault-injection matrix, the conditions they strike in, the safe
//! state each should end in, and how large each fault is.
//!
//! The expected safe states are the ones docs/embedding.md ("Fault injection: what each fault
//! should do") wrote down before the matrix was first run; [`FaultClass::expected`] is that
//! table. The magnitudes ([`FaultMagnitudes::fault_matrix`]) were chosen at the same time,
//! each with its reason, and not changed after.

use serde::Serialize;

/// One kind of fault the fault-injection matrix injects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultClass {
    /// A burst of non-finite IMU samples, shorter than the stale timeout.
    ImuNanBurst,
    /// The IMU keeps returning its last reading (fresh timestamps, frozen values).
    ImuFrozen,
    /// The IMU stops delivering samples (reads dropped).
    ImuStale,
    /// A step in the gyro's bias on the tilt axes.
    GyroBiasStep,
    /// One wheel's encoder reads zero for a while (lost counts).
    EncoderDropout,
    /// One wheel's encoder delivers one absurd sample, at both loop rates.
    EncoderGlitch,
    /// One motor gives no torque (driver off, phase open).
    MotorDead,
    /// One motor keeps its last torque whatever it is told.
    MotorStuck,
    /// The bus voltage sags: every driver's torque-speed envelope shrinks.
    TorqueSaturation,
    /// Outer tasks run longer than their period.
    LoopOverrun,
    /// Outer ticks are missed.
    MissedTicks,
    /// The controller's samples (IMU, and the encoders at the outer tick) arrive late,
    /// honestly stamped; the motor drivers still read their own encoders at once.
    SensorDelay,
    /// The velocity command jumps to the reverse speed.
    CommandJump,
    /// The command link goes silent.
    CommandLinkLost,
    /// The ball rolls onto a low-friction floor patch.
    LowFrictionPatch,
    /// A bar on the floor across the path.
    FloorBump,
    /// The payload's centre of mass shifts.
    PayloadShift,
}

impl FaultClass {
    /// Every class, in the matrix's order.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FaultClass;
    /// assert_eq!(FaultClass::ALL.len(), 17);
    /// assert_eq!(FaultClass::ALL[0].as_str(), "imu_nan_burst");
    /// ```
    pub const ALL: [Self; 17] = [
        Self::ImuNanBurst,
        Self::ImuFrozen,
        Self::ImuStale,
        Self::GyroBiasStep,
        Self::EncoderDropout,
        Self::EncoderGlitch,
        Self::MotorDead,
        Self::MotorStuck,
        Self::TorqueSaturation,
        Self::LoopOverrun,
        Self::MissedTicks,
        Self::SensorDelay,
        Self::CommandJump,
        Self::CommandLinkLost,
        Self::LowFrictionPatch,
        Self::FloorBump,
        Self::PayloadShift,
    ];

    /// The canonical name (snake_case; the JSON form).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::ImuNanBurst => "imu_nan_burst",
            Self::ImuFrozen => "imu_frozen",
            Self::ImuStale => "imu_stale",
            Self::GyroBiasStep => "gyro_bias_step",
            Self::EncoderDropout => "encoder_dropout",
            Self::EncoderGlitch => "encoder_glitch",
            Self::MotorDead => "motor_dead",
            Self::MotorStuck => "motor_stuck",
            Self::TorqueSaturation => "torque_saturation",
            Self::LoopOverrun => "loop_overrun",
            Self::MissedTicks => "missed_ticks",
            Self::SensorDelay => "sensor_delay",
            Self::CommandJump => "command_jump",
            Self::CommandLinkLost => "command_link_lost",
            Self::LowFrictionPatch => "low_friction_patch",
            Self::FloorBump => "floor_bump",
            Self::PayloadShift => "payload_shift",
        }
    }

    /// The safe state the fault should end in (docs/embedding.md, written before the runs).
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::{FaultClass, SafeState};
    /// assert_eq!(FaultClass::ImuStale.expected(), SafeState::ProtectiveStop);
    /// assert_eq!(FaultClass::CommandLinkLost.expected(), SafeState::ControlledStop);
    /// assert_eq!(FaultClass::PayloadShift.expected(), SafeState::KeepsBalancing);
    /// ```
    pub fn expected(self) -> SafeState {
        match self {
            // Detected by the supervisor, recoverable: brake to rest while balancing.
            Self::ImuNanBurst
            | Self::EncoderGlitch
            | Self::LoopOverrun
            | Self::MissedTicks
            | Self::CommandLinkLost => SafeState::ControlledStop,
            // No tilt information, or no way to balance: motors off before the fall.
            Self::ImuFrozen | Self::ImuStale | Self::MotorDead | Self::MotorStuck => {
                SafeState::ProtectiveStop
            }
            // Disturbances within what a balancing controller must ride through.
            Self::GyroBiasStep
            | Self::EncoderDropout
            | Self::TorqueSaturation
            | Self::SensorDelay
            | Self::CommandJump
            | Self::LowFrictionPatch
            | Self::FloorBump
            | Self::PayloadShift => SafeState::KeepsBalancing,
        }
    }
}

/// Where the robot is when the fault strikes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    /// Standing still on a zero velocity command.
    Standing,
    /// Cruising at the cruise speed; the command stays.
    Cruising,
    /// At the cruise speed, the command drops to zero as the fault strikes.
    Braking,
}

impl Condition {
    /// Every condition, in the matrix's order.
    pub const ALL: [Self; 3] = [Self::Standing, Self::Cruising, Self::Braking];

    /// The canonical name.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::Condition;
    /// assert_eq!(Condition::ALL.map(|c| c.as_str()), ["standing", "cruising", "braking"]);
    /// ```
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Standing => "standing",
            Self::Cruising => "cruising",
            Self::Braking => "braking",
        }
    }
}

/// How a faulted run ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SafeState {
    /// Still balancing and following the command (the ball's final speed within the
    /// protocol's bound of the command's).
    KeepsBalancing,
    /// A controlled stop: balancing, braked to rest, holding upright.
    ControlledStop,
    /// The fault was detected and the motors switched off before the body passed the tilt
    /// limit (a ballbot then falls unless something holds it: the rider, a stand).
    ProtectiveStop,
    /// Balancing, but not following the command: the ball's final speed is off it by more
    /// than the protocol's bound (a robot that drives off on its own). Not safe.
    Drifting,
    /// None of these: the robot fell with the fault undetected, or ended in another mode.
    Unsafe,
}

impl SafeState {
    /// Whether the state is safe: anything but [`Self::Drifting`] and [`Self::Unsafe`].
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::SafeState;
    /// assert!(SafeState::ControlledStop.is_safe() && !SafeState::Drifting.is_safe());
    /// ```
    pub fn is_safe(self) -> bool {
        !matches!(self, Self::Drifting | Self::Unsafe)
    }

    /// The canonical name.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::SafeState;
    /// assert_eq!(SafeState::ProtectiveStop.as_str(), "protective_stop");
    /// ```
    pub fn as_str(self) -> &'static str {
        match self {
            Self::KeepsBalancing => "keeps_balancing",
            Self::ControlledStop => "controlled_stop",
            Self::ProtectiveStop => "protective_stop",
            Self::Drifting => "drifting",
            Self::Unsafe => "unsafe",
        }
    }
}

/// How large each fault is. Chosen before the first run; the reasons are the fields' docs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FaultMagnitudes {
    /// Non-finite IMU samples in a burst: 3 (7.5 ms), shorter than the 20 ms stale timeout,
    /// so the burst is the recoverable case.
    pub imu_nan_samples: u32,
    /// Gyro bias step on roll and pitch rate (rad/s): 0.05 (2.9 deg/s), three times the
    /// Bosch BMI088's +-1 deg/s zero-rate offset: a calibration lost or a thermal shock.
    pub gyro_bias_rad_per_s: f64,
    /// How long one encoder reads zero (s): 0.05, twenty outer periods of lost counts.
    pub encoder_dropout_secs: f64,
    /// The glitching encoder's one sample (rad/s): 1,000, beyond any omniwheel's speed.
    pub encoder_glitch_rad_per_s: f64,
    /// Bus voltage left when it sags (fraction of nominal): 0.5. A DC motor's torque-speed
    /// line then gives half the torque at twice the speed: the envelope becomes
    /// `0.5 * bounds(speed / 0.5)`.
    pub bus_voltage_fraction: f64,
    /// How long an overrunning outer task takes (us): 3,000 (the period is 2,500).
    pub overrun_task_us: u64,
    /// Consecutive overrunning tasks: 5.
    pub overrun_tasks: u32,
    /// Consecutive missed outer ticks: 3 (a 10 ms gap between tasks, twice the 5 ms limit).
    pub missed_ticks: u32,
    /// Sensor delay on the controller's path (s): 0.01, four outer periods: a slow bus or a
    /// filtering IMU.
    pub sensor_delay_secs: f64,
    /// Ball-floor friction on the patch: 0.1 (rubber on a wet glazed tile or spilt oil;
    /// the default floor is 0.9).
    pub patch_floor_friction: f64,
    /// Patch length along the path (m): 1.0.
    pub patch_length_m: f64,
    /// Bar height (m): 0.015, a door threshold or cable protector.
    pub bump_height_m: f64,
    /// Bar width along the path (m): 0.04.
    pub bump_width_m: f64,
    /// Distance from the ball to the patch or the bar when the fault strikes (m): 0.3.
    pub obstacle_ahead_m: f64,
    /// Payload shift along the heading (m): 0.05, a bag sliding or a rider shifting.
    pub payload_shift_m: f64,
}

impl FaultMagnitudes {
    /// The fault-injection matrix's magnitudes (see the fields), in the full and the quick
    /// matrix alike.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FaultMagnitudes;
    /// assert_eq!(FaultMagnitudes::fault_matrix().missed_ticks, 3);
    /// ```
    pub fn fault_matrix() -> Self {
        Self {
            imu_nan_samples: 3,
            gyro_bias_rad_per_s: 0.05,
            encoder_dropout_secs: 0.05,
            encoder_glitch_rad_per_s: 1_000.0,
            bus_voltage_fraction: 0.5,
            overrun_task_us: 3_000,
            overrun_tasks: 5,
            missed_ticks: 3,
            sensor_delay_secs: 0.01,
            patch_floor_friction: 0.1,
            patch_length_m: 1.0,
            bump_height_m: 0.015,
            bump_width_m: 0.04,
            obstacle_ahead_m: 0.3,
            payload_shift_m: 0.05,
        }
    }

    /// The fault-injection matrix's magnitudes under their old name.
    #[deprecated(note = "renamed to `FaultMagnitudes::fault_matrix`")]
    // check-no-issue-numbers: allow (the deprecated alias keeps its old name for one release)
    pub fn issue15() -> Self {
        Self::fault_matrix()
    }
}
