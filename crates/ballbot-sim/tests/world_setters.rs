//! The world's setters keep `params()` truthful: gravity and friction set after construction
//! show in `BallbotWorld::params` (and so in logs and reports), the engine uses them, and bad
//! values are rejected with the field named, leaving the world unchanged.

use ballbot_sim::world::{BallbotWorld, WorldError, WorldParams};
use nalgebra::Vector3;

fn world() -> BallbotWorld {
    BallbotWorld::new(WorldParams::miapure_60kg()).unwrap()
}

fn rejected_field(result: Result<(), WorldError>) -> &'static str {
    match result {
        Err(WorldError::InvalidParameter { field, .. }) => field,
        other => panic!("expected an invalid parameter, got {other:?}"),
    }
}

#[test]
fn set_gravity_updates_params_and_the_fall() {
    // Lifted 1 m, the whole robot falls freely: internal contact forces cancel, so its
    // vertical momentum after a time t is -M g t for the gravity in force.
    let fall_momentum_ns = |gravity_m_per_s2: Option<f64>| {
        let mut w = world();
        if let Some(g) = gravity_m_per_s2 {
            w.set_gravity_m_per_s2(g).unwrap();
            assert_eq!(w.params().robot.sagittal.gravity_m_per_s2, g);
            assert_eq!(w.params().robot.frontal.gravity_m_per_s2, g);
        }
        w.translate_robot(Vector3::new(0.0, 0.0, 1.0));
        let p0 = w.linear_momentum_ns().z;
        for _ in 0..800 {
            w.step([0.0; 3]);
        }
        w.linear_momentum_ns().z - p0
    };
    let nominal = fall_momentum_ns(None);
    let low = fall_momentum_ns(Some(3.0));
    let g = WorldParams::miapure_60kg().robot.sagittal.gravity_m_per_s2;
    assert!(nominal < -1.0, "the robot must fall: {nominal} N s");
    assert!(
        (low / nominal - 3.0 / g).abs() < 1e-6,
        "momentum {low} N s at g = 3 against {nominal} N s at g = {g}"
    );
}

#[test]
fn set_wheel_friction_updates_params_and_bounds_the_traction() {
    // Ball and body clamped, the motors drive the wheels against the ball: the traction is
    // bounded by the friction cone of the coefficient set.
    let max_traction_ratio = |friction: Option<f64>| {
        let mut w = world();
        if let Some(mu) = friction {
            w.set_wheel_ball_friction(mu).unwrap();
            assert_eq!(w.params().robot.drivetrain.wheel_ball_friction, mu);
        }
        w.set_ball_fixed(true);
        w.set_body_fixed(true);
        let mut ratio: f64 = 0.0;
        for _ in 0..400 {
            let t = w.step([8.0, 8.0, 8.0]);
            for wheel in &t.wheels {
                if wheel.normal_force_n > 1.0 {
                    ratio = ratio.max(wheel.traction_n.abs() / wheel.normal_force_n);
                }
            }
        }
        ratio
    };
    let nominal = max_traction_ratio(None);
    assert!(
        nominal > 0.1,
        "the test needs traction beyond 0.1 N/N, got {nominal}"
    );
    let low = max_traction_ratio(Some(0.05));
    assert!(low <= 0.05 + 1e-9, "traction ratio {low} beyond mu = 0.05");
}

#[test]
fn set_floor_friction_updates_params_and_the_floor() {
    // Motors push the ball around; only floor friction can change the robot's horizontal
    // momentum (rolling resistance and spin friction are torques, set to 0 anyway).
    let horizontal_momentum = |friction: Option<f64>| {
        let mut p = WorldParams::miapure_60kg();
        p.rolling_resistance = 0.0;
        p.spin_friction_m = 0.0;
        let mut w = BallbotWorld::new(p).unwrap();
        if let Some(mu) = friction {
            w.set_floor_friction(mu).unwrap();
            assert_eq!(w.params().robot.drivetrain.ball_floor_friction, mu);
        }
        for _ in 0..400 {
            w.step([4.0, -2.0, -2.0]);
        }
        w.linear_momentum_ns().xy().norm()
    };
    let nominal = horizontal_momentum(None);
    assert!(
        nominal > 0.1,
        "the floor must push for the test to mean anything: {nominal}"
    );
    let frictionless = horizontal_momentum(Some(0.0));
    assert!(
        frictionless < 1e-6 * nominal,
        "frictionless floor pushed: {frictionless}"
    );
}

#[test]
fn setters_reject_bad_values_naming_the_field_and_change_nothing() {
    let mut w = world();
    let before = *w.params();
    assert_eq!(
        rejected_field(w.set_gravity_m_per_s2(f64::NAN)),
        "robot.sagittal.gravity_m_per_s2"
    );
    assert_eq!(
        rejected_field(w.set_wheel_ball_friction(-0.1)),
        "robot.drivetrain.wheel_ball_friction"
    );
    assert_eq!(
        rejected_field(w.set_floor_friction(f64::INFINITY)),
        "robot.drivetrain.ball_floor_friction"
    );
    assert_eq!(*w.params(), before);
    // Zero is the test rigs' free flight and frictionless contacts.
    w.set_gravity_m_per_s2(0.0).unwrap();
    w.set_wheel_ball_friction(0.0).unwrap();
    w.set_floor_friction(0.0).unwrap();
    assert_eq!(w.params().robot.sagittal.gravity_m_per_s2, 0.0);
}
