//! The hot paths trimmed for instruction count against the checked
//! formulations they replace: the same outputs, bit for bit, and the same rejections.
//!
//! - `MotorSpeedPi::step` prepares its torque-speed bounds against the PI's limit and runs the
//!   PI law without re-checking them; the reference is `SpeedPi::step_within` fed
//!   `MotorSpeedPi::torque_bounds_nm`, then the old "torque within the bounds" guard.
//! - `SpeedPi` checks only the requested torque's finiteness (it covers the speed error, also
//!   with `kp = 0`).
//! - `LqrPiOuter::step` checks the requested torque and the two ball angles instead of both
//!   whole states.
#![allow(clippy::unwrap_used)]

use ballbot_core::ActuatorParams;
use ballbot_core::ballbot::MotorSpeedPi;
use ballbot_core::control::{
    LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains, StepStatus,
};
use ballbot_core::{Wip, WipParams};
use nalgebra::Vector4;
use proptest::prelude::*;

/// The motor step as it was before the fast path: the actuator's bounds, the checked PI, and
/// a guard that the torque lies within the bounds.
struct CheckedMotor {
    pi: SpeedPi<f64>,
    bounds: MotorSpeedPi<f64>,
}

impl CheckedMotor {
    fn step(&mut self, reference: f64, feedforward: f64, speed: f64, dt: f64) -> (f64, f64) {
        let (lower, upper) = self.bounds.torque_bounds_nm(speed);
        let command = SpeedCommand {
            speed_rad_per_s: reference,
            feedforward_torque_nm: feedforward,
        };
        let out = self.pi.step_within(speed, &command, dt, lower, upper);
        if out.torque_nm >= lower && out.torque_nm <= upper {
            (out.torque_nm, out.saturation_nm)
        } else {
            (0.0, 0.0)
        }
    }
}

/// Speeds across the torque-speed line, beyond the no-load speed, and the special values.
fn speed() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -100.0..100.0f64,
        1 => prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(62.0),
            Just(-62.0),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
        ],
    ]
}

/// Mostly valid values in `range`, sometimes a non-finite one.
fn value(range: core::ops::Range<f64>) -> impl Strategy<Value = f64> {
    prop_oneof![
        12 => range,
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ]
}

fn dt() -> impl Strategy<Value = f64> {
    prop_oneof![
        10 => Just(1.25e-4),
        2 => 1e-5..1e-2f64,
        1 => prop_oneof![Just(0.0), Just(-1e-4), Just(f64::NAN), Just(f64::INFINITY)],
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn motor_pi_step_matches_the_checked_pi_within_the_motor_bounds(
        kp in prop_oneof![Just(0.0), 0.0..60.0f64],
        ki in prop_oneof![Just(0.0), 0.0..900.0f64],
        k_aw in prop_oneof![Just(0.0), 0.0..200.0f64, Just(1e9)],
        // Below, at and above the MiaPURE actuator's 43.2 N m peak.
        max_torque_nm in prop_oneof![Just(43.2), 1.0..80.0f64],
        steps in prop::collection::vec(
            (value(-80.0..80.0), value(-60.0..60.0), speed(), dt()),
            1..40,
        ),
    ) {
        let gains = SpeedPiGains {
            proportional_nm_s_per_rad: kp,
            integral_nm_per_rad: ki,
            anti_windup_per_s: k_aw,
            max_torque_nm,
        };
        let actuator = ActuatorParams::<f64>::miapure();
        let mut fast = MotorSpeedPi::new(gains, &actuator).unwrap();
        let mut checked = CheckedMotor {
            pi: SpeedPi::new(gains).unwrap(),
            bounds: fast,
        };
        for (k, &(reference, feedforward, speed, dt)) in steps.iter().enumerate() {
            let got = fast.step(reference, feedforward, speed, dt);
            let want = checked.step(reference, feedforward, speed, dt);
            prop_assert_eq!(
                (got.0.to_bits(), got.1.to_bits()),
                (want.0.to_bits(), want.1.to_bits()),
                "step {}: {:?} vs {:?} (ref {}, ff {}, speed {}, dt {})",
                k, got, want, reference, feedforward, speed, dt
            );
        }
    }
}

#[test]
fn speed_pi_without_proportional_gain_still_rejects_non_finite_speeds() {
    // With kp = 0 the proportional term of an infinite error is NaN, not infinite: the one
    // check on the requested torque must still catch it.
    let gains = SpeedPiGains {
        proportional_nm_s_per_rad: 0.0,
        integral_nm_per_rad: 50.0,
        anti_windup_per_s: 10.0,
        max_torque_nm: 43.2,
    };
    let mut pi = SpeedPi::new(gains).unwrap();
    let command = |speed: f64| SpeedCommand {
        speed_rad_per_s: speed,
        feedforward_torque_nm: 1.0,
    };
    pi.step(0.0, &command(1.0), 0.01);
    let before = pi.integral_nm();
    assert!(before > 0.0);
    for (measured, reference) in [
        (f64::NAN, 1.0),
        (f64::INFINITY, 1.0),
        (0.0, f64::NEG_INFINITY),
        (0.0, f64::NAN),
    ] {
        let out = pi.step(measured, &command(reference), 0.01);
        assert_eq!(
            out.status,
            StepStatus::InvalidInput,
            "{measured} {reference}"
        );
        assert_eq!(out.torque_nm, 0.0);
        assert_eq!(pi.integral_nm(), before);
    }
}

#[test]
fn lqr_pi_rejects_every_non_finite_state_entry_also_with_zero_gains() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let designed = LqrGains::for_wip(&wip, 83.9).unwrap();
    let zero = LqrGains::from_reduced([0.0, 0.0, 0.0], 83.9);
    for gains in [designed, zero] {
        let config = LqrPiOuterConfig {
            lqr: gains,
            max_speed_error_rad_per_s: 3.0,
        };
        let mut outer = LqrPiOuter::new(wip, config).unwrap();
        let good = Vector4::new(0.01, 0.2, -0.05, 2.0);
        let first = outer.step(&good, &good, 0.0025);
        assert_ne!(first.status, StepStatus::InvalidInput);
        let held = outer.reference_ball_rate_rad_per_s();
        for entry in 0..4 {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut broken = good;
                broken[entry] = bad;
                for (measured, command) in [(broken, good), (good, broken)] {
                    let out = outer.step(&measured, &command, 0.0025);
                    assert_eq!(
                        out.status,
                        StepStatus::InvalidInput,
                        "entry {entry} = {bad}"
                    );
                    assert_eq!(out.reference_torque_nm, 0.0);
                    assert_eq!(outer.reference_ball_rate_rad_per_s(), held);
                }
            }
        }
        for dt in [0.0, -0.0025, f64::NAN, f64::INFINITY] {
            assert_eq!(
                outer.step(&good, &good, dt).status,
                StepStatus::InvalidInput
            );
        }
    }
}
