//! What an environment steps: the world driven by the agent's torques, or the world with the
//! core's controller in the loop and the agent's residual torque added to the drivers'; the
//! events of both ([`EventLog`], every physics step); and the sensor delay between the world
//! and whoever reads it.

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::hal::MotorFeedback;
use ballbot_core::safety::Mode;
use ballbot_world::rig::{EventLog, Injector, WorldRobot};
use ballbot_world::world::{BallbotWorld, Measurement, StepTelemetry, WorldError, WorldParams};
use nalgebra::Vector3;
use std::collections::VecDeque;

/// The world an episode steps.
pub(crate) enum Plant {
    /// The agent's torques drive the wheels; the log records the world's events.
    Torque(Box<BallbotWorld>, Box<EventLog>),
    /// The core's robot loop drives the wheels; the agent's torque adds to it.
    Controlled(Box<WorldRobot>, Box<DelayedLink>),
}

impl Plant {
    pub(crate) fn torque(params: WorldParams) -> Result<Self, WorldError> {
        Ok(Self::Torque(
            Box::new(BallbotWorld::new(params)?),
            Box::default(),
        ))
    }

    pub(crate) fn controlled(
        params: WorldParams,
        config: BallbotControllerConfig<f64>,
        delay_us: u64,
    ) -> Result<Self, WorldError> {
        let robot = WorldRobot::with_config(params, config)?;
        Ok(Self::Controlled(
            Box::new(robot),
            Box::new(DelayedLink::new(delay_us)),
        ))
    }

    pub(crate) fn world(&self) -> &BallbotWorld {
        match self {
            Self::Torque(w, _) => w,
            Self::Controlled(r, _) => r.world(),
        }
    }

    pub(crate) fn world_mut(&mut self) -> &mut BallbotWorld {
        match self {
            Self::Torque(w, _) => w,
            Self::Controlled(r, _) => r.world_mut(),
        }
    }

    /// The events so far: the world's slips, lift-offs and driver trips (both plants), the
    /// controller's faults and traction limits (controlled plant).
    pub(crate) fn events(&self) -> &EventLog {
        match self {
            Self::Torque(_, log) => log,
            Self::Controlled(r, _) => r.events(),
        }
    }

    /// One physics step: `torque_nm` is the wheel torque (torque plant) or the residual added
    /// to the controller's (controlled plant, which follows `command`). The step's events go to
    /// the log (the controlled plant's [`WorldRobot`] keeps its own).
    pub(crate) fn step(&mut self, torque_nm: [f64; 3], command: [f64; 3]) -> &StepTelemetry {
        match self {
            Self::Torque(w, log) => {
                w.step(torque_nm);
                let params = w.params();
                log.observe_world(w.telemetry(), &params.failure, params.dt_secs);
                w.telemetry()
            }
            Self::Controlled(r, link) => {
                link.residual_nm = Vector3::from(torque_nm);
                let command = VelocityCommand {
                    vx_m_per_s: command[0],
                    vy_m_per_s: command[1],
                    yaw_rate_rad_per_s: command[2],
                };
                r.step_injected(Command::Velocity(command), link.as_mut())
            }
        }
    }

    /// The controller's mode (`None` for the torque plant).
    pub(crate) fn mode(&self) -> Option<Mode> {
        match self {
            Self::Torque(..) => None,
            Self::Controlled(r, _) => Some(r.mode()),
        }
    }
}

/// Delays the controller's IMU and outer-loop encoder samples by `delay_us` and adds the
/// agent's residual to the drivers' torque. (The drivers' own 8 kHz encoder samples are not
/// delayed: they never leave the motor driver.)
pub(crate) struct DelayedLink {
    delay_us: u64,
    pub(crate) residual_nm: Vector3<f64>,
    /// Whether the drivers applied the residual in this step (they do only while enabled).
    residual_applied: bool,
    imu: VecDeque<ImuSample<f64>>,
    encoders: VecDeque<EncoderSample<f64>>,
}

impl DelayedLink {
    fn new(delay_us: u64) -> Self {
        Self {
            delay_us,
            residual_nm: Vector3::zeros(),
            residual_applied: false,
            imu: VecDeque::new(),
            encoders: VecDeque::new(),
        }
    }
}

/// Queues `sample` and hands over the newest one at least `delay_us` old, if any (at the start,
/// while `now_us < delay_us`, the first sample counts as old enough: the robot was at rest
/// before it).
fn delayed<S: Copy>(
    queue: &mut VecDeque<S>,
    sample: S,
    now_us: u64,
    delay_us: u64,
    stamp: impl Fn(&S) -> u64,
) -> Option<S> {
    if delay_us == 0 {
        return Some(sample);
    }
    queue.push_back(sample);
    let due = now_us.saturating_sub(delay_us);
    while queue.len() > 1 && queue.get(1).is_some_and(|s| stamp(s) <= due) {
        queue.pop_front();
    }
    queue.front().filter(|s| stamp(s) <= due).copied()
}

impl Injector for DelayedLink {
    fn imu(&mut self, now_us: u64, sample: ImuSample<f64>) -> Option<ImuSample<f64>> {
        delayed(&mut self.imu, sample, now_us, self.delay_us, |s| {
            s.timestamp_us
        })
    }

    fn encoders(
        &mut self,
        now_us: u64,
        sample: EncoderSample<f64>,
        outer: bool,
    ) -> Option<EncoderSample<f64>> {
        if !outer {
            return Some(sample);
        }
        delayed(&mut self.encoders, sample, now_us, self.delay_us, |s| {
            s.timestamp_us
        })
    }

    fn torques(
        &mut self,
        _now_us: u64,
        torque_nm: Vector3<f64>,
        _wheel_speeds_rad_per_s: Vector3<f64>,
    ) -> Vector3<f64> {
        self.residual_applied = true;
        torque_nm + self.residual_nm
    }

    /// The drivers' torque as the loop's own: the residual is the agent's, added on the way to
    /// the drivers, and the loop's motor-health monitor compares what a driver delivers with
    /// what the loop asked (a residual above its tolerance, about a quarter of the action's
    /// range, would otherwise read as a stuck motor and switch the motors off).
    fn feedback(
        &mut self,
        _now_us: u64,
        mut feedback: [MotorFeedback<f64>; 3],
    ) -> [MotorFeedback<f64>; 3] {
        if std::mem::take(&mut self.residual_applied) {
            for (f, r) in feedback.iter_mut().zip(self.residual_nm.iter()) {
                f.torque_nm -= r;
            }
        }
        feedback
    }
}

/// The measurements of the last `steps + 1` physics steps: the oldest is what a sensor
/// `steps` physics steps late reports.
pub(crate) struct DelayLine {
    steps: usize,
    samples: VecDeque<Measurement>,
}

impl DelayLine {
    /// A delay of `steps` physics steps, filled with `initial`.
    pub(crate) fn new(steps: usize, initial: Measurement) -> Self {
        Self {
            steps,
            samples: std::iter::repeat_n(initial, steps + 1).collect(),
        }
    }

    /// Whether the line delays at all (a zero delay samples only when read).
    pub(crate) fn delays(&self) -> bool {
        self.steps > 0
    }

    pub(crate) fn push(&mut self, m: Measurement) {
        self.samples.push_back(m);
        while self.samples.len() > self.steps + 1 {
            self.samples.pop_front();
        }
    }

    pub(crate) fn oldest(&self) -> Option<&Measurement> {
        self.samples.front()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_delay_hands_over_the_newest_sample_old_enough() {
        let mut q = VecDeque::new();
        let mut out = Vec::new();
        for t in (0..=10_000).step_by(2_500) {
            out.push(delayed(&mut q, t, t, 5_000, |s| *s));
        }
        // Before the delay has passed, the first sample stands in (the robot was at rest before
        // the episode started); then the sample two periods old.
        assert_eq!(
            out,
            vec![Some(0), Some(0), Some(0), Some(2_500), Some(5_000)],
            "a 5 ms delay at a 2.5 ms period hands over the sample two periods old"
        );
        // Later in time, a sample younger than the delay is never handed over.
        let mut q = VecDeque::new();
        assert_eq!(delayed(&mut q, 10_000, 10_000, 5_000, |s| *s), None);
        assert_eq!(delayed(&mut q, 12_500, 12_500, 5_000, |s| *s), None);
        assert_eq!(delayed(&mut q, 15_000, 15_000, 5_000, |s| *s), Some(10_000));
        assert_eq!(delayed(&mut VecDeque::new(), 7, 7, 0, |s| *s), Some(7));
    }

    #[test]
    fn the_delay_line_reports_the_sample_steps_old() {
        let at = |t: f64| Measurement {
            time_secs: t,
            ..Measurement::default()
        };
        let mut line = DelayLine::new(3, at(0.0));
        for k in 1..=10 {
            line.push(at(f64::from(k)));
        }
        assert_eq!(line.oldest().map(|m| m.time_secs), Some(7.0));
    }
}
