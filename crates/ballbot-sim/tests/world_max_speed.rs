//! The maximum-speed study of the 3D world (`studies::max_speed`) on a small scale.

use ballbot_sim::studies::driver::{self, Study};
use ballbot_sim::studies::max_speed::{
    MaxSpeedExperiment, MaxSpeedJob, MaxSpeedProtocol, MaxSpeedStudySettings, Variant,
    failing_acceleration, job_count, run_study, runs_estimate, slow_ramp_trial,
};
use ballbot_sim::studies::ramp::RampParams;
use ballbot_sim::world::{FailureKind, WorldParams};

fn short_ramp(accel_m_per_s2: f64, top_m_per_s: f64) -> MaxSpeedProtocol {
    MaxSpeedProtocol {
        slow_ramp: RampParams {
            accel_m_per_s2,
            max_command_m_per_s: top_m_per_s,
            settle_secs: 0.2,
            sample_every_secs: 0.01,
        },
        ..MaxSpeedProtocol::default()
    }
}

/// Seeded trials at one heading, no map, no sensitivity.
fn tiny_settings(protocol: MaxSpeedProtocol, heading_deg: f64) -> MaxSpeedStudySettings {
    MaxSpeedStudySettings {
        protocol,
        trial_headings_deg: vec![heading_deg],
        seeds: vec![4],
        map_headings_deg: Vec::new(),
        sensitivity_headings_deg: Vec::new(),
        sensitivity_wheel_ball_friction: Vec::new(),
        sensitivity_com_height_m: Vec::new(),
        threads: 2,
    }
}

#[test]
fn failing_acceleration_is_lower_towards_ow1_than_away_from_it() {
    // Grid 0.3 m/s^2 in [1.2, 2.4]: towards OW1 the driving wheels slip from about
    // 1.8 m/s^2 (docs/world-reproduce.md), away from OW1 2.4 m/s^2 still runs.
    let protocol = MaxSpeedProtocol {
        accel_bracket_m_per_s2: [1.2, 2.4],
        accel_resolution_m_per_s2: 0.3,
        ..MaxSpeedProtocol::default()
    };
    let params = WorldParams::miapure_60kg();
    let fwd = failing_acceleration(params, &protocol, 0.0, 0).unwrap();
    let back = failing_acceleration(params, &protocol, 180.0, 0).unwrap();
    let a_fwd = fwd.largest_surviving_m_per_s2.unwrap();
    let a_back = back.largest_surviving_m_per_s2.unwrap();
    assert!(a_fwd < a_back, "{a_fwd} vs {a_back}");
    assert!((1.2..=1.8).contains(&a_fwd), "{a_fwd}");
    // The grid: the bracket between surviving and failing is one resolution step.
    let failing = fwd.smallest_failing_m_per_s2.unwrap();
    assert!((failing - a_fwd - 0.3).abs() < 1e-9, "{a_fwd} .. {failing}");
    let failure = fwd.failing.as_ref().unwrap().failure.unwrap();
    assert!(
        matches!(failure.kind, FailureKind::SustainedSlip { wheel: 1 | 2 }),
        "{failure:?}"
    );
    assert!(fwd.failing.as_ref().unwrap().max_speed_m_per_s < 1.5);
    assert!(fwd.failing_run.as_ref().unwrap().failure.is_some());
    assert_eq!(
        fwd.failed_during_ramp(protocol.fast_top_m_per_s),
        Some(true)
    );
    assert_eq!(back.failed_during_ramp(protocol.fast_top_m_per_s), None);
    // Away from OW1 the bracket's top survives: censored, reported as a lower bound.
    assert_eq!(back.smallest_failing_m_per_s2, None);
    assert!((a_back - 2.4).abs() < 1e-9);
    assert!(back.text().starts_with(">="), "{}", back.text());
    assert_eq!(back.runs, 2);
    // On the experiment driver: both ends first, then halvings, every value on the grid; a
    // replay of the failing ramp with an observer is the recorded run, bit for bit.
    let study = MaxSpeedExperiment {
        params,
        protocol,
        jobs: vec![MaxSpeedJob::Search {
            variant: Variant::Nominal,
            heading_deg: 0.0,
            seed: 0,
        }],
    };
    let search = study.bisection(&study.jobs[0]).unwrap();
    assert_eq!((search.passing, search.failing), (1.2, 2.4));
    assert!(fwd.runs >= 3 && fwd.runs as u64 <= study.runs_estimate(&study.jobs[0]));
    let mut steps = 0_u64;
    let replayed = driver::replay(&study, 0, Some(failing), &mut |_| steps += 1)
        .unwrap()
        .unwrap();
    assert!(steps > 1000, "{steps}");
    assert_eq!(Some(&replayed.outcome), fwd.failing.as_ref());
    assert_eq!(Some(&replayed.run), fwd.failing_run.as_ref());
}

#[test]
fn censored_and_failed_trials_are_reported_as_such() {
    // 2 m/s^2 towards OW1 slips OW2/OW3 below 1.2 m/s; 1 m/s^2 to 1 m/s away from it runs to
    // the end of the ramp, so its maximum speed is a lower bound, not a failure speed.
    let params = WorldParams::miapure_60kg();
    let failed = run_study(params, &tiny_settings(short_ramp(2.0, 3.0), 0.0), &|_| {}).unwrap();
    let t = &failed.trials[0].trials[0];
    assert!(!t.censored());
    assert!(t.max_speed_m_per_s < 1.2, "{}", t.max_speed_m_per_s);
    assert!(!t.speed_text().starts_with(">="));
    let json = failed.detail_json();
    let trial = &json["trials"][0]["trials"][0];
    assert_eq!(trial["censored"], false);
    assert_eq!(trial["failure"]["kind"], "sustained_slip");
    assert!(matches!(
        trial["failure"]["wheel"].as_str(),
        Some("OW2" | "OW3")
    ));
    assert_eq!(json["trials"][0]["mean_is_lower_bound"], false);
    // What happened: the slip rule ended the ramp, after slip events on the same wheel.
    assert_eq!(trial["outcome"]["kind"], "ended_by_stop_rule");
    assert_eq!(trial["outcome"]["stop_rule"], "sustained_slip");
    let wheel = trial["outcome"]["wheel"].as_str().unwrap();
    assert!(
        trial["events"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e["kind"] == "slip" && e["wheel"] == wheel),
        "{}",
        trial["events"]
    );
    // Slip while balancing: the supervisor had not stopped.
    assert_eq!(t.supervisor_stop_secs, None);
    assert!(trial["supervisor_stop_secs"].is_null());

    let ok = run_study(params, &tiny_settings(short_ramp(1.0, 1.0), 180.0), &|_| {}).unwrap();
    let t = &ok.trials[0].trials[0];
    assert!(t.censored());
    assert!(t.max_speed_m_per_s > 0.9, "{}", t.max_speed_m_per_s);
    assert_eq!(t.speed_text(), format!(">= {:.2}", t.max_speed_m_per_s));
    let json = ok.detail_json();
    assert_eq!(json["trials"][0]["trials"][0]["censored"], true);
    assert!(json["trials"][0]["trials"][0]["failure"].is_null());
    assert_eq!(json["trials"][0]["censored_trials"], 1);
    assert_eq!(json["trials"][0]["mean_is_lower_bound"], true);
    // The shaped command (jerk limit 2 m/s^3) lags the 1 m/s^2 ramp, then reaches its top.
    let samples = &ok.trials[0].first_run.samples;
    let last = samples.last().unwrap();
    assert!((last.shaped_command_m_per_s - 1.0).abs() < 0.02, "{last:?}");
    let mid = samples.iter().find(|x| x.command_m_per_s >= 0.5).unwrap();
    assert!(
        mid.shaped_command_m_per_s > 0.1 && mid.shaped_command_m_per_s < 0.45,
        "{mid:?}"
    );
}

#[test]
fn a_trial_is_determined_by_its_seed() {
    let params = WorldParams::miapure_60kg();
    let protocol = short_ramp(1.0, 0.5);
    let (a, ta) = slow_ramp_trial(params, &protocol, 90.0, 11).unwrap();
    let (b, tb) = slow_ramp_trial(params, &protocol, 90.0, 11).unwrap();
    let (c, _) = slow_ramp_trial(params, &protocol, 90.0, 12).unwrap();
    assert_eq!(a, b);
    assert_eq!(ta, tb);
    assert_eq!(ta.seed, 11);
    assert_ne!(
        a.samples, c.samples,
        "the seed must change the sensor noise"
    );
}

#[test]
fn summary_json_has_the_documented_shape() {
    let params = WorldParams::miapure_60kg();
    let mut settings = tiny_settings(short_ramp(1.0, 0.6), 180.0);
    settings.seeds = vec![1, 2];
    settings.map_headings_deg = vec![180.0];
    settings.protocol.accel_bracket_m_per_s2 = [1.0, 2.0];
    settings.protocol.accel_resolution_m_per_s2 = 1.0;
    settings.protocol.fast_top_m_per_s = 0.6;
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let study = run_study(params, &settings, &|_| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap();
    // Two seeded slow ramps and one search (the map's slow ramp is the first trial); progress
    // after every ramp, the search's too, within the bar's length.
    assert_eq!(job_count(&params, &settings), 3);
    let ramps = 2 + study.map[0].failing.runs;
    assert!(study.map[0].failing.runs >= 2);
    assert_eq!(calls.into_inner(), ramps);
    assert!(ramps as u64 <= runs_estimate(&params, &settings));
    let by_heading = study.max_speed_by_heading_json();
    let mean = by_heading["180"].as_f64().unwrap();
    assert_eq!(by_heading.as_object().unwrap().len(), 1);
    let trials = &study.trials[0].trials;
    assert_eq!(trials.len(), 2);
    assert!(
        (mean - (trials[0].max_speed_m_per_s + trials[1].max_speed_m_per_s) / 2.0).abs() < 1e-12
    );
    let detail = study.detail_json();
    for key in [
        "protocol",
        "wheel_ball_friction",
        "com_height_m",
        "trials",
        "failing_accel_by_heading",
        "map",
        "sensitivity",
        "paper",
    ] {
        assert!(detail.get(key).is_some(), "missing {key}");
    }
    assert_eq!(detail["wheel_ball_friction"], 0.6);
    assert_eq!(detail["com_height_m"], 0.5);
    assert_eq!(detail["protocol"]["slow_ramp"]["accel_m_per_s2"], 1.0);
    assert_eq!(detail["protocol"]["seeds"], serde_json::json!([1, 2]));
    assert!(detail["failing_accel_by_heading"]["180"]["largest_surviving_m_per_s2"].is_number());
    assert_eq!(detail["map"].as_array().unwrap().len(), 1);
    assert_eq!(detail["paper"].as_array().unwrap().len(), 2);
    assert_eq!(detail["paper"][1]["max_speed_m_per_s"], 2.3);
}

#[test]
fn sensitivity_values_equal_to_the_robot_share_its_runs() {
    let params = WorldParams::miapure_60kg();
    let mut settings = MaxSpeedStudySettings::quick();
    let base = job_count(&params, &settings);
    settings.sensitivity_headings_deg = vec![0.0];
    settings.sensitivity_wheel_ball_friction = vec![0.6];
    settings.sensitivity_com_height_m = vec![0.5];
    assert_eq!(job_count(&params, &settings), base);
    settings.sensitivity_wheel_ball_friction = vec![0.4, 0.6];
    // One more slow ramp and one more search.
    assert_eq!(job_count(&params, &settings), base + 2);
    assert_eq!(
        job_count(&params, &MaxSpeedStudySettings::paper()),
        // 24 map searches + 2 headings x 4 varied values; 9 trials + 21 further map headings
        // + 2 x 4 varied slow ramps.
        24 + 8 + 9 + 21 + 8
    );
}

#[test]
fn quasi_static_prediction_orders_the_headings_and_grows_with_mu() {
    // The core's steady-lean contact model (crates/ballbot-core/tests/kinematics.rs):
    // 2.25, 2.48, 4.07 m/s^2 at 0, 90, 180 deg with mu 0.6.
    use ballbot_sim::studies::max_speed::{Variant, quasi_static_failing_accel_m_per_s2};
    let robot = WorldParams::miapure_60kg().robot;
    let at = |h| quasi_static_failing_accel_m_per_s2(&robot, h).unwrap();
    assert!((at(0.0) - 2.25).abs() < 0.01, "{}", at(0.0));
    assert!((at(90.0) - 2.48).abs() < 0.01, "{}", at(90.0));
    assert!((at(180.0) - 4.07).abs() < 0.01, "{}", at(180.0));
    let slippery = Variant::WheelBallFriction(0.4)
        .apply(WorldParams::miapure_60kg())
        .robot;
    assert!(quasi_static_failing_accel_m_per_s2(&slippery, 0.0).unwrap() < at(0.0) - 0.3);
}

#[test]
fn a_controlled_stop_of_the_supervisor_is_reported() {
    // With the wheel-speed limit lowered to 8 rad/s (about 0.8 m/s towards OW1), a 1 m/s^2 ramp
    // to 1.5 m/s makes the core's supervisor start a controlled stop before the top.
    use ballbot_sim::studies::max_speed::controller;
    use ballbot_sim::studies::ramp::max_speed_ramp_with_config;
    let params = WorldParams::miapure_60kg();
    let protocol = short_ramp(1.0, 1.5);
    let mut config = controller(&params, &protocol).unwrap();
    let unlimited = max_speed_ramp_with_config(params, config, 0.0, &protocol.slow_ramp).unwrap();
    assert_eq!(unlimited.supervisor_stop_secs, None);
    config.safety.wheel_speed_limit_rad_per_s = 8.0;
    let run = max_speed_ramp_with_config(params, config, 0.0, &protocol.slow_ramp).unwrap();
    let stop_secs = run.supervisor_stop_secs.unwrap();
    // The ramp starts at 0.2 s; 0.8 m/s needs at least 0.8 s of it.
    assert!(stop_secs > 1.0 && stop_secs < 2.0, "{stop_secs}");
    // The stop brakes the command although the ramp asks for its top.
    let last = run.samples.last().unwrap();
    assert_eq!(last.command_m_per_s, 1.5);
    assert!(last.shaped_command_m_per_s < 0.8, "{last:?}");
}

#[test]
fn the_search_rejects_a_protocol_it_could_not_finish() {
    let world = WorldParams::miapure_60kg();
    for bad in [
        MaxSpeedProtocol {
            accel_resolution_m_per_s2: 0.0,
            ..MaxSpeedProtocol::default()
        },
        MaxSpeedProtocol {
            accel_resolution_m_per_s2: f64::NAN,
            ..MaxSpeedProtocol::default()
        },
        MaxSpeedProtocol {
            accel_bracket_m_per_s2: [2.0, 1.0],
            ..MaxSpeedProtocol::default()
        },
        MaxSpeedProtocol {
            fast_top_m_per_s: -1.0,
            ..MaxSpeedProtocol::default()
        },
    ] {
        // Rejected before any run: an error, not a hang or an overflow.
        let err = failing_acceleration(world, &bad, 0.0, 1)
            .unwrap_err()
            .to_string();
        assert!(err.contains("protocol."), "{err}");
    }
}
