//! Unit tests of the command shaping.

use super::*;
use crate::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{BallbotParams, Wip};
use approx::assert_relative_eq;
use nalgebra::Vector4;

const DT: f64 = 0.0025;

fn limits() -> AxisLimits<f64> {
    AxisLimits {
        max_value: 2.0,
        max_rate_per_s: 1.0,
        max_jerk_per_s2: 4.0,
    }
}

/// Runs the limiter towards `target` and checks the limits every step; returns the time of
/// arrival.
fn run_checked(limiter: &mut JerkLimiter<f64>, target: f64, steps: usize) -> Option<f64> {
    let l = limits();
    let start = limiter.value();
    let mut arrival = None;
    for k in 0..steps {
        let before_rate = limiter.rate_per_s();
        let v = limiter.step(target, &l, DT);
        assert!(limiter.rate_per_s().abs() <= l.max_rate_per_s + 1e-12);
        assert!(
            (limiter.rate_per_s() - before_rate).abs() <= l.max_jerk_per_s2 * DT + 1e-12,
            "jerk limit broken at step {k}"
        );
        // Never beyond the target, seen from the start.
        assert!(
            (v - target) * (start - target) >= -1e-12,
            "overshoot at {k}: {v}"
        );
        if v == target && arrival.is_none() {
            arrival = Some((k + 1) as f64 * DT);
        }
    }
    arrival
}

#[test]
fn jerk_limiter_reaches_a_step_target_in_near_minimum_time_within_limits() {
    let mut limiter = JerkLimiter::at(0.0);
    let arrival = run_checked(&mut limiter, 1.0, 2000).unwrap();
    // S-curve minimum time: v / a + a / j = 1 + 0.25 s.
    assert!(arrival > 1.24 && arrival < 1.30, "arrival {arrival}");
    assert_eq!(limiter.rate_per_s(), 0.0);
}

#[test]
fn unlimited_jerk_is_a_plain_rate_limiter() {
    // No jerk limit: the full acceleration from the first step, the value ramps at exactly
    // max_rate and settles on the target without overshoot (1 m/s at 1 m/s^2: 1 s, 400 steps).
    let l = AxisLimits {
        max_jerk_per_s2: AxisLimits::unlimited_jerk_per_s2(),
        ..limits()
    };
    assert!(l.validate().is_ok());
    let mut limiter = JerkLimiter::at(0.0);
    let mut arrival = None;
    for k in 1..=600 {
        let v = limiter.step(1.0, &l, DT);
        assert!(v.is_finite() && v <= 1.0, "step {k}: {v}");
        assert!(limiter.jerk_per_s2().is_finite());
        if k <= 399 {
            assert_relative_eq!(limiter.rate_per_s(), 1.0);
            assert_relative_eq!(v, k as f64 * DT, epsilon = 1e-12);
        }
        if v == 1.0 && arrival.is_none() {
            arrival = Some(k);
        }
    }
    // 400 steps, or 401 when the sum of 400 steps of 2.5 mm/s rounds to just below 1.
    assert!(matches!(arrival, Some(400 | 401)), "{arrival:?}");
    assert_eq!(limiter.rate_per_s(), 0.0);
    // A jerk limit of -inf or NaN is still refused.
    for bad in [f64::NEG_INFINITY, f64::NAN] {
        let l = AxisLimits {
            max_jerk_per_s2: bad,
            ..limits()
        };
        assert!(l.validate().is_err());
    }
}

#[test]
fn jerk_limiter_short_move_never_reaches_full_acceleration() {
    // 0.05 m/s at 4 m/s^3: triangular acceleration, peak sqrt(j dv) = 0.447 m/s^2.
    let mut limiter = JerkLimiter::at(0.0);
    let mut peak: f64 = 0.0;
    for _ in 0..400 {
        limiter.step(0.05, &limits(), DT);
        peak = peak.max(limiter.rate_per_s());
    }
    assert_eq!(limiter.value(), 0.05);
    assert!(peak < 0.5 && peak > 0.4, "peak {peak}");
}

#[test]
fn jerk_limiter_reverses_without_overshoot() {
    let mut limiter = JerkLimiter::at(0.0);
    run_checked(&mut limiter, 1.5, 300);
    assert!(limiter.rate_per_s() > 0.5);
    // Reverse while still accelerating: first the motion must turn around.
    let arrival = run_checked(&mut limiter, -1.0, 4000);
    assert!(arrival.is_some());
    assert_eq!(limiter.value(), -1.0);
}

#[test]
fn jerk_limiter_clamps_targets_and_ignores_bad_inputs() {
    let mut limiter = JerkLimiter::at(0.0);
    run_checked(&mut limiter, 2.0, 2000);
    for _ in 0..2000 {
        limiter.step(50.0, &limits(), DT);
    }
    assert_eq!(limiter.value(), 2.0);
    // A non-finite target holds; a bad dt changes nothing.
    let before = limiter;
    limiter.step(f64::NAN, &limits(), DT);
    assert_eq!(limiter.value(), 2.0);
    limiter.step(0.0, &limits(), f64::INFINITY);
    limiter.step(0.0, &limits(), -DT);
    limiter.step(0.0, &limits(), f64::NAN);
    assert_eq!(limiter.value(), before.value());
    limiter.reset(f64::NAN, 1.0);
    assert_eq!(limiter, JerkLimiter::at(0.0));
}

#[test]
fn lean_to_drive_deadband_gain_speed_limit_and_direction() {
    let lean = LeanToDrive::new(LeanToDriveParams::<f64>::rider()).unwrap();
    let p = *lean.params();
    let input = |x: f64, y: f64| LeanInput {
        towards_x_rad: x,
        towards_y_rad: y,
        yaw_rate_rad_per_s: 0.0,
    };
    // Inside the (radial) deadband, in any direction.
    for angle in [0.0f64, 1.0, 2.5, 4.0] {
        let v = lean.velocity(&input(
            0.99 * p.deadband_rad * angle.cos(),
            0.99 * p.deadband_rad * angle.sin(),
        ));
        assert_eq!((v.vx_m_per_s, v.vy_m_per_s), (0.0, 0.0));
    }
    // Continuous at the deadband edge, linear beyond it.
    let v = lean.velocity(&input(p.deadband_rad + 1e-9, 0.0));
    assert!(v.vx_m_per_s < 1e-8 && v.vx_m_per_s > 0.0);
    let v = lean.velocity(&input(0.0, -(p.deadband_rad + 0.05)));
    assert_relative_eq!(
        v.vy_m_per_s,
        -p.gain_m_per_s_per_rad * 0.05,
        epsilon = 1e-12
    );
    assert_eq!(v.vx_m_per_s, 0.0);
    // Diagonal: direction kept, speed capped.
    let v = lean.velocity(&input(0.5, 0.5));
    assert_relative_eq!(v.vx_m_per_s, v.vy_m_per_s, epsilon = 1e-12);
    assert_relative_eq!(
        v.vx_m_per_s.hypot(v.vy_m_per_s),
        p.max_speed_m_per_s,
        epsilon = 1e-12
    );
    // Garbage in, standing still out; yaw capped.
    let v = lean.velocity(&LeanInput {
        towards_x_rad: f64::NAN,
        towards_y_rad: 0.1,
        yaw_rate_rad_per_s: 100.0,
    });
    assert_eq!((v.vx_m_per_s, v.vy_m_per_s), (0.0, 0.0));
    assert_eq!(v.yaw_rate_rad_per_s, p.max_yaw_rate_rad_per_s);
}

/// The trajectory limits of the designed MiaPURE controller.
fn design_limits() -> TrajectoryLimits<f64> {
    crate::ballbot::BallbotControllerConfig::design(&BallbotParams::miapure_60kg())
        .and_then(|c| c.trajectory_limits())
        .unwrap()
}

fn shaper() -> CommandShaper<f64> {
    CommandShaper::new(
        CommandShaperParams::miapure(),
        &BallbotParams::miapure_60kg(),
    )
    .unwrap()
}

fn velocity(vx: f64, vy: f64, wz: f64) -> Command<'static, f64> {
    Command::Velocity(VelocityCommand {
        vx_m_per_s: vx,
        vy_m_per_s: vy,
        yaw_rate_rad_per_s: wz,
    })
}

#[test]
fn lean_feedforward_holds_the_nominal_wip_balanced_while_accelerating() {
    // The commanded tilt for a forward acceleration must be the tilt at which the nominal
    // WIP can accelerate its ball at that rate with zero tilt acceleration.
    let robot = BallbotParams::<f64>::miapure_60kg();
    let wip = Wip::new(robot.sagittal).unwrap();
    let mut s = shaper();
    let mut shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
    for _ in 0..400 {
        shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
    }
    let accel = shaped.acceleration.x;
    assert_relative_eq!(accel, 1.0, epsilon = 1e-12); // at the acceleration limit
    let tilt = shaped.planar.sagittal[TILT];
    assert!(tilt > 0.05, "leans forward to accelerate forward: {tilt}");
    let state = Vector4::new(tilt, 0.0, 0.0, 0.0);
    // theta_ddot is affine in the torque: pick the torque that zeroes it.
    let at0 = wip.accelerations(&state, 0.0);
    let at1 = wip.accelerations(&state, 1.0);
    let torque = -at0[0] / (at1[0] - at0[0]);
    let ball_accel = wip.accelerations(&state, torque)[1] * robot.sagittal.ball_radius_m;
    // First-order feedforward: within 1 % at 1 m/s^2.
    assert_relative_eq!(ball_accel, accel, max_relative = 0.01);
    // At constant speed the lean command is gone.
    for _ in 0..2000 {
        shaped = s.step(&velocity(2.0, 0.0, 0.0), DT);
    }
    assert_eq!(shaped.planar.sagittal[TILT], 0.0);
    assert_relative_eq!(
        shaped.planar.sagittal[BALL_RATE],
        2.0 / 0.1145,
        epsilon = 1e-9
    );
}

#[test]
fn sideways_and_yaw_commands_map_to_frontal_and_spin_with_model_signs() {
    let mut s = shaper();
    let mut shaped = s.step(&velocity(0.0, 0.5, 0.3), DT);
    assert!(
        shaped.planar.frontal[TILT] < 0.0,
        "+y acceleration leans towards +y"
    );
    for _ in 0..2000 {
        shaped = s.step(&velocity(0.0, 0.5, 0.3), DT);
    }
    // y = -r phi_x: +y travel is negative frontal ball rate.
    assert_relative_eq!(
        shaped.planar.frontal[BALL_RATE],
        -0.5 / 0.1145,
        epsilon = 1e-9
    );
    assert!(shaped.planar.frontal[BALL_ANGLE] < 0.0);
    assert_eq!(shaped.planar.sagittal, WipState::zeros());
    assert_eq!(shaped.planar.spin[1], 0.3);
    // The heading command integrates the shaped yaw rate.
    assert!(shaped.planar.spin[0] > 0.3 * 4.0 && shaped.planar.spin[0] < 0.3 * 5.01);
}

#[test]
fn commands_beyond_the_speed_limit_keep_their_direction() {
    let mut s = shaper();
    let mut shaped = s.step(&velocity(30.0, 40.0, 0.0), DT);
    for _ in 0..4000 {
        shaped = s.step(&velocity(30.0, 40.0, 0.0), DT);
    }
    assert_relative_eq!(shaped.velocity.vx_m_per_s, 1.2, epsilon = 1e-9);
    assert_relative_eq!(shaped.velocity.vy_m_per_s, 1.6, epsilon = 1e-9);
}

#[test]
fn non_finite_command_is_a_stop() {
    let mut s = shaper();
    for _ in 0..800 {
        s.step(&velocity(1.0, 0.0, 0.0), DT);
    }
    let v0 = s.velocity().vx_m_per_s;
    let shaped = s.step(&velocity(f64::NAN, 0.0, 0.0), DT);
    assert!(!shaped.command_finite);
    assert!(shaped.velocity.vx_m_per_s <= v0 + 1e-12);
    for _ in 0..2000 {
        s.step(&velocity(f64::INFINITY, 0.0, 0.0), DT);
    }
    assert!(s.is_at_rest());
}

#[test]
fn lean_mode_uses_the_riders_acceleration_limit() {
    let mut s = shaper();
    let lean = Command::Lean(LeanInput {
        towards_x_rad: 0.4,
        towards_y_rad: 0.0,
        yaw_rate_rad_per_s: 0.0,
    });
    let mut peak: f64 = 0.0;
    for _ in 0..2000 {
        let shaped = s.step(&lean, DT);
        peak = peak.max(shaped.acceleration.x);
    }
    assert_relative_eq!(peak, 0.5, epsilon = 1e-12);
    assert_relative_eq!(s.velocity().vx_m_per_s, 1.0, epsilon = 1e-12);
}

#[test]
fn trajectory_interpolates_and_maps_along_its_heading() {
    // Speeding up to 0.4 rad/s leaning 0.012 rad, then cruising upright (the leans within
    // what `TrajectoryLimits::CONSISTENCY_SECS` allows the interpolation to leave out).
    let samples = [
        Vector4::new(0.0, 0.0, 0.0, 0.0),
        Vector4::new(0.012, 0.1, 0.02, 0.4),
        Vector4::new(0.0, 0.3, 0.0, 0.4),
    ];
    let traj = Trajectory::new(&samples, 0.5, 0.0, &design_limits()).unwrap();
    assert_relative_eq!(traj.sample(0.75), Vector4::new(0.006, 0.2, 0.01, 0.4));
    assert_eq!(traj.sample(-1.0), samples[0]);
    assert_eq!(traj.sample(f64::NAN), samples[2]);
    assert_eq!(traj.sample(1.0), samples[2]);
    assert_eq!(traj.duration_secs(), 1.0);
    assert!(Trajectory::<f64>::new(&[], 0.5, 0.0, &design_limits()).is_err());
    assert!(Trajectory::new(&samples, 0.0, 0.0, &design_limits()).is_err());
    let bad = [Vector4::new(0.0, f64::NAN, 0.0, 0.0)];
    assert!(Trajectory::new(&bad, 0.1, 0.0, &design_limits()).is_err());

    // Heading 90 deg (body +y): tilt goes to the frontal plane with a minus sign.
    let traj = Trajectory::new(
        &samples,
        0.5,
        core::f64::consts::FRAC_PI_2,
        &design_limits(),
    )
    .unwrap();
    let mut s = shaper();
    let shaped = s.step(
        &Command::Trajectory {
            trajectory: traj,
            time_secs: 0.75,
        },
        DT,
    );
    assert_relative_eq!(shaped.planar.frontal[TILT], -0.006, epsilon = 1e-12);
    assert_relative_eq!(shaped.planar.frontal[TILT_RATE], -0.01, epsilon = 1e-12);
    assert_relative_eq!(shaped.planar.sagittal[TILT], 0.0, epsilon = 1e-12);
    // The speed target jumped to 0.4 rad/s: the limiter only lets it start moving.
    assert!(shaped.velocity.vy_m_per_s > 0.0 && shaped.velocity.vy_m_per_s < 1e-3);
}

#[test]
fn a_feasible_trajectory_passes_the_limiter_unchanged() {
    // A braking-like profile: speed 1 m/s -> 0 as a cosine over 3 s (peak decel 0.52
    // m/s^2, peak jerk 0.55 m/s^3: well inside the limits). Start the limiter on it.
    let r = 0.1145;
    let period = 0.01;
    // The body leans by the lean of the deceleration (and its rate), as the dynamics need.
    let lean = design_limits().lean_per_ball_accel_s2;
    let w = core::f64::consts::PI / 3.0;
    let samples: [WipState<f64>; 301] = core::array::from_fn(|k| {
        let t = k as f64 * period;
        let v = 0.5 * (1.0 + (w * t).cos());
        let (a, j) = (-0.5 * w * (w * t).sin(), -0.5 * w * w * (w * t).cos());
        Vector4::new(lean * a / r, 0.0, lean * j / r, v / r)
    });
    let traj = Trajectory::new(&samples, period, core::f64::consts::PI, &design_limits()).unwrap();
    let mut s = shaper();
    s.vx.reset(-1.0, 0.0); // heading 180 deg: moving towards -x
    let mut worst: f64 = 0.0;
    for k in 1..1200 {
        let t = k as f64 * DT;
        let shaped = s.step(
            &Command::Trajectory {
                trajectory: traj,
                time_secs: t,
            },
            DT,
        );
        let expected = -traj.sample(t)[BALL_RATE] * r;
        worst = worst.max((shaped.velocity.vx_m_per_s - expected).abs());
    }
    // One step of lag at most (0.52 m/s^2 x 2.5 ms = 1.3e-3 m/s); without the rate
    // feedforward the lag would be a^2 / (2 j) = 0.034 m/s.
    assert!(worst < 1.5e-3, "worst deviation {worst} m/s");
    assert!(s.velocity().vx_m_per_s.abs() < 1e-9);
}

/// A fixed acceleration limit (m/s^2) in every direction.
struct Cap(f64);

impl AccelLimit<f64> for Cap {
    fn accel_limit_m_per_s2(&self, _dir_x: f64, _dir_y: f64, _braking: bool) -> f64 {
        self.0
    }
}

/// An envelope that falls below the present acceleration (a slip reaction, a lower friction
/// estimate) is reached within the jerk limit, not in one step: on the diagonal, at 1 m/s^2
/// under a limit of 1, the limit drops to 0.25 and the acceleration falls by at most the jerk
/// step each step, reaching 0.25 after (1 - 0.25) / 2 m/s^3 = 0.375 s; without a jerk limit
/// it takes effect at once. Checked by mutation: without the easing (the bound taken as it
/// comes) the first step after the drop falls by 0.75 m/s^2.
#[test]
fn a_falling_envelope_is_reached_within_the_jerk_limit() {
    for jerk in [2.0, f64::INFINITY] {
        let mut params = CommandShaperParams::miapure();
        params.translation.max_jerk_per_s2 = jerk;
        let mut shaper = CommandShaper::new(params, &BallbotParams::miapure_60kg()).unwrap();
        let go = velocity(1.5, 1.5, 0.0);
        let accel = |s: &CommandShaper<f64>| s.vx.rate_per_s().hypot(s.vy.rate_per_s());
        for _ in 0..400 {
            shaper.step_within(&go, DT, &Cap(1.0));
        }
        assert_relative_eq!(accel(&shaper), 1.0, epsilon = 1e-9);
        let mut previous = accel(&shaper);
        let mut steps = 0;
        while accel(&shaper) > 0.25 + 1e-9 {
            shaper.step_within(&go, DT, &Cap(0.25));
            let now = accel(&shaper);
            assert!(
                previous - now <= jerk * DT + 1e-9,
                "{jerk}: {previous} -> {now}"
            );
            previous = now;
            steps += 1;
            assert!(steps < 1000, "{jerk}: never reached the envelope");
        }
        let expected = if jerk.is_finite() { 150 } else { 1 };
        assert!(
            (expected..=expected + 1).contains(&steps),
            "{jerk}: {steps} steps"
        );
    }
}
