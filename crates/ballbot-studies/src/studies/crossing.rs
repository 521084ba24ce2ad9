//! Bump and step tolerance (the study that proved the experiment driver,
//! [`crate::studies::driver`]): the highest floor bump, or step up, that MiaPURE with 60 kg
//! crosses at a speed and heading, with traction-aware control off and on.
//!
//! One trial: the robot stands for `settle_secs`, ramps (jerk-limited, `ramp_accel_m_per_s2`)
//! to the speed along the heading and cruises; `ahead_m` in front of the ball, once it cruises,
//! the [`Obstacle`] of the height tried is laid across its path: a bar (a circular arc of
//! `width_m` chord, [`FloorBump`]) or a step up (beyond its edge the floor is raised by the
//! height, the edge rounded, [`FloorStep`]). The run goes on for `after_secs` after the ball
//! reached the obstacle. The trial **passes** when the ball's centre got past it (beyond the
//! bar's far edge; over the step's rounded edge, above the raised floor) and the robot follows
//! its command again at the end (outcome `recovered`: balancing, within 0.2 m/s of the
//! command). The world's slip and lift-off stop rules are off
//! ([`StopRules::contact_rules_off`]): a fall (the tilt rule's 25 deg, or the body on the
//! floor) is the failure, and slips and lift-offs are events. A job bisects the height
//! ([`crate::studies::driver::bisect`]).
//!
//! The study is a [`Study`]: [`CrossingStudy`] is the type, [`execute`](super::driver::execute)
//! runs it, `report::crossing` renders it (`summary.json`'s `bump_tolerance` and
//! `step_tolerance`). The obstacle's contact is the floor's: the ball coating's compliant law
//! on the bar's arc, or on the step's riser, edge and top ([`ballbot_world::world::floor`]).

use super::driver::{Bisection, Study};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{AxisLimits, Command, JerkLimiter, VelocityCommand};
use ballbot_world::rig::{Happened, Outcome, OutcomeTracker, WorldRobot};
use ballbot_world::world::{
    BallbotWorld, FloorBump, FloorStep, StopRules, WorldError, WorldParams,
};
use nalgebra::Vector3;

/// What a crossing study lays across the path; its height is the trial's.
///
/// Serialised flat into the protocol (untagged): a bump as `width_m`, a step as
/// `edge_radius_m`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum Obstacle {
    /// A bar ([`FloorBump`]): a circular arc of the height tried, 4 m long across the path.
    Bump {
        /// The bar's chord along the path (m).
        width_m: f64,
    },
    /// A step up ([`FloorStep`]): from its edge line on, the floor is raised by the height
    /// tried; the edge is rounded with `edge_radius_m`, or with the height when the step is
    /// lower than that (a quarter-round edge, as `FloorStep` requires a radius <= the height).
    Step {
        /// The edge's radius (m).
        edge_radius_m: f64,
    },
}

impl Obstacle {
    /// The bump study's bar: 100 mm wide along the path, a cable protector's or a door
    /// threshold's size (a protocol choice, not a measured floor).
    pub const BUMP: Self = Self::Bump { width_m: 0.1 };

    /// The step study's step: its edge rounded with 3 mm. A wooden door threshold's or a
    /// floor-transition profile's edge is rounded over with about 3 mm (1/8 in, the common
    /// round-over), a ceramic tile's eased or cushion edge with 1 to 3 mm; 3 mm is the gentler
    /// end of that range (a protocol choice, not a measured floor). A step lower than 3 mm
    /// gets a quarter-round edge of its own height. The radius matters little against the
    /// ball's 114.5 mm: where the ball first touches the edge, the contact's normal leans from
    /// the vertical by less than 0.7 deg more with a sharp edge than with this one, for any
    /// step up to 40 mm (geometry); the floor's model uses the flat coating law over the whole
    /// step (`world::floor::terrain`).
    pub const STEP: Self = Self::Step {
        edge_radius_m: 0.003,
    };

    /// `bump` or `step`: the summary's `<name>_tolerance`, the progress line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Bump { .. } => "bump",
            Self::Step { .. } => "step",
        }
    }

    /// Its one size besides the height (m), and the settings' name of that field: a bar's
    /// width, a step's edge radius.
    fn size(&self) -> (f64, &'static str) {
        match *self {
            Self::Bump { width_m } => (width_m, "crossing.width_m"),
            Self::Step { edge_radius_m } => (edge_radius_m, "crossing.edge_radius_m"),
        }
    }

    /// Puts the obstacle `height_m` high on `world`'s floor across a path heading
    /// `heading_deg` (from world x), at `line_m` on the floor: the bar's centre line, the
    /// step's edge. Returns where, along the path from that line, the obstacle begins (the
    /// ball has reached it when its front gets there) and where the ball's centre is past it
    /// (m).
    pub fn lay(
        &self,
        world: &mut BallbotWorld,
        line_m: [f64; 2],
        heading_deg: f64,
        height_m: f64,
    ) -> Result<(f64, f64), WorldError> {
        match *self {
            Self::Bump { width_m } => {
                world.add_floor_bump(FloorBump {
                    centre_m: line_m,
                    heading_deg,
                    height_m,
                    width_m,
                    length_m: 4.0,
                })?;
                Ok((-0.5 * width_m, 0.5 * width_m))
            }
            Self::Step { edge_radius_m } => {
                let edge_radius_m = edge_radius_m.min(height_m);
                world.add_floor_step(FloorStep {
                    edge_m: line_m,
                    heading_deg,
                    height_m,
                    edge_radius_m,
                })?;
                // Past the rounded edge, the floor below the ball's centre is the raised one.
                Ok((0.0, edge_radius_m))
            }
        }
    }
}

/// A crossing study's protocol and grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CrossingSettings {
    /// Cruise speeds (m/s).
    pub speeds_m_per_s: Vec<f64>,
    /// Headings of travel in the body frame (deg; 0 towards OW1).
    pub headings_deg: Vec<f64>,
    /// Traction-aware control off (`false`), on (`true`), or both.
    pub traction_control: Vec<bool>,
    /// The height search (m): `passing` 0, `failing` tried first.
    pub height_search: Bisection,
    /// What is laid across the path (its fields flattened into the protocol).
    #[serde(flatten)]
    pub obstacle: Obstacle,
    /// Standing before the ramp (s).
    pub settle_secs: f64,
    /// The ramp's acceleration (m/s^2); its jerk is the core shaper's 2 m/s^3.
    pub ramp_accel_m_per_s2: f64,
    /// Cruising before the obstacle is laid (s).
    pub cruise_secs: f64,
    /// Distance from the ball's centre to the obstacle's line when it is laid (m): the bar's
    /// centre line, the step's edge.
    pub ahead_m: f64,
    /// How long the run goes on after the ball reached the obstacle (s).
    pub after_secs: f64,
    /// Sensor-noise seed of every run.
    pub seed: u64,
}

/// Jerk of the approach ramp (m/s^3): the core command shaper's default.
pub const RAMP_JERK_M_PER_S3: f64 = 2.0;

impl CrossingSettings {
    /// The full study (`ballbot reproduce`) over `obstacle` ([`Obstacle::BUMP`],
    /// [`Obstacle::STEP`]): 0.5 / 1.0 / 1.4 m/s towards 0 / 90 / 180 deg, traction-aware
    /// control off and on, heights bisected in (0, 40 mm] to 0.25 mm.
    ///
    /// 40 mm is above any bar or step a 0.2 m ball is expected to climb at walking speed.
    pub fn full(obstacle: Obstacle) -> Self {
        Self {
            speeds_m_per_s: vec![1.4, 1.0, 0.5],
            headings_deg: vec![0.0, 90.0, 180.0],
            traction_control: vec![false, true],
            height_search: Bisection::new(0.0, 0.04, 0.000_25),
            obstacle,
            settle_secs: 0.5,
            ramp_accel_m_per_s2: 0.5,
            cruise_secs: 0.5,
            ahead_m: 0.5,
            after_secs: 2.5,
            seed: 1,
        }
    }

    /// The CI smoke variant (`ballbot reproduce --quick`): 1.0 m/s towards 0 and 180 deg,
    /// traction-aware control off and on, heights to 2 mm.
    pub fn quick(obstacle: Obstacle) -> Self {
        Self {
            speeds_m_per_s: vec![1.0],
            headings_deg: vec![0.0, 180.0],
            height_search: Bisection::new(0.0, 0.04, 0.002),
            ..Self::full(obstacle)
        }
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), WorldError> {
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let non_negative = |v: f64| v.is_finite() && v >= 0.0;
        if self.speeds_m_per_s.is_empty() || !self.speeds_m_per_s.iter().all(|&v| positive(v)) {
            return invalid(
                "crossing.speeds_m_per_s",
                "must be non-empty, each finite and > 0",
            );
        }
        if self.headings_deg.is_empty() || !self.headings_deg.iter().all(|h| h.is_finite()) {
            return invalid("crossing.headings_deg", "must be non-empty, each finite");
        }
        if self.traction_control.is_empty() {
            return invalid("crossing.traction_control", "must be non-empty");
        }
        if let Err(requirement) = self.height_search.validate() {
            return invalid("crossing.height_search", requirement);
        }
        let s = &self.height_search;
        if s.passing != 0.0 || !positive(s.failing) {
            return invalid(
                "crossing.height_search",
                "passing must be 0 and failing a height > 0 (m)",
            );
        }
        for (v, field) in [
            self.obstacle.size(),
            (self.ramp_accel_m_per_s2, "crossing.ramp_accel_m_per_s2"),
            (self.ahead_m, "crossing.ahead_m"),
            (self.after_secs, "crossing.after_secs"),
        ] {
            if !positive(v) {
                return invalid(field, "must be finite and > 0");
            }
        }
        for (v, field) in [
            (self.settle_secs, "crossing.settle_secs"),
            (self.cruise_secs, "crossing.cruise_secs"),
        ] {
            if !non_negative(v) {
                return invalid(field, "must be finite and >= 0");
            }
        }
        Ok(())
    }
}

/// One cell of the grid.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CrossingJob {
    /// Cruise speed (m/s).
    pub speed_m_per_s: f64,
    /// Heading of travel (deg, body frame).
    pub heading_deg: f64,
    /// Whether traction-aware control is on.
    pub traction_control: bool,
}

/// One crossing.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossingTrial {
    /// The obstacle's height (m).
    pub height_m: f64,
    /// Whether the ball's centre got past the obstacle: beyond the bar's far edge, or over the
    /// step's rounded edge (above the raised floor).
    pub crossed: bool,
    /// Largest tilt from the vertical after the obstacle was laid (deg).
    pub peak_tilt_deg: f64,
    /// Largest upward speed of the ball after the obstacle was laid (m/s): how hard it was
    /// thrown.
    pub peak_ball_rise_m_per_s: f64,
    /// Highest the ball's centre rose above where it was when the obstacle was laid (m): the
    /// height when the ball rolled over the bar's crest or onto the step, more if the obstacle
    /// threw it into the air.
    pub peak_ball_lift_m: f64,
    /// How the run ended and its contact events.
    pub happened: Happened,
}

impl CrossingTrial {
    /// Whether the trial passed: crossed, and following the command again at the end.
    pub fn passed(&self) -> bool {
        self.crossed && matches!(self.happened.outcome, Outcome::Recovered { .. })
    }
}

/// The study: settings and the world it runs in.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossingStudy {
    /// The protocol, grid and obstacle.
    pub settings: CrossingSettings,
    /// The world (its sensor seed is replaced by the settings').
    pub world: WorldParams,
}

impl CrossingStudy {
    /// The controller of a job: the paper's configuration (the one the paper's studies pin),
    /// with traction-aware control when the job asks for it.
    pub fn controller(
        &self,
        job: &CrossingJob,
    ) -> Result<BallbotControllerConfig<f64>, WorldError> {
        let paper = BallbotControllerConfig::paper(&self.world.robot).map_err(WorldError::Robot)?;
        Ok(if job.traction_control {
            paper.with_traction_control()
        } else {
            paper
        })
    }
}

impl Study for CrossingStudy {
    type Job = CrossingJob;
    type Trial = CrossingTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<CrossingJob> {
        let s = &self.settings;
        let mut jobs = Vec::new();
        for &speed_m_per_s in &s.speeds_m_per_s {
            for &heading_deg in &s.headings_deg {
                for &traction_control in &s.traction_control {
                    jobs.push(CrossingJob {
                        speed_m_per_s,
                        heading_deg,
                        traction_control,
                    });
                }
            }
        }
        jobs
    }

    fn bisection(&self, _job: &CrossingJob) -> Option<Bisection> {
        Some(self.settings.height_search)
    }

    fn trial(
        &self,
        job: &CrossingJob,
        value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<CrossingTrial, WorldError> {
        let height_m = value.unwrap_or(self.settings.height_search.failing);
        cross(self, job, height_m, observe)
    }

    fn passed(&self, trial: &CrossingTrial) -> bool {
        trial.passed()
    }

    fn describe(&self, job: &CrossingJob, _value: Option<f64>, trial: &CrossingTrial) -> String {
        format!(
            "{} {:.0} deg {:.1} m/s traction {}: {:.2} mm {}",
            self.settings.obstacle.name(),
            job.heading_deg,
            job.speed_m_per_s,
            if job.traction_control { "on" } else { "off" },
            trial.height_m * 1e3,
            if trial.passed() {
                "crossed"
            } else {
                trial.happened.outcome.as_str()
            }
        )
    }
}

/// One crossing of the study's obstacle `height_m` high (see the [module](self) docs).
pub fn cross(
    study: &CrossingStudy,
    job: &CrossingJob,
    height_m: f64,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<CrossingTrial, WorldError> {
    let s = &study.settings;
    s.validate()?;
    if !(height_m.is_finite() && height_m > 0.0) {
        return Err(WorldError::InvalidParameter {
            field: "crossing height_m",
            requirement: "must be finite and > 0",
        });
    }
    let mut world = study.world;
    world.sensors.seed = s.seed;
    let dt = world.dt_secs;
    let mut sim = WorldRobot::with_config(world, study.controller(job)?)?;
    sim.world_mut()
        .set_stop_rules(StopRules::contact_rules_off());
    let mut judge = OutcomeTracker::default();
    let (sin_h, cos_h) = job.heading_deg.to_radians().sin_cos();
    let limits = AxisLimits {
        max_value: job.speed_m_per_s,
        max_rate_per_s: s.ramp_accel_m_per_s2,
        max_jerk_per_s2: RAMP_JERK_M_PER_S3,
    };
    let mut ramp = JerkLimiter::at(0.0);
    let ramp_secs =
        job.speed_m_per_s / s.ramp_accel_m_per_s2 + s.ramp_accel_m_per_s2 / RAMP_JERK_M_PER_S3;
    let lay_at_secs = s.settle_secs + ramp_secs + s.cruise_secs;
    // The run ends `after_secs` after the ball reached the obstacle, 0.25 s after a fall, or
    // at the latest at twice the planned time (a robot that never gets to it).
    let planned_secs = lay_at_secs + s.ahead_m / job.speed_m_per_s + s.after_secs;
    let steps = (2.0 * planned_secs / dt).ceil() as u64;
    let mut trial = CrossingTrial {
        height_m,
        crossed: false,
        peak_tilt_deg: 0.0,
        peak_ball_rise_m_per_s: 0.0,
        peak_ball_lift_m: 0.0,
        happened: Happened::of(&sim, &judge),
    };
    let mut laid: Option<Laid> = None;
    let mut ball_z_at_lay_m = 0.0;
    let mut reached_at: Option<f64> = None;
    for k in 0..steps {
        let t = k as f64 * dt;
        if laid.is_none() && t >= lay_at_secs {
            laid = Some(lay(&mut sim, s, job, height_m)?);
            ball_z_at_lay_m = sim.world().telemetry().ball_position_m.z;
        }
        let v = if t >= s.settle_secs {
            ramp.step(job.speed_m_per_s, &limits, dt)
        } else {
            0.0
        };
        let command = VelocityCommand {
            vx_m_per_s: v * cos_h,
            vy_m_per_s: v * sin_h,
            yaw_rate_rad_per_s: 0.0,
        };
        let tel = *sim.step(Command::Velocity(command));
        observe(&sim);
        if sim.world().failure().is_none() {
            let v_yaw = tel.ball_velocity_yaw_frame_m_per_s();
            judge.update(
                &sim,
                [v_yaw.x, v_yaw.y],
                [command.vx_m_per_s, command.vy_m_per_s],
            );
        }
        let Some(laid) = laid else {
            continue;
        };
        let along = tel.ball_position_m.dot(&laid.direction);
        let tilt = ballbot_world::world::failure::tilt_from_vertical_rad(&tel);
        trial.peak_tilt_deg = trial.peak_tilt_deg.max(tilt.to_degrees());
        trial.peak_ball_rise_m_per_s = trial
            .peak_ball_rise_m_per_s
            .max(tel.ball_velocity_m_per_s.z);
        trial.peak_ball_lift_m = trial
            .peak_ball_lift_m
            .max(tel.ball_position_m.z - ball_z_at_lay_m);
        if along >= laid.line_along_m + laid.past_m {
            trial.crossed = true;
        }
        let ball_front = along + world.robot.ball_radius_m();
        if reached_at.is_none() && ball_front >= laid.line_along_m + laid.begins_m {
            reached_at = Some(t);
        }
        let done = reached_at.is_some_and(|r| t >= r + s.after_secs);
        let fallen = sim
            .world()
            .failure()
            .is_some_and(|f| t >= f.time_secs + 0.25);
        if done || fallen {
            break;
        }
    }
    trial.happened = Happened::of(&sim, &judge);
    Ok(trial)
}

/// Where the obstacle lies on the path.
#[derive(Clone, Copy, Debug)]
struct Laid {
    /// The path's direction in the world (horizontal, unit).
    direction: Vector3<f64>,
    /// The obstacle's line (the bar's centre line, the step's edge) along the path (m).
    line_along_m: f64,
    /// Where the obstacle begins, from its line along the path (m).
    begins_m: f64,
    /// Where the ball's centre is past it, from its line along the path (m).
    past_m: f64,
}

/// Lays the study's obstacle `ahead_m` in front of the ball across its path.
fn lay(
    sim: &mut WorldRobot,
    s: &CrossingSettings,
    job: &CrossingJob,
    height_m: f64,
) -> Result<Laid, WorldError> {
    let tel = sim.world().telemetry();
    let (_, _, yaw) = tel.body_orientation.euler_angles();
    let heading_world_rad = yaw + job.heading_deg.to_radians();
    let direction = Vector3::new(heading_world_rad.cos(), heading_world_rad.sin(), 0.0);
    let ball = tel.ball_position_m;
    let line = ball + direction * s.ahead_m;
    let (begins_m, past_m) = s.obstacle.lay(
        sim.world_mut(),
        [line.x, line.y],
        heading_world_rad.to_degrees(),
        height_m,
    )?;
    Ok(Laid {
        direction,
        line_along_m: line.dot(&direction),
        begins_m,
        past_m,
    })
}
