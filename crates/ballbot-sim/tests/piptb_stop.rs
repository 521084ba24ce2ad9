//! The PIPTB's "until stopped" reading of `t3` (`studies::piptb::stop`): the stop criterion on
//! synthetic traces, and on real trials against the fixed window.

use ballbot_sim::planar::{ControllerKind, ControllerSettings};
use ballbot_sim::studies::piptb::{
    self, PiptbProfile, PiptbSettings, StopCriterion, run_trial, stop_time,
};

const TICK_SECS: f64 = 1.0 / 400.0;

/// A trace at 400 Hz: 1 m/s falling at 1 m/s^2 to 0.1 m/s at 0.9 s, then 0.04 m/s for
/// 0.1 s (a pass through the 0.05 band), 0.2 m/s until 1.2 s, then 0.01 m/s until 2 s.
fn trace() -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..800).map(|k| k as f64 * TICK_SECS).collect();
    let v = t
        .iter()
        .map(|&t| match t {
            t if t < 0.9 - 1e-9 => 1.0 - t,
            t if t < 1.0 - 1e-9 => 0.04,
            t if t < 1.2 - 1e-9 => -0.2,
            _ => 0.01,
        })
        .collect();
    (t, v)
}

fn criterion(band: f64, hold: f64) -> StopCriterion {
    StopCriterion {
        speed_band_m_per_s: band,
        hold_secs: hold,
    }
}

#[test]
fn a_synthetic_trace_with_a_known_stop_gives_that_t3() {
    let (t, v) = trace();
    let at = |c: StopCriterion, start: f64| stop_time(&t, &v, start, &c);
    // Held 0.2 s: the 0.1 s pass does not count; stopped at 1.2 s.
    let (t3, capped) = at(criterion(0.05, 0.2), 0.0);
    approx::assert_abs_diff_eq!(t3, 1.2, epsilon = 1e-9);
    assert!(!capped);
    // Held 0.05 s: the pass counts.
    approx::assert_abs_diff_eq!(at(criterion(0.05, 0.05), 0.0).0, 0.9, epsilon = 1e-9);
    // A band that excludes the pass's 0.04 m/s.
    approx::assert_abs_diff_eq!(at(criterion(0.03, 0.05), 0.0).0, 1.2, epsilon = 1e-9);
    // No hold: the first tick inside (1 - t <= 0.151 from t = 0.85 s).
    approx::assert_abs_diff_eq!(at(criterion(0.151, 0.0), 0.0).0, 0.85, epsilon = 1e-9);
    // Ticks before the start are ignored.
    approx::assert_abs_diff_eq!(at(criterion(0.05, 0.05), 0.92).0, 0.92, epsilon = 1e-9);
    // Never confirmed before the end: the cap (the last tick).
    let (t3, capped) = at(criterion(0.005, 0.2), 0.0);
    assert!(capped);
    assert_eq!(t3, *t.last().unwrap());
    // A hold longer than what is left after the last entry into the band: capped too.
    assert!(at(criterion(0.05, 0.9), 0.0).1);
    assert!(criterion(0.05, -0.1).validate().is_err());
    assert!(criterion(0.0, 0.2).validate().is_err());
}

/// Quick settings with a 1 s settle, so a late stop can still be confirmed.
fn settings() -> PiptbSettings {
    PiptbSettings {
        settle_secs: 1.0,
        ..PiptbSettings::quick()
    }
}

fn report() -> piptb::PiptbReport {
    let s = settings();
    let brake = piptb::braking_reference(&s).unwrap();
    piptb::run(&s, brake, &ControllerKind::ALL, None, &mut |_, _| {}).unwrap()
}

#[test]
fn until_stopped_extends_a_late_trial_and_shortens_an_early_one() {
    let s = settings();
    let fixed = report();
    let until = fixed.until_stopped(&s.stop_criterion()).unwrap();
    let (t2, t3) = (s.brake_start_secs(), s.brake_end_secs());
    let (mut late, mut early) = (0, 0);
    for (f, u) in fixed.controllers.iter().zip(&until.controllers) {
        for (tf, tu) in f.trials.iter().zip(&u.trials) {
            assert!(tf.fault.is_none());
            assert_eq!(tf.t3_secs, t3);
            assert!(!tf.t3_capped);
            // The braking effort is a running integral of tau^2: longer phase, more effort.
            let in_band_from_t3 = tf
                .series
                .time_secs
                .iter()
                .zip(&tf.series.speed_m_per_s)
                .all(|(&t, &v)| {
                    t < t3 - 1e-9
                        || t > t3 + s.stop_hold_secs + 1e-9
                        || v.abs() <= s.stop_speed_m_per_s
                });
            if !tf.stopped {
                late += 1;
                assert!(tu.t3_secs > t3, "{:?}: {}", f.kind, tu.t3_secs);
                assert!(tu.j_p >= tf.j_p, "{:?}: {} < {}", f.kind, tu.j_p, tf.j_p);
            } else if in_band_from_t3 {
                early += 1;
                assert!(tu.t3_secs <= t3 + 1e-9, "{:?}: {}", f.kind, tu.t3_secs);
                assert!(tu.j_p <= tf.j_p);
            }
            assert!(tu.t3_secs >= t2);
            // The speed at t3 is inside the band unless capped.
            assert!(tu.t3_capped || tu.end_speed_m_per_s.abs() <= s.stop_speed_m_per_s);
            assert_eq!(tu.stopped, !tu.t3_capped);
        }
    }
    assert!(
        late > 0 && early > 0,
        "both cases exercised: {late} late, {early} early"
    );
}

#[test]
fn the_fixed_window_from_the_series_is_bit_identical_to_the_trial() {
    let s = PiptbSettings::quick();
    let brake = piptb::braking_reference(&s).unwrap();
    let profile = PiptbProfile::new(&s, brake);
    for kind in ControllerKind::ALL {
        let r = run_trial(&s, &profile, &ControllerSettings::new(kind), 3, None).unwrap();
        let w = r.over_window(s.brake_start_secs(), s.brake_end_secs(), false);
        assert_eq!(w.j_p, r.j_p, "{kind:?}");
        assert_eq!(w.speed_rmse, r.speed_rmse, "{kind:?}");
        assert_eq!(w.torque_jitter_nm, r.torque_jitter_nm, "{kind:?}");
        assert_eq!(w.end_speed_m_per_s, r.end_speed_m_per_s, "{kind:?}");
        // The running effort only grows, and is 0 before braking.
        let e = &r.series.effort_n2m2s;
        assert!(e.windows(2).all(|p| p[1] >= p[0]));
        let before = r
            .series
            .time_secs
            .iter()
            .position(|&t| t >= s.brake_start_secs() - 1e-9);
        assert!(e[..before.unwrap()].iter().all(|&x| x == 0.0));
    }
}

/// Every key of `a` is in `b`, recursively through objects and the first element of arrays.
fn same_keys(a: &serde_json::Value, b: &serde_json::Value, path: &str) {
    match (a, b) {
        (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
            for (k, v) in x {
                let w = y.get(k).unwrap_or_else(|| panic!("{path}.{k} missing"));
                same_keys(v, w, &format!("{path}.{k}"));
            }
        }
        (serde_json::Value::Array(x), serde_json::Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{path}");
            if let (Some(v), Some(w)) = (x.first(), y.first()) {
                same_keys(v, w, &format!("{path}[0]"));
            }
        }
        _ => {}
    }
}

#[test]
fn until_stopped_summary_has_the_shape_of_the_fixed_one_and_the_sensitivity_covers_the_grid() {
    let fixed = report();
    let until = fixed
        .until_stopped(&fixed.settings.stop_criterion())
        .unwrap();
    let (a, b) = (fixed.summary_json(), until.summary_json());
    same_keys(&a, &b, "piptb");
    // Back: the same keys, but for the settings, which add the stop criterion.
    for (k, v) in b.as_object().unwrap() {
        if k != "settings" {
            same_keys(v, &a[k], &format!("piptb_until_stopped.{k}"));
        }
    }
    assert_eq!(b["settings"]["stop_hold_secs"], 0.2);
    let grid = fixed.stop_sensitivity(&[0.03, 0.08], &[0.0, 0.4]).unwrap();
    assert_eq!(grid.len(), 4);
    // A looser band or a shorter hold never stops later.
    let t3 = |r: &piptb::PiptbReport| -> f64 {
        r.controllers
            .iter()
            .flat_map(|c| &c.trials)
            .map(|t| t.t3_secs)
            .sum()
    };
    assert!(t3(&grid[2]) <= t3(&grid[0]) && t3(&grid[0]) <= t3(&grid[1]));
    assert!(fixed.matches_paper_order().is_some());
}
