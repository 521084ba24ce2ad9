//! The paper's controller comparison in the 3D world: the LQR, the cascaded
//! PI-PD and the cascaded LQR-PI balancing MiaPURE with 60 kg, standing, through a velocity
//! cycle and after a push.
//!
//! The paper compared the three on its testbed (PIPTB) and reports that LQR and PI-PD "were
//! not formally tested due to their poor performance in the balancing task for the MiaPURE
//! drivetrain during the pilot studies". Here each runs in the default world (its drivetrain's
//! stiction, coupling and backlash, docs/world-drivetrain.md) and, to tell what the drivetrain
//! does, in the same world with a rigid drivetrain. Every gain comes from its controller's own
//! design rule, nothing is tuned for the comparison:
//!
//! - `lqr_pi`: [`BallbotControllerConfig::paper`] (discrete LQR per plane at 400 Hz, the
//!   reference model, motor speed PIs at 8 kHz with a 30 rad/s bandwidth);
//! - `lqr`: the same LQR with the motor PIs off, its torque open loop to the drivers
//!   ([`BallbotControllerConfig::with_torque_only_lqr`]), as the paper ran it;
//! - `pi_pd`: a PI-PD per plane by pole placement ([`BallbotControllerConfig::with_pi_pd`],
//!   [`ballbot_core::control::PiPdGains::for_wip`]), torque open loop.
//!
//! The spin loop, the command shaper and the safety supervisor are the same for all three.
//!
//! **Tasks** (sensor seed 1; the world's slip and lift-off stop rules are off, so only a fall,
//! 25 deg or the body on the floor, or a driver trip ends a run early):
//! - `standing`: a zero command;
//! - `velocity_cycle`: 0.8 m/s away from OW1 (180 deg), then 0.8 m/s sideways (90 deg), then
//!   stop, each jerk-limited at 0.5 m/s^2 and 2 m/s^3;
//! - `push`: standing, a 20 N s push towards OW1 (0 deg) at the centre of mass over 0.1 s.
//!
//! **Measures**, over the whole run (the standing before the task included) up to its end or
//! a fall: `tilt_rms_rad` (the body's tilt from the
//! vertical), `speed_rmse_m_per_s` (the ball's velocity against the command, in the yaw
//! frame), `torque_jitter_nm` (the RMS, over the three wheels, of each motor's delivered torque
//! minus its own trailing 10 ms mean: the part of the torque above about 50 Hz), and
//! `balanced`: no fall or driver trip and still balancing at the end.

use super::driver::{Bisection, Study};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{AxisLimits, Command, JerkLimiter, VelocityCommand};
use ballbot_core::safety::Mode;
use ballbot_world::rig::{Happened, OutcomeTracker, WorldRobot};
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::{StopRules, TransmissionParams, WorldError, WorldParams};
use nalgebra::{Rotation3, Vector3};

/// The three controllers of the paper's comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Controller3d {
    /// LQR, torque open loop.
    Lqr,
    /// Cascaded PI-PD, torque open loop.
    PiPd,
    /// Cascaded LQR-PI (the paper's).
    LqrPi,
}

impl Controller3d {
    /// Every controller, in the paper's order.
    pub const ALL: [Self; 3] = [Self::Lqr, Self::PiPd, Self::LqrPi];

    /// The canonical (snake_case) name, the summary's key.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Lqr => "lqr",
            Self::PiPd => "pi_pd",
            Self::LqrPi => "lqr_pi",
        }
    }

    /// The configuration for `world`'s robot (module documentation).
    pub fn config(self, world: &WorldParams) -> Result<BallbotControllerConfig<f64>, WorldError> {
        let paper = BallbotControllerConfig::paper(&world.robot)?;
        Ok(match self {
            Self::Lqr => paper.with_torque_only_lqr(),
            Self::PiPd => paper.with_pi_pd()?,
            Self::LqrPi => paper,
        })
    }
}

/// The tasks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Task3d {
    /// Standing on a zero command.
    Standing,
    /// 0.8 m/s towards 180 deg, then towards 90 deg, then stop.
    VelocityCycle,
    /// A 20 N s push towards 0 deg while standing.
    Push,
}

impl Task3d {
    /// Every task.
    pub const ALL: [Self; 3] = [Self::Standing, Self::VelocityCycle, Self::Push];

    /// The canonical (snake_case) name, the summary's key.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Standing => "standing",
            Self::VelocityCycle => "velocity_cycle",
            Self::Push => "push",
        }
    }
}

/// Which drivetrain the world has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Drivetrain3d {
    /// The default world's ([`TransmissionParams::miapure`]).
    Default,
    /// The default world with a rigid drivetrain ([`TransmissionParams::rigid`]).
    Rigid,
}

impl Drivetrain3d {
    /// The canonical (snake_case) name, the summary's key.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Default => "default",
            Self::Rigid => "rigid",
        }
    }
}

/// The protocol.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Controllers3dSettings {
    /// The drivetrains to run (the default world first).
    pub drivetrains: Vec<Drivetrain3d>,
    /// Standing before the task starts (s; measured like the task).
    pub settle_secs: f64,
    /// How long the standing task stands after `settle_secs` (s).
    pub standing_secs: f64,
    /// How long each leg of the velocity cycle holds its command (s).
    pub cycle_leg_secs: f64,
    /// The cycle's speed (m/s).
    pub cycle_speed_m_per_s: f64,
    /// The cycle's acceleration and jerk limits (m/s^2, m/s^3).
    pub cycle_accel_m_per_s2: f64,
    /// See [`Self::cycle_accel_m_per_s2`].
    pub cycle_jerk_m_per_s3: f64,
    /// The push's impulse (N s), spread over `push_duration_secs`, towards `push_heading_deg`.
    pub push_impulse_ns: f64,
    /// See [`Self::push_impulse_ns`].
    pub push_duration_secs: f64,
    /// See [`Self::push_impulse_ns`] (deg, body frame; 0 towards OW1).
    pub push_heading_deg: f64,
    /// How long the push task watches after the push (s).
    pub after_push_secs: f64,
    /// Window of the torque-jitter mean (s).
    pub jitter_window_secs: f64,
    /// Sensor-noise seed.
    pub seed: u64,
}

impl Controllers3dSettings {
    /// The full comparison (`ballbot reproduce`): both drivetrains.
    pub fn full() -> Self {
        Self {
            drivetrains: vec![Drivetrain3d::Default, Drivetrain3d::Rigid],
            settle_secs: 1.0,
            standing_secs: 10.0,
            cycle_leg_secs: 5.0,
            cycle_speed_m_per_s: 0.8,
            cycle_accel_m_per_s2: 0.5,
            cycle_jerk_m_per_s3: 2.0,
            push_impulse_ns: 20.0,
            push_duration_secs: 0.1,
            push_heading_deg: 0.0,
            after_push_secs: 5.0,
            jitter_window_secs: 0.01,
            seed: 1,
        }
    }

    /// The CI smoke variant: the default world only, shorter tasks.
    pub fn quick() -> Self {
        Self {
            drivetrains: vec![Drivetrain3d::Default],
            standing_secs: 3.0,
            cycle_leg_secs: 3.0,
            after_push_secs: 3.0,
            ..Self::full()
        }
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), WorldError> {
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        if self.drivetrains.is_empty() {
            return invalid("controllers_3d.drivetrains", "must be non-empty");
        }
        for (v, field) in [
            (self.standing_secs, "controllers_3d.standing_secs"),
            (self.cycle_leg_secs, "controllers_3d.cycle_leg_secs"),
            (
                self.cycle_speed_m_per_s,
                "controllers_3d.cycle_speed_m_per_s",
            ),
            (
                self.cycle_accel_m_per_s2,
                "controllers_3d.cycle_accel_m_per_s2",
            ),
            (
                self.cycle_jerk_m_per_s3,
                "controllers_3d.cycle_jerk_m_per_s3",
            ),
            (self.push_impulse_ns, "controllers_3d.push_impulse_ns"),
            (self.push_duration_secs, "controllers_3d.push_duration_secs"),
            (self.after_push_secs, "controllers_3d.after_push_secs"),
            (self.jitter_window_secs, "controllers_3d.jitter_window_secs"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return invalid(field, "must be finite and > 0");
            }
        }
        if !(self.settle_secs.is_finite() && self.settle_secs >= 0.0) {
            return invalid("controllers_3d.settle_secs", "must be finite and >= 0");
        }
        if !self.push_heading_deg.is_finite() {
            return invalid("controllers_3d.push_heading_deg", "must be finite");
        }
        Ok(())
    }

    /// The task's length after `settle_secs` (s).
    pub fn task_secs(&self, task: Task3d) -> f64 {
        match task {
            Task3d::Standing => self.standing_secs,
            Task3d::VelocityCycle => 3.0 * self.cycle_leg_secs,
            Task3d::Push => self.push_duration_secs + self.after_push_secs,
        }
    }

    /// The velocity command at `t` s after `settle_secs`, before the jerk limit `(vx, vy)`
    /// (m/s, yaw frame).
    fn target(&self, task: Task3d, t: f64) -> [f64; 2] {
        if task != Task3d::VelocityCycle || t < 0.0 {
            return [0.0; 2];
        }
        let v = self.cycle_speed_m_per_s;
        match (t / self.cycle_leg_secs) as u32 {
            0 => [-v, 0.0],
            1 => [0.0, v],
            _ => [0.0; 2],
        }
    }
}

/// One run: a controller, a task, a drivetrain.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Controllers3dJob {
    /// The controller.
    pub controller: Controller3d,
    /// The task.
    pub task: Task3d,
    /// The world's drivetrain.
    pub drivetrain: Drivetrain3d,
}

/// What one run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Controllers3dTrial {
    /// No fall or driver trip, and still balancing at the end.
    pub balanced: bool,
    /// RMS of the body's tilt from the vertical (rad).
    pub tilt_rms_rad: f64,
    /// RMS of the ball's velocity error against the command (m/s).
    pub speed_rmse_m_per_s: f64,
    /// RMS over the wheels of the delivered torque minus its trailing mean (N m).
    pub torque_jitter_nm: f64,
    /// Largest tilt from the vertical (rad).
    pub peak_tilt_rad: f64,
    /// Simulated time the measures cover (s).
    pub measured_secs: f64,
    /// How the run ended and its events.
    pub happened: Happened,
}

/// The study: the protocol and the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Controllers3dStudy {
    /// The protocol.
    pub settings: Controllers3dSettings,
    /// The default world (the drivetrain is set per job).
    pub world: WorldParams,
}

impl Controllers3dStudy {
    /// The world of `job`.
    pub fn world(&self, job: &Controllers3dJob) -> WorldParams {
        let mut w = self.world;
        w.sensors.seed = self.settings.seed;
        if job.drivetrain == Drivetrain3d::Rigid {
            w.transmission = TransmissionParams::rigid();
        }
        w
    }
}

impl Study for Controllers3dStudy {
    type Job = Controllers3dJob;
    type Trial = Controllers3dTrial;
    type Error = WorldError;

    fn jobs(&self) -> Vec<Controllers3dJob> {
        let mut jobs = Vec::new();
        for &drivetrain in &self.settings.drivetrains {
            for controller in Controller3d::ALL {
                for task in Task3d::ALL {
                    jobs.push(Controllers3dJob {
                        controller,
                        task,
                        drivetrain,
                    });
                }
            }
        }
        jobs
    }

    fn bisection(&self, _job: &Controllers3dJob) -> Option<Bisection> {
        None
    }

    fn trial(
        &self,
        job: &Controllers3dJob,
        _value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<Controllers3dTrial, WorldError> {
        run_task(self, job, observe)
    }

    fn passed(&self, trial: &Controllers3dTrial) -> bool {
        trial.balanced
    }

    fn describe(
        &self,
        job: &Controllers3dJob,
        _value: Option<f64>,
        t: &Controllers3dTrial,
    ) -> String {
        format!(
            "{} {} ({} drivetrain): {}, tilt RMS {:.2} deg",
            job.controller.as_str(),
            job.task.as_str(),
            job.drivetrain.as_str(),
            if t.balanced {
                "balanced"
            } else {
                t.happened.outcome.as_str()
            },
            t.tilt_rms_rad.to_degrees()
        )
    }
}

/// Running sums of the measures.
#[derive(Clone, Debug, Default)]
struct Measures {
    steps: u64,
    tilt_sq: f64,
    speed_sq: f64,
    jitter_sq: f64,
    peak_tilt: f64,
}

/// Each wheel's trailing mean of the delivered torque over a fixed number of steps.
#[derive(Clone, Debug)]
struct TrailingMean {
    window: Vec<[f64; 3]>,
    sum: [f64; 3],
    next: usize,
    filled: usize,
}

impl TrailingMean {
    fn new(steps: usize) -> Self {
        Self {
            window: vec![[0.0; 3]; steps.max(1)],
            sum: [0.0; 3],
            next: 0,
            filled: 0,
        }
    }

    /// Adds `torques`; returns the mean including them.
    fn push(&mut self, torques: [f64; 3]) -> [f64; 3] {
        let old = self.window[self.next];
        for i in 0..3 {
            self.sum[i] += torques[i] - old[i];
        }
        self.window[self.next] = torques;
        self.next = (self.next + 1) % self.window.len();
        self.filled = (self.filled + 1).min(self.window.len());
        let n = self.filled as f64;
        self.sum.map(|s| s / n)
    }
}

/// One run of `job` (see the [module](self) docs).
pub fn run_task(
    study: &Controllers3dStudy,
    job: &Controllers3dJob,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<Controllers3dTrial, WorldError> {
    let s = &study.settings;
    s.validate()?;
    let world = study.world(job);
    let dt = world.dt_secs;
    let mut sim = WorldRobot::with_config(world, job.controller.config(&world)?)?;
    sim.world_mut()
        .set_stop_rules(StopRules::contact_rules_off());
    let mut judge = OutcomeTracker::default();
    let limits = AxisLimits {
        max_value: s.cycle_speed_m_per_s,
        max_rate_per_s: s.cycle_accel_m_per_s2,
        max_jerk_per_s2: s.cycle_jerk_m_per_s3,
    };
    let mut shaped = [JerkLimiter::at(0.0), JerkLimiter::at(0.0)];
    let mut torque_mean = TrailingMean::new((s.jitter_window_secs / dt).round() as usize);
    let settle_steps = (s.settle_secs / dt).round() as u64;
    let steps = settle_steps + (s.task_secs(job.task) / dt).round() as u64;
    let push_steps = (s.push_duration_secs / dt).round().max(1.0) as u64;
    let mut push_direction = Vector3::x();
    let mut m = Measures::default();
    for k in 0..steps {
        let t = k as f64 * dt - s.settle_secs;
        if job.task == Task3d::Push && k == settle_steps {
            let (_, _, yaw) = sim.world().telemetry().body_orientation.euler_angles();
            push_direction = Rotation3::from_axis_angle(
                &Vector3::z_axis(),
                yaw + s.push_heading_deg.to_radians(),
            ) * Vector3::x();
        }
        if job.task == Task3d::Push && (settle_steps..settle_steps + push_steps).contains(&k) {
            sim.world_mut()
                .push_body(push_direction * (s.push_impulse_ns / push_steps as f64));
        }
        let target = s.target(job.task, t);
        let v = [0, 1].map(|i| shaped[i].step(target[i], &limits, dt));
        let command = VelocityCommand {
            vx_m_per_s: v[0],
            vy_m_per_s: v[1],
            yaw_rate_rad_per_s: 0.0,
        };
        let tel = *sim.step(Command::Velocity(command));
        observe(&sim);
        let ball = tel.ball_velocity_yaw_frame_m_per_s();
        if sim.world().failure().is_none() {
            judge.update(&sim, [ball.x, ball.y], v);
        }
        let torques = tel.wheels.map(|w| w.motor_torque_nm);
        let mean = torque_mean.push(torques);
        let tilt = tilt_from_vertical_rad(&tel);
        m.steps += 1;
        m.tilt_sq += tilt * tilt;
        m.peak_tilt = m.peak_tilt.max(tilt);
        m.speed_sq += (ball.x - v[0]).powi(2) + (ball.y - v[1]).powi(2);
        m.jitter_sq += (0..3).map(|i| (torques[i] - mean[i]).powi(2)).sum::<f64>() / 3.0;
        if sim.world().failure().is_some() {
            break;
        }
    }
    let happened = Happened::of(&sim, &judge);
    let n = m.steps.max(1) as f64;
    Ok(Controllers3dTrial {
        balanced: sim.world().failure().is_none() && sim.mode() == Mode::Balancing,
        tilt_rms_rad: (m.tilt_sq / n).sqrt(),
        speed_rmse_m_per_s: (m.speed_sq / n).sqrt(),
        torque_jitter_nm: (m.jitter_sq / n).sqrt(),
        peak_tilt_rad: m.peak_tilt,
        measured_secs: m.steps as f64 * dt,
        happened,
    })
}
