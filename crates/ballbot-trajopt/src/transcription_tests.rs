//! Central-difference checks of every analytic derivative the transcription provides: the
//! constraint matrix `A(z)` of every row (collocation defects of both schemes, path and motor
//! bounds, linearised traction rows) and the cost's gradient and Hessian, at seeded random
//! points away from rest (tilted, moving, with torque).
//!
//! Every row's slack `s(z) = b(z) - A(z) z` at the linearisation point is the constraint value
//! (`-c(z)` for defects, `mu N -+ F` for traction, `b - a^T z` for bounds), so the analytic
//! Jacobian of the slack is `-A(z)` for every row alike.
//!
//! Tolerance: with a step `d_j = 1e-6 max(1, |z_j|)` the central difference's truncation
//! error is `O(d^2 |s'''|)` (about 1e-10 of a row's scale here) and its rounding error
//! `O(eps |s| / d)` (about 1e-10 |s|, |s| up to a few hundred N for the traction rows); so
//! `1e-6` relative to the row's largest entry (at least 1) leaves a margin of 100x over both
//! (the worst entry measured is 8e-9), while a wrong term is far above it: `h/8 -> h/7` in
//! the Hermite-Simpson midpoint's sensitivity alone is off by 0.1 of the row scale.

use super::{Sink, Slacks, Transcription};
use crate::drive::Drive;
use crate::method::Method;
use crate::problem::{BrakingProblem, Limits};
use ballbot_core::{DrivetrainParams, WipParams};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};

/// Dense `A` and `b`, summing repeated entries.
struct Dense {
    cols: usize,
    a: Vec<f64>,
    b: Vec<f64>,
}

impl Sink for Dense {
    fn entry(&mut self, row: usize, col: usize, value: f64) {
        self.a[row * self.cols + col] += value;
    }
    fn rhs(&mut self, row: usize, value: f64) {
        self.b[row] = value;
    }
}

fn dense(t: &Transcription, z: &[f64]) -> Dense {
    let (rows, cols) = (t.row_count(), t.variable_count());
    let mut d = Dense {
        cols,
        a: vec![0.0; rows * cols],
        b: vec![0.0; rows],
    };
    t.assemble(z, true, &mut d);
    d
}

fn slacks(t: &Transcription, z: &[f64]) -> Vec<f64> {
    let mut s = Slacks {
        z,
        slack: vec![0.0; t.row_count()],
    };
    t.assemble(z, false, &mut s);
    s.slack
}

/// MiaPURE with wheel inertia and both dampings (every term of the dynamics is live), every
/// path limit, motor limits and traction at an oblique heading, pinned end torques, and a
/// coarse grid (`h = 0.2 s`) so the `h`-dependent terms are large.
fn problem(method: Method) -> BrakingProblem {
    BrakingProblem {
        plane: WipParams {
            wheel_inertia_kg_m2: 0.05,
            drive_damping_nm_s_per_rad: 0.3,
            ball_damping_nm_s_per_rad: 0.2,
            ..WipParams::miapure_60kg()
        },
        duration_secs: 0.8,
        intervals: 4,
        method,
        zero_end_torques: true,
        limits: Limits {
            tilt_rad: Some(0.3),
            tilt_rate_rad_per_s: Some(2.0),
            ball_speed_m_per_s: Some(2.0),
            torque_nm: Some(80.0),
            drive: Some(Drive::Omniwheels {
                params: DrivetrainParams::miapure(),
                heading_rad: 0.4,
            }),
            traction: true,
            normal_force_margin_n: 0.0,
        },
        ..BrakingProblem::miapure()
    }
}

/// A random point away from rest: tilt up to 0.3 rad, tilt rate 1.5 rad/s, ball rate
/// 12 rad/s (1.4 m/s), torques 40 N m, in every knot and midpoint.
fn random_point(t: &Transcription, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let unit = Uniform::new(-1.0, 1.0).unwrap();
    let mut z = vec![0.0; t.variable_count()];
    for k in 0..=t.intervals {
        let i = t.state(k);
        for (j, scale) in [0.3, 2.0, 1.5, 12.0].into_iter().enumerate() {
            z[i + j] = scale * unit.sample(rng);
        }
        z[t.torque(k)] = 40.0 * unit.sample(rng);
        if let Some(m) = t.mid_torque(k).filter(|_| k < t.intervals) {
            z[m] = 40.0 * unit.sample(rng);
        }
    }
    z
}

/// Largest `|analytic - central difference| / max(1, row scale)` over every entry of `A`.
fn worst_constraint_jacobian_error(t: &Transcription, z: &[f64]) -> (f64, usize, usize) {
    let d = dense(t, z);
    let (rows, cols) = (t.row_count(), t.variable_count());
    let scale: Vec<f64> = (0..rows)
        .map(|r| {
            d.a[r * cols..(r + 1) * cols]
                .iter()
                .fold(1.0, |m: f64, v| m.max(v.abs()))
        })
        .collect();
    let mut worst = (0.0, 0, 0);
    for c in 0..cols {
        let step = 1e-6 * z[c].abs().max(1.0);
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        zp[c] += step;
        zm[c] -= step;
        let (sp, sm) = (slacks(t, &zp), slacks(t, &zm));
        for r in 0..rows {
            let fd = (sp[r] - sm[r]) / (2.0 * step);
            let err = (-d.a[r * cols + c] - fd).abs() / scale[r];
            if err > worst.0 {
                worst = (err, r, c);
            }
        }
    }
    worst
}

fn check_constraint_jacobians(method: Method) {
    let t = Transcription::new(&problem(method)).unwrap();
    assert!(t.cones.traction > 0 && t.cones.nonnegative > 0);
    let mut rng = ChaCha8Rng::seed_from_u64(0x7a_c0);
    for _ in 0..3 {
        let z = random_point(&t, &mut rng);
        let (err, row, col) = worst_constraint_jacobian_error(&t, &z);
        assert!(
            err < 1e-6,
            "{method:?}: row {row} col {col} off by {err:e} of the row scale"
        );
    }
}

#[test]
fn hermite_simpson_constraint_jacobians_match_central_differences() {
    check_constraint_jacobians(Method::HermiteSimpson);
}

#[test]
fn trapezoidal_constraint_jacobians_match_central_differences() {
    check_constraint_jacobians(Method::Trapezoidal);
}

/// The defect rows are nonlinear: the check above is not vacuous (the linearisation differs
/// from the plain `+-1` pattern by `h`-scaled terms).
#[test]
fn defect_rows_carry_dynamics_terms() {
    for method in [Method::HermiteSimpson, Method::Trapezoidal] {
        let t = Transcription::new(&problem(method)).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let z = random_point(&t, &mut rng);
        let d = dense(&t, &z);
        let cols = t.variable_count();
        // The tilt-rate defect row of the last interval: its tilt and torque columns are
        // all dynamics (no identity part).
        let row = t.cones.zero - 4 + 2;
        let k = t.intervals - 1;
        assert!(d.a[row * cols + t.torque(k)].abs() > 1e-3, "{method:?}");
        assert!(d.a[row * cols + t.state(k)].abs() > 1e-3, "{method:?}");
    }
}

/// The cost `J = sum w x^2`: gradient `2 w x` and Hessian `diag(2 w)` (the QP's `P`) against
/// central differences; its weights integrate `tau^2` exactly for a constant torque.
#[test]
fn cost_gradient_and_hessian_match_central_differences() {
    for method in [Method::HermiteSimpson, Method::Trapezoidal] {
        let t = Transcription::new(&problem(method)).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let z = random_point(&t, &mut rng);
        let j0 = t.cost(&z);
        for c in 0..t.variable_count() {
            let step = 1e-4 * z[c].abs().max(1.0);
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[c] += step;
            zm[c] -= step;
            let (jp, jm) = (t.cost(&zp), t.cost(&zm));
            let grad = 2.0 * t.weights[c] * z[c];
            let hess = 2.0 * t.weights[c];
            let tol = 1e-8 * j0.max(1.0) / step;
            assert!(
                ((jp - jm) / (2.0 * step) - grad).abs() < tol,
                "{method:?} {c}"
            );
            assert!(((jp - 2.0 * j0 + jm) / (step * step) - hess).abs() < tol / step);
        }
        let ones: Vec<f64> = (0..t.variable_count())
            .map(|c| {
                let torque = (0..=t.intervals).any(|k| t.torque(k) == c)
                    || (0..t.intervals).any(|k| t.mid_torque(k) == Some(c));
                f64::from(u8::from(torque))
            })
            .collect();
        approx::assert_relative_eq!(t.cost(&ones), 0.8, max_relative = 1e-12);
    }
}

/// The normal-force margin shifts every traction row's slack by exactly `-mu N_min` (the
/// cone `|F_i| <= mu (N_i - N_min)`), and leaves every other row and the Jacobian unchanged.
#[test]
fn normal_force_margin_shifts_the_traction_rows_by_mu_times_the_margin() {
    let plain = problem(Method::HermiteSimpson);
    let margin_n = 70.0;
    let mut with = plain;
    with.limits.normal_force_margin_n = margin_n;
    let (tp, tm) = (
        Transcription::new(&plain).unwrap(),
        Transcription::new(&with).unwrap(),
    );
    assert_eq!(tp.cones, tm.cones);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let z = random_point(&tp, &mut rng);
    let (sp, sm) = (slacks(&tp, &z), slacks(&tm, &z));
    let mu = DrivetrainParams::<f64>::miapure().wheel_ball_friction;
    let first_traction = tp.cones.zero + tp.cones.nonnegative;
    assert!(tp.cones.traction > 0);
    for (row, (a, b)) in sp.iter().zip(&sm).enumerate() {
        let shift = if row >= first_traction {
            mu * margin_n
        } else {
            0.0
        };
        approx::assert_relative_eq!(a - b, shift, epsilon = 1e-9);
    }
    let (dp, dm) = (dense(&tp, &z), dense(&tm, &z));
    assert_eq!(dp.a, dm.a);
}
