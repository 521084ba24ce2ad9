//! The planar plant against the core model, and the friction model's physics.

use ballbot_core::wip::{BALL_RATE, TILT_RATE};
use ballbot_core::{PlanarRobotParams, Wip, WipState, rk4_step};
use ballbot_sim::planar::{FrictionMode, PlanarPlant, TransmissionFriction};
use nalgebra::Vector4;

const RATE_HZ: f64 = 8000.0;

fn open_loop_torque_nm(t: f64) -> f64 {
    0.8 * (7.0 * t).sin() + 0.3 * (23.0 * t).cos()
}

#[test]
fn frictionless_plant_is_the_core_model_integrated_directly() {
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::none(), RATE_HZ).unwrap();
    let wip = Wip::new(robot.plane).unwrap();
    let s0 = Vector4::new(0.02, 0.0, -0.1, 3.0);
    plant.set_state(s0);
    let mut s = s0;
    let dt = 1.0 / RATE_HZ;
    for k in 0..4000 {
        let tau = open_loop_torque_nm(k as f64 * dt);
        plant.step(tau);
        s = rk4_step(|x| wip.derivative(x, tau), &s, dt);
    }
    // Same model and integrator; the plant's one-sin_cos-per-step trigonometry differs from
    // the core's per-stage sin_cos by rounding only.
    let err = (plant.state() - s).amax();
    assert!(err < 1e-12, "plant and core differ by {err}");
}

#[test]
fn fast_step_matches_rk4_over_the_reference_derivative_with_friction() {
    // The plant's step (one sin_cos, Taylor stage offsets) against the core's RK4 over
    // `PlanarPlant::derivative` (the core's WIP plus friction), through stick, slip and a
    // fast tumble that exercises the sin_cos fallback.
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::piptb(), RATE_HZ).unwrap();
    let reference = plant.clone();
    let dt = 1.0 / RATE_HZ;
    for s0 in [
        Vector4::new(0.01, 0.0, 0.0, 0.0),
        Vector4::new(-0.05, 1.0, 0.3, 12.0),
        Vector4::new(0.3, 0.0, 150.0, -40.0),
    ] {
        plant.set_state(s0);
        let mut s = s0;
        for k in 0..800 {
            let tau = 0.4 * (30.0 * k as f64 * dt).sin();
            plant.step(tau);
            let applied = robot
                .actuator
                .clamp_torque_nm(tau, s[BALL_RATE] - s[TILT_RATE]);
            s = rk4_step(|x| reference.derivative(x, applied).0, &s, dt);
        }
        let err = (plant.state() - s).amax() / s.amax().max(1.0);
        assert!(err < 1e-10, "from {s0:?}: relative difference {err}");
    }
}

#[test]
fn plant_rate_converges_to_a_fine_reference() {
    // The 8 kHz plant against RK4 at 80 kHz: RK4's error at 8 kHz is far below any sensor.
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::none(), RATE_HZ).unwrap();
    let wip = Wip::new(robot.plane).unwrap();
    let s0 = Vector4::new(0.05, 0.0, 0.0, 0.0);
    plant.set_state(s0);
    let mut fine = s0;
    let dt = 1.0 / RATE_HZ;
    for k in 0..2000 {
        let tau = open_loop_torque_nm(k as f64 * dt);
        plant.step(tau);
        for _ in 0..10 {
            fine = rk4_step(|x| wip.derivative(x, tau), &fine, dt / 10.0);
        }
    }
    let err = (plant.state() - fine).amax();
    assert!(err < 1e-9, "8 kHz RK4 error {err}");
}

/// Integrates `steps` plant steps under `torque_nm` and returns (energy change, work done by the
/// motor, work done by friction), the works summed at each step's start (rectangle rule).
fn energy_budget(plant: &mut PlanarPlant, torque_nm: f64, steps: usize) -> (f64, f64, f64) {
    let wip = *plant.wip();
    let e0 = wip.energy_j(plant.state());
    let (mut w_motor, mut w_friction) = (0.0, 0.0);
    let dt = plant.dt_secs();
    for _ in 0..steps {
        let before = *plant.state();
        let step = plant.step(torque_nm);
        let after = *plant.state();
        let v = 0.5 * (before[BALL_RATE] - before[TILT_RATE] + after[BALL_RATE] - after[TILT_RATE]);
        w_motor += step.applied_torque_nm * v * dt;
        w_friction += step.friction_torque_nm * v * dt;
    }
    (wip.energy_j(plant.state()) - e0, w_motor, w_friction)
}

#[test]
fn slipping_friction_only_dissipates_and_the_energy_budget_closes() {
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::piptb(), RATE_HZ).unwrap();
    // Upright, wheel spinning fast relative to the body, motor off: friction brakes the joint.
    plant.set_state(Vector4::new(0.0, 0.0, 0.0, 6.0));
    let (de, w_motor, w_friction) = energy_budget(&mut plant, 0.0, 800);
    assert_eq!(w_motor, 0.0);
    assert!(w_friction < -1e-3, "friction must dissipate: {w_friction}");
    let closure = (de - w_friction).abs();
    assert!(
        closure < 1e-3 * w_friction.abs(),
        "dE {de} vs friction work {w_friction}"
    );
}

#[test]
fn torque_below_stiction_keeps_the_joint_stuck() {
    let robot = PlanarRobotParams::piptb();
    let friction = TransmissionFriction::piptb();
    let mut plant = PlanarPlant::new(robot, friction, RATE_HZ).unwrap();
    plant.set_state(WipState::zeros());
    for _ in 0..400 {
        let step = plant.step(0.6 * friction.stiction_torque_nm);
        assert_eq!(step.friction_mode, FrictionMode::Stuck);
        assert!(plant.joint_rate_rad_per_s().abs() < 1e-9);
    }
    // The same torque without friction spins the joint up.
    let mut free = PlanarPlant::new(robot, TransmissionFriction::none(), RATE_HZ).unwrap();
    for _ in 0..400 {
        free.step(0.6 * friction.stiction_torque_nm);
    }
    assert!(free.joint_rate_rad_per_s() > 1.0);
}

#[test]
fn torque_above_stiction_breaks_away_then_slips_against_coulomb() {
    let robot = PlanarRobotParams::piptb();
    let friction = TransmissionFriction::piptb();
    let mut plant = PlanarPlant::new(robot, friction, RATE_HZ).unwrap();
    let torque = 2.0 * friction.stiction_torque_nm;
    let first = plant.step(torque);
    assert_eq!(first.friction_mode, FrictionMode::BreakingAway);
    assert_eq!(first.friction_torque_nm, -friction.stiction_torque_nm);
    for _ in 0..40 {
        plant.step(torque);
    }
    let later = plant.step(torque);
    assert_eq!(later.friction_mode, FrictionMode::Slipping);
    let v = plant.joint_rate_rad_per_s();
    assert!(v > friction.stick_window_rad_per_s);
    let expected = -(friction.coulomb_torque_nm + friction.viscous_nm_s_per_rad * v);
    assert!((later.friction_torque_nm - expected).abs() < 1e-3);
}

#[test]
fn a_slipping_joint_comes_to_rest_and_sticks() {
    // Motor off, joint slipping slowly: Coulomb friction stops it and then it stays stuck
    // (no chatter across zero), the Karnopp window doing its job.
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::piptb(), RATE_HZ).unwrap();
    plant.set_state(Vector4::new(0.0, 0.0, 0.0, 0.5));
    // Coulomb plus viscous stop 0.5 rad/s in about 15 ms (120 steps); from then on the joint
    // must stay stuck.
    let modes: Vec<FrictionMode> = (0..800).map(|_| plant.step(0.0).friction_mode).collect();
    let first_stuck = modes
        .iter()
        .position(|&m| m == FrictionMode::Stuck)
        .unwrap();
    assert!(
        (100..200).contains(&first_stuck),
        "stuck from step {first_stuck}"
    );
    assert!(
        modes[first_stuck..]
            .iter()
            .all(|&m| m == FrictionMode::Stuck),
        "chatter"
    );
    assert!(plant.joint_rate_rad_per_s().abs() < 1e-6);
}

#[test]
fn too_narrow_a_stick_window_is_rejected_naming_the_key() {
    let mut friction = TransmissionFriction::piptb();
    friction.stick_window_rad_per_s = 1e-4;
    let err = PlanarPlant::new(PlanarRobotParams::piptb(), friction, RATE_HZ).unwrap_err();
    assert!(
        err.to_string().contains("friction.stick_window_rad_per_s"),
        "{err}"
    );
}

#[test]
fn actuator_limits_torque_on_the_torque_speed_line() {
    let robot = PlanarRobotParams::piptb();
    let mut plant = PlanarPlant::new(robot, TransmissionFriction::none(), RATE_HZ).unwrap();
    let step = plant.step(1000.0);
    assert!(step.saturated);
    assert_eq!(step.applied_torque_nm, robot.actuator.peak_torque_nm);
    // Joint at half the no-load speed: half the peak is left when motoring.
    plant.set_state(Vector4::new(
        0.0,
        0.0,
        0.0,
        0.5 * robot.actuator.no_load_speed_rad_per_s,
    ));
    let step = plant.step(1000.0);
    assert!((step.applied_torque_nm - 0.5 * robot.actuator.peak_torque_nm).abs() < 1e-9);
    // Braking against the motion may use the full peak.
    let step = plant.step(-1000.0);
    assert!(step.saturated);
    assert_eq!(step.applied_torque_nm, -robot.actuator.peak_torque_nm);
}
