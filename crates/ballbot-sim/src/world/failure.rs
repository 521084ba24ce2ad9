//! Failure detection: tilt beyond the limit, body on the floor, sustained slip, lift-off, a
//! motor driver that disarmed.

use super::driver::DriverLimit;
use super::params::FailureParams;
use super::telemetry::StepTelemetry;

/// Why a run failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FailureKind {
    /// The body tilted beyond `max_tilt_rad`.
    Tilt {
        /// Tilt from the vertical when detected (rad).
        tilt_rad: f64,
    },
    /// A corner of the chassis reached the floor.
    BodyTouchedFloor,
    /// A wheel slipped for longer than `max_slip_duration_secs`.
    SustainedSlip {
        /// Wheel index, 0-based (OW1 is 0).
        wheel: usize,
    },
    /// A wheel lost contact for longer than `max_lift_off_duration_secs`.
    LiftOff {
        /// Wheel index, 0-based.
        wheel: usize,
    },
    /// A wheel's motor driver disarmed (overspeed or current-limit violation, see
    /// [`crate::world::driver`]): that wheel has no torque from then on.
    DriverTrip {
        /// Wheel index, 0-based.
        wheel: usize,
    },
}

/// A detected failure and when it happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Failure {
    /// What failed.
    pub kind: FailureKind,
    /// Simulated time of detection (s).
    pub time_secs: f64,
}

/// The paper's name of omniwheel `index` (0-based): `OW1`, `OW2`, `OW3`: how tables, logs, the
/// reproduce summary and Python results name a wheel. (`ballbot world --json` still reports
/// the 1-based numbers `failure_wheel` and `peak_cone_wheel`.)
///
/// ```
/// use ballbot_sim::world::wheel_name;
/// assert_eq!(wheel_name(0), "OW1");
/// assert_eq!(wheel_name(2), "OW3");
/// assert_eq!(wheel_name(7), "OW?");
/// ```
pub fn wheel_name(index: usize) -> &'static str {
    match index {
        0 => "OW1",
        1 => "OW2",
        2 => "OW3",
        _ => "OW?",
    }
}

impl FailureKind {
    /// Every kind's canonical name, in declaration order.
    pub const NAMES: [&'static str; 5] = [
        "tilt",
        "body_touched_floor",
        "sustained_slip",
        "lift_off",
        "driver_trip",
    ];

    /// The canonical (snake_case) name: `tilt`, `body_touched_floor`, `sustained_slip`,
    /// `lift_off` or `driver_trip`; JSON, logs and Python use it.
    ///
    /// ```
    /// use ballbot_sim::world::FailureKind;
    /// assert_eq!(FailureKind::LiftOff { wheel: 0 }.as_str(), "lift_off");
    /// ```
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Tilt { .. } => Self::NAMES[0],
            Self::BodyTouchedFloor => Self::NAMES[1],
            Self::SustainedSlip { .. } => Self::NAMES[2],
            Self::LiftOff { .. } => Self::NAMES[3],
            Self::DriverTrip { .. } => Self::NAMES[4],
        }
    }

    /// The wheel involved (0-based), for slip, lift-off and a driver trip.
    pub fn wheel(&self) -> Option<usize> {
        match self {
            Self::SustainedSlip { wheel }
            | Self::LiftOff { wheel }
            | Self::DriverTrip { wheel } => Some(*wheel),
            Self::Tilt { .. } | Self::BodyTouchedFloor => None,
        }
    }

    /// The wheel involved, named as [`wheel_name`] names it.
    pub fn wheel_name(&self) -> Option<&'static str> {
        self.wheel().map(wheel_name)
    }

    /// The tilt from the vertical when detected (rad), for a tilt failure.
    pub fn tilt_rad(&self) -> Option<f64> {
        match self {
            Self::Tilt { tilt_rad } => Some(*tilt_rad),
            _ => None,
        }
    }
}

/// Human-readable: `tilt 12.3 deg`, `body touched the floor`, `slip OW2`, `lift-off OW1`,
/// `driver trip OW3`.
///
/// ```
/// use ballbot_sim::world::FailureKind;
/// assert_eq!(FailureKind::SustainedSlip { wheel: 1 }.to_string(), "slip OW2");
/// assert_eq!(FailureKind::Tilt { tilt_rad: 0.5 }.to_string(), "tilt 28.6 deg");
/// assert_eq!(FailureKind::DriverTrip { wheel: 2 }.to_string(), "driver trip OW3");
/// ```
impl core::fmt::Display for FailureKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Tilt { tilt_rad } => write!(f, "tilt {:.1} deg", tilt_rad.to_degrees()),
            Self::BodyTouchedFloor => f.write_str("body touched the floor"),
            Self::SustainedSlip { wheel } => write!(f, "slip {}", wheel_name(*wheel)),
            Self::LiftOff { wheel } => write!(f, "lift-off {}", wheel_name(*wheel)),
            Self::DriverTrip { wheel } => write!(f, "driver trip {}", wheel_name(*wheel)),
        }
    }
}

/// `{"kind": "lift_off", "wheel": "OW1"}`, `{"kind": "tilt", "tilt_rad": 0.61}`: the canonical
/// JSON form ([`FailureKind::as_str`], [`wheel_name`]).
impl serde::Serialize for FailureKind {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        kind_entries(&mut map, self)?;
        map.end()
    }
}

fn kind_entries<M: serde::ser::SerializeMap>(
    map: &mut M,
    kind: &FailureKind,
) -> Result<(), M::Error> {
    map.serialize_entry("kind", kind.as_str())?;
    if let Some(wheel) = kind.wheel_name() {
        map.serialize_entry("wheel", wheel)?;
    }
    if let Some(tilt_rad) = kind.tilt_rad() {
        map.serialize_entry("tilt_rad", &tilt_rad)?;
    }
    Ok(())
}

/// `kind at 6.086 s`, e.g. `lift-off OW1 at 6.086 s`.
///
/// ```
/// use ballbot_sim::world::{Failure, FailureKind};
/// let f = Failure { kind: FailureKind::LiftOff { wheel: 0 }, time_secs: 6.0861 };
/// assert_eq!(f.to_string(), "lift-off OW1 at 6.086 s");
/// ```
impl core::fmt::Display for Failure {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} at {:.3} s", self.kind, self.time_secs)
    }
}

/// The kind's fields and `time_secs` in one JSON object:
/// `{"kind": "lift_off", "wheel": "OW1", "time_secs": 6.086}`.
impl serde::Serialize for Failure {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        kind_entries(&mut map, &self.kind)?;
        map.serialize_entry("time_secs", &self.time_secs)?;
        map.end()
    }
}

/// Watches the telemetry step by step and latches the first failure.
#[derive(Clone, Debug)]
pub struct FailureMonitor {
    params: FailureParams,
    /// `cos(max_tilt_rad)`: the tilt check compares the body axis' z component with it, so
    /// only a failing step pays for the arc cosine.
    cos_max_tilt: f64,
    slip_secs: [f64; 3],
    lift_off_secs: [f64; 3],
    first: Option<Failure>,
}

impl FailureMonitor {
    /// A monitor with no failure yet.
    pub fn new(params: FailureParams) -> Self {
        Self {
            params,
            cos_max_tilt: params.max_tilt_rad.min(core::f64::consts::PI).cos(),
            slip_secs: [0.0; 3],
            lift_off_secs: [0.0; 3],
            first: None,
        }
    }

    /// The first failure seen, if any.
    pub fn failure(&self) -> Option<Failure> {
        self.first
    }

    /// Clears the latched failure and the timers.
    pub fn reset(&mut self) {
        *self = Self::new(self.params);
    }

    /// Updates the timers with one step of `dt_secs`; `chassis_lowest_z_m` is the height of
    /// the chassis' lowest point above the floor. Returns the first failure (latched).
    pub fn update(
        &mut self,
        t: &StepTelemetry,
        chassis_lowest_z_m: f64,
        dt_secs: f64,
    ) -> Option<Failure> {
        if self.first.is_some() {
            return self.first;
        }
        let p = &self.params;
        let mut kind = None;
        // tilt > max_tilt  <=>  cos(tilt) < cos(max_tilt), for tilts in [0, pi].
        if body_axis_z(t) < self.cos_max_tilt {
            kind = Some(FailureKind::Tilt {
                tilt_rad: tilt_from_vertical_rad(t),
            });
        } else if chassis_lowest_z_m <= 0.0 {
            kind = Some(FailureKind::BodyTouchedFloor);
        }
        for (i, w) in t.wheels.iter().enumerate() {
            let slipping =
                w.slipping && w.slip_speed_m_per_s.abs() > p.slip_speed_threshold_m_per_s;
            self.slip_secs[i] = if slipping {
                self.slip_secs[i] + dt_secs
            } else {
                0.0
            };
            self.lift_off_secs[i] = if w.normal_force_n < p.lift_off_force_n {
                self.lift_off_secs[i] + dt_secs
            } else {
                0.0
            };
            if kind.is_none() && w.driver_limit == DriverLimit::Disarmed {
                kind = Some(FailureKind::DriverTrip { wheel: i });
            }
            if kind.is_none() && self.slip_secs[i] > p.max_slip_duration_secs {
                kind = Some(FailureKind::SustainedSlip { wheel: i });
            }
            if kind.is_none() && self.lift_off_secs[i] > p.max_lift_off_duration_secs {
                kind = Some(FailureKind::LiftOff { wheel: i });
            }
        }
        self.first = kind.map(|kind| Failure {
            kind,
            time_secs: t.time_secs,
        });
        self.first
    }
}

/// Angle between the body axis and the vertical (rad).
pub fn tilt_from_vertical_rad(t: &StepTelemetry) -> f64 {
    body_axis_z(t).acos()
}

/// The world z component of the body's z axis, clamped to [-1, 1] (the cosine of the tilt).
fn body_axis_z(t: &StepTelemetry) -> f64 {
    let z = t.body_orientation * nalgebra::Vector3::z();
    z.z.clamp(-1.0, 1.0)
}
