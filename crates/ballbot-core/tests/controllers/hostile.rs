//! Robustness: non-finite inputs and any input (proptest) give finite, bounded torque.

use super::rig::*;
use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedCommand,
    SpeedPi, SpeedPiGains, StepStatus,
};
use ballbot_core::{Wip, WipParams, WipState};
use nalgebra::Vector4;
use proptest::prelude::*;

#[test]
fn non_finite_measurements_give_zero_finite_torque_then_recover() {
    let preset = miapure();
    let good = Vector4::new(0.05, 0.0, 0.1, 1.0);
    let zero = Vector4::zeros();
    let dt = 1.0 / OUTER_HZ;
    let mut lqr = LqrController::new(lqr_gains(&preset)).unwrap();
    let mut pipd =
        PiPdController::new(PiPdGains::for_wip(&wip(&preset), preset.max_torque_nm).unwrap())
            .unwrap();
    let inner_g = inner_gains(&preset);
    let mut outer = LqrPiOuter::new(
        wip(&preset),
        LqrPiOuterConfig::new(lqr_gains(&preset), &inner_g).unwrap(),
    )
    .unwrap();
    let mut inner = SpeedPi::new(inner_g).unwrap();
    outer.step(&good, &zero, dt);
    pipd.step(&good, &zero, dt);
    let held_reference = outer.reference_ball_rate_rad_per_s();
    let held_integral = pipd.speed_error_integral_rad();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..4 {
            let mut s = good;
            s[i] = bad;
            for (m, c) in [(&s, &zero), (&good, &s)] {
                let a = lqr.step(m, c, dt);
                assert_eq!((a.torque_nm, a.status), (0.0, StepStatus::InvalidInput));
                let b = pipd.step(m, c, dt);
                assert_eq!((b.torque_nm, b.status), (0.0, StepStatus::InvalidInput));
                let o = outer.step(m, c, dt);
                assert_eq!(
                    (o.reference_torque_nm, o.status),
                    (0.0, StepStatus::InvalidInput)
                );
                assert_eq!(Some(o.reference_ball_rate_rad_per_s), held_reference);
                // The motor driver's PI sees a finite (held) reference and the measured
                // speed; with the speed itself non-finite it gives zero torque.
                let cmd = SpeedCommand {
                    speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                    feedforward_torque_nm: o.reference_torque_nm,
                };
                let e = inner.step(m[BALL_RATE], &cmd, 1.0 / INNER_HZ);
                assert!(e.torque_nm.is_finite() && e.torque_nm.abs() <= preset.max_torque_nm);
                if !m[BALL_RATE].is_finite() {
                    assert_eq!((e.torque_nm, e.status), (0.0, StepStatus::InvalidInput));
                }
            }
        }
    }
    // State held through the bad steps.
    assert_eq!(outer.reference_ball_rate_rad_per_s(), held_reference);
    assert_eq!(pipd.speed_error_integral_rad(), held_integral);
    // Valid again: a finite, positive balancing torque from each.
    assert!(lqr.step(&good, &zero, dt).torque_nm > 0.0);
    assert!(pipd.step(&good, &zero, dt).torque_nm > 0.0);
    assert!(outer.step(&good, &zero, dt).reference_torque_nm > 0.0);
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => proptest::num::f64::ANY,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
    ]
}

fn any_state() -> impl Strategy<Value = WipState<f64>> {
    [any_f64(), any_f64(), any_f64(), any_f64()].prop_map(Vector4::from)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// For arbitrary (including non-finite) inputs, no controller's `step` panics, and every
    /// torque it returns is finite and within its limit; rejected steps are flagged.
    #[test]
    fn step_never_panics_and_torque_is_finite_and_bounded(
        steps in proptest::collection::vec((any_state(), any_state(), any_f64(), any_f64()), 1..20)
    ) {
        let preset = miapure();
        let limit = preset.max_torque_nm;
        let mut lqr = LqrController::new(lqr_gains(&preset)).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip(&preset), limit).unwrap()).unwrap();
        let inner_g = inner_gains(&preset);
        let mut outer = LqrPiOuter::new(
            wip(&preset),
            LqrPiOuterConfig::new(lqr_gains(&preset), &inner_g).unwrap(),
        ).unwrap();
        let mut inner = SpeedPi::new(inner_g).unwrap();
        for (s, sc, dt, extra) in steps {
            let a = lqr.step(&s, &sc, dt);
            prop_assert!(a.torque_nm.is_finite() && a.torque_nm.abs() <= limit);
            let b = pipd.step(&s, &sc, dt);
            prop_assert!(b.torque_nm.is_finite() && b.torque_nm.abs() <= limit);
            prop_assert!(b.reference_tilt_rad.is_finite());
            let o = outer.step(&s, &sc, dt);
            prop_assert!(o.reference_torque_nm.is_finite() && o.reference_torque_nm.abs() <= limit);
            prop_assert!(o.reference_ball_rate_rad_per_s.is_finite());
            let cmd = SpeedCommand { speed_rad_per_s: o.reference_ball_rate_rad_per_s, feedforward_torque_nm: o.reference_torque_nm };
            let i = inner.step(s[BALL_RATE], &cmd, dt);
            prop_assert!(i.torque_nm.is_finite() && i.torque_nm.abs() <= limit);
            // The same with arbitrary raw inputs to the inner PI, and arbitrary bounds.
            let raw = SpeedCommand { speed_rad_per_s: extra, feedforward_torque_nm: sc[0] };
            let j = inner.step_within(s[1], &raw, dt, -extra.abs(), sc[2]);
            prop_assert!(j.torque_nm.is_finite() && j.torque_nm.abs() <= limit);
            prop_assert!(inner.integral_nm().is_finite());
            let all_finite = s.iter().chain(sc.iter()).all(|v| v.is_finite());
            if !all_finite {
                prop_assert_eq!(a.status, StepStatus::InvalidInput);
                prop_assert_eq!(o.status, StepStatus::InvalidInput);
            }
        }
    }
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -10.0..10.0f32,
        2 => proptest::num::f32::ANY,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// The same contract in f32, where overflow comes much sooner (`f32::MAX` is 3.4e38).
    #[test]
    fn f32_step_never_panics_and_torque_is_finite_and_bounded(
        steps in proptest::collection::vec(
            ([any_f32(), any_f32(), any_f32(), any_f32()], [any_f32(), any_f32(), any_f32(), any_f32()], any_f32()),
            1..20,
        )
    ) {
        let wip = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
        let limit = 83.9_f32;
        let inner_g = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, limit).unwrap();
        let lqr = LqrGains::for_wip(&wip, limit).unwrap();
        let mut lqr_c = LqrController::new(lqr).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip, limit).unwrap()).unwrap();
        let mut outer = LqrPiOuter::new(wip, LqrPiOuterConfig::new(lqr, &inner_g).unwrap()).unwrap();
        let mut inner = SpeedPi::new(inner_g).unwrap();
        for (s, sc, dt) in steps {
            let (s, sc) = (Vector4::from(s), Vector4::from(sc));
            let a = lqr_c.step(&s, &sc, dt).torque_nm;
            let b = pipd.step(&s, &sc, dt).torque_nm;
            let o = outer.step(&s, &sc, dt);
            prop_assert!(o.reference_ball_rate_rad_per_s.is_finite());
            let cmd = SpeedCommand {
                speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                feedforward_torque_nm: o.reference_torque_nm,
            };
            let i = inner.step(s[BALL_RATE], &cmd, dt).torque_nm;
            for t in [a, b, o.reference_torque_nm, i] {
                prop_assert!(t.is_finite() && t.abs() <= limit, "{t}");
            }
        }
    }
}
