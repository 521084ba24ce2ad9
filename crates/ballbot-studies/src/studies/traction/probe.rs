//! [`Probe`]: what one traction run measures, step by step, in the 3D world.

use ballbot_core::safety::Mode;
use ballbot_world::rig::{Happened, Outcome, OutcomeTracker, WorldRobot};
use ballbot_world::world::Failure;
use ballbot_world::world::failure::tilt_from_vertical_rad;
use nalgebra::Vector3;

/// One sample of a traction run (every `sample_every_secs`), along the run's heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TractionSample {
    /// Time (s).
    pub time_secs: f64,
    /// The command given to the controller along the heading (m/s; 0 for lean commands).
    pub command_m_per_s: f64,
    /// The shaped command along the heading (m/s): `r` times the planar commanded ball rates.
    pub shaped_m_per_s: f64,
    /// Ball speed along the heading (m/s).
    pub speed_m_per_s: f64,
    /// The controller's acceleration limit along the command's direction (m/s^2), if any.
    pub accel_limit_m_per_s2: Option<f64>,
    /// Largest friction-cone utilisation of the three wheels (world).
    pub max_cone_utilisation: f64,
    /// Largest estimated slip speed of the three wheels (controller, m/s).
    pub max_slip_estimate_m_per_s: f64,
    /// Largest slip speed of the three wheels (world, m/s).
    pub max_slip_m_per_s: f64,
}

/// What a run measured (see [`Probe`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// Heading of travel (deg, body frame, 0 towards OW1).
    pub heading_deg: f64,
    /// The world's failure, if any.
    pub failure: Option<Failure>,
    /// Largest acceleration the ball reached along the heading (m/s^2): the largest mean over
    /// a 0.1 s window of the sampled ball speed, before any failure.
    pub max_accel_m_per_s2: f64,
    /// Largest deceleration along the heading, the same way (m/s^2).
    pub max_decel_m_per_s2: f64,
    /// When the ball first reached 0.2 m/s along the heading (s), if it did.
    pub reached_0_2_secs: Option<f64>,
    /// When the ball first reached 1.4 m/s along the heading (s), if it did.
    pub reached_1_4_secs: Option<f64>,
    /// When the world first saw a wheel slip (|slip speed| above its threshold) (s).
    pub first_world_slip_secs: Option<f64>,
    /// When the controller's slip monitor first flagged a wheel (s).
    pub first_detection_secs: Option<f64>,
    /// Slip events the monitor counted.
    pub slip_events: u32,
    /// Outer steps in which the envelope limited the command.
    pub limited_steps: u32,
    /// Smallest friction estimate of the monitor.
    pub min_friction_estimate: Option<f64>,
    /// When the controller left balancing (controlled stop or fault) (s), if it did.
    pub supervisor_stop_secs: Option<f64>,
    /// Largest slip speed of the ball on the floor (m/s): contact-point velocity, horizontal.
    pub max_floor_slip_m_per_s: f64,
    /// Largest friction-cone utilisation of any wheel (world).
    pub peak_cone_utilisation: f64,
    /// Largest tilt of the body from the vertical (rad).
    pub max_tilt_rad: f64,
    /// Samples.
    pub samples: Vec<TractionSample>,
    /// How the run ended and its contact events, whatever the stop rules.
    pub happened: Happened,
}

impl RunRecord {
    /// The ball's mean acceleration from 0.2 to 1.4 m/s along the heading (m/s^2), if it got
    /// there: what the ramp sustained, without the transients at its start and end.
    pub fn mean_accel_m_per_s2(&self) -> Option<f64> {
        let dt = self.reached_1_4_secs? - self.reached_0_2_secs?;
        (dt > 0.0).then(|| 1.2 / dt)
    }
}

/// Measures a run in the 3D world step by step: call [`Probe::observe`] after every physics
/// step, then [`Probe::finish`].
#[derive(Clone, Debug)]
pub struct Probe {
    direction: Vector3<f64>,
    sample_every: u64,
    steps: u64,
    slip_threshold_m_per_s: f64,
    judge: OutcomeTracker,
    past_stop_rules: bool,
    record: RunRecord,
}

impl Probe {
    /// A probe for a run towards `heading_deg`, sampling every `sample_every` physics steps;
    /// a wheel counts as slipping in the world above `slip_threshold_m_per_s` (the world's
    /// `FailureParams::slip_speed_threshold_m_per_s`).
    pub fn new(heading_deg: f64, sample_every: u64, slip_threshold_m_per_s: f64) -> Self {
        let (s, c) = heading_deg.to_radians().sin_cos();
        Self {
            direction: Vector3::new(c, s, 0.0),
            sample_every: sample_every.max(1),
            steps: 0,
            slip_threshold_m_per_s,
            judge: OutcomeTracker::default(),
            past_stop_rules: false,
            record: RunRecord {
                heading_deg,
                failure: None,
                max_accel_m_per_s2: 0.0,
                max_decel_m_per_s2: 0.0,
                reached_0_2_secs: None,
                reached_1_4_secs: None,
                first_world_slip_secs: None,
                first_detection_secs: None,
                slip_events: 0,
                limited_steps: 0,
                min_friction_estimate: None,
                supervisor_stop_secs: None,
                max_floor_slip_m_per_s: 0.0,
                peak_cone_utilisation: 0.0,
                max_tilt_rad: 0.0,
                samples: Vec::new(),
                happened: Happened {
                    outcome: Outcome::Unsettled,
                    events: Vec::new(),
                    events_dropped: 0,
                },
            },
        }
    }

    /// For a run that goes on past the world's first failure (a patch crossing): its outcome
    /// is judged to the end, and only the body on the floor is a fall
    /// ([`Happened::past_stop_rules`]).
    pub fn past_stop_rules(mut self) -> Self {
        self.past_stop_rules = true;
        self
    }

    /// The ball's speed along the heading (m/s), in the body's yaw frame.
    pub fn speed_m_per_s(&self, sim: &WorldRobot) -> f64 {
        let v = sim.world().telemetry().ball_velocity_yaw_frame_m_per_s();
        v.dot(&self.direction)
    }

    /// Folds in the state after one physics step; `command_m_per_s` is the command given along
    /// the heading. Returns whether the world has failed.
    pub fn observe(&mut self, sim: &WorldRobot, command_m_per_s: f64) -> bool {
        let speed = self.speed_m_per_s(sim);
        let t = sim.world().telemetry();
        let time = t.time_secs;
        let r = &mut self.record;
        if r.reached_0_2_secs.is_none() && speed >= 0.2 {
            r.reached_0_2_secs = Some(time);
        }
        if r.reached_1_4_secs.is_none() && speed >= 1.4 {
            r.reached_1_4_secs = Some(time);
        }
        let max_slip = t
            .wheels
            .iter()
            .map(|w| w.slip_speed_m_per_s.abs())
            .fold(0.0, f64::max);
        if r.first_world_slip_secs.is_none() && max_slip > self.slip_threshold_m_per_s {
            r.first_world_slip_secs = Some(time);
        }
        let cone = t
            .wheels
            .iter()
            .map(|w| w.cone_utilisation)
            .fold(0.0, f64::max);
        r.peak_cone_utilisation = r.peak_cone_utilisation.max(cone);
        r.max_tilt_rad = r.max_tilt_rad.max(tilt_from_vertical_rad(t));
        // The ball's contact point on the floor: v + w x (-r z), horizontal.
        let radius = sim.world().params().robot.ball_radius_m();
        let w = t.ball_angular_velocity_rad_per_s;
        let floor_slip = (t.ball_velocity_m_per_s + w.cross(&Vector3::new(0.0, 0.0, -radius)))
            .xy()
            .norm();
        r.max_floor_slip_m_per_s = r.max_floor_slip_m_per_s.max(floor_slip);
        if r.supervisor_stop_secs.is_none()
            && matches!(sim.mode(), Mode::ControlledStop | Mode::Fault)
        {
            r.supervisor_stop_secs = Some(time);
        }
        let out = sim.last_outer();
        let traction = out.and_then(|o| o.traction);
        if let Some(tr) = traction {
            if r.first_detection_secs.is_none() && tr.slip.any_slipping() {
                r.first_detection_secs = Some(time);
            }
            r.slip_events = tr.slip.slip_events;
            r.limited_steps = tr.limited_steps;
            let mu = tr.slip.friction_estimate;
            r.min_friction_estimate = Some(r.min_friction_estimate.map_or(mu, |m| m.min(mu)));
        }
        if self.steps.is_multiple_of(self.sample_every) {
            let radius_m = sim.world().params().robot.ball_radius_m();
            let shaped = out.map_or(0.0, |o| {
                let vx = radius_m * o.commands.sagittal[3];
                let vy = -radius_m * o.commands.frontal[3];
                vx * self.direction.x + vy * self.direction.y
            });
            r.samples.push(TractionSample {
                time_secs: time,
                command_m_per_s,
                shaped_m_per_s: shaped,
                speed_m_per_s: speed,
                accel_limit_m_per_s2: traction.and_then(|tr| tr.accel_limit_m_per_s2),
                max_cone_utilisation: cone,
                max_slip_estimate_m_per_s: traction
                    .map_or(0.0, |tr| tr.slip.slip_speed_m_per_s.amax()),
                max_slip_m_per_s: max_slip,
            });
        }
        self.steps += 1;
        if self.past_stop_rules || r.failure.is_none() {
            let v = t.ball_velocity_yaw_frame_m_per_s();
            let command = self.direction * command_m_per_s;
            self.judge.update(sim, [v.x, v.y], [command.x, command.y]);
        }
        r.failure = sim.world().failure();
        r.failure.is_some()
    }

    /// The record of the run of `sim` (the one observed), with the accelerations from the
    /// samples (0.1 s windows) and what happened.
    pub fn finish(mut self, sim: &WorldRobot, sample_period_secs: f64) -> RunRecord {
        self.record.happened = if self.past_stop_rules {
            Happened::past_stop_rules(sim, &self.judge)
        } else {
            Happened::of(sim, &self.judge)
        };
        let r = &mut self.record;
        let window = (0.1 / sample_period_secs).round().max(1.0) as usize;
        let s = &r.samples;
        for i in 0..s.len().saturating_sub(window) {
            let (a, b) = (&s[i], &s[i + window]);
            let accel = (b.speed_m_per_s - a.speed_m_per_s) / (b.time_secs - a.time_secs);
            r.max_accel_m_per_s2 = r.max_accel_m_per_s2.max(accel);
            r.max_decel_m_per_s2 = r.max_decel_m_per_s2.max(-accel);
        }
        self.record
    }
}
