//! Hardware abstraction: the four things the controller needs from a robot, as small traits in
//! the spirit of `embedded-hal` (typed errors, no allocation, `&mut self` so a driver may talk
//! to a bus).
//!
//! | trait | what it gives | called from |
//! |---|---|---|
//! | [`Imu`] | one [`ImuSample`] (attitude, body rates, timestamp) | the 400 Hz outer task |
//! | [`WheelEncoders`] | one [`EncoderSample`] (three omniwheel speeds, timestamp) | both tasks |
//! | [`MotorTorques`] | apply three omniwheel torques (returning the drivers' [`MotorFeedback`]), or switch the motors off | the 8 kHz inner task |
//! | [`MonotonicClock`] | microseconds since an arbitrary start, never decreasing | both tasks |
//!
//! Units are those of the controller: angles in rad, rates in rad/s, torques in N m **at the
//! omniwheel** (after the gearbox: divide by [`crate::ActuatorParams::gear_ratio`] for the
//! rotor), times in microseconds of the same clock for every timestamp. A driver converts raw
//! counts and frames once, at the edge.
//!
//! Errors are the implementation's own type, bounded by [`DeviceError`] so that generic code
//! can classify them ([`DeviceErrorKind`]) without knowing the device. The controller needs no
//! special handling for a failed read: it keeps the last sample, and the safety supervisor
//! declares the data stale once it is older than its timeout
//! ([`crate::safety::Fault::ImuStale`], [`crate::safety::Fault::EncoderStale`]).
//!
//! A robot whose motor drivers run the speed PI themselves (the paper's MiaPURE: the main
//! controller sends [`crate::ballbot::MotorReferences`] over a bus) implements
//! [`MotorTorques`] on the motor-driver side, where [`crate::ballbot::MotorSpeedLoop`] runs.
//!
//! ```
//! use ballbot_core::estimation::ImuSample;
//! use ballbot_core::hal::{DeviceError, DeviceErrorKind, Imu, MonotonicClock};
//!
//! /// A made-up IMU on a bus that can time out.
//! struct BusImu { now_us: u64, responding: bool }
//!
//! #[derive(Debug, Clone, Copy, PartialEq)]
//! enum BusError { Timeout }
//! impl DeviceError for BusError {
//!     fn kind(&self) -> DeviceErrorKind {
//!         DeviceErrorKind::Timeout
//!     }
//! }
//!
//! impl Imu<f32> for BusImu {
//!     type Error = BusError;
//!     fn read(&mut self) -> Result<ImuSample<f32>, BusError> {
//!         if self.responding {
//!             Ok(ImuSample::upright(self.now_us))
//!         } else {
//!             Err(BusError::Timeout)
//!         }
//!     }
//! }
//!
//! let mut imu = BusImu { now_us: 2500, responding: true };
//! assert_eq!(imu.read()?.timestamp_us, 2500);
//! imu.responding = false;
//! assert_eq!(imu.read().map_err(|e| e.kind()), Err(DeviceErrorKind::Timeout));
//! # Ok::<(), BusError>(())
//! ```

use crate::estimation::{EncoderSample, ImuSample};
use core::convert::Infallible;
use core::fmt;
use nalgebra::Vector3;

/// What kind of failure a device reported, for code that handles any device's error.
///
/// ```
/// use ballbot_core::hal::{DeviceError, DeviceErrorKind};
/// use core::convert::Infallible;
/// // A driver with nothing more to say about a failure can return the kind itself.
/// fn read_status(bus_ok: bool) -> Result<u8, DeviceErrorKind> {
///     if bus_ok { Ok(0x2a) } else { Err(DeviceErrorKind::Bus) }
/// }
/// assert_eq!(read_status(false).map_err(|e| e.kind()), Err(DeviceErrorKind::Bus));
/// assert_eq!(DeviceErrorKind::Timeout.to_string(), "device timed out");
/// // A device that cannot fail uses `Infallible`, which is a `DeviceError` too.
/// fn classify<E: DeviceError>(result: Result<u8, E>) -> Option<DeviceErrorKind> {
///     result.err().map(|e| e.kind())
/// }
/// assert_eq!(classify(Ok::<u8, Infallible>(1)), None);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DeviceErrorKind {
    /// No fresh data yet (e.g. the sensor has not produced a new sample since the last read).
    NotReady,
    /// The device did not answer in time.
    Timeout,
    /// A bus error (CRC, arbitration, NACK, framing).
    Bus,
    /// The device reports an internal fault (over-temperature, over-current, self-test).
    Device,
    /// Anything else.
    Other,
}

impl fmt::Display for DeviceErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotReady => "no fresh data",
            Self::Timeout => "device timed out",
            Self::Bus => "bus error",
            Self::Device => "device fault",
            Self::Other => "device error",
        })
    }
}

/// A device error: any `Debug` type that can say what kind of failure it is.
///
/// [`DeviceErrorKind`] implements it (for drivers with nothing more to say), and so does
/// [`Infallible`] (for devices that cannot fail, such as a simulated one or a memory-mapped
/// timer).
///
/// ```
/// use ballbot_core::hal::{DeviceError, DeviceErrorKind};
/// assert_eq!(DeviceErrorKind::Bus.kind(), DeviceErrorKind::Bus);
/// ```
pub trait DeviceError: fmt::Debug {
    /// The kind of failure.
    fn kind(&self) -> DeviceErrorKind;
}

impl DeviceError for DeviceErrorKind {
    fn kind(&self) -> DeviceErrorKind {
        *self
    }
}

impl DeviceError for Infallible {
    fn kind(&self) -> DeviceErrorKind {
        match *self {}
    }
}

/// The body's inertial measurement unit: attitude and body angular velocity.
///
/// The sample's frames and signs are those of [`ImuSample`] (ZYX Euler angles, body rates in
/// body coordinates); its timestamp is when the IMU measured it, on the [`MonotonicClock`].
/// Returning the same sample twice is fine (the supervisor looks at the timestamp); a failed
/// read returns `Err` and the controller keeps the last good sample until it is stale.
///
/// ```
/// use ballbot_core::estimation::ImuSample;
/// use ballbot_core::hal::Imu;
/// use core::convert::Infallible;
/// struct Level;
/// impl Imu<f64> for Level {
///     type Error = Infallible;
///     fn read(&mut self) -> Result<ImuSample<f64>, Infallible> {
///         Ok(ImuSample::upright(0))
///     }
/// }
/// assert_eq!(Level.read(), Ok(ImuSample::upright(0)));
/// ```
pub trait Imu<T: nalgebra::Scalar> {
    /// The driver's error.
    type Error: DeviceError;

    /// The latest sample.
    fn read(&mut self) -> Result<ImuSample<T>, Self::Error>;
}

/// The three omniwheel encoders, as speeds.
///
/// Speeds in rad/s at the omniwheel (after the gearbox), positive as in
/// [`crate::kinematics`], wheel `i` at azimuth `alpha_i` of
/// [`crate::DrivetrainParams::wheel_azimuths_rad`]. A driver that counts ticks differentiates
/// them (ticks per period, or time per tick at low speed) and converts once.
///
/// ```
/// use ballbot_core::estimation::EncoderSample;
/// use ballbot_core::hal::{DeviceErrorKind, WheelEncoders};
/// use nalgebra::Vector3;
/// /// Counts ticks of a 4096-count encoder on the omniwheel shaft over a 125 us period.
/// struct Ticks { counts_per_period: [i32; 3], now_us: u64 }
/// impl WheelEncoders<f32> for Ticks {
///     type Error = DeviceErrorKind;
///     fn read(&mut self) -> Result<EncoderSample<f32>, DeviceErrorKind> {
///         let rad_per_count = core::f32::consts::TAU / 4096.0;
///         let speed = |c: i32| c as f32 * rad_per_count / 125e-6;
///         let [a, b, c] = self.counts_per_period;
///         Ok(EncoderSample {
///             timestamp_us: self.now_us,
///             wheel_speeds_rad_per_s: Vector3::new(speed(a), speed(b), speed(c)),
///         })
///     }
/// }
/// let s = Ticks { counts_per_period: [1, 0, -1], now_us: 0 }.read()?;
/// approx::assert_relative_eq!(s.wheel_speeds_rad_per_s[0], 12.27, epsilon = 0.01);
/// # Ok::<(), DeviceErrorKind>(())
/// ```
pub trait WheelEncoders<T: nalgebra::Scalar> {
    /// The driver's error.
    type Error: DeviceError;

    /// The latest speeds of the three omniwheels.
    fn read(&mut self) -> Result<EncoderSample<T>, Self::Error>;
}

/// The three motor drivers, commanded in torque.
///
/// `apply` receives torques already within the actuator's torque-speed limits (the inner loop
/// clamps them); the driver converts to current (`torque / (gear ratio x torque constant)`) and
/// returns what each driver last reported ([`MotorFeedback`]: measured torque, speed, bus
/// voltage, error flags), as an ODrive reports it. The feedback may be one period old (the
/// reply to the previous setpoint, as over a bus); the motor-health monitor
/// ([`crate::safety::MotorHealthMonitor`]) allows for that. `disable` must leave the motors
/// unpowered (coasting, or shorted if the hardware brakes) whatever the drivers' state (a
/// safe-torque-off line or the power stage's enable, not only a bus message), and is called on
/// every inner step while the controller is not balancing, so it must be cheap and idempotent.
///
/// ```
/// use ballbot_core::hal::{MotorFeedback, MotorTorques};
/// use core::convert::Infallible;
/// use nalgebra::Vector3;
/// /// Drivers that deliver exactly what they are told, at 45 V, the wheels at rest.
/// #[derive(Default)]
/// struct Recorder { last_nm: Option<Vector3<f64>> }
/// impl MotorTorques<f64> for Recorder {
///     type Error = Infallible;
///     fn apply(&mut self, torque_nm: &Vector3<f64>) -> Result<[MotorFeedback<f64>; 3], Infallible> {
///         self.last_nm = Some(*torque_nm);
///         Ok([0, 1, 2].map(|i| MotorFeedback::healthy(torque_nm[i], 0.0, 45.0)))
///     }
///     fn disable(&mut self) -> Result<(), Infallible> {
///         self.last_nm = None;
///         Ok(())
///     }
/// }
/// let mut m = Recorder::default();
/// let feedback = m.apply(&Vector3::new(1.0, -2.0, 0.5))?;
/// assert_eq!(m.last_nm, Some(Vector3::new(1.0, -2.0, 0.5)));
/// assert_eq!(feedback[1].torque_nm, -2.0);
/// m.disable()?;
/// assert_eq!(m.last_nm, None);
/// # Ok::<(), Infallible>(())
/// ```
pub trait MotorTorques<T: nalgebra::Scalar> {
    /// The driver's error.
    type Error: DeviceError;

    /// Applies `torque_nm[i]` (N m, at the omniwheel) to omniwheel `i` until the next call, and
    /// returns the drivers' latest feedback, wheel `i` at index `i`.
    fn apply(&mut self, torque_nm: &Vector3<T>) -> Result<[MotorFeedback<T>; 3], Self::Error>;

    /// Switches the motors off.
    fn disable(&mut self) -> Result<(), Self::Error>;
}

/// A motor driver's error flags, a bit set modelled on the ODrive's error classes (firmware
/// 0.5.x: `ODrive.error`, `axis.error`, `axis.motor.error`, `axis.encoder.error`,
/// `axis.controller.error`). A driver maps its own codes onto these once, at the edge; any
/// flag means the driver cannot be trusted to deliver the commanded torque.
///
/// | flag | ODrive errors it stands for |
/// |---|---|
/// | [`Self::OVER_CURRENT`] | `motor.error` `CURRENT_LIMIT_VIOLATION`, `CURRENT_SENSE_SATURATION`; `ODrive.error` `DC_BUS_OVER_CURRENT`, `DC_BUS_OVER_REGEN_CURRENT` |
/// | [`Self::BUS_UNDER_VOLTAGE`] | `ODrive.error` `DC_BUS_UNDER_VOLTAGE` |
/// | [`Self::BUS_OVER_VOLTAGE`] | `ODrive.error` `DC_BUS_OVER_VOLTAGE` |
/// | [`Self::ENCODER`] | any `encoder.error` (`CPR_POLEPAIRS_MISMATCH`, `NO_RESPONSE`, `ILLEGAL_HALL_STATE`, `ABS_SPI_*`) |
/// | [`Self::DRIVER_FAULT`] | `motor.error` `DRV_FAULT` (gate driver), `MODULATION_IS_NAN`, `CONTROL_DEADLINE_MISSED` |
/// | [`Self::OVER_TEMPERATURE`] | `motor.error` `MOTOR_THERMISTOR_OVER_TEMP`, `FET_THERMISTOR_OVER_TEMP` |
/// | [`Self::OVERSPEED`] | `controller.error` `OVERSPEED` |
/// | [`Self::DISARMED`] | the axis left `AXIS_STATE_CLOSED_LOOP_CONTROL` without being told to (any other `axis.error`, e.g. `WATCHDOG_TIMER_EXPIRED`) |
///
/// ```
/// use ballbot_core::hal::DriverErrors;
/// let flags = DriverErrors::OVERSPEED.union(DriverErrors::DISARMED);
/// assert!(flags.contains(DriverErrors::OVERSPEED) && !flags.is_empty());
/// assert!(!flags.contains(DriverErrors::ENCODER));
/// assert_eq!(DriverErrors::from_bits(flags.bits()), flags);
/// assert!(DriverErrors::NONE.is_empty());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DriverErrors(u16);

impl DriverErrors {
    /// No error.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert!(DriverErrors::NONE.is_empty());
    /// assert_eq!(DriverErrors::NONE, DriverErrors::default());
    /// ```
    pub const NONE: Self = Self(0);
    /// Over-current: the motor or bus current beyond its limit and margin.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert_eq!(DriverErrors::OVER_CURRENT.bits(), 1);
    /// assert!(!DriverErrors::OVER_CURRENT.is_empty());
    /// ```
    pub const OVER_CURRENT: Self = Self(1 << 0);
    /// The DC bus voltage below the driver's undervoltage trip.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let sag = DriverErrors::BUS_UNDER_VOLTAGE;
    /// assert!(sag.contains(DriverErrors::BUS_UNDER_VOLTAGE));
    /// assert!(!sag.contains(DriverErrors::BUS_OVER_VOLTAGE));
    /// ```
    pub const BUS_UNDER_VOLTAGE: Self = Self(1 << 1);
    /// The DC bus voltage above the driver's overvoltage trip.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert_eq!(DriverErrors::BUS_OVER_VOLTAGE.bits(), 1 << 2);
    /// assert_ne!(DriverErrors::BUS_OVER_VOLTAGE, DriverErrors::BUS_UNDER_VOLTAGE);
    /// ```
    pub const BUS_OVER_VOLTAGE: Self = Self(1 << 2);
    /// The driver's encoder failed (no response, lost calibration, illegal state).
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let flags = DriverErrors::OVER_CURRENT.union(DriverErrors::ENCODER);
    /// assert!(flags.contains(DriverErrors::ENCODER));
    /// ```
    pub const ENCODER: Self = Self(1 << 3);
    /// The power stage failed (gate-driver fault, non-finite modulation, missed deadline).
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert_eq!(DriverErrors::from_bits(1 << 4), DriverErrors::DRIVER_FAULT);
    /// ```
    pub const DRIVER_FAULT: Self = Self(1 << 4);
    /// The motor or power stage is too hot.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let hot = DriverErrors::OVER_TEMPERATURE;
    /// assert!(!hot.is_empty() && !hot.contains(DriverErrors::OVERSPEED));
    /// ```
    pub const OVER_TEMPERATURE: Self = Self(1 << 5);
    /// The motor turned faster than the driver's velocity limit and tolerance.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert_eq!(DriverErrors::OVERSPEED.bits(), 1 << 6);
    /// ```
    pub const OVERSPEED: Self = Self(1 << 6);
    /// The driver left closed-loop control on its own: it applies no torque.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let flags = DriverErrors::DISARMED.union(DriverErrors::NONE);
    /// assert_eq!(flags, DriverErrors::DISARMED);
    /// ```
    pub const DISARMED: Self = Self(1 << 7);

    /// The flags from their bits (bits without a flag are kept: a driver may report more).
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert_eq!(DriverErrors::from_bits(0), DriverErrors::NONE);
    /// // An unknown bit survives the round trip and still counts as an error.
    /// assert_eq!(DriverErrors::from_bits(1 << 15).bits(), 1 << 15);
    /// assert!(!DriverErrors::from_bits(1 << 15).is_empty());
    /// ```
    pub const fn from_bits(bits: u16) -> Self {
        Self(bits)
    }

    /// The flags as bits (for telemetry).
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let flags = DriverErrors::OVER_CURRENT.union(DriverErrors::DISARMED);
    /// assert_eq!(flags.bits(), 0b1000_0001);
    /// ```
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Whether no flag is set.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// assert!(DriverErrors::NONE.is_empty());
    /// assert!(!DriverErrors::ENCODER.is_empty());
    /// ```
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every flag of `other` is set.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let flags = DriverErrors::ENCODER.union(DriverErrors::OVERSPEED);
    /// assert!(flags.contains(DriverErrors::ENCODER) && flags.contains(DriverErrors::NONE));
    /// assert!(!DriverErrors::ENCODER.contains(flags));
    /// ```
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Both sets of flags.
    ///
    /// ```
    /// use ballbot_core::hal::DriverErrors;
    /// let flags = DriverErrors::OVER_CURRENT.union(DriverErrors::BUS_UNDER_VOLTAGE);
    /// assert_eq!(flags, DriverErrors::from_bits(0b11));
    /// ```
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

/// What one motor driver reports, converted at the edge to the controller's units (at the
/// omniwheel, after the gearbox, as [`MotorTorques`]).
///
/// An ODrive gives `motor.current_control.Iq_measured` (A), `encoder.vel_estimate` (turn/s of
/// the rotor), `vbus_voltage` (V) and its error registers; the driver multiplies the current by
/// `gear ratio x torque constant` (the ODrive's `8.27 / KV`) and the speed by `2 pi / gear
/// ratio`, and maps the errors onto [`DriverErrors`].
///
/// ```
/// use ballbot_core::hal::{DriverErrors, MotorFeedback};
/// // 10 A measured on MiaPURE's motor (K_t = 8.27 / 98.68 N m/A, ratio 7.5): 6.29 N m at the wheel.
/// let kt = 8.27 / 98.68;
/// let fb = MotorFeedback::healthy(10.0 * 7.5 * kt, 3.0, 45.0);
/// approx::assert_relative_eq!(fb.torque_nm, 6.286, epsilon = 1e-3);
/// assert!(fb.errors.is_empty());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotorFeedback<T> {
    /// Torque the driver measures it delivers (N m at the omniwheel): the measured q-axis
    /// current times gear ratio and torque constant.
    pub torque_nm: T,
    /// The driver's own speed estimate (rad/s at the omniwheel).
    pub speed_rad_per_s: T,
    /// The driver's DC bus voltage (V).
    pub bus_voltage_v: T,
    /// The driver's error flags.
    pub errors: DriverErrors,
}

impl<T: Copy> MotorFeedback<T> {
    /// A report without errors.
    ///
    /// ```
    /// use ballbot_core::hal::MotorFeedback;
    /// let fb = MotorFeedback::healthy(6.0, -3.0, 45.0);
    /// assert_eq!((fb.torque_nm, fb.speed_rad_per_s, fb.bus_voltage_v), (6.0, -3.0, 45.0));
    /// assert!(fb.errors.is_empty());
    /// ```
    pub const fn healthy(torque_nm: T, speed_rad_per_s: T, bus_voltage_v: T) -> Self {
        Self {
            torque_nm,
            speed_rad_per_s,
            bus_voltage_v,
            errors: DriverErrors::NONE,
        }
    }
}

/// A monotonic clock in microseconds (a free-running hardware timer, extended to 64 bits).
///
/// Never decreasing; the same clock must stamp the sensor samples. 64-bit integer time does
/// not lose resolution however long the robot runs (a 32-bit microsecond counter wraps after
/// 71 minutes: extend it in the driver). A clock that goes backwards is reported by the
/// supervisor as [`crate::safety::Fault::ClockFault`].
///
/// ```
/// use ballbot_core::hal::MonotonicClock;
/// /// A 32-bit hardware counter at 1 MHz, extended to 64 bits by counting wraps.
/// struct Extended { high: u64, last_low: u32, counter: u32 }
/// impl MonotonicClock for Extended {
///     fn now_us(&mut self) -> u64 {
///         let low = self.counter; // a register read on hardware
///         if low < self.last_low {
///             self.high += 1 << 32;
///         }
///         self.last_low = low;
///         self.high | u64::from(low)
///     }
/// }
/// let mut clock = Extended { high: 0, last_low: 0, counter: u32::MAX };
/// let before = clock.now_us();
/// clock.counter = 5; // the counter wrapped
/// assert_eq!(clock.now_us() - before, 6);
/// ```
pub trait MonotonicClock {
    /// Microseconds since an arbitrary, fixed start.
    fn now_us(&mut self) -> u64;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed buffer for `Display` output (the core has no `String`).
    struct Buf([u8; 32], usize);
    impl fmt::Write for Buf {
        fn write_str(&mut self, s: &str) -> fmt::Result {
            let end = self.1 + s.len();
            self.0
                .get_mut(self.1..end)
                .ok_or(fmt::Error)?
                .copy_from_slice(s.as_bytes());
            self.1 = end;
            Ok(())
        }
    }

    #[test]
    fn every_kind_has_a_distinct_nonempty_description() {
        let kinds = [
            DeviceErrorKind::NotReady,
            DeviceErrorKind::Timeout,
            DeviceErrorKind::Bus,
            DeviceErrorKind::Device,
            DeviceErrorKind::Other,
        ];
        let texts = kinds.map(|kind| {
            let mut buf = Buf([0; 32], 0);
            fmt::write(&mut buf, format_args!("{kind}")).unwrap();
            assert_eq!(kind.kind(), kind);
            buf
        });
        for (i, a) in texts.iter().enumerate() {
            assert!(a.1 > 0);
            for b in &texts[i + 1..] {
                assert_ne!(&a.0[..a.1], &b.0[..b.1]);
            }
        }
    }
}
