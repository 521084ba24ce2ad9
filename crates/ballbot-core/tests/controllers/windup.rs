//! Anti-windup: long saturation, the integral's fixed point, speed steps.

use super::rig::*;
use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains, StepStatus,
};
use nalgebra::Vector4;

/// Long saturation: the motor driver is derated to 30 N m (thermal or supply limit) while the
/// outer loop still plans with the full 83.9 N m, the drive has 5 N m of Coulomb friction, and
/// the robot starts at 15 deg. The inner loop is saturated for about 0.2 s, six time constants
/// of its 30 rad/s error dynamics: the speed error and the integral would wind up. With the
/// anti-windup (back-calculation plus the reference anchor band) the LQR-PI's excursion stays
/// close to that of the LQR (which has no integrator to wind up); with both disabled, the
/// same run overshoots far more, which shows that this test can fail.
#[test]
fn lqr_pi_does_not_overshoot_after_a_long_saturation() {
    let base = miapure();
    let driver_limit_nm = 30.0;
    let tilt0 = 15.0_f64.to_radians();
    let friction = Friction::Coulomb {
        torque_nm: 5.0,
        slip_rate_rad_per_s: 0.05,
    };
    let derated = Preset {
        max_torque_nm: driver_limit_nm,
        ..base
    };
    let inner = SpeedPiGains {
        max_torque_nm: driver_limit_nm,
        ..inner_gains(&base)
    };
    let with = LqrPiOuterConfig::new(lqr_gains(&base), &inner).unwrap();
    let inner_without = SpeedPiGains {
        anti_windup_per_s: 0.0,
        ..inner
    };
    let without = LqrPiOuterConfig {
        max_speed_error_rad_per_s: 1e6,
        ..with
    };
    let lqr = LqrGains {
        max_torque_nm: driver_limit_nm,
        ..lqr_gains(&base)
    };
    let mut results = Vec::new();
    for (name, mut c) in [
        ("LQR", Controller::Lqr(LqrController::new(lqr).unwrap())),
        ("LQR-PI", Controller::lqr_pi(&derated, inner, with)),
        (
            "LQR-PI without anti-windup",
            Controller::lqr_pi(&derated, inner_without, without),
        ),
    ] {
        let trace = simulate(
            &derated,
            &mut c,
            friction,
            Vector4::new(tilt0, 0.0, 0.0, 0.0),
            |_| Vector4::zeros(),
            8.0,
        );
        assert_eq!(trace.fell_at_secs, None, "{name} fell");
        let r = derated.params.ball_radius_m;
        let saturated_secs = trace
            .samples
            .iter()
            .filter(|s| s.torque_nm.abs() >= driver_limit_nm - 1e-9)
            .count() as f64
            / OUTER_HZ;
        let peak_speed = trace
            .samples
            .iter()
            .map(|s| (s.state[BALL_RATE] * r).abs())
            .fold(0.0, f64::max);
        let reverse_tilt = trace
            .samples
            .iter()
            .map(|s| -s.state[TILT])
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: saturated {saturated_secs:.3} s, peak ball speed {peak_speed:.3} m/s, \
             reverse tilt {:.2} deg",
            reverse_tilt.to_degrees()
        );
        results.push((saturated_secs, peak_speed, trace.settle_time_secs()));
    }
    let [
        (_, lqr_peak, _),
        (sat, pi_peak, pi_settle),
        (_, raw_peak, _),
    ] = results[..]
    else {
        unreachable!()
    };
    assert!(sat >= 0.15, "the scenario must saturate for long: {sat} s");
    assert!(
        pi_peak < 1.25 * lqr_peak,
        "LQR-PI {pi_peak} vs LQR {lqr_peak}"
    );
    assert!(pi_settle.is_some_and(|t| t < 3.0), "{pi_settle:?}");
    assert!(raw_peak > 1.5 * lqr_peak, "without anti-windup {raw_peak}");
}

/// Back-calculation, checked by its fixed point (the unit test
/// `saturation_keeps_the_integral_within_the_limit` only checks `I <= max`, which the
/// clamp alone guarantees: it passes with the anti-windup sign flipped). Held saturated at an
/// upper bound `u` below the actuator peak with a constant error `e`, the update
/// `I += ki e dt + k_aw dt (u - kp e - I)` settles at `I* = u - kp e + ki e / k_aw`, here
/// 4 - 1 + 2 = 5 N m, inside the 10 N m clamp; the request then exceeds the output by exactly
/// `ki e / k_aw` = 2 N m. A flipped or missing back-calculation term winds the integral up to
/// the clamp (10 N m) instead.
#[test]
fn back_calculation_settles_the_integral_at_its_fixed_point() {
    let gains = SpeedPiGains::<f64> {
        proportional_nm_s_per_rad: 2.0,
        integral_nm_per_rad: 20.0,
        anti_windup_per_s: 5.0,
        max_torque_nm: 10.0,
    };
    let (upper, error, dt) = (4.0, 0.5, 0.001);
    let command = SpeedCommand {
        speed_rad_per_s: error,
        feedforward_torque_nm: 0.0,
    };
    let expected = upper - gains.proportional_nm_s_per_rad * error
        + gains.integral_nm_per_rad * error / gains.anti_windup_per_s;
    assert_eq!(expected, 5.0);
    let mut pi = SpeedPi::new(gains).unwrap();
    // The integral error shrinks by (1 - k_aw dt) = 0.995 per step: 0.995^8000 ~ 4e-18.
    // (The first steps are unsaturated: the request kp e = 1 N m grows with the integral.)
    for _ in 0..8000 {
        pi.step_within(0.0, &command, dt, -10.0, upper);
    }
    let out = pi.step_within(0.0, &command, dt, -10.0, upper);
    assert_eq!((out.torque_nm, out.status), (upper, StepStatus::Saturated));
    assert!(
        (pi.integral_nm() - expected).abs() < 1e-9,
        "integral {} vs fixed point {expected}",
        pi.integral_nm()
    );
    // Without back-calculation the same run winds the integral up to the clamp.
    let mut raw = SpeedPi::new(SpeedPiGains {
        anti_windup_per_s: 0.0,
        ..gains
    })
    .unwrap();
    for _ in 0..8000 {
        raw.step_within(0.0, &command, dt, -10.0, upper);
    }
    assert_eq!(raw.integral_nm(), gains.max_torque_nm);
}

/// A speed step clips the PI-PD's reference tilt for a long time (the longer, the larger the
/// step). With conditional integration the speed overshoot stays about the same small amount
/// whatever the step; a winding-up integral would grow it with the clipped time.
#[test]
fn pi_pd_speed_steps_do_not_wind_up_the_speed_integral() {
    for preset in presets() {
        let r = preset.params.ball_radius_m;
        for v in [1.0, 3.0] {
            let mut c = Controller::new(Kind::PiPd, &preset);
            let step = move |t: f64| if t < 0.2 { 0.0 } else { v };
            let trace = simulate(
                &preset,
                &mut c,
                Friction::None,
                Vector4::zeros(),
                speed_command(r, step),
                8.0,
            );
            assert_eq!(trace.fell_at_secs, None, "{} {v} m/s fell", preset.name);
            let overshoot = trace
                .samples
                .iter()
                .map(|s| s.state[BALL_RATE] * r - v)
                .fold(f64::MIN, f64::max);
            let clipped_secs = trace
                .samples
                .iter()
                .filter(|s| (s.state[BALL_RATE] * r - v).abs() > 0.5)
                .count() as f64
                / OUTER_HZ;
            let final_error = trace.max_speed_error(7.0, 8.0);
            eprintln!(
                "{:>16} PI-PD step to {v} m/s: overshoot {overshoot:.3} m/s, {clipped_secs:.2} s \
                 more than 0.5 m/s off, final error {final_error:.4} m/s, max tilt {:.1} deg",
                preset.name,
                trace.max_abs_tilt_rad().to_degrees()
            );
            assert!(overshoot < 0.15, "{} {v}: {overshoot}", preset.name);
            assert!(final_error < 0.01, "{} {v}: {final_error}", preset.name);
        }
    }
}
