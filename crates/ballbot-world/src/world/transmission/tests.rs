use super::*;

const DT: f64 = 1.0 / 8000.0;
const N: f64 = 7.5;
const I_R: f64 = 1.5e-4;
const I_W: f64 = 1.2e-3;

fn drivetrain(params: TransmissionParams, viscous: f64) -> Drivetrain {
    params
        .validate(
            Drivetrain::new(params, N, I_R, I_W, viscous).stuck_inertia_kg_m2(),
            DT,
        )
        .unwrap();
    Drivetrain::new(params, N, I_R, I_W, viscous)
}

fn motor_only(motor_nm: f64) -> DrivetrainLoads {
    DrivetrainLoads {
        motor_nm,
        traction_nm: 0.0,
        gap_nm: 0.0,
    }
}

/// Runs `secs` with a constant motor torque and an unloaded wheel; returns the final state.
fn run(d: &Drivetrain, motor_nm: f64, secs: f64, s: &mut DrivetrainState) {
    for _ in 0..(secs / DT).round() as usize {
        d.step(s, &motor_only(motor_nm), DT);
    }
}

#[test]
fn stiction_holds_the_drivetrain_below_breakaway_and_releases_it_above() {
    for params in [
        TransmissionParams::miapure(),
        TransmissionParams {
            coupling_stiffness_nm_per_rad: 0.0,
            coupling_damping_nm_s_per_rad: 0.0,
            backlash_rad: 0.0,
            ..TransmissionParams::miapure()
        },
    ] {
        let d = drivetrain(params, 0.0);
        let t_s = params.stiction_torque_nm;
        // 95 % of the breakaway torque for 1 s: the wheel does not move (beyond the coupling's
        // wind-up, which is not motion of the wheel).
        let mut s = DrivetrainState::default();
        run(&d, 0.95 * t_s, 1.0, &mut s);
        assert!(
            s.wheel_speed_rad_per_s.abs() < 1e-9 && s.motor_speed_rad_per_s.abs() < 1e-9,
            "{params:?}: {s:?}"
        );
        assert!(s.wheel_angle_rad.abs() < 1e-9, "{s:?}");
        let held = d.step(&mut s, &motor_only(0.95 * t_s), DT);
        assert_eq!(held.mode, GearboxMode::Stuck);
        assert!(
            (held.friction_torque_nm - 0.95 * t_s).abs() < 1e-9,
            "{held:?}"
        );
        // 5 % above it: the drivetrain breaks away, and once sliding its momentum about the
        // output, J_m w_m + I_w w_w, grows at tau - T_c (the backlash rattles, the coupling
        // rings, but both are internal).
        let mut s = DrivetrainState::default();
        let tau = 1.05 * t_s;
        let momentum = |s: &DrivetrainState| {
            N * N * I_R * s.motor_speed_rad_per_s + I_W * s.wheel_speed_rad_per_s
        };
        run(&d, tau, 0.1, &mut s);
        assert!(s.wheel_speed_rad_per_s > 0.5, "{params:?}: {s:?}");
        let before = momentum(&s);
        run(&d, tau, 0.1, &mut s);
        let rate = (momentum(&s) - before) / 0.1;
        assert_eq!(
            d.step(&mut s, &motor_only(tau), DT).mode,
            GearboxMode::Sliding
        );
        let expected = tau - params.coulomb_torque_nm;
        assert!(
            (rate - expected).abs() < 1e-3 * expected,
            "{params:?}: {rate} vs {expected}"
        );
    }
}

#[test]
fn a_sliding_gearbox_stops_and_stays_stopped() {
    let params = TransmissionParams::miapure();
    let d = drivetrain(params, 0.0);
    let mut s = DrivetrainState {
        motor_speed_rad_per_s: 2.0,
        wheel_speed_rad_per_s: 2.0,
        ..DrivetrainState::default()
    };
    // Coulomb friction decelerates the whole drivetrain at T_c / J; it comes to rest after
    // about w J / T_c and stays there.
    let j = I_W + N * N * I_R;
    let stop_secs = 2.0 * j / params.coulomb_torque_nm;
    run(&d, 0.0, stop_secs * 1.5, &mut s);
    assert!(s.motor_speed_rad_per_s.abs() < 1e-6, "{s:?}");
    // The unloaded wheel may still rattle inside the backlash, but no further.
    let play = s.wheel_angle_rad - s.motor_angle_rad;
    assert!(play.abs() < 0.5 * params.backlash_rad + 1e-3, "{s:?}");
    let travelled = s.motor_angle_rad;
    let expected = 2.0 * 2.0 / (2.0 * params.coulomb_torque_nm / j);
    assert!(
        (travelled - expected).abs() < 0.05 * expected,
        "{travelled} vs {expected}"
    );
}

#[test]
fn backlash_shows_as_a_dead_band_in_a_torque_reversal() {
    // The wheel held by a (practically) infinite inertia; no gearbox friction, viscous
    // damping to settle the motor side.
    let params = TransmissionParams {
        stiction_torque_nm: 0.0,
        coulomb_torque_nm: 0.0,
        ..TransmissionParams::miapure()
    };
    let d = Drivetrain::new(params, N, I_R, 1e9, 0.5);
    let tau = 1.0;
    let mut s = DrivetrainState::default();
    run(&d, tau, 0.5, &mut s);
    let forward = s.motor_angle_rad - s.wheel_angle_rad;
    // The coupling carries the torque, wound up by tau / k beyond the dead band's edge.
    assert!((d.coupling_torque_nm(&s) - tau).abs() < 1e-6, "{s:?}");
    run(&d, -tau, 0.5, &mut s);
    let backward = s.motor_angle_rad - s.wheel_angle_rad;
    let k = params.coupling_stiffness_nm_per_rad;
    let dead_band = forward - backward - 2.0 * tau / k;
    assert!(
        (dead_band - params.backlash_rad).abs() < 1e-3 * params.backlash_rad,
        "{dead_band} vs {}",
        params.backlash_rad
    );
    // Inside the dead band no torque passes.
    let mid = DrivetrainState {
        motor_angle_rad: 0.4 * params.backlash_rad,
        motor_speed_rad_per_s: 1.0,
        ..DrivetrainState::default()
    };
    assert_eq!(d.coupling_torque_nm(&mid), 0.0);
}

#[test]
fn an_undamped_coupling_keeps_its_energy_and_the_spin_momentum_follows_the_motor_torque() {
    let params = TransmissionParams {
        stiction_torque_nm: 0.0,
        coulomb_torque_nm: 0.0,
        coupling_damping_nm_s_per_rad: 0.0,
        ..TransmissionParams::miapure()
    };
    let d = drivetrain(params, 0.0);
    // Wound up by 0.01 rad and released: motor side and wheel swing against each other.
    let mut s = DrivetrainState {
        motor_angle_rad: 0.01,
        ..DrivetrainState::default()
    };
    // Semi-implicit Euler keeps a nearby energy: the energy read at each step swings by about
    // omega dt / 2 (8 %) within a period, but its average over 100 steps does not drift.
    let energy = |s: &DrivetrainState| d.kinetic_energy_j(s) + d.coupling_energy_j(s);
    let mut momentum_from_rates = 0.0;
    let mut averages = Vec::new();
    let mut sum = 0.0;
    for k in 0..8000 {
        let step = d.step(&mut s, &motor_only(0.0), DT);
        momentum_from_rates += step.spin_momentum_rate_nm * DT;
        sum += energy(&s);
        if k % 100 == 99 {
            averages.push(sum / 100.0);
            sum = 0.0;
        }
    }
    let (first, last) = (averages[0], averages[averages.len() - 1]);
    assert!(
        (last - first).abs() < 0.02 * first,
        "energy {first} -> {last}"
    );
    // With no external torque the spin momentum n I_r w_m + I_w w_w changes only by the
    // rotor's share of the internal torques: it is what the body takes.
    assert!(
        (d.spin_momentum_nms(&s) - momentum_from_rates).abs() < 1e-9,
        "{} vs {momentum_from_rates}",
        d.spin_momentum_nms(&s)
    );
}

#[test]
fn validation_names_the_field() {
    let j = I_W + N * N * I_R;
    let bad = TransmissionParams {
        coulomb_torque_nm: 1.0,
        ..TransmissionParams::miapure()
    };
    let err = bad.validate(j, DT).unwrap_err().to_string();
    assert!(err.contains("transmission.coulomb_torque_nm"), "{err}");
    let bad = TransmissionParams {
        backlash_rad: 1e-3,
        ..TransmissionParams::rigid()
    };
    let err = bad.validate(j, DT).unwrap_err().to_string();
    assert!(
        err.contains("transmission.coupling_stiffness_nm_per_rad"),
        "{err}"
    );
    let bad = TransmissionParams {
        stick_window_rad_per_s: 1e-4,
        ..TransmissionParams::miapure()
    };
    let err = bad.validate(N * N * I_R, DT).unwrap_err().to_string();
    assert!(err.contains("transmission.stick_window_rad_per_s"), "{err}");
    let bad = TransmissionParams {
        backlash_rad: f64::NAN,
        ..TransmissionParams::miapure()
    };
    let err = bad.validate(j, DT).unwrap_err().to_string();
    assert!(err.contains("transmission.backlash_rad"), "{err}");
    TransmissionParams::rigid().validate(j, DT).unwrap();
}

#[test]
fn a_compliant_drivetrain_needs_a_rotor() {
    use crate::world::WorldParams;
    let mut p = WorldParams::miapure_60kg();
    p.rotor_inertia_kg_m2 = 0.0;
    let err = p.validate().unwrap_err().to_string();
    assert!(err.contains("rotor_inertia_kg_m2"), "{err}");
    p.transmission = TransmissionParams::rigid();
    p.validate().unwrap();
}
