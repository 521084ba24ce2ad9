//! What happened during a closed-loop world run, as records: per wheel its slips, lift-offs and
//! a driver trip; per fault the controller raised, when; when traction-aware control held the
//! command back. Each [`Event`] has its onset, its duration and its peak. The [`EventLog`]
//! watches every step whatever the stop rules ([`crate::world::StopRules`]), so a study can
//! report the events beside its outcome instead of ending at the first one.

use crate::world::params::FailureParams;
use crate::world::{DriverLimit, StepTelemetry, wheel_name};
use ballbot_core::ballbot::OuterOutput;
use ballbot_core::safety::Fault;

/// What an [`Event`] was, with its peak.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EventKind {
    /// A wheel slipping on the ball faster than the failure parameters' threshold
    /// ([`FailureParams::slip_speed_threshold_m_per_s`]).
    Slip {
        /// Wheel index, 0-based.
        wheel: usize,
        /// The largest slip speed (m/s).
        peak_slip_m_per_s: f64,
    },
    /// A wheel's normal force below [`FailureParams::lift_off_force_n`].
    LiftOff {
        /// Wheel index, 0-based.
        wheel: usize,
        /// The smallest normal force (N).
        min_normal_force_n: f64,
    },
    /// A wheel's motor driver disarmed (it stays so).
    DriverTrip {
        /// Wheel index, 0-based.
        wheel: usize,
    },
    /// The controller's supervisor reported a fault (one event per fault, while it is
    /// reported step after step).
    ControllerFault {
        /// The fault.
        fault: Fault,
    },
    /// Traction-aware control held the command below what it asked for.
    TractionLimit {
        /// The smallest acceleration the envelope allowed (m/s^2).
        min_accel_limit_m_per_s2: f64,
    },
}

impl EventKind {
    /// The canonical name: `slip`, `lift_off`, `driver_trip`, `controller_fault`,
    /// `traction_limit`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Slip { .. } => "slip",
            Self::LiftOff { .. } => "lift_off",
            Self::DriverTrip { .. } => "driver_trip",
            Self::ControllerFault { .. } => "controller_fault",
            Self::TractionLimit { .. } => "traction_limit",
        }
    }
}

/// One event of a run.
///
/// JSON: `{"kind": "slip", "wheel": "OW2", "onset_secs": 1.21, "duration_secs": 0.05,
/// "ongoing": false, "peak_slip_m_per_s": 0.31}`, the peak's key naming its unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// What happened, and its peak.
    pub kind: EventKind,
    /// When it began (s, simulated).
    pub onset_secs: f64,
    /// How long it lasted (s); up to the last step seen while [`Self::ongoing`].
    pub duration_secs: f64,
    /// Whether it was still going on at the last step seen.
    pub ongoing: bool,
}

impl serde::Serialize for Event {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("kind", self.kind.as_str())?;
        match self.kind {
            EventKind::Slip {
                wheel,
                peak_slip_m_per_s,
            } => {
                map.serialize_entry("wheel", wheel_name(wheel))?;
                map.serialize_entry("peak_slip_m_per_s", &peak_slip_m_per_s)?;
            }
            EventKind::LiftOff {
                wheel,
                min_normal_force_n,
            } => {
                map.serialize_entry("wheel", wheel_name(wheel))?;
                map.serialize_entry("min_normal_force_n", &min_normal_force_n)?;
            }
            EventKind::DriverTrip { wheel } => map.serialize_entry("wheel", wheel_name(wheel))?,
            EventKind::ControllerFault { fault } => map.serialize_entry("fault", fault.as_str())?,
            EventKind::TractionLimit {
                min_accel_limit_m_per_s2,
            } => map.serialize_entry("min_accel_limit_m_per_s2", &min_accel_limit_m_per_s2)?,
        }
        map.serialize_entry("onset_secs", &self.onset_secs)?;
        map.serialize_entry("duration_secs", &self.duration_secs)?;
        map.serialize_entry("ongoing", &self.ongoing)?;
        map.end()
    }
}

/// The events of one run, in order of onset. At most [`EventLog::MAX_EVENTS`] are kept (a
/// wheel chattering in and out of contact for minutes would otherwise grow it without bound);
/// the rest are counted in [`EventLog::dropped`].
#[derive(Clone, Debug, Default)]
pub struct EventLog {
    events: Vec<Event>,
    dropped: u64,
    slip: [Option<usize>; 3],
    lift_off: [Option<usize>; 3],
    trip: [Option<usize>; 3],
    faults: [Option<usize>; Fault::ALL.len()],
    limit: Option<usize>,
}

/// Opens, extends or closes the event `open` points at, for a condition `active` at `t`
/// after a step of `dt`: `peak` folds the step's value into an open event's kind.
#[allow(clippy::too_many_arguments)]
fn track(
    events: &mut Vec<Event>,
    dropped: &mut u64,
    open: &mut Option<usize>,
    active: bool,
    t: f64,
    dt: f64,
    kind: EventKind,
    peak: impl FnOnce(&mut EventKind),
) {
    match (*open, active) {
        (Some(i), true) => {
            if let Some(e) = events.get_mut(i) {
                e.duration_secs = t - e.onset_secs + dt;
                peak(&mut e.kind);
            }
        }
        (Some(i), false) => {
            if let Some(e) = events.get_mut(i) {
                e.ongoing = false;
            }
            *open = None;
        }
        (None, true) => {
            if events.len() < EventLog::MAX_EVENTS {
                *open = Some(events.len());
                events.push(Event {
                    kind,
                    onset_secs: t,
                    duration_secs: dt,
                    ongoing: true,
                });
            } else {
                *dropped += 1;
            }
        }
        (None, false) => {}
    }
}

impl EventLog {
    /// The most events kept.
    pub const MAX_EVENTS: usize = 10_000;

    /// The events so far, in order of onset.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// Events not kept beyond [`Self::MAX_EVENTS`].
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Forgets every event.
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// One world step of `dt_secs` that ended at `t.time_secs`: slips, lift-offs and driver
    /// trips per wheel, by the thresholds of `failure`.
    ///
    /// ```
    /// use ballbot_world::rig::events::{EventKind, EventLog};
    /// use ballbot_world::world::{BallbotWorld, WorldParams};
    /// let params = WorldParams::miapure_60kg();
    /// let world = BallbotWorld::new(params)?;
    /// let mut t = *world.telemetry();
    /// let mut log = EventLog::default();
    /// for w in &mut t.wheels {
    ///     w.normal_force_n = 300.0; // standing on its wheels
    /// }
    /// for k in 0..4 {
    ///     t.time_secs = f64::from(k) * 1.25e-4;
    ///     t.wheels[1].normal_force_n = [300.0, 0.5, 0.25, 300.0][k as usize];
    ///     log.observe_world(&t, &params.failure, 1.25e-4);
    /// }
    /// let e = log.events()[0];
    /// assert_eq!(e.kind, EventKind::LiftOff { wheel: 1, min_normal_force_n: 0.25 });
    /// assert_eq!((e.onset_secs, e.duration_secs, e.ongoing), (1.25e-4, 2.5e-4, false));
    /// # Ok::<(), ballbot_world::world::WorldError>(())
    /// ```
    pub fn observe_world(&mut self, t: &StepTelemetry, failure: &FailureParams, dt_secs: f64) {
        let time = t.time_secs;
        for (i, w) in t.wheels.iter().enumerate() {
            let slip = w.slip_speed_m_per_s.abs();
            let slipping = w.slipping && slip > failure.slip_speed_threshold_m_per_s;
            track(
                &mut self.events,
                &mut self.dropped,
                &mut self.slip[i],
                slipping,
                time,
                dt_secs,
                EventKind::Slip {
                    wheel: i,
                    peak_slip_m_per_s: slip,
                },
                |k| {
                    if let EventKind::Slip {
                        peak_slip_m_per_s, ..
                    } = k
                    {
                        *peak_slip_m_per_s = peak_slip_m_per_s.max(slip);
                    }
                },
            );
            let force = w.normal_force_n;
            track(
                &mut self.events,
                &mut self.dropped,
                &mut self.lift_off[i],
                force < failure.lift_off_force_n,
                time,
                dt_secs,
                EventKind::LiftOff {
                    wheel: i,
                    min_normal_force_n: force,
                },
                |k| {
                    if let EventKind::LiftOff {
                        min_normal_force_n, ..
                    } = k
                    {
                        *min_normal_force_n = min_normal_force_n.min(force);
                    }
                },
            );
            track(
                &mut self.events,
                &mut self.dropped,
                &mut self.trip[i],
                w.driver_limit == DriverLimit::Disarmed,
                time,
                dt_secs,
                EventKind::DriverTrip { wheel: i },
                |_| {},
            );
        }
    }

    /// One outer step of `dt_secs` whose output is `out`, at `time_secs`: the faults the
    /// supervisor reported, and whether traction-aware control held the command back.
    pub fn observe_controller(&mut self, time_secs: f64, out: &OuterOutput<f64>, dt_secs: f64) {
        for (i, fault) in Fault::ALL.iter().enumerate() {
            track(
                &mut self.events,
                &mut self.dropped,
                &mut self.faults[i],
                out.safety.faults.contains(*fault),
                time_secs,
                dt_secs,
                EventKind::ControllerFault { fault: *fault },
                |_| {},
            );
        }
        let limit = out
            .traction
            .as_ref()
            .filter(|t| t.limited)
            .and_then(|t| t.accel_limit_m_per_s2);
        let allowed = limit.unwrap_or(f64::INFINITY);
        track(
            &mut self.events,
            &mut self.dropped,
            &mut self.limit,
            limit.is_some(),
            time_secs,
            dt_secs,
            EventKind::TractionLimit {
                min_accel_limit_m_per_s2: allowed,
            },
            |k| {
                if let EventKind::TractionLimit {
                    min_accel_limit_m_per_s2,
                } = k
                {
                    *min_accel_limit_m_per_s2 = min_accel_limit_m_per_s2.min(allowed);
                }
            },
        );
    }
}
