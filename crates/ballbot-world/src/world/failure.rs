//! Failure detection: tilt beyond the limit, body on the floor, sustained slip, lift-off, a
//! motor driver that disarmed.

use super::driver::DriverLimit;
use super::params::FailureParams;
use super::telemetry::StepTelemetry;

/// Why a run failed.
#[derive(Clone, Copy, Debug, PartialEq, schemars::JsonSchema)]
#[schemars(rename_all = "snake_case")]
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
#[derive(Clone, Copy, Debug, PartialEq, schemars::JsonSchema)]
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
/// use ballbot_world::world::wheel_name;
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
    /// use ballbot_world::world::FailureKind;
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
/// use ballbot_world::world::FailureKind;
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
/// use ballbot_world::world::{Failure, FailureKind};
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

/// Which failures end a run early: the world's **stop rules**. The body touching the floor
/// (a fall, from the chassis' geometry) always ends it; the others are rules of thumb that save
/// simulated time, and a study that asks what happens after a slip or a lift-off switches
/// them off (`ballbot world --stop-on none`). All on by default, as every study ran before.
///
/// ```
/// use ballbot_world::world::StopRules;
/// let rules: StopRules = "slip,lift-off".parse()?;
/// assert!(rules.slip && rules.lift_off && !rules.tilt && !rules.driver_trip);
/// assert_eq!(rules.to_string(), "slip,lift-off");
/// assert_eq!("none".parse::<StopRules>()?, StopRules::none());
/// assert_eq!(StopRules::default().to_string(), "tilt,slip,lift-off,driver-trip");
/// assert!("slip,wobble".parse::<StopRules>().is_err());
/// # Ok::<(), String>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct StopRules {
    /// Tilt beyond [`FailureParams::max_tilt_rad`].
    pub tilt: bool,
    /// A wheel slipping for longer than [`FailureParams::max_slip_duration_secs`].
    pub slip: bool,
    /// A wheel lifted off for longer than [`FailureParams::max_lift_off_duration_secs`].
    pub lift_off: bool,
    /// A motor driver that disarmed.
    pub driver_trip: bool,
}

impl StopRules {
    /// Every rule on: how every study ran before the rules could be switched off.
    pub const fn all() -> Self {
        Self {
            tilt: true,
            slip: true,
            lift_off: true,
            driver_trip: true,
        }
    }

    /// No rule: a run ends only at its end or when the body touches the floor.
    pub const fn none() -> Self {
        Self {
            tilt: false,
            slip: false,
            lift_off: false,
            driver_trip: false,
        }
    }

    /// The slip and lift-off rules off, tilt and driver trip on: what counting falls instead
    /// of contact events needs (the Monte Carlo's `falls` count, `world_push.rules_relaxed`).
    ///
    /// ```
    /// use ballbot_world::world::StopRules;
    /// assert_eq!(StopRules::contact_rules_off().to_string(), "tilt,driver-trip");
    /// ```
    pub const fn contact_rules_off() -> Self {
        Self {
            slip: false,
            lift_off: false,
            ..Self::all()
        }
    }

    /// The rules' names, in order (`--stop-on` takes them comma-separated, or `all`, `none`).
    pub const NAMES: [&'static str; 4] = ["tilt", "slip", "lift-off", "driver-trip"];

    fn flags(&self) -> [bool; 4] {
        [self.tilt, self.slip, self.lift_off, self.driver_trip]
    }

    /// Whether the rule that `kind` would trigger is on (a body on the floor always ends).
    pub fn stops_on(&self, kind: &FailureKind) -> bool {
        match kind {
            FailureKind::Tilt { .. } => self.tilt,
            FailureKind::SustainedSlip { .. } => self.slip,
            FailureKind::LiftOff { .. } => self.lift_off,
            FailureKind::DriverTrip { .. } => self.driver_trip,
            FailureKind::BodyTouchedFloor => true,
        }
    }
}

impl Default for StopRules {
    fn default() -> Self {
        Self::all()
    }
}

/// The rules' names joined by commas (`none` when there is none).
impl core::fmt::Display for StopRules {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let on: Vec<&str> = Self::NAMES
            .iter()
            .zip(self.flags())
            .filter_map(|(n, on)| on.then_some(*n))
            .collect();
        if on.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&on.join(","))
        }
    }
}

impl core::str::FromStr for StopRules {
    type Err = String;

    /// `all`, `none`, or rule names separated by commas.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "all" => return Ok(Self::all()),
            "none" => return Ok(Self::none()),
            _ => {}
        }
        let mut rules = Self::none();
        for name in s.split(',').map(str::trim) {
            match name {
                "tilt" => rules.tilt = true,
                "slip" => rules.slip = true,
                "lift-off" => rules.lift_off = true,
                "driver-trip" => rules.driver_trip = true,
                other => {
                    return Err(format!(
                        "unknown stop rule `{other}`: expected `all`, `none` or some of {}",
                        Self::NAMES.join(", ")
                    ));
                }
            }
        }
        Ok(rules)
    }
}

/// Watches the telemetry step by step and latches the first failure its stop rules end a run
/// on.
#[derive(Clone, Debug)]
pub struct FailureMonitor {
    params: FailureParams,
    rules: StopRules,
    /// `cos(max_tilt_rad)`: the tilt check compares the body axis' z component with it, so
    /// only a failing step pays for the arc cosine.
    cos_max_tilt: f64,
    slip_secs: [f64; 3],
    lift_off_secs: [f64; 3],
    first: Option<Failure>,
}

impl FailureMonitor {
    /// A monitor with no failure yet, every stop rule on.
    pub fn new(params: FailureParams) -> Self {
        Self::with_rules(params, StopRules::all())
    }

    /// A monitor with no failure yet that ends a run only on `rules`.
    pub fn with_rules(params: FailureParams, rules: StopRules) -> Self {
        Self {
            params,
            rules,
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
        *self = Self::with_rules(self.params, self.rules);
    }

    /// The stop rules.
    pub fn rules(&self) -> StopRules {
        self.rules
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
        let rules = self.rules;
        // The candidates in order of precedence; the first whose rule is on is latched.
        let mut kind = None;
        let mut consider = |k: FailureKind| {
            if kind.is_none() && rules.stops_on(&k) {
                kind = Some(k);
            }
        };
        // tilt > max_tilt  <=>  cos(tilt) < cos(max_tilt), for tilts in [0, pi].
        if body_axis_z(t) < self.cos_max_tilt {
            consider(FailureKind::Tilt {
                tilt_rad: tilt_from_vertical_rad(t),
            });
        }
        if chassis_lowest_z_m <= 0.0 {
            consider(FailureKind::BodyTouchedFloor);
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
            if w.driver_limit == DriverLimit::Disarmed {
                consider(FailureKind::DriverTrip { wheel: i });
            }
            if self.slip_secs[i] > p.max_slip_duration_secs {
                consider(FailureKind::SustainedSlip { wheel: i });
            }
            if self.lift_off_secs[i] > p.max_lift_off_duration_secs {
                consider(FailureKind::LiftOff { wheel: i });
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
