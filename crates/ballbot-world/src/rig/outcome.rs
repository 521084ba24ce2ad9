//! How a closed-loop world run ended: [`Outcome`], judged step by step by an
//! [`OutcomeTracker`].
//!
//! - **Fell**: the chassis touched the floor. This is geometry, not a threshold: the world
//!   checks the lowest corner of the chassis plate (`chassis_half_width_m` from the body's
//!   axis, in the body's pose) against the floor every step
//!   ([`crate::world::FailureKind::BodyTouchedFloor`]). A body tilted beyond recovery gets
//!   there; one that is not, does not.
//! - **Ended by a stop rule**: a world stop rule ([`crate::world::StopRules`]: tilt, slip,
//!   lift-off, driver trip) ended the run before anything else was known; which one is named.
//! - **Stopped**: the controller left balancing (a controlled stop, or the motors off) and the
//!   body did not reach the floor; the time it left.
//! - **At rest**: balancing, commanded to stand, the ball below [`OutcomeTracker::REST_M_PER_S`]
//!   from the time given to the end.
//! - **Recovered**: balancing, the ball within [`OutcomeTracker::TRACK_M_PER_S`] of its command
//!   from the time given to the end.
//! - **Unsettled**: none of these when the run ended (still in a transient).

use super::{Event, WorldRobot};
use crate::world::{Failure, FailureKind};
use ballbot_core::safety::Mode;

/// How a run ended (see the [module](self) docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    /// The chassis touched the floor at `time_secs`.
    Fell {
        /// When (s).
        time_secs: f64,
    },
    /// A world stop rule ended the run.
    EndedByStopRule {
        /// The rule's failure.
        rule: FailureKind,
        /// When (s).
        time_secs: f64,
    },
    /// The controller left balancing at `time_secs` and the body stayed off the floor.
    Stopped {
        /// When (s).
        time_secs: f64,
    },
    /// At rest from `time_secs` to the end.
    AtRest {
        /// Since when (s).
        time_secs: f64,
    },
    /// Following the command from `time_secs` to the end.
    Recovered {
        /// Since when (s).
        time_secs: f64,
    },
    /// None of the above at the end.
    Unsettled,
}

impl Outcome {
    /// The canonical name: `fell`, `ended_by_stop_rule`, `stopped`, `at_rest`, `recovered`,
    /// `unsettled`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Fell { .. } => "fell",
            Self::EndedByStopRule { .. } => "ended_by_stop_rule",
            Self::Stopped { .. } => "stopped",
            Self::AtRest { .. } => "at_rest",
            Self::Recovered { .. } => "recovered",
            Self::Unsettled => "unsettled",
        }
    }

    /// The name as one table cell: [`Self::as_str`], with the stop rule after a colon for
    /// [`Self::EndedByStopRule`] (`ended_by_stop_rule:lift_off`).
    ///
    /// ```
    /// use ballbot_world::rig::Outcome;
    /// use ballbot_world::world::FailureKind;
    /// assert_eq!(Outcome::Fell { time_secs: 1.0 }.label(), "fell");
    /// let rule = FailureKind::LiftOff { wheel: 0 };
    /// assert_eq!(Outcome::EndedByStopRule { rule, time_secs: 1.0 }.label(), "ended_by_stop_rule:lift_off");
    /// ```
    pub fn label(&self) -> String {
        match self {
            Self::EndedByStopRule { rule, .. } => format!("{}:{}", self.as_str(), rule.as_str()),
            _ => self.as_str().to_owned(),
        }
    }

    /// When it was reached (s), for every outcome but [`Self::Unsettled`].
    pub fn time_secs(&self) -> Option<f64> {
        match self {
            Self::Fell { time_secs }
            | Self::EndedByStopRule { time_secs, .. }
            | Self::Stopped { time_secs }
            | Self::AtRest { time_secs }
            | Self::Recovered { time_secs } => Some(*time_secs),
            Self::Unsettled => None,
        }
    }
}

/// `{"kind": "fell", "time_secs": 2.31}`; a stop rule adds `"stop_rule": "sustained_slip"` and
/// its wheel.
impl serde::Serialize for Outcome {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("kind", self.as_str())?;
        if let Self::EndedByStopRule { rule, .. } = self {
            map.serialize_entry("stop_rule", rule.as_str())?;
            if let Some(wheel) = rule.wheel_name() {
                map.serialize_entry("wheel", wheel)?;
            }
        }
        if let Some(t) = self.time_secs() {
            map.serialize_entry("time_secs", &t)?;
        }
        map.end()
    }
}

/// Watches a run step by step and tells its [`Outcome`] at any time.
#[derive(Clone, Copy, Debug, Default)]
pub struct OutcomeTracker {
    rest_since: Option<f64>,
    track_since: Option<f64>,
    left_balancing: Option<f64>,
}

impl OutcomeTracker {
    /// Ball speed below which a robot commanded to stand is at rest (m/s).
    pub const REST_M_PER_S: f64 = 0.05;
    /// Ball speed error within which a robot follows its command (m/s).
    pub const TRACK_M_PER_S: f64 = 0.2;

    /// One step of `sim`, whose ball moved at `ball_velocity_m_per_s` and was commanded
    /// `command_m_per_s` (both in the body's yaw frame: x, y).
    pub fn update(
        &mut self,
        sim: &WorldRobot,
        ball_velocity_m_per_s: [f64; 2],
        command_m_per_s: [f64; 2],
    ) {
        let now = sim.world().time_secs();
        if sim.mode() != Mode::Balancing {
            self.left_balancing.get_or_insert(now);
            self.rest_since = None;
            self.track_since = None;
            return;
        }
        self.left_balancing = None;
        let [vx, vy] = ball_velocity_m_per_s;
        let error = (vx - command_m_per_s[0]).hypot(vy - command_m_per_s[1]);
        let standing = command_m_per_s == [0.0, 0.0];
        let since = |s: Option<f64>, ok: bool| if ok { Some(s.unwrap_or(now)) } else { None };
        self.rest_since = since(
            self.rest_since,
            standing && vx.hypot(vy) < Self::REST_M_PER_S,
        );
        self.track_since = since(self.track_since, error < Self::TRACK_M_PER_S);
    }

    /// The outcome so far, given the world's first failure.
    pub fn outcome(&self, failure: Option<Failure>) -> Outcome {
        match failure {
            Some(Failure {
                kind: FailureKind::BodyTouchedFloor,
                time_secs,
            }) => return Outcome::Fell { time_secs },
            Some(Failure { kind, time_secs }) => {
                return Outcome::EndedByStopRule {
                    rule: kind,
                    time_secs,
                };
            }
            None => {}
        }
        if let Some(time_secs) = self.left_balancing {
            Outcome::Stopped { time_secs }
        } else if let Some(time_secs) = self.rest_since {
            Outcome::AtRest { time_secs }
        } else if let Some(time_secs) = self.track_since {
            Outcome::Recovered { time_secs }
        } else {
            Outcome::Unsettled
        }
    }
}

/// What happened in one closed-loop run, in its one canonical form: how it ended and the
/// events on the way, whatever the stop rules. Every world study's run record carries one.
///
/// JSON: `{"outcome": {"kind": "at_rest", "time_secs": 6.1}, "events": [...],
/// "events_dropped": 0}`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Happened {
    /// How the run ended ([`Outcome`]).
    pub outcome: Outcome,
    /// Slips, lift-offs, driver trips, controller faults and traction limits, in order of
    /// onset ([`crate::rig::EventLog`]).
    pub events: Vec<Event>,
    /// Events beyond [`crate::rig::EventLog::MAX_EVENTS`], not kept.
    pub events_dropped: u64,
}

impl Happened {
    /// The run of `sim` so far, as `judge` saw it.
    pub fn of(sim: &WorldRobot, judge: &OutcomeTracker) -> Self {
        Self::with_failure(sim, judge, sim.world().failure())
    }

    /// The run of a protocol that goes on past the world's stop rules (it watched the whole
    /// run with `judge`): only the body on the floor ends it; the rule the world latched is
    /// among the events.
    pub fn past_stop_rules(sim: &WorldRobot, judge: &OutcomeTracker) -> Self {
        let fell = sim
            .world()
            .failure()
            .filter(|f| f.kind == FailureKind::BodyTouchedFloor);
        Self::with_failure(sim, judge, fell)
    }

    fn with_failure(sim: &WorldRobot, judge: &OutcomeTracker, failure: Option<Failure>) -> Self {
        Self {
            outcome: judge.outcome(failure),
            events: sim.events().events().to_vec(),
            events_dropped: sim.events().dropped(),
        }
    }

    /// Whether the body reached the floor.
    pub fn fell(&self) -> bool {
        matches!(self.outcome, Outcome::Fell { .. })
    }
}
