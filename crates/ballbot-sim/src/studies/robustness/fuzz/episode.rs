//! One seeded fuzz episode of the 3D controller: a healthy closed loop on the planar plant,
//! hit by bursts of hostile inputs (hostile episodes) or driven by any command the API
//! accepts (accepted-command episodes), with every invariant checked on every step.

use super::hostile::{accepted_command, chance, hostile, index, request, symmetric, unit};
use super::rig::{FuzzRig, INNER_PER_OUTER, InnerFault};
use ballbot_core::ballbot::{BallbotControllerConfig, OuterInput};
use ballbot_core::command::Command;
use ballbot_core::estimation::{EncoderSample, ImuSample};
use ballbot_core::safety::{Fault, Mode, ModeRequest};
use ballbot_core::wip::WipState;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

/// What an episode does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EpisodeKind {
    /// Healthy loop, bursts of hostile sensor, clock, command and request inputs.
    Hostile,
    /// Any velocity, lean or stop command the API accepts, switched at random times, on
    /// healthy sensors: must never end with the motors off.
    Accepted,
    /// The same with trajectories the API accepts (any finite samples, any sample period)
    /// among them: a fall is a finding (see the module docs of `fuzz`).
    AcceptedTrajectories,
}

/// A broken invariant, re-runnable from its episode seed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Violation {
    /// `bad_command` (a motor command broke a hard invariant: must never happen) or
    /// `finding` (the controller did something the issue asks it not to, reported and
    /// explained: a single wrong in-range IMU sample reaching the torque limit, an accepted
    /// trajectory the robot cannot follow).
    pub kind: &'static str,
    /// The episode's seed.
    pub episode_seed: u64,
    /// The outer step at which it broke.
    pub outer_step: u64,
    /// What broke.
    pub what: String,
}

/// What one episode counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EpisodeCounts {
    /// Outer steps of the fuzzed controller.
    pub outer_steps: u64,
    /// Inner (motor PI) steps.
    pub inner_steps: u64,
    /// Outer steps of the clean twins of the single-sample checks.
    pub twin_outer_steps: u64,
    /// Steps on which each fault was raised, by `Fault::ALL` index.
    pub faults: [u64; Fault::ALL.len()],
    /// Single corrupted samples compared against a clean twin.
    pub single_sample_checks: u64,
    /// Broken invariants, first ones.
    pub violations: Vec<Violation>,
    /// Bad commands counted (all, not only the recorded ones).
    pub bad_commands: u64,
    /// Findings counted.
    pub findings: u64,
    /// Findings by what happened (the violation's text up to the details in brackets).
    pub findings_by_what: std::collections::BTreeMap<String, u64>,
}

/// A motor command that broke a hard invariant.
pub const BAD: &str = "bad_command";
/// Something the issue asks the controller not to do, reported and explained.
pub const FINDING: &str = "finding";

/// Outer steps a single corrupted sample is followed against its clean twin.
const TWIN_STEPS: usize = 40;
/// After the twin window, applied torques of the two may differ by at most this (N m): no
/// integrator wound up by one sample.
const MAX_LASTING_TORQUE_DIFFERENCE_NM: f64 = 1.0;

/// Runs one episode of `outer_steps` outer steps on the controller of `config`.
pub fn run_episode(
    config: BallbotControllerConfig<f64>,
    kind: EpisodeKind,
    seed: u64,
    outer_steps: u64,
) -> Result<EpisodeCounts, ballbot_core::Error> {
    Ok(run_episode_on(
        FuzzRig::new(config)?,
        kind,
        seed,
        outer_steps,
    ))
}

/// [`run_episode`] on a given rig (e.g. a motor loop configured otherwise).
pub fn run_episode_on(
    mut rig: FuzzRig,
    kind: EpisodeKind,
    seed: u64,
    outer_steps: u64,
) -> EpisodeCounts {
    let config = rig.config;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut counts = EpisodeCounts::default();
    let mut now_us: u64 = 1_000_000;
    let mut command: Command<'static, f64> = Command::Stop;
    let mut trajectory: Option<(Vec<WipState<f64>>, f64, f64, u64)> = None;
    let mut burst: Option<(Target, u32)> = None;
    let mut last_imu_stamp = now_us;
    // The oracle of the stale check (docs/embedding.md): the newest valid IMU sample's time,
    // a stamp ahead of the clock counting as now.
    let mut newest_imu_us: u64 = now_us;
    let mut k: u64 = 0;
    while k < outer_steps {
        // The clock: mostly the period, sometimes jittered; hostile episodes also stall it,
        // jump it forward and send it back.
        let step_us = match kind {
            EpisodeKind::Hostile if chance(&mut rng, 0.002) => match index(&mut rng, 3) {
                0 => 0,
                1 => 2_500 + (unit(&mut rng) * 1e6) as u64,
                _ => {
                    now_us = now_us.saturating_sub((unit(&mut rng) * 1e6) as u64);
                    0
                }
            },
            _ if chance(&mut rng, 0.05) => 2_500 + (symmetric(&mut rng, 1_000.0)) as u64,
            _ => 2_500,
        };
        now_us = now_us.saturating_add(step_us);
        // The documented clock semantics: nothing kept is ahead of the clock.
        newest_imu_us = newest_imu_us.min(now_us);
        let (mut imu, mut encoders) = rig.plant.sensors(now_us);
        // A real IMU is never bit-identical twice (the frozen check relies on it).
        imu.roll_rad += symmetric(&mut rng, 1e-6);
        imu.angular_velocity_rad_per_s[1] += symmetric(&mut rng, 1e-6);
        // Requests: re-arm after a stop or a fault (the plant stood up again), and, in
        // hostile episodes, anything at any time.
        let mode = rig.controller.mode();
        let mut req = match mode {
            Mode::Fault => ModeRequest::Reset,
            Mode::Idle => ModeRequest::Arm,
            Mode::ControlledStop if chance(&mut rng, 0.01) => ModeRequest::Resume,
            _ => ModeRequest::None,
        };
        if kind == EpisodeKind::Hostile && chance(&mut rng, 0.005) {
            req = request(&mut rng);
        }
        if chance(&mut rng, 0.004) {
            if kind == EpisodeKind::AcceptedTrajectories && chance(&mut rng, 0.5) {
                trajectory = Some(random_trajectory(&mut rng, k));
            } else {
                trajectory = None;
                command = accepted_command(&mut rng);
            }
        }
        let mut command_ts = Some(now_us);
        let mut inner_fault = None;
        let mut single = false;
        let mut corrupted = None;
        if kind == EpisodeKind::Hostile {
            if burst.is_none() && chance(&mut rng, 0.02) {
                let len = if chance(&mut rng, 0.5) {
                    1
                } else {
                    1 + index(&mut rng, 8) as u32
                };
                burst = Some((Target::random(&mut rng), len));
            }
            if let Some((target, left)) = burst {
                single = left == 1;
                corrupted = Some(target);
                target.apply(
                    &mut rng,
                    &mut imu,
                    &mut encoders,
                    &mut command_ts,
                    &mut inner_fault,
                    now_us,
                    last_imu_stamp,
                );
                burst = (left > 1).then_some((target, left - 1));
            }
        }
        let traj;
        let cmd = match &trajectory {
            Some((samples, period, heading, start)) => {
                traj = rig.controller.accept_trajectory(samples, *period, *heading);
                match traj {
                    Ok(t) => Command::Trajectory {
                        trajectory: t,
                        time_secs: (k - start) as f64 * 0.0025,
                    },
                    Err(_) => Command::Stop,
                }
            }
            None => command,
        };
        let mut cmd = cmd;
        if kind == EpisodeKind::Hostile && chance(&mut rng, 0.002) {
            cmd = Command::Velocity(ballbot_core::command::VelocityCommand {
                vx_m_per_s: hostile(&mut rng),
                vy_m_per_s: hostile(&mut rng),
                yaw_rate_rad_per_s: hostile(&mut rng),
            });
        }
        let input = OuterInput {
            now_us,
            imu,
            encoders,
            command: cmd,
            command_timestamp_us: command_ts,
            request: req,
        };
        // Oracle of the stale check: if no valid IMU sample newer than the kept one came for
        // longer than the timeout plus a period, the motors must be off.
        let gyro = config.safety.gyro_range_rad_per_s;
        let valid = imu.is_finite()
            && imu.roll_rad.abs() <= core::f64::consts::PI
            && imu.pitch_rad.abs() <= core::f64::consts::FRAC_PI_2
            && imu.yaw_rad.abs() <= core::f64::consts::TAU
            && imu
                .angular_velocity_rad_per_s
                .iter()
                .all(|w| w.abs() <= gyro);
        if valid {
            newest_imu_us = newest_imu_us.max(imu.timestamp_us.min(now_us));
            last_imu_stamp = imu.timestamp_us.min(now_us);
        }
        let twin = (single && rig.controller.mode() == Mode::Balancing).then_some(rig);
        let period = rig.period(&input, inner_fault);
        counts.outer_steps += 1;
        counts.inner_steps += INNER_PER_OUTER as u64;
        for f in period.out.safety.faults.iter() {
            counts.faults[usize::from(f.code())] += 1;
        }
        let mut found: Vec<(&'static str, String)> = Vec::new();
        if let Some(what) = period.broken {
            found.push((BAD, format!("{what} (corrupted: {corrupted:?})")));
        }
        let timeout = config.safety.imu_timeout_us + 2 * 2_500;
        if period.out.motors.enabled
            && now_us.saturating_sub(newest_imu_us) > timeout
            && step_us != 0
        {
            found.push((
                BAD,
                "the motors stayed on without a fresh IMU sample for longer than the timeout"
                    .to_owned(),
            ));
        }
        if kind == EpisodeKind::Accepted && period.out.safety.mode == Mode::Fault {
            let kind = if matches!(cmd, Command::Trajectory { .. }) {
                FINDING
            } else {
                BAD
            };
            found.push((
                kind,
                format!(
                    "an accepted command ended in a fault with the motors off ({:?}; command {})",
                    period.out.safety.faults.iter().collect::<Vec<_>>(),
                    describe(&cmd)
                ),
            ));
        }
        let at = k;
        if let Some(mut clean) = twin {
            counts.single_sample_checks += 1;
            let healthy = healthy_input(&clean, &input);
            let (twin_steps, what) =
                follow_twin(&mut clean, &mut rig, healthy, &input, period, &mut now_us);
            counts.twin_outer_steps += twin_steps;
            counts.outer_steps += twin_steps;
            counts.inner_steps += twin_steps * INNER_PER_OUTER as u64;
            k += twin_steps;
            // The 8 kHz loop guards its own input: a sample there that gets through is a bad
            // command. An in-range wrong IMU or encoder sample at the outer tick is
            // indistinguishable from a real one to the outer loop: a finding.
            let kind = match corrupted {
                Some(Target::InnerEncoder(_) | Target::InnerDt) => BAD,
                _ => FINDING,
            };
            found.extend(what.map(|w| (kind, format!("{w} (corrupted: {corrupted:?})"))));
            last_imu_stamp = now_us;
            newest_imu_us = now_us;
        }
        for (kind, what) in found {
            if kind == BAD {
                counts.bad_commands += 1;
            } else {
                counts.findings += 1;
                let head = what.split(" (").next().unwrap_or_default().to_owned();
                let head = match corrupted {
                    Some(t) if head.starts_with("a single") => format!("{head}: {}", t.sensor()),
                    _ => head,
                };
                *counts.findings_by_what.entry(head).or_insert(0) += 1;
            }
            let recorded = counts.violations.iter().filter(|v| v.kind == kind).count();
            if recorded < 10 {
                counts.violations.push(Violation {
                    kind,
                    episode_seed: seed,
                    outer_step: at,
                    what,
                });
            }
        }
        if rig.plant.fallen(0.6) {
            rig.plant.reset();
        }
        k += 1;
    }
    counts
}

/// The input `input` would have been without its corruption: the twin's own plant sensors.
fn healthy_input<'a>(twin: &FuzzRig, input: &OuterInput<'a, f64>) -> OuterInput<'a, f64> {
    let (imu, encoders) = twin.plant.sensors(input.now_us);
    OuterInput {
        imu,
        encoders,
        command_timestamp_us: Some(input.now_us),
        ..*input
    }
}

/// Runs the clean twin on `healthy` and then both rigs on healthy samples for
/// [`TWIN_STEPS`]; checks that the corrupted one never reached the torque limit where the
/// clean one did not, and that their torques agree at the end.
fn follow_twin(
    clean: &mut FuzzRig,
    rig: &mut FuzzRig,
    healthy: OuterInput<'_, f64>,
    input: &OuterInput<'_, f64>,
    first: super::rig::Period,
    now_us: &mut u64,
) -> (u64, Option<&'static str>) {
    let peak = rig.config.robot.drivetrain.actuator.peak_torque_nm;
    let near = 0.99 * peak;
    let mut what = None;
    let clean_first = clean.period(&healthy, None);
    let hit = |p: &super::rig::Period| p.torques.iter().any(|t| t.amax() >= near);
    if hit(&first) && !hit(&clean_first) {
        what = Some("a single corrupted sample drove a motor to its torque limit");
    }
    let mut last = (
        first.torques[INNER_PER_OUTER - 1],
        clean_first.torques[INNER_PER_OUTER - 1],
    );
    let mut steps = 0;
    for _ in 0..TWIN_STEPS {
        *now_us += 2_500;
        let a_in = OuterInput {
            now_us: *now_us,
            command_timestamp_us: Some(*now_us),
            request: ModeRequest::None,
            ..with_sensors(rig, input, *now_us)
        };
        let b_in = OuterInput {
            now_us: *now_us,
            command_timestamp_us: Some(*now_us),
            request: ModeRequest::None,
            ..with_sensors(clean, input, *now_us)
        };
        let a = rig.period(&a_in, None);
        let b = clean.period(&b_in, None);
        steps += 1;
        if what.is_none() {
            what = a.broken;
        }
        if what.is_none() && hit(&a) && !hit(&b) {
            what = Some("a single corrupted sample drove a motor to its torque limit");
        }
        last = (
            a.torques[INNER_PER_OUTER - 1],
            b.torques[INNER_PER_OUTER - 1],
        );
    }
    // Only where the corrupted sample raised no fault: a detected one changes the mode (a
    // controlled stop), and the runs rightly part.
    let same_mode = rig.controller.mode() == clean.controller.mode();
    if what.is_none() && same_mode && (last.0 - last.1).amax() > MAX_LASTING_TORQUE_DIFFERENCE_NM {
        what = Some(
            "a single corrupted sample left a lasting torque difference (integrator wound up)",
        );
    }
    (steps, what)
}

fn with_sensors<'a>(
    rig: &FuzzRig,
    input: &OuterInput<'a, f64>,
    now_us: u64,
) -> OuterInput<'a, f64> {
    let (imu, encoders) = rig.plant.sensors(now_us);
    OuterInput {
        imu,
        encoders,
        ..*input
    }
}

/// A trajectory the API accepts: 1 to 40 finite samples, any positive sample period, values
/// from gentle to absurd.
fn random_trajectory(rng: &mut ChaCha8Rng, start: u64) -> (Vec<WipState<f64>>, f64, f64, u64) {
    let n = 1 + index(rng, 40);
    let scale = [0.1, 1.0, 10.0, 1e4][index(rng, 4)];
    let samples = (0..n)
        .map(|_| {
            WipState::new(
                symmetric(rng, 0.1 * scale),
                symmetric(rng, 10.0 * scale),
                symmetric(rng, scale),
                symmetric(rng, 10.0 * scale),
            )
        })
        .collect();
    let period = [1e-6, 1e-3, 0.0025, 0.1, 10.0, 1e6][index(rng, 6)];
    (samples, period, symmetric(rng, 10.0), start)
}

/// What a burst corrupts.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    /// An IMU field (roll, pitch, yaw, three rates).
    Imu(usize),
    /// An encoder speed at the outer tick.
    Encoder(usize),
    /// The IMU stamp: ahead of the clock, stalled, or behind it.
    ImuStamp(usize),
    /// The encoder stamp, likewise.
    EncoderStamp(usize),
    /// The command link's stamp: none, stalled.
    CommandStamp,
    /// An encoder sample in the 8 kHz loop.
    InnerEncoder(usize),
    /// The 8 kHz loop's step length.
    InnerDt,
}

impl Target {
    /// Which sensor the target is, for the tallies.
    fn sensor(self) -> &'static str {
        match self {
            Self::Imu(_) | Self::ImuStamp(_) => "IMU at the outer tick",
            Self::Encoder(_) | Self::EncoderStamp(_) => "encoder at the outer tick",
            Self::CommandStamp => "command link",
            Self::InnerEncoder(_) | Self::InnerDt => "the 8 kHz loop",
        }
    }

    fn random(rng: &mut ChaCha8Rng) -> Self {
        match index(rng, 8) {
            0 | 1 => Self::Imu(index(rng, 6)),
            2 => Self::Encoder(index(rng, 3)),
            3 => Self::ImuStamp(index(rng, 3)),
            4 => Self::EncoderStamp(index(rng, 3)),
            5 => Self::CommandStamp,
            6 => Self::InnerEncoder(index(rng, 3)),
            _ => Self::InnerDt,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn apply(
        self,
        rng: &mut ChaCha8Rng,
        imu: &mut ImuSample<f64>,
        encoders: &mut EncoderSample<f64>,
        command_ts: &mut Option<u64>,
        inner: &mut Option<InnerFault>,
        now_us: u64,
        last_imu_stamp: u64,
    ) {
        let stamp = |rng: &mut ChaCha8Rng, which: usize| match which {
            0 => now_us.saturating_add(1 + (unit(rng) * 3.6e9) as u64),
            1 => last_imu_stamp,
            _ => now_us.saturating_sub(1 + (unit(rng) * 1e7) as u64),
        };
        match self {
            Self::Imu(i) => {
                let v = hostile(rng);
                match i {
                    0 => imu.roll_rad = v,
                    1 => imu.pitch_rad = v,
                    2 => imu.yaw_rad = v,
                    j => imu.angular_velocity_rad_per_s[j - 3] = v,
                }
            }
            Self::Encoder(w) => encoders.wheel_speeds_rad_per_s[w] = hostile(rng),
            Self::ImuStamp(which) => imu.timestamp_us = stamp(rng, which),
            Self::EncoderStamp(which) => encoders.timestamp_us = stamp(rng, which),
            Self::CommandStamp => *command_ts = None,
            Self::InnerEncoder(w) => {
                *inner = Some(InnerFault::Encoder {
                    step: index(rng, INNER_PER_OUTER),
                    wheel: w,
                    value: hostile(rng),
                });
            }
            Self::InnerDt => {
                *inner = Some(InnerFault::Dt {
                    dt_secs: hostile(rng),
                })
            }
        }
    }
}

/// A short description of a command for a violation's record.
fn describe(command: &Command<'_, f64>) -> String {
    match command {
        Command::Stop => "stop".to_owned(),
        Command::Velocity(v) => format!(
            "velocity {:.3e} {:.3e} {:.3e}",
            v.vx_m_per_s, v.vy_m_per_s, v.yaw_rate_rad_per_s
        ),
        Command::Lean(l) => format!(
            "lean {:.3e} {:.3e} {:.3e}",
            l.towards_x_rad, l.towards_y_rad, l.yaw_rate_rad_per_s
        ),
        Command::Trajectory { time_secs, .. } => format!("trajectory at {time_secs:.2} s"),
    }
}
