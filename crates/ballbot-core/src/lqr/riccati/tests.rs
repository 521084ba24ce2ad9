//! Unit tests of the Riccati solvers.
#![allow(non_snake_case)]

use super::solve::{continuous_lyapunov_stable, discrete_lyapunov_stable};
use super::*;
use crate::Error;
use crate::linalg::is_schur_stable;
use approx::assert_relative_eq;
use nalgebra::{Matrix1, Matrix2, Vector2};

fn settings() -> RiccatiSettings<f64> {
    RiccatiSettings::default()
}

#[test]
fn settings_are_validated() {
    assert!(settings().validate().is_ok());
    for tolerance in [0.0, -1.0, f64::NAN] {
        let s = RiccatiSettings {
            tolerance,
            ..settings()
        };
        assert_eq!(
            s.validate(),
            Err(Error::invalid("tolerance", "must be finite and > 0"))
        );
    }
    let s = RiccatiSettings {
        max_iterations: 0,
        ..settings()
    };
    assert!(matches!(
        s.validate(),
        Err(Error::InvalidParameter {
            field: "max_iterations",
            ..
        })
    ));
}

#[test]
fn malformed_input_names_the_argument() {
    let a = Matrix2::new(1.0, 0.1, 0.0, 1.0);
    let b = Vector2::new(0.0, 0.1);
    let q = Matrix2::identity();
    let r = Matrix1::new(1.0);
    let field = |res: Result<RiccatiSolution<f64, 2, 1>, Error>| match res {
        Err(Error::InvalidParameter { field, .. }) => field,
        other => panic!("expected an error, got {other:?}"),
    };
    let nan_a = Matrix2::new(f64::NAN, 0.0, 0.0, 1.0);
    assert_eq!(field(solve_dare(&nan_a, &b, &q, &r, &settings())), "a");
    assert_eq!(field(solve_care(&nan_a, &b, &q, &r, &settings())), "a");
    let inf_b = Vector2::new(f64::INFINITY, 0.0);
    assert_eq!(field(solve_dare(&a, &inf_b, &q, &r, &settings())), "b");
    let bad_q = Matrix2::new(1.0, 0.5, 0.0, 1.0);
    assert_eq!(field(solve_dare(&a, &b, &bad_q, &r, &settings())), "q");
    assert_eq!(
        field(solve_dare(&a, &b, &q, &Matrix1::new(0.0), &settings())),
        "r"
    );
    assert_eq!(
        field(solve_care(&a, &b, &q, &Matrix1::new(-1.0), &settings())),
        "r"
    );
}

#[test]
fn weights_validation() {
    let r2 = Matrix2::new(1.0, 0.2, 0.2, 1.0);
    assert!(validate_weights(&Matrix2::<f64>::zeros(), &r2).is_ok());
    assert!(validate_weights(&Matrix2::new(1.0, 1.0, 1.0, 1.0), &r2).is_ok());
    assert_eq!(
        validate_weights(&Matrix2::new(1.0, 2.0, 2.0, 1.0), &r2),
        Err(Error::invalid("q", "must be positive semidefinite"))
    );
    assert_eq!(
        validate_weights(
            &Matrix2::<f64>::identity(),
            &Matrix2::new(1.0, 0.0, 0.5, 1.0)
        ),
        Err(Error::invalid("r", "must be symmetric"))
    );
    assert_eq!(
        validate_weights(
            &Matrix2::<f64>::identity(),
            &Matrix2::new(1.0, 0.0, 0.0, 0.0)
        ),
        Err(Error::invalid("r", "must be positive definite"))
    );
}

#[test]
fn zero_weight_on_a_stable_plant_gives_zero_gain() {
    let a = Matrix2::new(0.5, 0.1, 0.0, -0.3);
    let b = Vector2::new(0.0, 1.0);
    let sol = solve_dare(&a, &b, &Matrix2::zeros(), &Matrix1::new(1.0), &settings()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    assert_eq!(sol.x, Matrix2::zeros());
    assert_eq!(sol.gain, nalgebra::RowVector2::zeros());
}

#[test]
fn singular_but_detectable_q_uses_the_fallback_certificate() {
    // Double integrator weighting position only: X is positive definite but
    // Q + K^T R K may be singular; either certificate must accept the stable loop.
    let a = Matrix2::new(1.0, 0.1, 0.0, 1.0);
    let b = Vector2::new(0.005, 0.1);
    let q = Matrix2::new(1.0, 0.0, 0.0, 0.0);
    let sol = solve_dare(&a, &b, &q, &Matrix1::new(1.0), &settings()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    assert!(sol.residual < 1e-12);
    assert!(is_schur_stable(&(a - b * sol.gain)));
}

#[test]
fn lyapunov_certificates_accept_stable_and_reject_unstable() {
    let x = Matrix2::new(2.0, 0.3, 0.3, 1.0);
    assert!(discrete_lyapunov_stable(
        &Matrix2::new(0.5, 0.1, 0.0, 0.4),
        &x
    ));
    assert!(!discrete_lyapunov_stable(
        &Matrix2::new(1.1, 0.0, 0.0, 0.4),
        &x
    ));
    assert!(continuous_lyapunov_stable(
        &Matrix2::new(-1.0, 0.5, 0.0, -2.0),
        &x
    ));
    assert!(!continuous_lyapunov_stable(
        &Matrix2::new(0.1, 0.0, 0.0, -2.0),
        &x
    ));
    // An indefinite X cannot certify, the fallback decides.
    let bad_x = Matrix2::new(1.0, 0.0, 0.0, -1.0);
    assert!(discrete_lyapunov_stable(
        &Matrix2::new(0.5, 0.0, 0.0, 0.4),
        &bad_x
    ));
    assert!(!discrete_lyapunov_stable(
        &Matrix2::new(1.5, 0.0, 0.0, 0.4),
        &bad_x
    ));
}

#[test]
fn two_input_dare_matches_textbook_gain() {
    let a = Matrix2::new(1.1, 0.2, -0.1, 0.9);
    let b = Matrix2::new(1.0, 0.0, 0.3, 0.5);
    let q = Matrix2::new(2.0, 0.5, 0.5, 1.0);
    let r = Matrix2::new(1.0, 0.1, 0.1, 0.5);
    let sol = solve_dare(&a, &b, &q, &r, &settings()).unwrap();
    assert_eq!(sol.status, RiccatiStatus::Converged);
    let x = sol.x;
    let k = (r + b.transpose() * x * b).try_inverse().unwrap() * b.transpose() * x * a;
    assert_relative_eq!(sol.gain, k, max_relative = 1e-12);
    let res = a.transpose() * x * a - x - a.transpose() * x * b * k + q;
    assert!(res.norm() < 1e-12 * x.norm());
}

#[test]
fn status_display_and_predicates() {
    assert!(RiccatiStatus::Converged.is_converged());
    for s in [
        RiccatiStatus::MaxIterations,
        RiccatiStatus::NotStabilizable,
        RiccatiStatus::NonFinite,
    ] {
        assert!(!s.is_converged());
        let mut buf = [0u8; 96];
        let mut w = Buf(&mut buf, 0);
        core::fmt::Write::write_fmt(&mut w, format_args!("{s}")).unwrap();
        assert!(w.1 > 5);
    }
}

/// A fixed-size `fmt::Write` sink (no allocation in this crate's unit tests).
struct Buf<'a>(&'a mut [u8], usize);

impl core::fmt::Write for Buf<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.1 + s.len();
        self.0
            .get_mut(self.1..end)
            .ok_or(core::fmt::Error)?
            .copy_from_slice(s.as_bytes());
        self.1 = end;
        Ok(())
    }
}
