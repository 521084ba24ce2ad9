//! Planar rollouts (`ballbot_sim::planar::rollout`, the loop behind Python's
//! `closed_loop_rollout`) against a direct integration of the core's WIP model.

use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, SpeedCommand, SpeedPi, SpeedPiGains,
    StepStatus,
};
use ballbot_core::{Wip, WipParams, WipState, rk4_step};
use ballbot_sim::planar::{RolloutController, RolloutSettings, rollout};

const DT: f64 = 0.0025;

fn settings(n_steps: usize, substeps: usize) -> RolloutSettings {
    RolloutSettings {
        dt_secs: DT,
        n_steps,
        substeps,
    }
}

#[test]
fn an_lqr_rollout_is_the_core_wip_integrated_with_the_held_torque() {
    let plane = WipParams::miapure_60kg();
    let wip = Wip::new(plane).unwrap();
    let gains = LqrGains::for_wip(&wip, 83.9).unwrap();
    let start = WipState::new(0.15, 0.0, -0.2, 1.0);
    let command = WipState::new(0.0, 0.0, 0.0, 2.0);
    let run = rollout(
        plane,
        &RolloutController::Lqr(LqrController::new(gains).unwrap()),
        start,
        &[command],
        &settings(2000, 4),
    )
    .unwrap();
    // The same loop written out: torque from the exact state, held over 4 RK4 substeps.
    let mut c = LqrController::new(gains).unwrap();
    let mut s = start;
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        let o = c.step(&s, &command, DT);
        assert!((run.torque_nm[k] - o.torque_nm).abs() <= 1e-9 * (1.0 + o.torque_nm.abs()));
        for _ in 0..4 {
            s = rk4_step(|x| wip.derivative(x, o.torque_nm), &s, DT / 4.0);
        }
        worst = worst.max((run.states[k + 1] - s).amax());
    }
    assert!(worst < 1e-9, "rollout and the core's WIP differ by {worst}");
    assert!((run.states[2000][3] - 2.0).abs() < 1e-3, "tracks 2 rad/s");
    assert!(run.status.iter().all(|s| *s != StepStatus::InvalidInput));
}

#[test]
fn an_lqr_pi_rollout_recovers_follows_the_lqr_and_differs_slightly_from_an_exact_ball_rate_pi() {
    let plane = WipParams::miapure_60kg();
    let wip = Wip::new(plane).unwrap();
    let gains = LqrGains::for_wip(&wip, 83.9).unwrap();
    let inner_gains = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, 83.9).unwrap();
    let config = LqrPiOuterConfig::new(gains, &inner_gains).unwrap();
    let controller = RolloutController::LqrPi {
        outer: LqrPiOuter::new(wip, config).unwrap(),
        inner: SpeedPi::new(inner_gains).unwrap(),
    };
    let start = WipState::new(10f64.to_radians(), 0.0, 0.0, 0.0);
    let run = rollout(
        plane,
        &controller,
        start,
        &[WipState::zeros()],
        &settings(4000, 20),
    )
    .unwrap();
    let end = run.states[4000];
    assert!(end[0].abs() < 1e-3 && end[3].abs() < 1e-2, "{end:?}");
    let lqr = rollout(
        plane,
        &RolloutController::Lqr(LqrController::new(gains).unwrap()),
        WipState::new(0.05, 0.0, 0.0, 0.0),
        &[WipState::zeros()],
        &settings(800, 20),
    )
    .unwrap();
    let pi = rollout(
        plane,
        &controller,
        WipState::new(0.05, 0.0, 0.0, 0.0),
        &[WipState::zeros()],
        &settings(800, 20),
    )
    .unwrap();
    let gap = (0..=800)
        .map(|k| (pi.states[k][0] - lqr.states[k][0]).abs())
        .fold(0.0, f64::max);
    assert!(
        gap < 2e-3,
        "LQR-PI without disturbance follows the LQR: {gap}"
    );
    // Against a speed PI on the exact ball rate at every substep (the bindings' own loop
    // before the rollouts ran on the planar scheduler): the drive's view (joint rate, the
    // reference shifted by the sampled tilt rate) barely moves the 10 deg recovery.
    let mut outer = LqrPiOuter::new(wip, config).unwrap();
    let mut inner = SpeedPi::new(inner_gains).unwrap();
    let mut s = start;
    let mut worst: f64 = 0.0;
    for k in 0..4000 {
        let o = outer.step(&s, &WipState::zeros(), DT);
        let command = SpeedCommand {
            speed_rad_per_s: o.reference_ball_rate_rad_per_s,
            feedforward_torque_nm: o.reference_torque_nm,
        };
        for _ in 0..20 {
            let torque = inner.step(s[3], &command, DT / 20.0).torque_nm;
            s = rk4_step(|x| wip.derivative(x, torque), &s, DT / 20.0);
        }
        worst = worst.max((run.states[k + 1][0] - s[0]).abs());
    }
    println!("LQR-PI rollout: tilt within {worst:.3e} rad of an exact-ball-rate PI");
    // Small, but not zero: the drive does not see the exact ball rate.
    assert!(worst < 2e-4 && worst > 1e-6, "{worst}");
}

#[test]
fn a_diverging_rollout_ends_in_nan_rows_and_bad_settings_name_the_field() {
    let plane = WipParams::miapure_60kg();
    let wip = Wip::new(plane).unwrap();
    let lqr =
        RolloutController::Lqr(LqrController::new(LqrGains::for_wip(&wip, 83.9).unwrap()).unwrap());
    let nan = WipState::from_element(f64::NAN);
    let run = rollout(plane, &lqr, nan, &[WipState::zeros()], &settings(5, 2)).unwrap();
    assert_eq!((run.states.len(), run.torque_nm.len()), (6, 5));
    assert!(run.states[1..].iter().all(|s| s.iter().all(|x| x.is_nan())));
    assert!(run.status.iter().all(|s| *s == StepStatus::InvalidInput));
    let err = |s: RolloutSettings, commands: &[WipState<f64>]| {
        rollout(plane, &lqr, WipState::zeros(), commands, &s)
            .unwrap_err()
            .to_string()
    };
    let zero = [WipState::zeros()];
    assert!(
        err(
            RolloutSettings {
                dt_secs: 0.0,
                ..settings(5, 1)
            },
            &zero
        )
        .contains("dt_secs")
    );
    assert!(err(settings(5, 0), &zero).contains("substeps"));
    assert!(err(settings(5, 1), &[WipState::zeros(); 3]).contains("commands"));
}
