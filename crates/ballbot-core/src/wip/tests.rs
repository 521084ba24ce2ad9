//! Unit tests of the WIP model.

use super::*;
use crate::check::lit;
use crate::rk4_step;
use crate::{Error, WipParams};
use approx::assert_relative_eq;
use nalgebra::{RealField, Vector4};

/// MiaPURE with friction and wheel inertia switched on, so that every term of the
/// Jacobian is exercised.
fn lossy_params() -> WipParams<f64> {
    WipParams {
        wheel_inertia_kg_m2: 0.05,
        ball_damping_nm_s_per_rad: 0.7,
        drive_damping_nm_s_per_rad: 0.3,
        ..WipParams::miapure_60kg()
    }
}

/// Relative energy error `(final, worst over the run)` of the frictionless, unforced WIP
/// released from a 20 deg tilt.
fn energy_drift<T: RealField + Copy>(params: WipParams<T>, steps: usize, dt: T) -> (T, T) {
    let wip = Wip::new(params).unwrap();
    let mut s = Vector4::new(
        lit::<T>(20.0_f64.to_radians()),
        T::zero(),
        T::zero(),
        T::zero(),
    );
    let e0 = wip.energy_j(&s);
    let mut worst = T::zero();
    for _ in 0..steps {
        s = rk4_step(|x| wip.derivative(x, T::zero()), &s, dt);
        worst = worst.max(((wip.energy_j(&s) - e0) / e0).abs());
    }
    (((wip.energy_j(&s) - e0) / e0).abs(), worst)
}

#[test]
fn energy_is_conserved_without_friction_or_torque() {
    // 10 s at 1 kHz from a 20 deg tilt: the body falls through the bottom and swings back
    // (the potential's zero is at the ball centre, so E0 = m_U g l cos 20 deg). Measured:
    // MiaPURE final 9.4e-9, worst 1.7e-8 (at the fastest point of the swing).
    // The PIPTB swings about twice as fast (l = 0.25 m), so it gets a 2 kHz step for the
    // same bound (at 1 kHz its final drift is 3.5e-8).
    for (params, steps, dt) in [
        (WipParams::<f64>::miapure_60kg(), 10_000, 1e-3),
        (WipParams::piptb(), 20_000, 5e-4),
    ] {
        let (last, worst) = energy_drift(params, steps, dt);
        assert!(last < 1e-8, "relative energy drift after 10 s {last:e}");
        assert!(worst < 2e-8, "worst relative energy drift {worst:e}");
    }
    // The error is RK4's: halving the step shrinks it about 2^4 times.
    let (coarse, _) = energy_drift(WipParams::<f64>::miapure_60kg(), 5_000, 2e-3);
    let (fine, _) = energy_drift(WipParams::<f64>::miapure_60kg(), 10_000, 1e-3);
    assert!(coarse / fine > 8.0, "ratio {}", coarse / fine);
}

#[test]
fn energy_is_conserved_in_f32_to_its_precision() {
    let (last, worst) = energy_drift(WipParams::<f32>::miapure_60kg(), 10_000, 1e-3);
    assert!(
        last < 5e-5 && worst < 5e-5,
        "relative energy drift {last:e} {worst:e}"
    );
}

#[test]
fn friction_dissipates_exactly_the_damping_power() {
    // d/dt E = tau (phi_dot - theta_dot) - b_m (phi_dot - theta_dot)^2 - b_k phi_dot^2.
    let wip = Wip::new(lossy_params()).unwrap();
    let s = Vector4::new(0.2, 1.0, -0.7, 3.0);
    let tau = 12.0;
    let sd = wip.derivative(&s, tau);
    let h = 1e-6;
    let de = (wip.energy_j(&(s + sd * h)) - wip.energy_j(&(s - sd * h))) / (2.0 * h);
    let rel = s[BALL_RATE] - s[TILT_RATE];
    let p = wip.params();
    let expected = wip.input_power_w(&s, tau)
        - p.drive_damping_nm_s_per_rad * rel * rel
        - p.ball_damping_nm_s_per_rad * s[BALL_RATE] * s[BALL_RATE];
    assert_relative_eq!(de, expected, max_relative = 1e-6);
}

fn check_jacobians(wip: &Wip<f64>, s: &WipState<f64>, tau: f64) {
    let lin = wip.linearize(s, tau);
    let h = 1e-6;
    for j in 0..4 {
        let mut e = Vector4::zeros();
        e[j] = h;
        let fd = (wip.derivative(&(s + e), tau) - wip.derivative(&(s - e), tau)) / (2.0 * h);
        for i in 0..4 {
            assert!(
                (lin.A[(i, j)] - fd[i]).abs() < 1e-6 * (1.0 + fd[i].abs()),
                "A[{i},{j}] = {} but finite differences give {}",
                lin.A[(i, j)],
                fd[i]
            );
        }
    }
    let fd = (wip.derivative(s, tau + h) - wip.derivative(s, tau - h)) / (2.0 * h);
    for i in 0..4 {
        assert!(
            (lin.B[i] - fd[i]).abs() < 1e-6 * (1.0 + fd[i].abs()),
            "B[{i}]"
        );
    }
}

#[test]
fn analytic_jacobians_match_central_differences() {
    let states = [
        Vector4::zeros(),
        Vector4::new(0.3, 2.0, -1.1, 4.0),
        Vector4::new(-0.8, -5.0, 2.5, -9.0),
        Vector4::new(1.4, 0.0, 0.2, 12.0),
    ];
    for params in [
        WipParams::miapure_60kg(),
        WipParams::piptb(),
        lossy_params(),
    ] {
        let wip = Wip::new(params).unwrap();
        for s in &states {
            for tau in [0.0, 17.0, -40.0] {
                check_jacobians(&wip, s, tau);
            }
        }
    }
}

#[test]
fn upright_linearisation_matches_model_md() {
    // MODEL.md section 6: A31 = 64.64, A41 = -257.39, B3 = -0.8836, B4 = 4.4545.
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let m = wip.mass_matrix(0.0);
    assert_relative_eq!(m[(0, 0)], 22.575, max_relative = 1e-4);
    assert_relative_eq!(m[(0, 1)], 4.2537, max_relative = 1e-4);
    assert_relative_eq!(m[(1, 1)], 1.0683, max_relative = 1e-4);
    let lin = wip.linearize_upright();
    assert_relative_eq!(lin.A[(2, 0)], 64.64, max_relative = 1e-3);
    assert_relative_eq!(lin.A[(3, 0)], -257.39, max_relative = 1e-3);
    assert_relative_eq!(lin.B[2], -0.8836, max_relative = 1e-3);
    assert_relative_eq!(lin.B[3], 4.4545, max_relative = 1e-3);
    // Non-minimum phase: a forward ball torque first tips the body back.
    assert!(lin.B[2] < 0.0 && lin.B[3] > 0.0);
}

#[test]
fn open_loop_poles_match_model_md() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    assert_relative_eq!(wip.upright_unstable_pole_rad_per_s(), 8.04, epsilon = 5e-3);
    // The eigenvalues of the full linearisation are 0, 0, +-8.04.
    let eig = wip.linearize_upright().A.complex_eigenvalues();
    let mut re: [f64; 4] = core::array::from_fn(|i| eig[i].re);
    re.sort_by(f64::total_cmp);
    assert_relative_eq!(re[0], -8.04, epsilon = 5e-3);
    assert_relative_eq!(re[3], 8.04, epsilon = 5e-3);
    assert!(re[1].abs() < 1e-9 && re[2].abs() < 1e-9);
    assert!(eig.iter().all(|z| z.im.abs() < 1e-9));
    // And in f32.
    let wip32 = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
    assert_relative_eq!(
        wip32.upright_unstable_pole_rad_per_s(),
        8.04,
        epsilon = 5e-3
    );
}

#[test]
fn reduced_linearisation_keeps_tilt_and_rates() {
    let wip = Wip::new(lossy_params()).unwrap();
    let lin = wip.linearize(&Vector4::new(0.1, 0.0, 0.2, 3.0), 5.0);
    let (a, b) = lin.reduced();
    assert_eq!(a[(0, 1)], 1.0);
    assert_eq!(a[(1, 0)], lin.A[(2, 0)]);
    assert_eq!(a[(2, 2)], lin.A[(3, 3)]);
    assert_eq!(b[1], lin.B[2]);
    assert_eq!(b[2], lin.B[3]);
}

#[test]
fn cruise_equilibrium_is_an_equilibrium() {
    let wip = Wip::new(lossy_params()).unwrap();
    let (s, tau) = wip.cruise_equilibrium(10.0).unwrap();
    let sd = wip.derivative(&s, tau);
    assert!(
        sd[TILT_RATE].abs() < 1e-12 && sd[BALL_RATE].abs() < 1e-12,
        "{sd:?}"
    );
    assert!(s[TILT] > 0.0, "ball friction needs a forward lean");
    // Frictionless: upright, zero torque, and the same linearisation as upright.
    let ideal = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    assert_eq!(ideal.cruise_equilibrium(12.0).unwrap().1, 0.0);
    assert_eq!(
        ideal.linearize_cruise(12.0).unwrap().A,
        ideal.linearize_upright().A
    );
    assert!(wip.cruise_equilibrium(1e9).is_none());
}

#[test]
fn invalid_parameters_name_the_field() {
    let bad = WipParams {
        body_mass_kg: -1.0,
        ..WipParams::<f64>::miapure_60kg()
    };
    assert_eq!(
        Wip::new(bad).unwrap_err(),
        Error::invalid("body_mass_kg", "must be finite and > 0")
    );
    let bad = WipParams {
        com_height_m: f64::NAN,
        ..WipParams::<f64>::miapure_60kg()
    };
    assert!(matches!(
        Wip::new(bad),
        Err(Error::InvalidParameter {
            field: "com_height_m",
            ..
        })
    ));
    let bad = WipParams {
        wheel_inertia_kg_m2: -0.1,
        ..WipParams::<f64>::miapure_60kg()
    };
    assert!(matches!(
        Wip::new(bad),
        Err(Error::InvalidParameter {
            field: "wheel_inertia_kg_m2",
            ..
        })
    ));
    // Any non-negative wheel inertia keeps the mass matrix positive definite at every tilt.
    let heavy = WipParams {
        wheel_inertia_kg_m2: 50.0,
        ..WipParams::<f64>::miapure_60kg()
    };
    let wip = Wip::new(heavy).unwrap();
    for tilt in [0.0, 1.0, core::f64::consts::PI] {
        assert!(wip.mass_matrix(tilt).determinant() > 0.0);
    }
}
