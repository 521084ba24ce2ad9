//! The mechanism study's variants and records: each mechanism switches on exactly its own part
//! of the ideal world, `all` is the default world, and a small study reports every run it made.

use ballbot_core::BallbotParams;
use ballbot_core::ballbot::WheelMapping;
use ballbot_sim::studies::driver::{self, Study};
use ballbot_sim::studies::max_speed::MaxSpeedProtocol;
use ballbot_sim::studies::mechanisms::{
    ControllerVariant, Mechanism, MechanismExperiment, MechanismJob, MechanismStudySettings,
    MechanismTrial, run_study,
};
use ballbot_sim::studies::ramp::RampParams;
use ballbot_sim::world::{DriverModel, WorldParams};

fn robot() -> BallbotParams<f64> {
    BallbotParams::miapure_60kg()
}

#[test]
fn each_mechanism_changes_only_its_own_part_of_the_ideal_world() {
    let ideal = WorldParams::ideal(robot());
    assert_eq!(Mechanism::Ideal.params(robot()), ideal);
    assert_eq!(
        Mechanism::All.params(robot()),
        WorldParams::with_robot(robot())
    );
    assert_eq!(WorldParams::miapure_60kg(), WorldParams::realistic(robot()));
    for m in Mechanism::ALL {
        let p = m.params(robot());
        let gaps = p.contact.rollers != ideal.contact.rollers;
        let axle = p.contact.axle_loss != ideal.contact.axle_loss;
        let rubber = p.contact.normal_law != ideal.contact.normal_law;
        let driver = p.driver != ideal.driver;
        let drivetrain = p.transmission != ideal.transmission;
        let sensing = p.sensors != ideal.sensors;
        let changed = [gaps, axle, rubber, driver, drivetrain, sensing];
        let expected = match m {
            Mechanism::Ideal => [false; 6],
            Mechanism::RollerGaps => [true, false, false, false, false, false],
            Mechanism::AxleLosses => [false, true, false, false, false, false],
            Mechanism::RubberCoating => [false, false, true, false, false, false],
            Mechanism::MotorDriver => [false, false, false, true, false, false],
            Mechanism::Drivetrain => [false, false, false, false, true, false],
            Mechanism::Sensing => [false, false, false, false, false, true],
            // The default world: every mechanism but the sensing.
            Mechanism::All => [true, true, true, true, true, false],
        };
        assert_eq!(changed, expected, "{}", m.as_str());
        // Nothing else moves: the robot, failure limits and the step are the ideal's.
        assert_eq!(p.robot, ideal.robot);
        assert_eq!((p.failure, p.dt_secs), (ideal.failure, ideal.dt_secs));
    }
    assert_eq!(
        WorldParams::realistic(robot()).driver.model,
        DriverModel::Odrive
    );
}

#[test]
fn the_paper_variant_is_the_corrected_controller_with_the_upright_mapping_and_no_jerk_limit() {
    let params = WorldParams::ideal(robot());
    let protocol = MaxSpeedProtocol::default();
    let corrected = ControllerVariant::Corrected
        .config(&params, &protocol)
        .unwrap();
    let paper = ControllerVariant::Paper.config(&params, &protocol).unwrap();
    assert_eq!(corrected.wheel_mapping, WheelMapping::RollingBall);
    assert_eq!(paper.wheel_mapping, WheelMapping::Upright);
    assert!(corrected.shaping.translation.max_jerk_per_s2.is_finite());
    assert_eq!(paper.shaping.translation.max_jerk_per_s2, f64::INFINITY);
    let mut same = paper;
    same.wheel_mapping = corrected.wheel_mapping;
    same.shaping.translation.max_jerk_per_s2 = corrected.shaping.translation.max_jerk_per_s2;
    assert_eq!(same, corrected);
}

#[test]
fn a_small_study_reports_every_run_and_its_summary_records() {
    let protocol = MaxSpeedProtocol {
        slow_ramp: RampParams {
            accel_m_per_s2: 2.0,
            max_command_m_per_s: 0.6,
            settle_secs: 0.2,
            sample_every_secs: 0.01,
        },
        ..MaxSpeedProtocol::default()
    };
    let settings = MechanismStudySettings {
        protocol,
        headings_deg: vec![0.0],
        mechanisms: vec![Mechanism::Ideal, Mechanism::All],
        controllers: ControllerVariant::ALL.to_vec(),
        sweep_accels_m_per_s2: vec![],
        sweep_wheel_ball_friction: vec![],
        sweep_headings_deg: vec![],
        ripple_speeds_m_per_s: vec![0.5],
        ripple: ballbot_sim::studies::mechanisms::RippleProtocol {
            settle_secs: 0.3,
            window_secs: 0.25,
            ..Default::default()
        },
        ..MechanismStudySettings::paper()
    };
    let study = run_study(robot(), &settings, &|_| {}).unwrap();
    assert_eq!(study.runs.len(), 4);
    // On the experiment driver: the ripple cruise (the last job) replays with an observer,
    // bit for bit.
    let experiment = MechanismExperiment {
        robot: robot(),
        settings: settings.clone(),
    };
    let last = experiment.jobs().len() - 1;
    assert!(matches!(experiment.jobs()[last], MechanismJob::Ripple(..)));
    let mut steps = 0_u64;
    let replayed = driver::replay(&experiment, last, None, &mut |_| steps += 1)
        .unwrap()
        .unwrap();
    assert!(steps > 1000, "{steps}");
    assert_eq!(
        replayed,
        MechanismTrial::Ripple(Box::new(study.ripple[0].clone()))
    );
    for c in ControllerVariant::ALL {
        for m in [Mechanism::Ideal, Mechanism::All] {
            let run = study.run(c, m, 0.0).unwrap();
            assert!(run.outcome.max_speed_m_per_s > 0.3, "{run:?}");
        }
    }
    let json = study.slow_ramp_json();
    for c in ["corrected", "paper"] {
        for m in ["ideal", "all"] {
            let record = &json["controllers"][c][m]["0"];
            assert!(
                record["max_speed_m_per_s"].as_f64().unwrap() > 0.3,
                "{json}"
            );
        }
    }
    // The default world's roller gaps (10 rollers). Cruising towards OW1, OW1's rollers do the
    // rolling (its wheel barely turns, no roller passes) while OW2 and OW3 turn alike, so
    // their roller-passing lines coincide.
    let ripple = &study.ripple[0];
    assert_eq!(ripple.roller_count, 10);
    let [ow1, ow2, ow3] = &ripple.wheels;
    assert!(
        ow1.mean_speed_rad_per_s < 0.05 * ow2.mean_speed_rad_per_s,
        "{ripple:?}"
    );
    let (f2, f3) = (
        ow2.roller_passing_hz.unwrap(),
        ow3.roller_passing_hz.unwrap(),
    );
    assert!((f2 - f3).abs() < 0.02 * f2 && f2 > 3.0, "{f2} {f3}");
    assert_eq!(study.ripple_json()[0]["wheels"][1]["wheel"], "OW2");
    assert!(study.table().contains("MiaPURE hardware"));
}
