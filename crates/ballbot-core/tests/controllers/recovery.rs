//! Recovery from a 10 deg tilt.

use super::rig::*;
use ballbot_core::control::{
    LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedCommand, SpeedPi,
    SpeedPiGains,
};
use ballbot_core::{Wip, WipParams, rk4_step};
use nalgebra::Vector4;

#[test]
fn every_controller_recovers_every_preset_from_10_deg() {
    let tilt0 = 10.0_f64.to_radians();
    for preset in presets() {
        for kind in [Kind::Lqr, Kind::PiPd, Kind::LqrPi] {
            let mut c = Controller::new(kind, &preset);
            let trace = simulate(
                &preset,
                &mut c,
                Friction::None,
                Vector4::new(tilt0, 0.0, 0.0, 0.0),
                |_| Vector4::zeros(),
                8.0,
            );
            let settle = trace.settle_time_secs();
            eprintln!(
                "{:>16} {kind:?}: settle {settle:?} s, max tilt {:.2} deg, max torque {:.1} N m",
                preset.name,
                trace.max_abs_tilt_rad().to_degrees(),
                trace.max_abs_torque_nm()
            );
            let settle = settle.unwrap_or(f64::INFINITY);
            assert!(settle <= 5.0, "{} {kind:?}: settle {settle} s", preset.name);
        }
    }
}

/// Without a disturbance the speed error obeys `e_dot = -B4 tau_e` from `e = 0`, so the inner
/// PI adds (almost) nothing and the LQR-PI moves like the LQR: a check of the reference model's
/// signs and of the outer/inner timing.
#[test]
fn without_disturbance_lqr_pi_moves_like_lqr() {
    for preset in presets() {
        let run = |kind| {
            simulate(
                &preset,
                &mut Controller::new(kind, &preset),
                Friction::None,
                Vector4::new(10.0_f64.to_radians(), 0.0, 0.0, 0.0),
                |_| Vector4::zeros(),
                3.0,
            )
        };
        let (a, b) = (run(Kind::Lqr), run(Kind::LqrPi));
        let max_diff = a
            .samples
            .iter()
            .zip(&b.samples)
            .map(|(x, y)| (x.state[TILT] - y.state[TILT]).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{:>16}: max tilt difference LQR vs LQR-PI {:.4} deg",
            preset.name,
            max_diff.to_degrees()
        );
        assert!(max_diff < 0.1_f64.to_radians(), "{}", preset.name);
    }
}

/// The same controllers in f32 (microcontroller arithmetic), on an f32 plant: designs and
/// loops work without f64.
#[test]
fn f32_controllers_recover_miapure_from_10_deg() {
    let wip = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
    let limit = 83.9_f32;
    let lqr = LqrGains::for_wip(&wip, limit).unwrap();
    let inner = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, limit).unwrap();
    let config = LqrPiOuterConfig::new(lqr, &inner).unwrap();
    for use_pi_pd in [false, true] {
        let mut outer = LqrPiOuter::new(wip, config).unwrap();
        let mut pi = SpeedPi::new(inner).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip, limit).unwrap()).unwrap();
        let mut s = Vector4::new(10.0_f32.to_radians(), 0.0, 0.0, 0.0);
        let mut command = SpeedCommand {
            speed_rad_per_s: 0.0,
            feedforward_torque_nm: 0.0,
        };
        let mut torque = 0.0_f32;
        let dt_inner = 1.0 / INNER_HZ as f32;
        for k in 0..(6.0 * INNER_HZ) as usize {
            if k % INNER_PER_OUTER == 0 {
                let sc = Vector4::zeros();
                if use_pi_pd {
                    torque = pipd.step(&s, &sc, 1.0 / OUTER_HZ as f32).torque_nm;
                } else {
                    let o = outer.step(&s, &sc, 1.0 / OUTER_HZ as f32);
                    command = SpeedCommand {
                        speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                        feedforward_torque_nm: o.reference_torque_nm,
                    };
                }
            }
            if !use_pi_pd {
                torque = pi.step(s[BALL_RATE], &command, dt_inner).torque_nm;
            }
            assert!(torque.is_finite() && torque.abs() <= limit);
            s = rk4_step(|x| wip.derivative(x, torque), &s, dt_inner);
        }
        let which = if use_pi_pd { "PI-PD" } else { "LQR-PI" };
        eprintln!("f32 {which}: after 6 s {s:?}");
        assert!(s[TILT].abs() < 0.5_f32.to_radians(), "{which}: {s:?}");
        assert!(s[BALL_RATE].abs() * 0.1145 < 0.02, "{which}: {s:?}");
    }
}
