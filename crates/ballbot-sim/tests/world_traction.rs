//! Traction-aware control in the 3D world: a ramp towards OW1 that fails without it
//! survives with it; a slip on a wet patch is found within a stated latency; slow ramps raise
//! no alarm.

use ballbot_core::BallbotParams;
use ballbot_sim::studies::max_speed::ShaperLimits;
use ballbot_sim::studies::traction::runs::{cross_patch, ramp};
use ballbot_sim::studies::traction::{Control, FrictionPatch};
use ballbot_sim::world::WorldParams;

fn params() -> WorldParams {
    let mut p = WorldParams::with_robot(BallbotParams::miapure_60kg());
    p.sensors.seed = 1;
    p
}

/// Towards OW1 a 1.5 m/s^2 ramp to 2 m/s makes OW2 or OW3 slip in the default world; with
/// traction-aware control the same request is held to the envelope (1.30 m/s^2) and nothing
/// slips. The ball's own acceleration overshoots the envelope where the acceleration starts
/// and ends (the LQR rights the body by running the ball: 1.72 m/s^2 over 0.1 s, measured):
/// within 40 %, which the safety factor of 2 absorbs. Checked by mutation: with the safety factor at 1 the
/// envelope (2.25 m/s^2) lets the ramp through unchanged and it fails.
#[test]
fn a_ramp_towards_ow1_that_slips_without_traction_control_survives_with_it() {
    let caps = ShaperLimits::default();
    let p = params();
    let off = ramp(
        p,
        Control::TractionOff.config(&p, &caps).unwrap(),
        0.0,
        1.5,
        2.0,
    )
    .unwrap();
    assert!(off.failure.is_some(), "off: {:?}", off.failure);
    let on = ramp(
        p,
        Control::TractionOn.config(&p, &caps).unwrap(),
        0.0,
        1.5,
        2.0,
    )
    .unwrap();
    assert!(on.failure.is_none(), "on: {:?}", on.failure);
    assert_eq!(on.slip_events, 0);
    assert!(on.limited_steps > 100, "{}", on.limited_steps);
    assert!(
        (1.0..1.3 * 1.4).contains(&on.max_accel_m_per_s2),
        "{}",
        on.max_accel_m_per_s2
    );
}

/// A wet patch (wheel-ball friction 0.3) crossed while accelerating at the envelope towards
/// OW1: the wheels slip, and the monitor flags it within 20 ms of the world's first slip
/// (measured 15.4 ms; 12.9 ms before the monitor confirmed a flag on a second update), counts one
/// event and lowers its friction estimate.
#[test]
fn slip_on_a_wet_patch_is_detected_within_20_ms() {
    let p = params();
    let config = Control::TractionOn
        .config(&p, &ShaperLimits::default())
        .unwrap();
    let patch = FrictionPatch {
        length_m: 0.5,
        floor_friction: 0.3,
        wheel_ball_friction: Some(0.3),
    };
    let (r, window) = cross_patch(p, config, 0.0, 3.0, 2.0, 1.4, 0.0, &patch, 0.2).unwrap();
    let entered = window.expect("the ball reached the patch").entered_secs;
    let slip = r
        .first_world_slip_secs
        .expect("the wheels slip on the wet patch");
    assert!(slip >= entered, "slip {slip} before the patch {entered}");
    let detected = r.first_detection_secs.expect("detected");
    let latency_ms = (detected - slip) * 1e3;
    eprintln!("world slip at {slip:.4} s, detected at {detected:.4} s: latency {latency_ms:.2} ms");
    assert!((0.0..=20.0).contains(&latency_ms), "{latency_ms} ms");
    assert!(r.slip_events >= 1);
    assert!(r.min_friction_estimate.is_some_and(|mu| mu < 0.6));
}

/// Gentle ramps (0.5 m/s^2 to 1 m/s) at 0, 90 and 180 deg: nothing slips and the monitor
/// raises no alarm (its estimate stays below the 0.05 m/s at which it calls a wheel slipping:
/// the roller ripple, the sensors, and since the drivetrain model the coupling's wind-up and
/// the backlash between the motor's encoder and the wheel: 0.040 / 0.033 / 0.030 m/s at 0 / 90
/// / 180 deg).
#[test]
fn gentle_ramps_raise_no_alarm() {
    let p = params();
    let config = Control::TractionOn
        .config(&p, &ShaperLimits::default())
        .unwrap();
    for h in [0.0, 90.0, 180.0] {
        let r = ramp(p, config, h, 0.5, 1.0).unwrap();
        assert!(
            r.failure.is_none() && r.first_world_slip_secs.is_none(),
            "{h}"
        );
        assert_eq!(r.slip_events, 0, "{h} deg: false alarm");
        let peak = r
            .samples
            .iter()
            .map(|s| s.max_slip_estimate_m_per_s)
            .fold(0.0, f64::max);
        let threshold = config.traction.slip_speed_threshold_m_per_s;
        eprintln!("{h} deg: peak slip estimate {peak:.4} m/s");
        assert!(peak < threshold, "{h} deg: slip estimate {peak}");
    }
}

/// A push is not a slip. Standing on a zero command with traction-aware control and
/// balance-point estimation on (the defaults to come), pushes at the centre of mass (spread over
/// 0.1 s) of 20 and 40 N s towards 0, 90, 180 and 270 deg: the robot recovers without a
/// `WheelSlip` fault or a stop, and wherever no wheel slips in the world the monitor flags no
/// slip (checked by mutation: with every wheel's evidence taken as supported, as before the fix,
/// the pushes flag slips and stop the robot). Every 20 N s push and the 40 N s pushes towards 0,
/// 90 and 180 deg slip no wheel. Since the drivetrain model (the coupling's wind-up and the
/// backlash between motor and wheel) the 40 N s push towards 270 deg slips OW2 for about 17 ms
/// during the recovery, and the robot still comes to rest upright. The monitor flags that real
/// slip, but its observers then coast on a residual that holds the push's momentum too, so the
/// flag lasts the 0.5 s coast limit and raises `WheelSlip`: a controlled stop from standing for
/// a 17 ms slip (a known limitation, docs/traction.md). In the world
/// with a rigid drivetrain, 50 N s pushes slip the wheels for 17 to 34 ms (towards 0, 90 and
/// 270 deg), which the monitor does not flag: a slip shared so that the no-spin part stays quiet,
/// whose demand came with the push (docs/traction.md). Since the wheel contacts follow the
/// coating's whole-range law (2.64 mm of travel) the pushes towards 180 deg, which
/// slip no wheel, are flagged for one (20 N s) and three (40 N s) outer periods: a false flag,
/// too short to raise `WheelSlip` or stop the robot, which is what is asserted there.
#[test]
fn a_push_in_the_world_is_not_read_as_slip() {
    use ballbot_core::ballbot::BallbotControllerConfig;
    use ballbot_core::safety::{Fault, Mode};
    use ballbot_sim::rig::{NoFaults, WorldRobot};
    use ballbot_sim::studies::push::{PushParams, push_trial_with};
    let p = params();
    let config = BallbotControllerConfig::design(&p.robot)
        .unwrap()
        .with_traction_control()
        .with_balance_point_estimation();
    for heading in [0.0, 90.0, 180.0, 270.0] {
        for impulse in [20.0, 40.0] {
            let sim = WorldRobot::with_config(p, config).unwrap();
            let (mut flags, mut world_slips, mut slip_fault, mut stopped) = (0, 0, false, false);
            let mut observe = |sim: &WorldRobot| {
                let wheels = &sim.world().telemetry().wheels;
                world_slips += usize::from(wheels.iter().any(|w| w.slipping));
                if let Some(out) = sim.last_outer() {
                    let t = out.traction.expect("traction control is on");
                    flags += usize::from(t.slip.any_slipping());
                    slip_fault |= out.safety.faults.contains(Fault::WheelSlip);
                    stopped |= out.safety.mode != Mode::Balancing;
                }
            };
            let trial = push_trial_with(
                sim,
                &mut NoFaults,
                &PushParams::default(),
                heading,
                impulse,
                &mut observe,
            )
            .unwrap();
            let label = format!("{impulse} N s towards {heading} deg");
            eprintln!(
                "{label}: {:?}, world slip {:.1} ms, monitor flags {flags} physics steps",
                trial.outcome,
                world_slips as f64 / 8.0
            );
            // The one push that slips a wheel in the world (see above).
            let slips = impulse > 30.0 && heading == 270.0;
            if slips {
                assert!(
                    world_slips > 0 && world_slips < 8 * 40,
                    "{label}: {world_slips}"
                );
            } else {
                assert_eq!(world_slips, 0, "{label}: the world's wheels slipped");
                assert!(!slip_fault && !stopped, "{label}");
                // Towards 180 deg the monitor flags for one to three outer periods since the
                // wheel contacts' whole-range law, without a fault (see above).
                if heading != 180.0 {
                    assert_eq!(flags, 0, "{label}: slip flagged in {flags} steps");
                }
            }
            assert!(trial.recovered(), "{label}: {:?}", trial.outcome);
        }
    }
}

/// The study on the experiment driver: each kind of run that is not a search (a ramp on, a
/// stop, a patch crossing, a rider's lean; the quick study's) replayed with an observer is the
/// trial the driver recorded, bit for bit, and the observer saw every physics step. Checked by
/// mutation: without the observer call in `stop_from_cruise_observed` the stop's replay counts
/// no steps.
#[test]
fn every_kind_of_traction_run_replays_through_the_driver() {
    use ballbot_sim::studies::driver::{execute, replay};
    use ballbot_sim::studies::traction::{
        PatchVariant, TractionExperiment, TractionJob, TractionStudySettings, TractionTrial,
    };
    let settings = TractionStudySettings::quick();
    let mut study = TractionExperiment::phase_one(BallbotParams::miapure_60kg(), &settings);
    let on = Control::TractionOn;
    study.jobs = vec![
        TractionJob::RampOn {
            heading_deg: 0.0,
            accel_m_per_s2: 3.0,
            seed: 1,
        },
        TractionJob::Stop {
            heading_deg: 180.0,
            control: on,
        },
        TractionJob::Patch {
            variant: PatchVariant::Wet,
            control: on,
        },
        TractionJob::Rider {
            heading_deg: 0.0,
            control: on,
        },
    ];
    let records = execute(&study, 0, &|_| {}).unwrap();
    assert_eq!(records.len(), study.jobs.len());
    for (i, record) in records.iter().enumerate() {
        let job = study.jobs[i];
        let [(None, recorded)] = &record.trials[..] else {
            panic!(
                "{job:?}: one trial at no value, got {}",
                record.trials.len()
            );
        };
        assert!(matches!(recorded, TractionTrial::Run(_)), "{job:?}");
        let mut steps = 0u64;
        let replayed = replay(&study, i, None, &mut |_| steps += 1)
            .expect("the job exists")
            .unwrap();
        eprintln!("{job:?}: {steps} physics steps observed");
        assert!(steps > 1000, "{job:?}: {steps} steps observed");
        assert_eq!(&replayed, recorded, "{job:?}");
    }
}

/// The traction study's search (traction-aware control off) through the driver is the
/// maximum-speed study's `failing_acceleration` at the same heading and seed: the same bracket,
/// ramps, trials at its ends and run count; and a ramp of it replayed with an observer is the
/// recorded one. Checked by mutation: with the search's seed one higher, or traction-aware
/// control on in the search, the results differ.
#[test]
fn the_traction_search_is_the_max_speed_search() {
    use ballbot_sim::studies::driver::{Study, execute, replay};
    use ballbot_sim::studies::max_speed::failing_acceleration;
    use ballbot_sim::studies::traction::{
        TractionExperiment, TractionJob, TractionStudySettings, TractionTrial, search_result,
    };
    let settings = TractionStudySettings::quick();
    let mut study = TractionExperiment::phase_one(BallbotParams::miapure_60kg(), &settings);
    study.jobs = vec![TractionJob::Search { heading_deg: 0.0 }];
    let direct =
        failing_acceleration(study.params, &settings.protocol, 0.0, settings.seed).unwrap();
    let mut records = execute(&study, 0, &|_| {}).unwrap();
    let record = records.pop().unwrap();
    let bracket = record.bracket.expect("a search has a bracket");
    assert_eq!(bracket.passed, direct.largest_surviving_m_per_s2);
    assert_eq!(bracket.failed, direct.smallest_failing_m_per_s2);
    let failed = bracket.failed.expect("the quick search fails towards OW1");
    assert!(record.trials.len() as u64 <= study.runs_estimate(&study.jobs[0]));
    let Some(TractionTrial::Search(recorded)) = record.trial_at(failed).cloned() else {
        panic!("no search ramp at {failed}");
    };
    let via_driver = search_result(0.0, record).unwrap();
    eprintln!(
        "search 0 deg: {:?} .. {:?} m/s^2 in {} runs",
        via_driver.largest_surviving_m_per_s2,
        via_driver.smallest_failing_m_per_s2,
        via_driver.runs
    );
    assert_eq!(via_driver, direct);
    let mut steps = 0u64;
    let replayed = replay(&study, 0, Some(failed), &mut |_| steps += 1)
        .expect("the job exists")
        .unwrap();
    assert!(steps > 1000, "{steps} steps observed");
    assert_eq!(replayed, TractionTrial::Search(recorded));
}

/// One ramp per sensor seed of `seeds` towards `heading_deg`, two at a time.
fn ramps(
    control: Control,
    heading_deg: f64,
    seeds: std::ops::RangeInclusive<u64>,
    accel_m_per_s2: f64,
    top_m_per_s: f64,
) -> Vec<(u64, ballbot_sim::studies::traction::RunRecord)> {
    let seeds: Vec<u64> = seeds.collect();
    let run = |seed: u64| {
        let mut p = params();
        p.sensors.seed = seed;
        let config = control.config(&p, &ShaperLimits::default()).unwrap();
        (
            seed,
            ramp(p, config, heading_deg, accel_m_per_s2, top_m_per_s).unwrap(),
        )
    };
    std::thread::scope(|scope| {
        let (first, second) = seeds.split_at(seeds.len() / 2);
        let other = scope.spawn(|| second.iter().map(|&s| run(s)).collect::<Vec<_>>());
        let mut out: Vec<_> = first.iter().map(|&s| run(s)).collect();
        out.extend(other.join().unwrap());
        out
    })
}

/// The diagonals' controlled ramps (the study's: 3 m/s^2 to 3 m/s towards 45 and 315 deg,
/// traction-aware control on, the shaper's caps lifted), sensor seeds 1 to 8: none fails, and
/// no wheel comes near its friction cone (measured at most 0.75). The monitor still flags a
/// slip no wheel has in most of them (docs/traction.md, "Known limitation"); its reaction is
/// reached within the jerk limit now, so the flag costs acceleration, not the contacts.
/// Checked by mutation: with the envelope's decrease taking effect at once (and the pending
/// acceleration bounded in one step, as before), 10 of the 16 ramps fail: OW2 or OW3 lifts
/// off about 50 ms after the flag, with a cone use of 0.98 to 1.
#[test]
fn the_diagonals_controlled_ramps_survive_their_slip_reaction() {
    for heading_deg in [45.0, 315.0] {
        for (seed, r) in ramps(Control::TractionOn, heading_deg, 1..=8, 3.0, 3.0) {
            eprintln!(
                "{heading_deg} deg, seed {seed}: failure {:?}, flagged at {:?} s, world slip at \
                 {:?} s, friction estimate {:?}, cone use {:.2}",
                r.failure,
                r.first_detection_secs,
                r.first_world_slip_secs,
                r.min_friction_estimate,
                r.peak_cone_utilisation
            );
            assert!(r.failure.is_none(), "{heading_deg} deg, seed {seed}");
            assert!(
                r.peak_cone_utilisation < 0.85,
                "{heading_deg} deg, seed {seed}: cone use {}",
                r.peak_cone_utilisation
            );
        }
    }
}

/// The shipped controller at its own caps (1 m/s^2, here to 2 m/s) on the same diagonals and
/// seeds: no wheel comes near its friction cone (measured at most 0.65; 0.95 to 1.0 in 6 of
/// the 16 runs while a slip flag cut the envelope at once). Checked by the same mutation.
#[test]
fn the_shipped_controller_keeps_its_margins_on_the_diagonals() {
    for heading_deg in [45.0, 315.0] {
        for (seed, r) in ramps(Control::Shipped, heading_deg, 1..=8, 1.0, 2.0) {
            assert!(r.failure.is_none(), "{heading_deg} deg, seed {seed}");
            assert!(
                r.peak_cone_utilisation < 0.8,
                "{heading_deg} deg, seed {seed}: cone use {}",
                r.peak_cone_utilisation
            );
        }
    }
}
