//! LQR synthesis: matrix exponential, ZOH, Riccati solvers and the WIP/spin gain design.
//!
//! Reference numbers: MODEL.md section 6 (MiaPURE with 60 kg, Q = diag(100, 10, 1),
//! R = 0.1: k = [-234.8, -45.70, -3.162], poles -19.5, -4.78, -2.06).
// Test helpers outside `#[test]` fns unwrap too.
#![allow(clippy::unwrap_used)]

use approx::assert_relative_eq;
use ballbot_core::linalg::{expm, is_schur_stable, zoh};
use ballbot_core::lqr::{
    Lqr, RiccatiSettings, RiccatiStatus, SpinLqrWeights, WipLqrWeights, outer_loop_dt_secs,
    solve_care, solve_dare, spin_lqr, spin_lqr_discrete, wip_lqr, wip_lqr_discrete,
};
use ballbot_core::{Error, Spin, SpinParams, Wip, WipParams, rk4_step};
use nalgebra::{
    Complex, Matrix1, Matrix2, Matrix3, Matrix4, RealField, SMatrix, SVector, Vector2, Vector3,
    Vector4,
};
use proptest::prelude::*;

const MODEL_GAINS: [f64; 3] = [-234.8, -45.70, -3.162];
const MODEL_POLES: [f64; 3] = [-19.5, -4.78, -2.06];

fn presets<T: RealField + Copy>() -> [(&'static str, WipParams<T>); 3] {
    [
        ("miapure_60kg", WipParams::miapure_60kg()),
        ("miapure_unloaded", WipParams::miapure_unloaded()),
        ("piptb", WipParams::piptb()),
    ]
}

fn f<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}

fn to_f64<T: RealField + Copy>(x: T) -> f64 {
    nalgebra::try_convert(x).unwrap()
}

/// Real parts sorted ascending, after checking the imaginary parts vanish.
fn real_sorted<T: RealField + Copy>(ev: &SVector<Complex<T>, 3>, tol: f64) -> [f64; 3] {
    let mut re = [0.0; 3];
    for (i, z) in ev.iter().enumerate() {
        assert!(to_f64(z.im).abs() < tol, "complex pole {z:?}");
        re[i] = to_f64(z.re);
    }
    re.sort_by(f64::total_cmp);
    re
}

// ---------------------------------------------------------------- continuous WIP design

fn check_model_gains<T: RealField + Copy>(rel_tol: f64) {
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).unwrap();
    let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).unwrap();
    let k = lqr.reduced_gains();
    for i in 0..3 {
        assert_relative_eq!(to_f64(k[i]), MODEL_GAINS[i], max_relative = rel_tol);
    }
    let paper = lqr.paper_gains();
    assert_eq!(paper, Vector4::new(k[0], T::zero(), k[1], k[2]));
}

#[test]
fn continuous_gains_match_model_md_to_0_1_percent() {
    check_model_gains::<f64>(1e-3);
}

#[test]
fn continuous_gains_match_model_md_f32() {
    check_model_gains::<f32>(1e-3);
}

fn check_model_poles<T: RealField + Copy>(tol: f64) {
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).unwrap();
    let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).unwrap();
    let poles = real_sorted(&lqr.closed_loop_eigenvalues().unwrap(), tol);
    for i in 0..3 {
        // MODEL.md prints 3 significant digits.
        assert_relative_eq!(poles[i], MODEL_POLES[i], max_relative = 5e-3);
    }
}

#[test]
fn continuous_closed_loop_poles_match_model_md() {
    check_model_poles::<f64>(1e-9);
    check_model_poles::<f32>(1e-3);
}

#[test]
fn continuous_care_residual_is_small() {
    for (name, params) in presets::<f64>() {
        let wip = Wip::new(params).unwrap();
        let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).unwrap();
        assert!(lqr.residual < 1e-10, "{name}: residual {}", lqr.residual);
        assert!(lqr.dt_secs.is_none());
        // Re-check the CARE from scratch: A^T X + X A - X B R^-1 B^T X + Q = 0.
        let (a, b) = wip.linearize_upright().reduced();
        let x = lqr.cost_to_go;
        let q = WipLqrWeights::<f64>::model_default().q;
        let res = a.transpose() * x + x * a - x * b * b.transpose() * x / 0.1 + q;
        assert!(res.norm() < 1e-9 * x.norm(), "{name}: {res}");
        // Optimal gain K = R^-1 B^T X.
        assert_relative_eq!(lqr.gain, x * b / 0.1, max_relative = 1e-9);
    }
}

// ---------------------------------------------------------------- discrete WIP design

fn check_discrete_stable<T: RealField + Copy>() {
    for (name, params) in presets::<T>() {
        let wip = Wip::new(params).unwrap();
        let lqr =
            wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), outer_loop_dt_secs()).unwrap();
        let ev = lqr.closed_loop_eigenvalues().unwrap();
        for z in ev.iter() {
            let modulus = to_f64(z.re).hypot(to_f64(z.im));
            assert!(modulus < 1.0, "{name}: |z| = {modulus}");
        }
        assert!(is_schur_stable(&lqr.closed_loop), "{name}");
        // The open loop is unstable: the gain did the work.
        let d = zoh(
            &wip.linearize_upright().reduced().0,
            &wip.linearize_upright().reduced().1,
            outer_loop_dt_secs::<T>(),
        )
        .unwrap();
        assert!(!is_schur_stable(&d.a), "{name}");
    }
}

#[test]
fn discrete_closed_loop_inside_unit_circle_all_presets_400hz() {
    check_discrete_stable::<f64>();
}

#[test]
fn discrete_closed_loop_inside_unit_circle_all_presets_400hz_f32() {
    check_discrete_stable::<f32>();
}

#[test]
fn discrete_poles_map_to_continuous_poles() {
    // At 400 Hz the sampled closed loop's poles are close to exp(s dt) of the continuous ones.
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let dt = outer_loop_dt_secs::<f64>();
    let lqr = wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), dt).unwrap();
    let z = real_sorted(&lqr.closed_loop_eigenvalues().unwrap(), 1e-9);
    for (zi, si) in z.iter().zip(MODEL_POLES) {
        let s = zi.ln() / dt;
        assert_relative_eq!(s, si, max_relative = 2e-2);
    }
}

/// docs/model.md section 6 prints the 400 Hz discrete gains `[-229.9, -44.51, -3.060]`; the
/// convergence test above checks the trend, this one pins the printed numbers. Four
/// significant digits are printed, so 5e-4 relative.
#[test]
fn discrete_gains_400hz_match_docs() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let lqr =
        wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), outer_loop_dt_secs()).unwrap();
    let k = lqr.reduced_gains();
    for (got, want) in k.iter().zip([-229.9, -44.51, -3.060]) {
        assert_relative_eq!(*got, want, max_relative = 5e-4);
    }
}

/// Relative gain error of the discrete design at `dt` against the continuous one.
fn discrete_gain_error<T: RealField + Copy>(dt: f64) -> f64 {
    let wip = Wip::new(WipParams::<T>::miapure_60kg()).unwrap();
    let w = WipLqrWeights::model_default();
    let kc = wip_lqr(&wip, &w).unwrap().gain;
    let kd = wip_lqr_discrete(&wip, &w, f(dt)).unwrap().gain;
    to_f64((kd - kc).norm() / kc.norm())
}

#[test]
fn discrete_gains_converge_to_continuous_as_dt_shrinks() {
    let dts = [0.04, 0.01, 0.0025, 0.000625, 0.00015625, 0.0000390625];
    let errors = dts.map(discrete_gain_error::<f64>);
    // First order in dt: each 4x smaller step cuts the error by about 4.
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!((3.0..5.0).contains(&ratio), "errors {errors:?}");
    }
    // 2 % at 400 Hz, 0.03 % at 25.6 kHz.
    assert!(errors[2] < 0.03 && errors[5] < 5e-4, "errors {errors:?}");
    // f32 follows the same trend until round-off (about 1e-4 here).
    let errors32 = [0.04, 0.01, 0.0025].map(discrete_gain_error::<f32>);
    for (e32, e64) in errors32.iter().zip(errors) {
        assert_relative_eq!(*e32, e64, max_relative = 0.05);
    }
}

#[test]
fn lqr_torque_sign_pushes_ball_under_the_body() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let lqr = wip_lqr(&wip, &WipLqrWeights::model_default()).unwrap();
    let lean_forward = Vector3::new(0.05, 0.0, 0.0);
    assert!(lqr.control(&Vector3::zeros(), &lean_forward) > 0.0);
    assert!(lqr.reduced_gains().iter().all(|k| *k < 0.0));
}

fn simulate_nonlinear_balance<T: RealField + Copy>(params: WipParams<T>) -> Vector4<T> {
    // The nonlinear WIP under the 400 Hz discrete LQR (torque held between samples), from a
    // 5 deg lean and 0.5 m/s ball speed: it must come back upright and stop the ball.
    let wip = Wip::new(params).unwrap();
    let dt: T = outer_loop_dt_secs();
    let lqr = wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), dt).unwrap();
    let v0: T = f(0.5);
    let mut s = Vector4::new(
        f(5f64.to_radians()),
        T::zero(),
        T::zero(),
        v0 / params.ball_radius_m,
    );
    for _ in 0..(8.0 * 400.0) as usize {
        let reduced = Vector3::new(s[0], s[2], s[3]);
        let tau = lqr.control(&Vector3::zeros(), &reduced);
        for _ in 0..4 {
            s = rk4_step(|x| wip.derivative(x, tau), &s, dt / f(4.0));
        }
    }
    s
}

#[test]
fn nonlinear_wip_balances_under_discrete_lqr_all_presets() {
    for (name, params) in presets::<f64>() {
        let s = simulate_nonlinear_balance(params);
        assert!(
            s[0].abs() < 1e-4 && s[2].abs() < 1e-3 && s[3].abs() < 1e-2,
            "{name}: {s}"
        );
    }
    for (name, params) in presets::<f32>() {
        let s = simulate_nonlinear_balance(params);
        assert!(
            s[0].abs() < 1e-3 && s[2].abs() < 1e-2 && s[3].abs() < 1e-1,
            "{name}: {s}"
        );
    }
}

// ---------------------------------------------------------------- Riccati solvers

#[test]
fn dare_residual_small_miapure_400hz() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let (a, b) = wip.linearize_upright().reduced();
    let d = zoh(&a, &b, 0.0025).unwrap();
    let q = Matrix3::from_diagonal(&Vector3::new(100.0, 10.0, 1.0));
    let r = Matrix1::new(0.1);
    let sol = solve_dare(&d.a, &d.b, &q, &r, &RiccatiSettings::default()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    assert!(sol.residual < 1e-11, "residual {}", sol.residual);
    // Independent residual with the textbook form.
    let x = sol.x;
    let s = r + d.b.transpose() * x * d.b;
    let k = d.b.transpose() * x * d.a / s[0];
    assert_relative_eq!(sol.gain, k, max_relative = 1e-10);
    let res = d.a.transpose() * x * d.a - x - d.a.transpose() * x * d.b * k + q;
    assert!(res.norm() < 1e-9 * x.norm(), "{res}");
    assert!(sol.iterations <= 20, "{} iterations", sol.iterations);

    let (a32, b32) = Wip::new(WipParams::<f32>::miapure_60kg())
        .unwrap()
        .linearize_upright()
        .reduced();
    let d32 = zoh(&a32, &b32, 0.0025).unwrap();
    let sol32 = solve_dare(
        &d32.a,
        &d32.b,
        &q.cast::<f32>(),
        &r.cast::<f32>(),
        &RiccatiSettings::default(),
    )
    .unwrap();
    assert_eq!(sol32.status, RiccatiStatus::Converged);
    assert!(sol32.residual < 1e-3, "f32 residual {}", sol32.residual);
    assert_relative_eq!(sol32.gain.cast::<f64>(), sol.gain, max_relative = 1e-3);
}

#[test]
fn dare_scalar_matches_closed_form() {
    // x = a^2 x - a^2 b^2 x^2 / (r + b^2 x) + q has the positive root of
    // b^2 x^2 + (r (1 - a^2) - q b^2) x - q r = 0.
    for (a, b, q, r) in [
        (2.0, 1.0, 1.0, 1.0),
        (0.5, 0.3, 2.0, 0.1),
        (1.0, 1.0, 1.0, 1.0),
        (-3.0, 0.1, 1.0, 10.0),
    ] {
        let (qa, qb, qc): (f64, f64, f64) = (b * b, r * (1.0 - a * a) - q * b * b, -q * r);
        let x = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        let sol = solve_dare(
            &Matrix1::new(a),
            &Matrix1::new(b),
            &Matrix1::new(q),
            &Matrix1::new(r),
            &RiccatiSettings::default(),
        )
        .unwrap();
        assert_eq!(sol.status, RiccatiStatus::Converged);
        assert_relative_eq!(sol.x[0], x, max_relative = 1e-12);
    }
}

#[test]
fn care_scalar_matches_closed_form() {
    // 2 a x - b^2 x^2 / r + q = 0: x = r (a + sqrt(a^2 + b^2 q / r)) / b^2.
    for (a, b, q, r) in [
        (1.0f64, 1.0, 1.0, 1.0),
        (-2.0, 0.5, 3.0, 0.1),
        (0.0, 2.0, 1.0, 1.0),
        (50.0, 1.0, 1e-3, 1.0),
    ] {
        let x = r * (a + (a * a + b * b * q / r).sqrt()) / (b * b);
        let sol = solve_care(
            &Matrix1::new(a),
            &Matrix1::new(b),
            &Matrix1::new(q),
            &Matrix1::new(r),
            &RiccatiSettings::default(),
        )
        .unwrap();
        assert_eq!(sol.status, RiccatiStatus::Converged, "{a} {b} {q} {r}");
        assert_relative_eq!(sol.x[0], x, max_relative = 1e-10);
    }
}

#[test]
fn care_multi_input_residual() {
    // Two inputs, four states, a cross-coupled unstable plant.
    let a = Matrix4::new(
        0.0, 1.0, 0.0, 0.0, //
        30.0, -0.1, 2.0, 0.0, //
        0.0, 0.0, 0.0, 1.0, //
        -1.0, 0.0, 5.0, 0.0,
    );
    let b = SMatrix::<f64, 4, 2>::new(0.0, 0.0, 1.0, 0.2, 0.0, 0.0, -0.3, 2.0);
    let q = Matrix4::from_diagonal(&Vector4::new(10.0, 1.0, 5.0, 0.5));
    let r = Matrix2::new(0.5, 0.1, 0.1, 1.0);
    let sol = solve_care(&a, &b, &q, &r, &RiccatiSettings::default()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    let x = sol.x;
    let res = a.transpose() * x + x * a - x * b * r.try_inverse().unwrap() * b.transpose() * x + q;
    assert!(res.norm() < 1e-10 * x.norm(), "{res}");
    // And the DARE of its ZOH discretisation.
    let d = zoh(&a, &b, 0.01).unwrap();
    let sol = solve_dare(&d.a, &d.b, &q, &r, &RiccatiSettings::default()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    assert!(sol.residual < 1e-11);
}

#[test]
fn unstabilisable_pairs_report_failure() {
    let settings = RiccatiSettings::default();
    // An unstable mode that the input cannot reach, weighted by Q (the doubling diverges) or
    // unweighted (it converges to a non-stabilising solution).
    let a = Matrix2::new(1.2, 0.0, 0.0, 0.5);
    let b = Vector2::new(0.0, 1.0);
    let r = Matrix1::new(1.0);
    for q in [Matrix2::identity(), Matrix2::new(0.0, 0.0, 0.0, 1.0)] {
        let sol = solve_dare(&a, &b, &q, &r, &settings).unwrap();
        assert_eq!(sol.status, RiccatiStatus::NotStabilizable, "{q}");
        let sol32 = solve_dare(
            &a.cast::<f32>(),
            &b.cast::<f32>(),
            &q.cast::<f32>(),
            &r.cast::<f32>(),
            &RiccatiSettings::default(),
        )
        .unwrap();
        assert_eq!(sol32.status, RiccatiStatus::NotStabilizable, "f32 {q}");
        // Continuous: eigenvalue +1 unreachable.
        let ac = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        let sol = solve_care(&ac, &b, &q, &r, &settings).unwrap();
        assert_eq!(sol.status, RiccatiStatus::NotStabilizable, "care {q}");
    }
    // A marginal (unit-circle) uncontrollable mode: no asymptotically stable closed loop.
    let a = Matrix2::new(1.0, 0.0, 0.0, 1.1);
    let sol = solve_dare(&a, &b, &Matrix2::identity(), &r, &settings).unwrap();
    assert_eq!(sol.status, RiccatiStatus::NotStabilizable);
    // The same plant with a controllable unstable mode is fine.
    let a = Matrix2::new(1.2, 1.0, 0.0, 0.5);
    let b = Vector2::new(0.0, 1.0);
    let sol = solve_dare(&a, &b, &Matrix2::identity(), &r, &settings).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
}

#[test]
fn full_wip_state_with_unweighted_ball_angle_is_not_stabilising() {
    // MODEL.md section 2: on the 4-state model with zero weight on phi, the phi integrator is
    // undetectable and no stabilising solution exists; that is why the design uses the
    // reduced state.
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let lin = wip.linearize_upright();
    let q = Matrix4::from_diagonal(&Vector4::new(100.0, 0.0, 10.0, 1.0));
    let d = zoh(&lin.A, &lin.B, 0.0025).unwrap();
    let sol = solve_dare(
        &d.a,
        &d.b,
        &q,
        &Matrix1::new(0.1),
        &RiccatiSettings::default(),
    )
    .unwrap();
    assert_ne!(sol.status, RiccatiStatus::Converged);
    let weights = ballbot_core::lqr::LqrWeights::new(q, 0.1);
    assert!(matches!(
        Lqr::discrete(&lin.A, &lin.B, &weights, 0.0025),
        Err(Error::NoStabilizingGain { .. })
    ));
}

#[test]
fn iteration_limit_is_reported() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let (a, b) = wip.linearize_upright().reduced();
    let d = zoh(&a, &b, 0.0025).unwrap();
    let q = Matrix3::from_diagonal(&Vector3::new(100.0, 10.0, 1.0));
    let settings = RiccatiSettings {
        max_iterations: 3,
        ..RiccatiSettings::default()
    };
    let sol = solve_dare(&d.a, &d.b, &q, &Matrix1::new(0.1), &settings).unwrap();
    assert!(matches!(
        sol.status,
        RiccatiStatus::MaxIterations | RiccatiStatus::NotStabilizable
    ));
    assert_eq!(sol.iterations, 3);
}

#[test]
fn invalid_weights_name_the_field() {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let field = |w: WipLqrWeights<f64>| match wip_lqr(&wip, &w) {
        Err(Error::InvalidParameter { field, .. }) => field,
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    assert_eq!(field(WipLqrWeights::diagonal([100.0, 10.0, 1.0], 0.0)), "r");
    assert_eq!(
        field(WipLqrWeights::diagonal([100.0, 10.0, 1.0], -1.0)),
        "r"
    );
    assert_eq!(
        field(WipLqrWeights::diagonal([100.0, 10.0, 1.0], f64::NAN)),
        "r"
    );
    assert_eq!(
        field(WipLqrWeights::diagonal([100.0, -10.0, 1.0], 0.1)),
        "q"
    );
    assert_eq!(
        field(WipLqrWeights::diagonal([100.0, f64::INFINITY, 1.0], 0.1)),
        "q"
    );
    let mut asym = WipLqrWeights::model_default();
    asym.q[(0, 1)] = 1.0;
    assert_eq!(field(asym), "q");
    // Symmetric with positive diagonal but indefinite.
    let mut indefinite = WipLqrWeights::model_default();
    indefinite.q[(0, 1)] = 50.0;
    indefinite.q[(1, 0)] = 50.0;
    assert_eq!(field(indefinite), "q");
    // Positive semidefinite with off-diagonal terms is fine.
    let mut psd = WipLqrWeights::model_default();
    psd.q[(0, 1)] = 10.0;
    psd.q[(1, 0)] = 10.0;
    assert!(wip_lqr(&wip, &psd).is_ok());
    assert!(matches!(
        wip_lqr_discrete(&wip, &WipLqrWeights::model_default(), 0.0),
        Err(Error::InvalidParameter {
            field: "dt_secs",
            ..
        })
    ));
}

#[test]
fn spin_lqr_continuous_and_discrete() {
    let spin = Spin::new(SpinParams::<f64>::miapure_60kg()).unwrap();
    let w = SpinLqrWeights::diagonal([25.0, 1.0], 0.5);
    let lqr = spin_lqr(&spin, &w).unwrap();
    // k1 = sqrt(q1 / r) for a plant whose first state integrates the second.
    assert_relative_eq!(lqr.gain[0], (25.0f64 / 0.5).sqrt(), max_relative = 1e-10);
    // Closed loop I s^2 + (D + k2) s + k1 = 0 from the gain itself.
    let p = spin.params();
    let (a, b) = spin.state_space();
    let acl = a - b * lqr.gain.transpose();
    assert_relative_eq!(acl, lqr.closed_loop, max_relative = 1e-12);
    assert_relative_eq!(
        acl[(1, 0)],
        -lqr.gain[0] / p.inertia_kg_m2,
        max_relative = 1e-12
    );
    for z in lqr.closed_loop_eigenvalues().unwrap().iter() {
        assert!(z.re < 0.0);
    }
    let mut errors = [0.0; 3];
    for (i, dt) in [0.01, 0.0025, 0.000625].into_iter().enumerate() {
        let d = spin_lqr_discrete(&spin, &w, dt).unwrap();
        assert!(
            d.closed_loop_eigenvalues()
                .unwrap()
                .iter()
                .all(|z| z.re.hypot(z.im) < 1.0)
        );
        errors[i] = (d.gain - lqr.gain).norm() / lqr.gain.norm();
    }
    assert!(
        errors[0] > errors[1] && errors[1] > errors[2] && errors[2] < 1e-3,
        "{errors:?}"
    );
    let spin32 = Spin::new(SpinParams::<f32>::miapure_unloaded()).unwrap();
    let lqr32 =
        spin_lqr_discrete(&spin32, &SpinLqrWeights::diagonal([25.0, 1.0], 0.5), 0.0025).unwrap();
    assert!(is_schur_stable(&lqr32.closed_loop));
}

// ---------------------------------------------------------------- expm and ZOH

fn check_expm_closed_forms<T: RealField + Copy>(tol: f64) {
    // Rotation generator, including large angles (many squarings).
    for t in [0.1, 0.7, 3.0, 50.0] {
        let tt: T = f(t);
        let e = expm(&Matrix2::new(T::zero(), -tt, tt, T::zero())).unwrap();
        let want = Matrix2::new(t.cos(), -t.sin(), t.sin(), t.cos());
        // Squaring amplifies the rounding error by about the number of doublings times eps.
        let err = (e.map(to_f64) - want).norm();
        assert!(err < tol * t.max(1.0), "t = {t}: {err}");
    }
    // Nilpotent: exp(N) = I + N + N^2 / 2.
    let n = Matrix3::new(0.0, 2.0, -3.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0);
    let want = Matrix3::identity() + n + n * n / 2.0;
    let e = expm(&n.map(f::<T>)).unwrap().map(to_f64);
    assert!((e - want).norm() < tol * want.norm(), "{e}");
    // Diagonalisable: V diag(exp(l)) V^-1, with a stiff spread of eigenvalues.
    let v = Matrix3::new(1.0, 2.0, 0.0, 0.0, 1.0, -1.0, 1.0, 0.0, 3.0);
    let l = Vector3::new(-20.0, 0.5, 2.0);
    let a = v * Matrix3::from_diagonal(&l) * v.try_inverse().unwrap();
    let want = v * Matrix3::from_diagonal(&l.map(f64::exp)) * v.try_inverse().unwrap();
    let e = expm(&a.map(f::<T>)).unwrap().map(to_f64);
    assert!((e - want).norm() < 20.0 * tol * want.norm(), "{e}\n{want}");
}

#[test]
fn expm_matches_closed_forms() {
    check_expm_closed_forms::<f64>(1e-13);
}

#[test]
fn expm_matches_closed_forms_f32() {
    check_expm_closed_forms::<f32>(1e-5);
}

/// ZOH against a fine RK4 integration of `x_dot = A x + B u` over one step.
fn check_zoh_against_rk4<T: RealField + Copy>(dt: f64, tol: f64) {
    let wip = Wip::new(WipParams::<f64>::miapure_60kg()).unwrap();
    let (a, b) = wip.linearize_upright().reduced();
    let d = zoh(&a.map(f::<T>), &b.map(f::<T>), f(dt)).unwrap();
    let substeps = 2000;
    let h = dt / substeps as f64;
    let run = |x0: Vector3<f64>, u: f64| {
        let mut x = x0;
        for _ in 0..substeps {
            x = rk4_step(|x| a * x + b * u, &x, h);
        }
        x
    };
    for i in 0..3 {
        let col = run(Vector3::ith(i, 1.0), 0.0);
        let got = d.a.column(i).map(to_f64);
        assert!(
            (got - col).norm() < tol * col.norm(),
            "dt {dt} column {i}: {got} vs {col}"
        );
    }
    let bd = run(Vector3::zeros(), 1.0);
    let got = d.b.map(to_f64);
    assert!(
        (got - bd).norm() < tol * bd.norm(),
        "dt {dt}: {got} vs {bd}"
    );
    // Ad is the plain exponential.
    let e = expm(&(a.map(f::<T>) * f::<T>(dt))).unwrap().map(to_f64);
    assert!((e - d.a.map(to_f64)).norm() < tol * e.norm());
}

#[test]
fn zoh_matches_fine_rk4() {
    for dt in [1.0 / 8000.0, 0.0025, 0.05, 0.5] {
        check_zoh_against_rk4::<f64>(dt, 1e-12);
        check_zoh_against_rk4::<f32>(dt, 1e-4);
    }
}

// ---------------------------------------------------------------- properties

fn matrix3(entries: [f64; 9]) -> Matrix3<f64> {
    Matrix3::from_row_slice(&entries)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Two ZOH steps are one ZOH step of twice the length: Ad(2h) = Ad(h)^2,
    /// Bd(2h) = Ad(h) Bd(h) + Bd(h).
    #[test]
    fn zoh_semigroup(a in proptest::array::uniform9(-20.0f64..20.0),
                     b in proptest::array::uniform3(-5.0f64..5.0),
                     dt in 1e-4f64..0.1) {
        let a = matrix3(a);
        let b = Vector3::from(b);
        let one = zoh(&a, &b, dt).unwrap();
        let two = zoh(&a, &b, 2.0 * dt).unwrap();
        let ad2 = one.a * one.a;
        let bd2 = one.a * one.b + one.b;
        prop_assert!((two.a - ad2).norm() <= 1e-12 * ad2.norm().max(1.0), "{} vs {}", two.a, ad2);
        prop_assert!((two.b - bd2).norm() <= 1e-12 * (bd2.norm() + one.a.norm() * one.b.norm()),
            "{} vs {}", two.b, bd2);
    }

    /// exp(A) exp(-A) = I, and Pade-based expm agrees with the Taylor-based ZOH.
    #[test]
    fn expm_inverse_and_zoh_agree(a in proptest::array::uniform9(-3.0f64..3.0)) {
        let a = matrix3(a);
        let e = expm(&a).unwrap();
        let e_inv = expm(&(-a)).unwrap();
        let scale = e.norm() * e_inv.norm();
        prop_assert!((e * e_inv - Matrix3::identity()).norm() <= 1e-13 * scale);
        let d = zoh(&a, &Vector3::zeros(), 1.0).unwrap();
        prop_assert!((d.a - e).norm() <= 1e-13 * e.norm().max(1.0));
    }

    /// Any controllable single-input plant in companion form (open-loop poles anywhere)
    /// gives a converged DARE with a small residual and a closed loop inside the unit circle;
    /// its CARE likewise gives a Hurwitz closed loop.
    #[test]
    fn riccati_converges_for_controllable_companion_plants(
        c in proptest::array::uniform3(-3.0f64..3.0),
        q_diag in proptest::array::uniform3(0.01f64..100.0),
        r in 0.01f64..10.0,
    ) {
        let a = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, c[0], c[1], c[2]);
        let b = Vector3::new(0.0, 0.0, 1.0);
        let q = Matrix3::from_diagonal(&Vector3::from(q_diag));
        let r = Matrix1::new(r);
        let settings = RiccatiSettings::default();
        let sol = solve_care(&a, &b, &q, &r, &settings).unwrap();
        prop_assert_eq!(sol.status, RiccatiStatus::Converged);
        prop_assert!(sol.residual < 1e-9, "care residual {}", sol.residual);
        let poles = ballbot_core::linalg::eigenvalues(&(a - b * sol.gain)).unwrap();
        prop_assert!(poles.iter().all(|z| z.re < 0.0), "{:?}", poles);
        let d = zoh(&a, &b, 0.05).unwrap();
        let sol = solve_dare(&d.a, &d.b, &q, &r, &settings).unwrap();
        prop_assert_eq!(sol.status, RiccatiStatus::Converged);
        prop_assert!(sol.residual < 1e-9, "dare residual {}", sol.residual);
        let z = ballbot_core::linalg::eigenvalues(&(d.a - d.b * sol.gain)).unwrap();
        prop_assert!(z.iter().all(|z| z.re.hypot(z.im) < 1.0), "{:?}", z);
    }
}
