//! Minimum braking time and push recovery in the 3D world (`studies::world_braking`, `studies::push`).

use ballbot_sim::rig::{EventKind, Happened, Outcome};
use ballbot_sim::studies::driver::{self, Study};
use ballbot_sim::studies::push::{
    PushOutcome, PushParams, PushSearch, push_recovery_limit, push_trial,
};
use ballbot_sim::studies::world_braking::{
    BrakingExperiment, BrakingOutcome, BrakingParams, BrakingRun, BrakingStudy, BrakingStudyParams,
    TrajectoryFeedforward, braking_run, braking_study, fly_braking,
};
use ballbot_sim::trajopt::SolveStatus;
use ballbot_sim::world::{
    ContactNormalLaw, ContactParams, FailureKind, RubberLayer, StopRules, WorldParams,
};

/// The protocol with a shorter approach and cruise (the tests run in debug builds).
fn fast_braking() -> BrakingParams {
    BrakingParams {
        approach_accel_m_per_s2: 1.0,
        settle_secs: 0.2,
        cruise_secs: 1.0,
        ..BrakingParams::default()
    }
}

fn fast_push() -> PushParams {
    PushParams {
        settle_secs: 0.5,
        observe_secs: 3.0,
        rest_within_secs: 2.5,
        ..PushParams::default()
    }
}

#[test]
fn braking_study_succeeds_at_a_generous_time_fails_at_an_impossible_one_and_bisects_between() {
    let world = WorldParams::miapure_60kg();
    let study = BrakingStudyParams {
        durations_secs: vec![3.0, 1.0, 0.5],
        bisection_resolution_secs: Some(1.0),
    };
    let mut seen = Vec::new();
    let r = braking_study(world, &fast_braking(), &study, 180.0, &mut |run| {
        seen.push(run.duration_secs)
    })
    .unwrap();
    // 3 s: stopped, at rest at the end, tracking the command closely.
    let ok = &r.descent[0];
    assert!(ok.outcome.is_success(), "{:?}", ok.outcome);
    let last = ok.samples.last().unwrap();
    assert!(last.speed_m_per_s.abs() < 0.05, "{last:?}");
    assert!(last.command_m_per_s.abs() < 1e-9);
    assert!(ok.peaks.speed_error_m_per_s < 0.15, "{:?}", ok.peaks);
    assert!(ok.peaks.cone_utilisation.iter().all(|&u| u < 0.9));
    // Cruising at 1.4 m/s before braking.
    let cruise = ok
        .samples
        .iter()
        .rev()
        .find(|s| s.time_secs < ok.brake_start_secs - 0.05)
        .unwrap();
    assert!((cruise.speed_m_per_s - 1.4).abs() < 0.1, "{cruise:?}");
    // 1 s: the world fails (the plan exists: the planar model brakes in ~0.8 s).
    let bad = &r.descent[1];
    assert!(
        matches!(bad.outcome, BrakingOutcome::Failed(_)),
        "{:?}",
        bad.outcome
    );
    assert!(bad.plan_cost_n2m2s.is_some());
    // The descent stopped at the first failure; the bisection tried 2 s once.
    assert_eq!(r.descent.len(), 2);
    assert_eq!(r.shortest_success_secs, Some(3.0));
    assert_eq!(r.first_failure_secs, Some(1.0));
    assert_eq!(r.bisection.len(), 1);
    assert_eq!(r.bisection[0].duration_secs, 2.0);
    let limit = r.limit_secs.unwrap();
    let below = r.limit_failure_secs.unwrap();
    assert!((2.0..=3.0).contains(&limit) && (1.0..=2.0).contains(&below));
    assert_eq!(limit - below, 1.0);
    // The bracket's ends are a success and a failure actually flown.
    let outcome = |t: f64| {
        r.descent
            .iter()
            .chain(&r.bisection)
            .find(|run| run.duration_secs == t)
            .map(|run| run.outcome.is_success())
    };
    assert_eq!(outcome(limit), Some(true));
    assert_eq!(outcome(below), Some(false));
    assert_eq!(seen, vec![3.0, 1.0, 2.0]);
    assert_eq!(r.shortest_success().unwrap().duration_secs, 3.0);
    assert_eq!(r.first_failure().unwrap().duration_secs, 1.0);
}

/// The descent of 3, 1 and 0.5 s with a bisection to 1 s at 180 deg, as a driver study.
fn short_descent(world: WorldParams) -> BrakingExperiment {
    BrakingExperiment {
        world,
        params: fast_braking(),
        study: BrakingStudyParams {
            durations_secs: vec![3.0, 1.0, 0.5],
            bisection_resolution_secs: Some(1.0),
        },
        headings_deg: vec![180.0],
    }
}

/// `a` and `b` are the same run: the fields that tell first (a readable failure), then all.
fn assert_same_run(a: &BrakingRun, b: &BrakingRun) {
    assert_eq!(a.duration_secs, b.duration_secs);
    assert_eq!(a.outcome, b.outcome);
    assert_eq!(a.plan_cost_n2m2s, b.plan_cost_n2m2s);
    assert_eq!(a.plan_peak_tilt_rad, b.plan_peak_tilt_rad);
    assert_eq!(a.peaks, b.peaks);
    assert_eq!(a.telemetry_hash, b.telemetry_hash);
    assert!(a == b, "the runs at T = {} s differ", a.duration_secs);
}

/// Every trial of the study is solved from a cold start: its record at `T` is the single run
/// at `T` (what `ballbot brake` and `braking_run(.., T, None)` give), and the driver's replay
/// of a trial with an observer is that trial again.
#[test]
fn a_braking_record_is_the_cold_run_at_its_time_and_replays_with_an_observer() {
    let world = WorldParams::miapure_60kg();
    let experiment = short_descent(world);
    let mut lines = Vec::new();
    let records = driver::execute(&experiment, 1, &|_| {}).unwrap();
    let record = &records[0];
    // 3 s stops, 1 s fails (the descent: 2 scanned), then the bisection tries 2 s.
    assert_eq!(record.scanned, 2);
    let tried: Vec<_> = record.trials.iter().map(|(v, _)| *v).collect();
    assert_eq!(tried, [Some(3.0), Some(1.0), Some(2.0)]);
    for (value, run) in &record.trials {
        lines.push(experiment.describe(&180.0, *value, run));
    }
    assert_eq!(lines[1], "brake 180 deg T 1.00 s: failed");
    // The runs after the first (once warm-started from the one before) are the cold runs.
    for t in [1.0, 2.0] {
        let single = braking_run(world, &fast_braking(), 180.0, t, None).unwrap();
        assert_same_run(record.trial_at(t).unwrap(), &single);
    }
    // The same as a BrakingStudy: the descent, the bisection and the bracket.
    let study = BrakingStudy::from_record(180.0, record.clone());
    assert_eq!(study.descent.len(), 2);
    assert_eq!(study.bisection.len(), 1);
    assert_eq!(study.shortest_success_secs, Some(3.0));
    assert_eq!(study.first_failure_secs, Some(1.0));
    let b = record.bracket.unwrap();
    assert_eq!(
        (study.limit_secs, study.limit_failure_secs),
        (b.passed, b.failed)
    );
    // Replayed with an observer that counts the steps: the same trial.
    let mut steps = 0_u64;
    let again = driver::replay(&experiment, 0, Some(2.0), &mut |_| steps += 1)
        .unwrap()
        .unwrap();
    assert!(steps > 1000, "{steps} steps observed");
    assert_eq!(steps.div_ceil(80) as usize, again.samples.len());
    assert_same_run(&again, record.trial_at(2.0).unwrap());
}

/// The progress bar's length: the scan's values plus the halvings of its widest step to the
/// resolution (1e-9 s wider than the protocol's).
#[test]
fn a_braking_job_estimates_its_runs_from_the_scan_and_the_widest_step() {
    let mut experiment = short_descent(WorldParams::miapure_60kg());
    // 3 scanned, and 2 s (3 s to 1 s) halved to 1 s once: 3 + 1.
    assert_eq!(experiment.runs_estimate(&180.0), 4);
    // The paper's 10 durations with steps of 0.5 s halved to 0.05 s: 10 + 4.
    experiment.study = BrakingStudyParams::paper();
    assert_eq!(experiment.runs_estimate(&180.0), 14);
    // Without a bisection: the scan alone.
    experiment.study.bisection_resolution_secs = None;
    assert_eq!(experiment.runs_estimate(&180.0), 10);
}

/// Braking's limit at 180 deg was a lift-off of OW1 a few tens of ms into the stop,
/// and the lift-off stop rule called it a failure. With the rule off the same run goes on: OW1
/// comes back down and the robot is at rest in the window, the lift-off kept as an event.
/// Both runs record what happened; only the verdict and the outcome differ. Pinned to the
/// default world with the wheel contacts' linear fit of the coating
/// (`ContactParams::rubber_coated`), where this run exists: with the whole-range law the
/// contacts travel 2.64 mm before they open, and at T = 1.5 s OW1 stays on the ball, with the
/// rule or without it (checked at the end; docs/results.md, "MiaPURE minimum braking time").
#[test]
fn a_braking_the_lift_off_rule_fails_comes_to_rest_without_it() {
    let whole_range = WorldParams::miapure_60kg();
    let fit = ContactParams::rubber_coated(&whole_range.robot, &RubberLayer::miapure());
    let mut world = whole_range;
    world.contact.normal_law = ContactNormalLaw::Linear;
    world.contact.normal_stiffness_n_per_m = fit.normal_stiffness_n_per_m;
    world.contact.normal_damping_n_s_per_m = fit.normal_damping_n_s_per_m;
    let ruled = braking_run(world, &fast_braking(), 180.0, 1.5, None).unwrap();
    let relaxed_params = BrakingParams {
        stop_rules: StopRules {
            lift_off: false,
            ..StopRules::all()
        },
        ..fast_braking()
    };
    let relaxed = braking_run(world, &relaxed_params, 180.0, 1.5, None).unwrap();
    let ow1_lift_off = |h: &Happened| {
        h.events
            .iter()
            .find(|e| matches!(e.kind, EventKind::LiftOff { wheel: 0, .. }))
            .copied()
    };
    // With the rule: failed by OW1's lift-off, less than 0.1 s into braking.
    let ruled_happened = ruled.happened.as_ref().unwrap();
    match ruled_happened.outcome {
        Outcome::EndedByStopRule {
            rule: FailureKind::LiftOff { wheel: 0 },
            time_secs,
        } => assert!(time_secs - ruled.brake_start_secs < 0.1, "{time_secs}"),
        o => panic!("expected the lift-off rule on OW1, got {o:?}"),
    }
    assert!(matches!(ruled.outcome, BrakingOutcome::Failed(_)));
    // Without it: stopped and at rest, the lift-off an event of more than the rule's 20 ms.
    let happened = relaxed.happened.as_ref().unwrap();
    assert!(relaxed.outcome.is_success(), "{:?}", relaxed.outcome);
    assert!(
        matches!(happened.outcome, Outcome::AtRest { time_secs } if time_secs < relaxed.brake_start_secs + 1.5 + 0.5),
        "{:?}",
        happened.outcome
    );
    let lift = ow1_lift_off(happened).expect("OW1 lifts off");
    assert!(!lift.ongoing && lift.duration_secs > world.failure.max_lift_off_duration_secs);
    assert!(lift.onset_secs - relaxed.brake_start_secs < 0.1, "{lift:?}");
    // The same lift-off began in the ruled run.
    let ruled_lift = ow1_lift_off(ruled_happened).expect("OW1 lifts off with the rule");
    assert_eq!(ruled_lift.onset_secs, lift.onset_secs);
    // The default world (the whole-range law): OW1 stays on, the rule has nothing to end.
    let whole = braking_run(whole_range, &fast_braking(), 180.0, 1.5, None).unwrap();
    let whole_happened = whole.happened.as_ref().unwrap();
    assert!(whole.outcome.is_success(), "{:?}", whole.outcome);
    assert!(ow1_lift_off(whole_happened).is_none(), "{whole_happened:?}");
}

#[test]
fn braking_faster_than_the_planner_allows_has_no_trajectory() {
    let world = WorldParams::miapure_60kg();
    let run = braking_run(world, &fast_braking(), 180.0, 0.3, None).unwrap();
    assert!(run.plan.is_none());
    assert!(
        matches!(run.outcome, BrakingOutcome::NoTrajectory { status } if status != SolveStatus::Solved),
        "{:?}",
        run.outcome
    );
    assert!(run.samples.is_empty());
    assert!(!run.outcome.is_success());
}

/// Regression: a braking trajectory tips the body back first; the core feeds forward its
/// whole torque `c(theta*) theta_ddot* + b phi_ddot*` and OW1 stays loaded, while with the
/// equilibrium-lean feedforward alone (the ablation, no `c theta_ddot*` term) the controller
/// kicks the ball so hard that OW1 lifts off at the onset of a 2 s braking at 180 deg.
#[test]
fn tilt_acceleration_feedforward_keeps_ow1_loaded_at_the_onset_of_braking() {
    let world = WorldParams::miapure_60kg();
    let full = fast_braking();
    let core = BrakingParams {
        feedforward: TrajectoryFeedforward::Core,
        ..full
    };
    let with = braking_run(world, &full, 180.0, 2.0, None).unwrap();
    assert!(with.outcome.is_success(), "{:?}", with.outcome);
    assert!(with.peaks.min_normal_force_n[0] > 100.0, "{:?}", with.peaks);
    // Flying the same plan again is the same run, bit for bit, with or without an observer.
    let mut steps = 0_u64;
    let again = fly_braking(
        world,
        &full,
        180.0,
        with.plan.as_ref().unwrap(),
        &mut |_, _| steps += 1,
    )
    .unwrap();
    assert_eq!(again.telemetry_hash, with.telemetry_hash);
    assert_eq!(again.samples, with.samples);
    assert_eq!(again.outcome, with.outcome);
    assert_eq!(steps.div_ceil(80) as usize, again.samples.len());
    let without = braking_run(world, &core, 180.0, 2.0, None).unwrap();
    match without.outcome {
        BrakingOutcome::Failed(f) => {
            assert_eq!(f.kind, FailureKind::LiftOff { wheel: 0 });
            assert!(f.time_secs - without.brake_start_secs < 0.1, "{f:?}");
        }
        o => panic!("expected lift-off of OW1, got {o:?}"),
    }
}

#[test]
fn push_recovery_small_push_recovered_huge_not_and_the_bisection_lies_between() {
    let world = WorldParams::miapure_60kg();
    let p = fast_push();
    let small = push_trial(world, &p, 90.0, 5.0).unwrap();
    assert_eq!(small.outcome, PushOutcome::Recovered);
    assert!(small.peak_tilt_rad.to_degrees() < 3.0 && small.peak_tilt_rad > 0.0);
    assert!(small.rest_speed_m_per_s < p.rest_speed_m_per_s);
    let huge = push_trial(world, &p, 90.0, 150.0).unwrap();
    assert!(!huge.recovered(), "{:?}", huge.outcome);
    let search = PushSearch {
        upper_ns: 160.0,
        resolution_ns: 20.0,
    };
    let r = push_recovery_limit(world, &p, &search, 90.0, &mut |_| {}).unwrap();
    let failing = r.smallest_failing_ns.unwrap();
    assert!(r.largest_recovered_ns >= 5.0 && failing <= 160.0);
    assert!(failing - r.largest_recovered_ns <= 20.0);
    assert!(r.largest_recovered().unwrap().recovered());
    assert!(!r.smallest_failing().unwrap().recovered());
    // Every recovered impulse is below every failing one (monotone on this grid).
    let max_ok = r
        .trials
        .iter()
        .filter(|t| t.recovered())
        .map(|t| t.impulse_ns)
        .fold(0.0, f64::max);
    let min_bad = r
        .trials
        .iter()
        .filter(|t| !t.recovered())
        .map(|t| t.impulse_ns)
        .fold(f64::INFINITY, f64::min);
    assert!(max_ok < min_bad);
    assert_eq!(max_ok, r.largest_recovered_ns);
    assert_eq!(min_bad, failing);
}

#[test]
fn push_trials_are_bit_identical_for_a_seed_and_differ_across_seeds() {
    let mut world = WorldParams::miapure_60kg();
    world.sensors.seed = 3;
    let p = PushParams {
        settle_secs: 0.3,
        observe_secs: 1.0,
        rest_within_secs: 0.5,
        ..PushParams::default()
    };
    let a = push_trial(world, &p, 0.0, 20.0).unwrap();
    let b = push_trial(world, &p, 0.0, 20.0).unwrap();
    assert_eq!(a, b);
    world.sensors.seed = 4;
    let c = push_trial(world, &p, 0.0, 20.0).unwrap();
    assert_ne!(a.telemetry_hash, c.telemetry_hash);
    // The push direction is the body's: 0 deg moves the robot towards +x (OW1), 90 deg
    // towards +y (the body starts with yaw 0).
    let after = a.samples.iter().find(|s| s.time_secs > 0.2).unwrap();
    let [vx, vy] = after.ball_velocity_m_per_s;
    assert!(vx > 0.05 && vy.abs() < 0.2 * vx, "{after:?}");
    let side = push_trial(world, &p, 90.0, 20.0).unwrap();
    let after = side.samples.iter().find(|s| s.time_secs > 0.2).unwrap();
    let [vx, vy] = after.ball_velocity_m_per_s;
    assert!(vy > 0.05 && vx.abs() < 0.2 * vy, "{after:?}");
}

#[test]
fn invalid_parameters_are_errors() {
    let world = WorldParams::miapure_60kg();
    let bad = BrakingParams {
        rest_speed_m_per_s: 0.0,
        ..BrakingParams::default()
    };
    assert!(braking_run(world, &bad, 180.0, 2.0, None).is_err());
    assert!(braking_run(world, &BrakingParams::default(), 180.0, f64::NAN, None).is_err());
    let empty = BrakingStudyParams {
        durations_secs: Vec::new(),
        bisection_resolution_secs: None,
    };
    assert!(braking_study(world, &BrakingParams::default(), &empty, 0.0, &mut |_| {}).is_err());
    assert!(push_trial(world, &PushParams::default(), 0.0, -1.0).is_err());
    let p = PushParams {
        rest_within_secs: 5.0,
        ..PushParams::default()
    };
    assert!(p.validate().is_err());
    // A resolution finer than the floats near `upper_ns` resolve would never close the bracket.
    let endless = PushSearch {
        upper_ns: 100.0,
        resolution_ns: 1e-300,
    };
    let err = push_recovery_limit(world, &PushParams::default(), &endless, 0.0, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("resolution_ns"), "{err}");
}
