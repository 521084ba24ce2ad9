//! The normal-force margin of the planner's traction cones (`Limits::normal_force_margin_n`):
//! `|F_i| <= mu (N_i - N_min)` at every knot.

use ballbot_core::BallbotParams;
use ballbot_sim::studies::world_braking::{BrakingError, BrakingParams, braking_problem};
use ballbot_sim::trajopt::{BrakingProblem, BrakingSolution, Limits, TrajoptError};

/// The smallest `mu (N_i - margin) - |F_i|` over every knot and wheel (N): >= 0 inside the
/// shifted cones.
fn worst_cone_slack_n(sol: &BrakingSolution, mu: f64, margin_n: f64) -> f64 {
    sol.contacts
        .iter()
        .flat_map(|c| (0..3).map(move |i| mu * (c.normal_n[i] - margin_n) - c.traction_n[i]))
        .fold(f64::INFINITY, f64::min)
}

fn min_normal_n(sol: &BrakingSolution) -> f64 {
    sol.contacts
        .iter()
        .flat_map(|c| c.normal_n)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn planner_with_a_margin_keeps_every_normal_force_above_it_and_costs_more() {
    // MiaPURE with 60 kg, 1.4 m/s to rest in 1.0 s at 180 deg (the world study's problem):
    // without a margin the onset unloads OW1 to nearly 0 N (docs/world-reproduce.md).
    let robot = BallbotParams::miapure_60kg();
    let mu = robot.drivetrain.wheel_ball_friction;
    let margin_n = 100.0;
    let plain = braking_problem(&robot, &BrakingParams::default(), 180.0, 1.0);
    let with = braking_problem(
        &robot,
        &BrakingParams {
            normal_force_margin_n: margin_n,
            ..BrakingParams::default()
        },
        180.0,
        1.0,
    );
    assert_eq!(with.limits.normal_force_margin_n, margin_n);
    let (free, safe) = (plain.solve().unwrap(), with.solve().unwrap());
    assert!(free.is_solved() && safe.is_solved());
    assert!(
        min_normal_n(&free) < margin_n - 10.0,
        "the test must exercise the margin: {}",
        min_normal_n(&free)
    );
    let tol = 1e-5;
    assert!(
        min_normal_n(&safe) >= margin_n - tol,
        "{}",
        min_normal_n(&safe)
    );
    assert!(worst_cone_slack_n(&safe, mu, margin_n) >= -tol);
    assert!(safe.cost_n2m2s > free.cost_n2m2s);
}

#[test]
fn margin_zero_is_the_plain_cone_bit_for_bit() {
    let robot = BallbotParams::miapure_60kg();
    let explicit = braking_problem(
        &robot,
        &BrakingParams {
            normal_force_margin_n: 0.0,
            ..BrakingParams::default()
        },
        0.0,
        1.5,
    );
    let default = braking_problem(&robot, &BrakingParams::default(), 0.0, 1.5);
    assert_eq!(default.limits.normal_force_margin_n, 0.0);
    let (a, b) = (explicit.solve().unwrap(), default.solve().unwrap());
    // Everything but the wall time.
    assert_eq!(a.status, b.status);
    assert_eq!(a.trajectory, b.trajectory);
    assert_eq!(a.contacts, b.contacts);
    assert_eq!(a.cost_n2m2s.to_bits(), b.cost_n2m2s.to_bits());
    assert_eq!(a.iterations, b.iterations);
    // The plain cone admits a normal force below a margin the shifted one would forbid.
    assert!(worst_cone_slack_n(&a, robot.drivetrain.wheel_ball_friction, 0.0) >= -1e-6);
}

#[test]
fn invalid_margins_are_rejected_naming_the_field() {
    let robot = BallbotParams::miapure_60kg();
    let base = braking_problem(&robot, &BrakingParams::default(), 180.0, 2.0);
    for margin in [-1.0, f64::NAN, f64::INFINITY] {
        let p = BrakingProblem {
            limits: Limits {
                normal_force_margin_n: margin,
                ..base.limits
            },
            ..base
        };
        assert!(matches!(
            p.validate(),
            Err(TrajoptError::InvalidInput {
                field: "limits.normal_force_margin_n",
                ..
            })
        ));
    }
    // A margin without the traction cones it shifts.
    let no_traction = BrakingProblem {
        limits: Limits {
            traction: false,
            normal_force_margin_n: 50.0,
            ..base.limits
        },
        ..base
    };
    assert!(no_traction.validate().is_err());
    let params = BrakingParams {
        normal_force_margin_n: -5.0,
        ..BrakingParams::default()
    };
    assert!(matches!(
        params.validate(),
        Err(BrakingError::InvalidParameter {
            field: "normal_force_margin_n",
            ..
        })
    ));
}
