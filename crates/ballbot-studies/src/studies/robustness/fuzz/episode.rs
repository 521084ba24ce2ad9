//! One seeded fuzz episode of the 3D controller: a healthy closed loop on the planar plant,
//! pushed now and then, hit by bursts of hostile inputs (hostile episodes) or driven by any
//! command the API accepts (accepted-command episodes), with every invariant of
//! [`super::invariants`] checked on every step.

use super::corruption::Target;
use super::hostile::{accepted_command, chance, hostile, index, request, symmetric, unit};
use super::invariants::{self as inv, BAD, Invariant};
use super::plant::tilt_from_vertical_rad;
use super::rig::{FuzzRig, INNER_PER_OUTER, InnerFault, Observed};
use super::trajectories::{describe, random_trajectory, valid_trajectory};
use ballbot_core::ballbot::{BallbotControllerConfig, OuterInput};
use ballbot_core::command::{Command, Trajectory};
use ballbot_core::safety::{Fault, Mode, ModeRequest};
use ballbot_core::wip::WipState;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use std::collections::{BTreeMap, BTreeSet};

/// What an episode does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EpisodeKind {
    /// Healthy loop, bursts of hostile sensor, clock, command and request inputs.
    Hostile,
    /// Any velocity, lean or stop command the API accepts, switched at random times, on
    /// healthy sensors: must never end with the motors off.
    Accepted,
    /// The same with trajectories the API accepts (any finite samples, any sample period)
    /// among them: must never end with the motors off either (the `accepted_command` invariant).
    AcceptedTrajectories,
}

/// A broken invariant, re-runnable from its episode seed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Violation {
    /// `bad_command` (must never happen) or `finding` (reported and explained), the class of
    /// the invariant (see [`super::invariants`]).
    pub kind: &'static str,
    /// The invariant's key.
    pub invariant: &'static str,
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
    /// Pushes on the plant.
    pub pushes: u64,
    /// Broken invariants, first ones.
    pub violations: Vec<Violation>,
    /// Bad commands counted (all, not only the recorded ones).
    pub bad_commands: u64,
    /// Findings counted.
    pub findings: u64,
    /// Findings by what happened (the violation's text up to the details in brackets).
    pub findings_by_what: BTreeMap<String, u64>,
    /// Breaks (events) by invariant key.
    pub by_invariant: BTreeMap<&'static str, u64>,
}

impl EpisodeCounts {
    /// Counts a break of `invariant` at `outer_step` of episode `seed`, recording the first
    /// ten of each class.
    pub fn record(&mut self, invariant: Invariant, seed: u64, outer_step: u64, what: String) {
        *self.by_invariant.entry(invariant.key).or_insert(0) += 1;
        if invariant.class == BAD {
            self.bad_commands += 1;
        } else {
            self.findings += 1;
            let head = what.split(" (").next().unwrap_or_default().to_owned();
            *self.findings_by_what.entry(head).or_insert(0) += 1;
        }
        let recorded = self
            .violations
            .iter()
            .filter(|v| v.kind == invariant.class)
            .count();
        if recorded < 10 {
            self.violations.push(Violation {
                kind: invariant.class,
                invariant: invariant.key,
                episode_seed: seed,
                outer_step,
                what,
            });
        }
    }
}

/// Item 5: a fault this soon after a push on the plant is the push's (2 s: in the campaign's
/// accepted episodes every such fault came within 0.5 s of the push, and none without one).
const PUSH_RECOVERY_STEPS: u64 = 800;
/// The bin of a push's impulse (N s) in the findings' counts: the Monte Carlo's 40 N s and
/// the world's recovery limits (43 to 79 N s) at the bins' edges.
fn push_bin(impulse_ns: f64) -> &'static str {
    match impulse_ns {
        x if x < 10.0 => "1 to 10",
        x if x < 40.0 => "10 to 40",
        x if x < 100.0 => "40 to 100",
        _ => "100 to 200",
    }
}

/// Outer steps a single corrupted sample is followed against its clean twin.
const TWIN_STEPS: usize = 40;
/// After the twin window, applied torques of the two may differ by at most this (N m): no
/// integrator wound up by one sample.
const MAX_LASTING_TORQUE_DIFFERENCE_NM: f64 = 1.0;
/// Outer period (us).
const PERIOD_US: u64 = 2_500;
/// Item 3: a slip flag on the slip-free plant must be clear after this many outer steps of
/// consistent data (2 s: the slip monitor's hold and the observers' settling are well below).
const SLIP_CLEAR_STEPS: u64 = 800;
/// Item 3: a controlled stop at rest for this long (2 s) ...
const STOPPED_FOR_STEPS: u64 = 800;
/// ... after this long of consistent data (4 s: a push's recovery is over) ...
const STOPPED_QUIET_STEPS: u64 = 1_600;
/// ... holds the ball below this (m/s): five times the runtime's rest speed (0.02 m/s).
const STILL_M_PER_S: f64 = 0.1;
/// Item 4: a controlled stop reports rest within this many outer steps (10 s): three times
/// the slowest stop the shaper's limits allow (2 m/s at 1 m/s^2 with a jerk of 2 m/s^3,
/// starting at full acceleration: 3.5 s).
const STOP_BOUND_STEPS: u64 = 4_000;
/// Item 8: a velocity target this far from the shaped one (m/s) ...
const ENVELOPE_GAP_M_PER_S: f64 = 0.5;
/// ... without an acceleration limit for this many steps (0.1 s) skipped the envelope.
const ENVELOPE_STEPS: u32 = 40;
/// Item 9: after re-arming at rest on a stop command, the ball stays below
/// [`STILL_M_PER_S`] for this many outer steps (2 s).
const REARM_STEPS: u64 = 800;

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

/// What the invariants keep between steps.
#[derive(Debug)]
struct Oracle {
    /// The newest valid IMU sample's time, a stamp ahead of the clock counting as now.
    newest_imu_us: u64,
    /// The stamp of the newest valid IMU sample (for stalled-stamp corruptions).
    last_imu_stamp: u64,
    /// Consecutive outer ticks on which the clock did not advance (a stall), and whether it
    /// stepped back on this tick.
    ticks_stalled: u64,
    stepped_back: bool,
    /// The last step with a corrupted sample, a push, a plant reset or a twin check.
    last_disturbance: u64,
    /// The last push on the plant: its step and impulse (N s).
    last_push: Option<(u64, f64)>,
    /// Consecutive steps in a controlled stop, and of those reported at rest.
    stop_steps: u64,
    stopped_steps: u64,
    /// Consecutive steps a velocity target was far from the shaped command without a limit.
    envelope_steps: u32,
    /// The step the robot was re-armed at rest, while the window of item 9 is open.
    rearmed_at: Option<u64>,
    /// Until this step the command stays a stop (after a disarm).
    hold_stop_until: u64,
    /// Invariants broken in the previous step (a break is counted when it starts).
    broken: BTreeSet<&'static str>,
}

/// [`run_episode`] on a given rig (e.g. a motor loop configured otherwise, or the `f32`
/// controller).
pub fn run_episode_on(
    mut rig: FuzzRig,
    kind: EpisodeKind,
    seed: u64,
    outer_steps: u64,
) -> EpisodeCounts {
    let config = rig.config;
    // What the controller accepts (`BallbotController::accept_trajectory`).
    let trajectory_limits = config.trajectory_limits();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut counts = EpisodeCounts::default();
    let mut now_us: u64 = 1_000_000;
    let mut command: Command<'static, f64> = Command::Stop;
    let mut trajectory: Option<(Vec<WipState<f64>>, f64, f64, u64)> = None;
    let mut burst: Option<(Target, u32)> = None;
    let mut stall_left: u32 = 0;
    let mut o = Oracle {
        newest_imu_us: now_us,
        last_imu_stamp: now_us,
        ticks_stalled: 0,
        stepped_back: false,
        last_disturbance: 0,
        last_push: None,
        stop_steps: 0,
        stopped_steps: 0,
        envelope_steps: 0,
        rearmed_at: None,
        hold_stop_until: 0,
        broken: BTreeSet::new(),
    };
    let tilt_limit = config.safety.tilt_limit_rad;
    let clock_ticks = config.safety.imu_timeout_us.div_ceil(PERIOD_US) + 1;
    let accepted = kind != EpisodeKind::Hostile;
    let mut k: u64 = 0;
    while k < outer_steps {
        // The clock: mostly the period, sometimes jittered; hostile episodes also stall it
        // (for up to 60 ticks), jump it forward and send it back.
        let step_us = if stall_left > 0 {
            stall_left -= 1;
            0
        } else {
            match kind {
                EpisodeKind::Hostile if chance(&mut rng, 0.002) => match index(&mut rng, 3) {
                    0 => {
                        stall_left = index(&mut rng, 60) as u32;
                        0
                    }
                    1 => PERIOD_US + (unit(&mut rng) * 1e6) as u64,
                    _ => {
                        now_us = now_us.saturating_sub((unit(&mut rng) * 1e6) as u64);
                        0
                    }
                },
                _ if chance(&mut rng, 0.05) => {
                    (PERIOD_US as f64 + symmetric(&mut rng, 1_000.0)) as u64
                }
                _ => PERIOD_US,
            }
        };
        let previous_us = now_us;
        now_us = now_us.saturating_add(step_us);
        o.stepped_back = now_us < previous_us;
        if now_us > previous_us {
            o.ticks_stalled = 0;
        } else {
            o.ticks_stalled += 1;
        }
        // The documented clock semantics: nothing kept is ahead of the clock.
        o.newest_imu_us = o.newest_imu_us.min(now_us);
        // Pushes on the plant, from small to beyond recoverable: 1 to 200 N s, log-uniform,
        // any direction (the Monte Carlo's push is 40 N s), one every 5 s on average.
        if chance(&mut rng, 0.0005) {
            let size = 10f64.powf(2.3 * unit(&mut rng));
            let (s, c) = (std::f64::consts::TAU * unit(&mut rng)).sin_cos();
            rig.plant.push([size * c, size * s]);
            counts.pushes += 1;
            o.last_disturbance = k;
            o.last_push = Some((k, size));
        }
        let (mut imu, mut encoders) = rig.plant.sensors(now_us);
        // A real IMU is never bit-identical twice (the frozen check relies on it).
        imu.roll_rad += symmetric(&mut rng, 1e-6);
        imu.angular_velocity_rad_per_s[1] += symmetric(&mut rng, 1e-6);
        let mode = rig.mode();
        let req = next_request(&mut rng, kind, mode, &o, k);
        if req == ModeRequest::Disarm && mode == Mode::Balancing {
            o.hold_stop_until = k + 3 * REARM_STEPS;
        }
        if k < o.hold_stop_until {
            trajectory = None;
            command = Command::Stop;
        } else if chance(&mut rng, 0.004) {
            if kind == EpisodeKind::AcceptedTrajectories && !rig.is_f32() && chance(&mut rng, 0.5) {
                // Half of them valid (a manoeuvre within the limits), half gentle to absurd
                // (mostly rejected: the rejection is exercised too).
                trajectory = Some(match &trajectory_limits {
                    Ok(limits) if chance(&mut rng, 0.5) => {
                        valid_trajectory(&mut rng, &config, limits, k)
                    }
                    _ => random_trajectory(&mut rng, k),
                });
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
                    &config,
                    &mut imu,
                    &mut encoders,
                    &mut command_ts,
                    &mut inner_fault,
                    now_us,
                    o.last_imu_stamp,
                );
                burst = (left > 1).then_some((target, left - 1));
            }
            // Item 7: a wild first encoder reading as the motors are enabled.
            if corrupted.is_none()
                && mode == Mode::Idle
                && req == ModeRequest::Arm
                && chance(&mut rng, 0.3)
            {
                let range = config.safety.encoder_range_rad_per_s;
                inner_fault = Some(InnerFault::Encoder {
                    step: 0,
                    wheel: index(&mut rng, 3),
                    value: symmetric(&mut rng, range),
                });
                corrupted = Some(Target::FirstAfterEnable);
                single = true;
            }
        }
        if corrupted.is_some() {
            o.last_disturbance = k;
        }
        let traj;
        let cmd = match &trajectory {
            Some((samples, period, heading, start)) => {
                // What the controller accepts (`BallbotController::accept_trajectory`): the
                // limits of its configuration.
                traj = match &trajectory_limits {
                    Ok(limits) => Trajectory::new(samples, *period, *heading, limits),
                    Err(e) => Err(*e),
                };
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
        let fresh = valid && imu.timestamp_us > o.newest_imu_us;
        if valid {
            o.newest_imu_us = o.newest_imu_us.max(imu.timestamp_us.min(now_us));
            o.last_imu_stamp = imu.timestamp_us.min(now_us);
        }
        let arming = mode == Mode::Idle && req == ModeRequest::Arm;
        let twin = (single && (mode == Mode::Balancing || arming)).then_some(rig);
        let period = rig.period(&input, inner_fault);
        counts.outer_steps += 1;
        counts.inner_steps += INNER_PER_OUTER as u64;
        for f in period.out.safety.faults.iter() {
            counts.faults[usize::from(f.code())] += 1;
        }
        let out = period.out;
        let mut found: Vec<(Invariant, String)> = Vec::new();
        if let Some(what) = period.broken {
            let invariant = if what.starts_with("a mode transition") {
                inv::TRANSITIONS
            } else {
                inv::LIMITS
            };
            found.push((invariant, format!("{what} (corrupted: {corrupted:?})")));
        }
        let timeout = config.safety.imu_timeout_us + 2 * PERIOD_US;
        if out.motors.enabled && now_us.saturating_sub(o.newest_imu_us) > timeout && step_us != 0 {
            found.push((
                inv::STALE_IMU,
                "the motors stayed on without a fresh IMU sample for longer than the timeout"
                    .to_owned(),
            ));
        }
        // 1: the tilt from the vertical, on a valid fresh sample of the true attitude.
        let imu_true = !matches!(corrupted, Some(Target::Imu(_) | Target::ImuStamp(_)));
        let tilt = tilt_from_vertical_rad(imu.roll_rad, imu.pitch_rad);
        if imu_true && fresh && out.motors.enabled && tilt > tilt_limit + 1e-6 {
            found.push((
                inv::TILT,
                format!(
                    "motors on at {:.1} deg from the vertical (roll {:.1}, pitch {:.1} deg; limit {:.1})",
                    tilt.to_degrees(),
                    imu.roll_rad.to_degrees(),
                    imu.pitch_rad.to_degrees(),
                    tilt_limit.to_degrees()
                ),
            ));
        }
        // 2: dead motors are the runtime episodes' (`fuzz::runtime`): the drivers' feedback
        // and its health monitor live in `RobotLoop`.
        // 3: slip flags clear on consistent data; a stop at rest holds the ball still.
        let quiet = k.saturating_sub(o.last_disturbance);
        if let Some(slipping) = out.slipping
            && slipping.iter().any(|s| *s)
            && quiet > SLIP_CLEAR_STEPS
        {
            found.push((
                inv::SLIP_CLEARS,
                format!("slip flags {slipping:?} after {quiet} steps of consistent data"),
            ));
        }
        if out.safety.mode == Mode::ControlledStop {
            o.stop_steps += 1;
            o.stopped_steps = if out.stopped { o.stopped_steps + 1 } else { 0 };
        } else {
            o.stop_steps = 0;
            o.stopped_steps = 0;
        }
        let speed = rig.plant.ball_speed_m_per_s();
        if o.stopped_steps > STOPPED_FOR_STEPS
            && quiet > STOPPED_QUIET_STEPS
            && speed > STILL_M_PER_S
        {
            found.push((
                inv::STOPPED_STILL,
                format!("the ball rolls at {speed:.3} m/s while the stop reports rest"),
            ));
        }
        // 4: a controlled stop reaches rest.
        if o.stop_steps > STOP_BOUND_STEPS && !out.stopped {
            found.push((
                inv::STOP_REACHES_REST,
                format!(
                    "a controlled stop has not reported rest after {} s (ball {speed:.3} m/s)",
                    o.stop_steps as f64 * 0.0025
                ),
            ));
        }
        // 5: an accepted command never ends in a fault, unless a push knocked the robot over.
        if accepted && out.safety.mode == Mode::Fault && mode != Mode::Fault {
            let faults = out.safety.faults.iter().collect::<Vec<_>>();
            match o.last_push.filter(|(at, _)| k - at <= PUSH_RECOVERY_STEPS) {
                Some((at, ns)) => found.push((
                    inv::FELL_AFTER_PUSH,
                    format!(
                        "a fault within 2 s of a push of {} N s ({:.2} s after {ns:.1} N s; {faults:?}; command {})",
                        push_bin(ns),
                        (k - at) as f64 * 0.0025,
                        describe(&cmd)
                    ),
                )),
                None => found.push((
                    inv::ACCEPTED,
                    format!(
                        "an accepted command ended in a fault with the motors off ({faults:?}; command {})",
                        describe(&cmd)
                    ),
                )),
            }
        }
        // 6: the clock. A clock that stepped back runs on from its new reading: the supervisor raises
        // `ClockFault` on that tick (a controlled stop), and an operator may resume on fresh
        // samples. A stall is judged over its length.
        if o.stepped_back && out.safety.mode == Mode::Balancing {
            found.push((
                inv::CLOCK,
                "still balancing on the tick the clock stepped back".to_owned(),
            ));
        }
        if o.ticks_stalled > clock_ticks && out.safety.mode == Mode::Balancing {
            found.push((
                inv::CLOCK,
                format!(
                    "still balancing after {} ticks of a clock that did not advance",
                    o.ticks_stalled
                ),
            ));
        }
        // 8: finite intermediates, and the envelope.
        if !out.intermediates_finite {
            found.push((
                inv::FINITE_INTERMEDIATES,
                format!(
                    "a non-finite intermediate value (command {})",
                    describe(&cmd)
                ),
            ));
        }
        if envelope_skipped(&config, &out, &cmd) {
            o.envelope_steps += 1;
        } else {
            o.envelope_steps = 0;
        }
        if o.envelope_steps > ENVELOPE_STEPS {
            found.push((
                inv::ENVELOPE,
                format!(
                    "the shaped command accelerates towards {} without a traction limit",
                    describe(&cmd)
                ),
            ));
        }
        // 9: re-armed at rest on a stop command, no drift.
        if arming && out.safety.mode == Mode::Balancing {
            let at_rest = speed < 0.01 && rig.plant.tilt_from_vertical_rad() < 0.01;
            o.rearmed_at = at_rest.then_some(k);
        }
        if let Some(at) = o.rearmed_at {
            let stop = matches!(cmd, Command::Stop) && out.safety.mode == Mode::Balancing;
            if k - at > REARM_STEPS || !stop || o.last_disturbance > at {
                o.rearmed_at = None;
            } else if speed > STILL_M_PER_S {
                found.push((
                    inv::REARM_DRIFT,
                    format!(
                        "re-armed at rest on a stop, the ball rolls at {speed:.3} m/s after {:.2} s",
                        (k - at) as f64 * 0.0025
                    ),
                ));
                o.rearmed_at = None;
            }
        }
        // After a disarm the operator catches the robot and sets it upright.
        if req == ModeRequest::Disarm && out.safety.mode == Mode::Idle {
            rig.plant.reset();
            o.last_disturbance = k;
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
            let invariant = match corrupted {
                Some(Target::InnerBurst(_)) => inv::ENCODER_BURST,
                Some(Target::InnerEncoder(_) | Target::InnerDt | Target::FirstAfterEnable) => {
                    inv::ENCODER_GUARD
                }
                _ => inv::SINGLE_OUTER_SAMPLE,
            };
            let sensor = corrupted.map_or("", Target::sensor);
            found.extend(what.map(|w| {
                (
                    invariant,
                    format!("{w}: {sensor} (corrupted: {corrupted:?}, {inner_fault:?})"),
                )
            }));
            o.last_imu_stamp = now_us;
            o.newest_imu_us = now_us;
            o.last_disturbance = k;
        }
        let mut broken_now = BTreeSet::new();
        for (invariant, what) in found {
            broken_now.insert(invariant.key);
            // Once per event: the twin checks are events of their own.
            let ongoing = o.broken.contains(invariant.key)
                && !matches!(
                    invariant.key,
                    "single_outer_sample" | "encoder_guard" | "encoder_burst"
                );
            if !ongoing {
                counts.record(invariant, seed, at, what);
            }
        }
        o.broken = broken_now;
        if rig.plant.fallen(0.6) {
            rig.plant.reset();
            o.last_disturbance = k;
        }
        k += 1;
    }
    counts
}

/// The operator's request: re-arm after a fault or a disarm (the plant stood up again),
/// resume a controlled stop once it has been at rest for 2.5 s (or has overrun the bound of
/// item 4), stop and disarm at random; in hostile episodes, anything at any time.
fn next_request(
    rng: &mut ChaCha8Rng,
    kind: EpisodeKind,
    mode: Mode,
    o: &Oracle,
    k: u64,
) -> ModeRequest {
    let settled =
        o.stopped_steps >= STOPPED_FOR_STEPS + 200 || o.stop_steps > STOP_BOUND_STEPS + 400;
    let mut req = match mode {
        Mode::Fault => ModeRequest::Reset,
        Mode::Idle => ModeRequest::Arm,
        Mode::ControlledStop if settled && chance(rng, 0.01) => ModeRequest::Resume,
        Mode::Balancing if k >= o.hold_stop_until && chance(rng, 0.0005) => ModeRequest::Disarm,
        Mode::Balancing if chance(rng, 0.0005) => ModeRequest::Stop,
        _ => ModeRequest::None,
    };
    if kind == EpisodeKind::Hostile && chance(rng, 0.005) {
        req = request(rng);
    }
    req
}

/// Item 8: with traction-aware control, balancing on a velocity command whose target (clamped
/// to the shaper's top speed, computed without overflow) is far from the shaped command, and
/// no acceleration limit in this step.
fn envelope_skipped(
    config: &BallbotControllerConfig<f64>,
    out: &Observed,
    cmd: &Command<'_, f64>,
) -> bool {
    let (Some(None), Command::Velocity(v), Mode::Balancing) =
        (out.accel_limit_m_per_s2, cmd, out.safety.mode)
    else {
        return false;
    };
    let top = config.shaping.translation.max_value;
    // Scaled before squaring: no overflow for any finite component.
    let big = v.vx_m_per_s.abs().max(v.vy_m_per_s.abs());
    let target = if big == 0.0 {
        (0.0, 0.0)
    } else {
        let (x, y) = (v.vx_m_per_s / big, v.vy_m_per_s / big);
        let unit_norm = x.hypot(y);
        if big > top / unit_norm {
            (x * top / unit_norm, y * top / unit_norm)
        } else {
            (v.vx_m_per_s, v.vy_m_per_s)
        }
    };
    let robot = &config.robot;
    let [front, sag] = out.command_ball_rate_rad_per_s;
    // The shaper's ball rates: sagittal `vx / r`, frontal `-vy / r`.
    let shaped = (
        sag * robot.sagittal.ball_radius_m,
        -front * robot.frontal.ball_radius_m,
    );
    (target.0 - shaped.0).hypot(target.1 - shaped.1) > ENVELOPE_GAP_M_PER_S
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
    let same_mode = rig.mode() == clean.mode();
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
