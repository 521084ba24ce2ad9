//! The fuzzer's invariants: what each checks, which item of the safe-by-default hardening it
//! belongs to ([`Invariant::item`]), and how a break is counted (`bad_command`: must never happen, CI fails on one; `finding`: reported
//! with counts and seeds, explained in docs/robustness.md). Each is a property checked on
//! every step of every episode it applies to, not an example.
//!
//! A break is counted once per *event*: on the step it starts, not again while it lasts (a
//! robot that keeps its motors on for 400 steps of a stalled clock is one event).

use serde::Serialize;

/// A hard invariant: must never break (CI fails on one).
pub const BAD: &str = "bad_command";
/// Something the controller should not do but that cannot be told from the truth at the
/// controller's input (or that has no detection in the HAL yet), reported and explained.
pub const FINDING: &str = "finding";

/// One invariant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Invariant {
    /// Key in the counts.
    pub key: &'static str,
    /// The item of the safe-by-default hardening (release 0.8.0) it checks: 1 the tilt from
    /// the vertical, 2 dead or unanswering motors, 3 slip flags that clear and stops that
    /// hold still, 4 stops that reach rest, 5 accepted commands that end balancing or
    /// stopped, 6 a stalled or backwards clock, 7 the encoder guard, 8 huge finite commands,
    /// 9 re-arming at rest; 0 for the reliability campaign's first invariants, which came
    /// before it. Serialized as `item`.
    pub item: u8,
    /// [`BAD`] or [`FINDING`].
    pub class: &'static str,
    /// What it checks.
    pub what: &'static str,
}

const fn inv(key: &'static str, item: u8, class: &'static str, what: &'static str) -> Invariant {
    Invariant {
        key,
        item,
        class,
        what,
    }
}

/// Every motor reference and torque finite, within the peak torque, the no-load speed and the
/// torque-speed line at the measured speed, zero with the motors off (item 0: one of the
/// reliability campaign's first invariants).
pub const LIMITS: Invariant = inv(
    "limits",
    0,
    BAD,
    "motor references and torques finite, within the peak, the no-load speed and the torque-speed line, zero with the motors off",
);
/// Only the documented mode transitions (item 0).
pub const TRANSITIONS: Invariant = inv(
    "transitions",
    0,
    BAD,
    "only the documented mode transitions",
);
/// Motors off once no fresh valid IMU sample came for longer than the timeout, by the clock.
pub const STALE_IMU: Invariant = inv(
    "stale_imu",
    0,
    BAD,
    "motors off once no fresh valid IMU sample came for longer than the IMU timeout (by the clock)",
);
/// A single wrong in-range sample at the outer tick reaching the torque limit or winding an
/// integrator up (compared with a clean twin): indistinguishable from a real one.
pub const SINGLE_OUTER_SAMPLE: Invariant = inv(
    "single_outer_sample",
    0,
    FINDING,
    "a single wrong IMU or encoder sample at the outer tick drives a motor to its torque limit or leaves a lasting torque difference (against a clean twin)",
);
/// 1: the tilt from the vertical beyond the limit is a fault within one step.
pub const TILT: Invariant = inv(
    "tilt_from_vertical",
    1,
    BAD,
    "a valid fresh IMU sample tilted from the vertical beyond the supervisor's tilt limit leaves the motors off in the same step",
);
/// 2: a dead motor detected from the drivers' feedback (`RobotLoop` episodes: a wheel dies
/// for 0.2 to 2 s, its driver applying and reporting nothing).
pub const MOTOR_HEALTH: Invariant = inv(
    "motor_health",
    2,
    BAD,
    "RobotLoop: a dead driver (applying and reporting 0 N m) commanded beyond three times the health monitor's absolute tolerance for its persistence plus two periods, with the motors on, leaves them on",
);
/// 3: a slip flag on a plant that cannot slip clears within a bounded time on consistent data.
pub const SLIP_CLEARS: Invariant = inv(
    "slip_clears",
    3,
    BAD,
    "no wheel flagged slipping on the slip-free plant after 2 s of consistent data (no corrupted sample, push or reset)",
);
/// 3: a stopped robot does not move.
pub const STOPPED_STILL: Invariant = inv(
    "stopped_is_still",
    3,
    BAD,
    "in a controlled stop reported at rest for 2 s, after 4 s of consistent data, the ball is below 0.1 m/s",
);
/// 4: a stop reaches rest within a bounded time.
pub const STOP_REACHES_REST: Invariant = inv(
    "stop_reaches_rest",
    4,
    BAD,
    "a controlled stop reports rest within 10 s, from any finite state",
);
/// 5: an accepted command or trajectory ends balancing or in a controlled stop.
pub const ACCEPTED: Invariant = inv(
    "accepted_command",
    5,
    BAD,
    "an accepted velocity, lean, stop or trajectory command on healthy sensors, with no push on the plant in the last 2 s, never ends in a fault",
);
/// 5: what the accepted-command invariant leaves out: a fault within 2 s of a push on the
/// plant. Pushes go up to 200 N s, beyond what any ballbot recovers, so such a fall is the
/// push's, not the command's (without pushes the accepted episodes end in no fault at all;
/// docs/robustness.md). Counted with the impulse, so that a fall after a small push shows.
pub const FELL_AFTER_PUSH: Invariant = inv(
    "fell_after_push",
    5,
    FINDING,
    "an accepted command ended in a fault within 2 s of a push on the plant (the impulse is in the message)",
);
/// 6: a stalled or backwards clock is a fault: the controller leaves balancing on the tick
/// the clock steps back, and within the IMU timeout counted in ticks of a stall (the
/// documented reaction, docs/embedding.md: `ClockStalled` or
/// `ClockFault`, a controlled stop; the motors go off once the samples the same clock stamps
/// are stale by ticks).
pub const CLOCK: Invariant = inv(
    "clock",
    6,
    BAD,
    "the controller leaves balancing (a controlled stop or motors off) on the tick the clock steps back, and once it has not advanced for more than the IMU timeout counted in outer ticks",
);
/// 7: the encoder guard: a wild first reading after enabling, or any single sample in the
/// 8 kHz loop, or a wrong step length, never reaches the torque limit.
pub const ENCODER_GUARD: Invariant = inv(
    "encoder_guard",
    7,
    BAD,
    "a wrong encoder sample in the 8 kHz loop (single, or the first after enabling) or a wrong step length never drives a motor to its torque limit where a clean twin does not, nor winds an integrator up",
);
/// 7, open: a constant wrong reading within the encoder's range for longer than the guard's
/// hold is a continuous trajectory, which the guard cannot tell from a wheel that really
/// changed speed: it re-synchronises onto it (`SpeedGuard`, docs/embedding.md). Counted as a
/// finding until the guard also bounds a re-synchronisation by what the wheel could reach
/// from its last trusted speed, or the drivers' own feedback catches it.
pub const ENCODER_BURST: Invariant = inv(
    "encoder_burst",
    7,
    FINDING,
    "a constant wrong encoder reading within range for 9 to 20 samples in the 8 kHz loop (longer than the guard's hold) drives a motor to its torque limit where a clean twin does not",
);
/// 8: huge finite commands produce no non-finite intermediate value.
pub const FINITE_INTERMEDIATES: Invariant = inv(
    "finite_intermediates",
    8,
    BAD,
    "estimated states, shaped commands, reference torques and rates and the traction report stay finite",
);
/// 8: huge finite commands never skip the traction envelope.
pub const ENVELOPE: Invariant = inv(
    "traction_envelope",
    8,
    BAD,
    "with traction-aware control, a velocity command 0.5 m/s or more away from the shaped one is under an acceleration limit (not None for 0.1 s)",
);
/// 9: after disarm and re-arm the robot does not drift on a stop command.
pub const REARM_DRIFT: Invariant = inv(
    "rearm_drift",
    9,
    BAD,
    "re-armed at rest on a stop command, the ball stays below 0.1 m/s for 2 s",
);
/// `RobotLoop` on failing devices: every torque it writes finite and within the limits.
pub const RUNTIME_LIMITS: Invariant = inv(
    "runtime_limits",
    0,
    BAD,
    "RobotLoop with failing HAL reads and writes: every torque it writes finite, within the peak and the torque-speed line",
);
/// `RobotLoop`: persistent read errors end with the motors off within the timeout.
pub const RUNTIME_READ_ERRORS: Invariant = inv(
    "runtime_read_errors",
    0,
    BAD,
    "RobotLoop: IMU or encoder reads failing for longer than their timeout (plus two periods) leave the motors off",
);
/// `RobotLoop`: persistent motor write errors are a fault (`Fault::MotorUnanswered`, from the
/// motor health monitor's count of unanswered steps).
pub const RUNTIME_WRITE_ERRORS: Invariant = inv(
    "runtime_write_errors",
    2,
    BAD,
    "RobotLoop: motor writes failing for longer than the motor health monitor's persistence (plus two periods) leave the motors off",
);
/// The planar controllers: finite, saturated output for any input.
pub const PLANAR: Invariant = inv(
    "planar_controllers",
    0,
    BAD,
    "LQR, PI-PD and LQR-PI planes (f64 and f32): every output finite, torques within their limit, for any input; no state poisoned (a sane input after hostile ones gives a finite output)",
);

/// Every invariant, in report order.
pub const ALL: [Invariant; 21] = [
    LIMITS,
    TRANSITIONS,
    STALE_IMU,
    SINGLE_OUTER_SAMPLE,
    TILT,
    MOTOR_HEALTH,
    SLIP_CLEARS,
    STOPPED_STILL,
    STOP_REACHES_REST,
    ACCEPTED,
    FELL_AFTER_PUSH,
    CLOCK,
    ENCODER_GUARD,
    ENCODER_BURST,
    FINITE_INTERMEDIATES,
    ENVELOPE,
    REARM_DRIFT,
    RUNTIME_LIMITS,
    RUNTIME_READ_ERRORS,
    RUNTIME_WRITE_ERRORS,
    PLANAR,
];

/// The invariant of `key`.
pub fn by_key(key: &str) -> Option<Invariant> {
    ALL.iter().copied().find(|i| i.key == key)
}
