//! Trajectory acceptance ([`TrajectoryLimits`]): what the validation rejects (the controller
//! cannot follow it), and that what it accepts ends in balancing or a controlled stop on the
//! closed-loop planar plant.

#![allow(clippy::unwrap_used)] // test helpers, not only #[test] functions

use crate::ballbot3d::{OUTER_US, Rig, velocity};
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, JerkLimiter, Trajectory, TrajectoryLimits};
use ballbot_core::safety::{Mode, ModeRequest};
use ballbot_core::wip::{BALL_RATE, TILT};
use ballbot_core::{BallbotParams, Error, WipState};
use nalgebra::Vector4;

fn design() -> BallbotControllerConfig<f64> {
    BallbotControllerConfig::design(&BallbotParams::miapure_60kg()).unwrap()
}

/// The world-braking study's widened shaping (fast trajectories, 0.5 rad tilt commands).
fn brisk() -> BallbotControllerConfig<f64> {
    let mut config = design();
    config.shaping.translation.max_rate_per_s = 20.0;
    config.shaping.translation.max_jerk_per_s2 = 500.0;
    config.shaping.max_tilt_command_rad = 0.5;
    config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
    config
}

fn field(result: Result<Trajectory<'_, f64>, Error>) -> Option<&'static str> {
    match result {
        Err(Error::InvalidParameter { field, .. }) => Some(field),
        _ => None,
    }
}

#[test]
fn validation_rejects_what_the_controller_cannot_follow() {
    let limits = design().trajectory_limits().unwrap();
    let still = [Vector4::zeros(), Vector4::zeros()];
    // Sample periods near the smallest positive double, or just under the outer period.
    for period in [f64::MIN_POSITIVE, 5e-324, 1e-300, 1e-6, 0.0024] {
        let got = field(Trajectory::new(&still, period, 0.0, &limits));
        assert_eq!(got, Some("sample_period_secs"), "{period:e}");
    }
    assert!(Trajectory::new(&still, 0.0025, 0.0, &limits).is_ok());
    // Tilts, tilt rates and ball rates beyond their physical bounds, near the largest double
    // and just beyond the bound.
    let beyond = |i: usize, x: f64| {
        let mut s = Vector4::zeros();
        s[i] = x;
        [s]
    };
    for (i, bound) in [
        (0, limits.max_tilt_rad),
        (2, limits.max_tilt_rate_rad_per_s),
        (3, limits.max_ball_rate_rad_per_s),
    ] {
        for x in [f64::MAX, -1e300, bound * (1.0 + 1e-9)] {
            let samples = beyond(i, x);
            let got = field(Trajectory::new(&samples, 0.01, 0.0, &limits));
            assert_eq!(got, Some("samples"), "state {i} at {x:e}");
        }
    }
    // A tilt-rate step over one outer period (1 rad/s in 2.5 ms): the tilt does not follow
    // (inconsistent), and 400 rad/s^2 needs c0 x 400 N m.
    let step = [Vector4::zeros(), Vector4::new(0.0, 0.0, 1.0, 0.0)];
    assert_eq!(
        field(Trajectory::new(&step, 0.0025, 0.0, &limits)),
        Some("samples")
    );
    // The same with the tilt following the rate: still beyond the torque.
    let step = [
        Vector4::zeros(),
        Vector4::new(0.00125, 0.0, 1.0, 0.0),
        Vector4::new(0.00375, 0.0, 1.0, 0.0),
    ];
    assert_eq!(
        field(Trajectory::new(&step, 0.0025, 0.0, &limits)),
        Some("samples")
    );
    // A tilt that changes while its rate says it does not.
    let drift = [Vector4::zeros(), Vector4::new(0.1, 0.0, 0.0, 0.0)];
    assert_eq!(
        field(Trajectory::new(&drift, 0.01, 0.0, &limits)),
        Some("samples")
    );
    // A ball acceleration beyond the shaper's (1 m/s^2 / r).
    let a = limits.max_ball_accel_rad_per_s2 * 1.01;
    let fast = [Vector4::zeros(), Vector4::new(0.0, 0.0, 0.0, a * 0.1)];
    assert_eq!(
        field(Trajectory::new(&fast, 0.1, 0.0, &limits)),
        Some("samples")
    );
    // Ending with the body still swinging (the last sample is held at rate 0).
    let swinging = [Vector4::new(0.0, 0.0, 0.5, 0.0)];
    assert_eq!(
        field(Trajectory::new(&swinging, 0.01, 0.0, &limits)),
        Some("samples")
    );
}

#[test]
fn trajectories_the_old_check_accepted_are_refused() {
    // What `Trajectory::new` accepted before its limits, and the controller faulted on with the
    // motors off (a sample period near the smallest double, a tilt near the largest) or ran
    // away with (a tilt-rate step over a short interval, a lean held for 1.5e54 s that its
    // accelerations do not need: the fuzzer's, which fell): refused by the controller's
    // limits.
    let fine = [Vector4::zeros(), Vector4::new(0.0, 0.0, 0.0, 1.0)];
    let huge = [
        Vector4::new(1e308, 0.0, 0.0, 0.0),
        Vector4::new(-1e308, 0.0, 1e308, 0.0),
    ];
    let step = [
        Vector4::zeros(),
        Vector4::new(0.0, 0.0, 1.0, 0.0),
        Vector4::new(0.0, 0.0, 1.0, 0.0),
        Vector4::zeros(),
    ];
    let held = [
        Vector4::new(0.058_703, -3.943_568, 0.524_541, -1.161_322),
        Vector4::new(-0.010_445, 7.675_331, 0.564_121, -8.698_330),
        Vector4::new(0.048_540, -9.349_682, 0.167_794, 6.784_700),
    ];
    // The same lean and tilt rate held as long, then upright: only its interpolation is
    // wrong.
    let held_then_upright = [held[0], Vector4::new(0.0, 0.0, 0.0, 0.0)];
    // A lean of 1 deg held for ever after the end: it accelerates the ball for ever.
    let leaning_at_the_end = [Vector4::new(0.0175, 0.0, 0.0, 0.0)];
    let cases: [(&[WipState<f64>], f64); 6] = [
        (&fine, 1e-300),
        (&huge, 0.01),
        (&step, 0.0025),
        (&held, 1.514e54),
        (&held_then_upright, 1.514e54),
        (&leaning_at_the_end, 0.0025),
    ];
    let rig = Rig::with_config(design());
    for (i, (samples, period)) in cases.into_iter().enumerate() {
        assert!(
            rig.outer.accept_trajectory(samples, period, 0.0).is_err(),
            "case {i}"
        );
    }
}

/// splitmix64: the seeded generator of the random trajectories.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [0, 1], or exactly 1 a quarter of the time (at the bound).
    fn fraction(&mut self) -> f64 {
        if self.unit() < 0.25 { 1.0 } else { self.unit() }
    }

    fn sign(&mut self) -> f64 {
        if self.unit() < 0.5 { -1.0 } else { 1.0 }
    }
}

/// A random trajectory within `limits` (dynamically inconsistent on purpose: the tilt and the
/// ball move independently, as far as the limits allow): a smooth tilt excursion `sum A (1 - cos(w t)) / 2`
/// (back upright and still at the end) and a ball rate `V0 + V1 (1 - cos(w_b t)) / 2`, the
/// torque split between them at random, amplitudes up to the bounds, the period from the floor
/// to 0.2 s, any heading.
fn random_trajectory(
    rng: &mut Rng,
    limits: &TrajectoryLimits<f64>,
) -> (Vec<WipState<f64>>, f64, f64) {
    let floor = limits.min_sample_period_secs;
    let period = floor * (0.2f64 / floor).powf(rng.unit() * rng.unit());
    let duration = 0.2 + 3.8 * rng.unit();
    let n = ((duration / period).round() as usize).max(1);
    let total = n as f64 * period;
    let margin = 0.999;
    // The torque and the lean split between tilt and ball acceleration at random.
    let share = rng.unit();
    let tilt_accel = margin
        * share
        * limits
            .max_tilt_accel_rad_per_s2()
            .min(limits.max_tilt_rad / limits.lean_per_tilt_accel_s2);
    let ball_accel = margin
        * (1.0 - share)
        * (limits.max_torque_nm / limits.ball_inertia_kg_m2)
            .min(limits.max_tilt_rad / limits.lean_per_ball_accel_s2)
            .min(limits.max_ball_accel_rad_per_s2 / (1.0 - share).max(1e-9));
    // Two tilt harmonics (whole cycles over the duration), each with half of each bound.
    let harmonics: Vec<(f64, f64)> = (0..2)
        .map(|_| {
            let w = 2.0 * std::f64::consts::PI * (1 + (rng.next() % 6)) as f64 / total;
            let a = (0.5 * limits.max_tilt_rad)
                .min(limits.max_tilt_rate_rad_per_s / w)
                .min(tilt_accel / (w * w));
            (margin * a * rng.fraction() * rng.sign(), w)
        })
        .collect();
    let w_b = 2.0 * std::f64::consts::PI * (1 + (rng.next() % 3)) as f64 / (2.0 * total);
    let v_max = margin * limits.max_ball_rate_rad_per_s;
    let v1 = (v_max.min(2.0 * ball_accel / w_b)) * rng.fraction() * rng.sign();
    let v0 = (v_max - v1.abs()) * rng.fraction() * rng.sign();
    let samples = (0..=n)
        .map(|k| {
            let t = k as f64 * period;
            let (mut tilt, mut rate) = (0.0, 0.0);
            for &(a, w) in &harmonics {
                tilt += a * (1.0 - (w * t).cos()) / 2.0;
                rate += a * w * (w * t).sin() / 2.0;
            }
            let ball_rate = v0 + v1 * (1.0 - (w_b * t).cos()) / 2.0;
            let ball_angle = v0 * t + v1 * (t - (w_b * t).sin() / w_b) / 2.0;
            Vector4::new(tilt, ball_angle, rate, ball_rate)
        })
        .collect();
    let heading = std::f64::consts::PI * (2.0 * rng.unit() - 1.0);
    (samples, period, heading)
}

/// Runs accepted random trajectories on the closed-loop plant: never a fault with the motors
/// off, the tilt within the supervisor's limit, balancing at the end.
fn accepted_trajectories_end_balancing(
    config: BallbotControllerConfig<f64>,
    seed: u64,
    count: usize,
) {
    let limits = config.trajectory_limits().unwrap();
    let tilt_limit = config.safety.tilt_limit_rad;
    let mut rng = Rng(seed);
    for i in 0..count {
        let (samples, period, heading) = random_trajectory(&mut rng, &limits);
        let mut rig = Rig::with_config(config);
        let accepted = rig.outer.accept_trajectory(&samples, period, heading);
        assert!(
            accepted.is_ok(),
            "seed {seed}, trajectory {i}: generated outside the limits: {:?}",
            accepted.err()
        );
        let trajectory = accepted.unwrap();
        rig.arm();
        // First the cruise the trajectory starts at (a trajectory starts where the robot is),
        // ramped within the designed shaping's limits.
        let start = samples[0][BALL_RATE] * config.robot.sagittal.ball_radius_m;
        let ramp_limits = design().shaping.translation;
        let mut ramp = JerkLimiter::at(0.0);
        for _ in 0..1600 {
            let v = ramp.step(start, &ramp_limits, OUTER_US as f64 * 1e-6);
            rig.step(
                velocity(v * heading.cos(), v * heading.sin(), 0.0),
                ModeRequest::None,
            );
        }
        let steps = ((trajectory.duration_secs() + 3.0) / (OUTER_US as f64 * 1e-6)) as u64;
        let mut peak_tilt: f64 = 0.0;
        for k in 0..steps {
            let time_secs = k as f64 * OUTER_US as f64 * 1e-6;
            let out = rig.step(
                Command::Trajectory {
                    trajectory,
                    time_secs,
                },
                ModeRequest::None,
            );
            let s = &rig.plant.states;
            peak_tilt = peak_tilt
                .max(s.frontal[TILT].abs())
                .max(s.sagittal[TILT].abs());
            assert!(
                out.safety.mode != Mode::Fault && out.motors.enabled,
                "seed {seed}, trajectory {i} (period {period} s, {} samples, heading {heading:.2}): \
                 {:?} at {time_secs:.3} s",
                samples.len(),
                out.safety
            );
            assert!(
                peak_tilt < tilt_limit,
                "seed {seed}, trajectory {i}: tilt {peak_tilt}"
            );
        }
        assert_eq!(
            rig.outer.mode(),
            Mode::Balancing,
            "seed {seed}, trajectory {i}"
        );
        let planned = samples.iter().fold(0.0f64, |m, s| m.max(s[TILT].abs()));
        println!(
            "seed {seed}, trajectory {i}: period {period:.4} s, peak tilt {peak_tilt:.3} rad (planned {planned:.3})"
        );
    }
}

#[test]
fn accepted_random_trajectories_end_balancing_on_the_designed_controller() {
    accepted_trajectories_end_balancing(design(), 0x7472_616a, 12);
}

#[test]
fn accepted_random_trajectories_end_balancing_on_the_brisk_controller() {
    accepted_trajectories_end_balancing(brisk(), 0x6272_6973, 12);
}
