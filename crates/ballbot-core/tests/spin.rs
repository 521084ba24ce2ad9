//! The spin model `I_z theta_z_ddot + D_z theta_z_dot = tau_z` (docs/model.md section 3)
//! against its closed-form solution. Before this module the model was checked only through
//! the spin LQR and the 3D controller, whose reference model is the same `Spin`: flipping the
//! sign of the damping term passed every integration test (one unit test of `ballbot.rs`
//! caught it).

#![allow(clippy::unwrap_used)]

use ballbot_core::{Spin, SpinParams, rk4_step};
use nalgebra::Vector2;

/// Unforced from `w0`: `w(t) = w0 e^{-t / tau}`, `theta(t) = w0 tau (1 - e^{-t / tau})` with
/// `tau = I_z / D_z` (1.8 s for MiaPURE with 60 kg). Under a constant torque the rate settles
/// at `tau_z / D_z`. RK4 at 1 ms has a relative error near `(dt / tau)^4 / 120 ~ 1e-15` per
/// step, so 1e-9 over 5 s leaves room for rounding only; a wrong sign or a missing `1 / I_z`
/// is off by order one.
#[test]
fn spin_model_follows_the_closed_form_first_order_decay() {
    let params = SpinParams::<f64>::miapure_60kg();
    let (inertia, damping) = (params.inertia_kg_m2, params.damping_nm_s_per_rad);
    assert_eq!((inertia, damping), (1.8, 1.0), "MODEL.md section 6");
    let spin = Spin::new(params).unwrap();
    let tau = inertia / damping;
    let dt = 1e-3;
    for (w0, torque) in [(2.0, 0.0), (-0.5, 3.0), (0.0, -1.5)] {
        let mut s = Vector2::new(0.0, w0);
        for k in 1..=5000 {
            s = rk4_step(|x| spin.derivative(x, torque), &s, dt);
            let t = f64::from(k) * dt;
            let w_inf = torque / damping;
            let decay = (-t / tau).exp();
            let rate = w_inf + (w0 - w_inf) * decay;
            let heading = w_inf * t + (w0 - w_inf) * tau * (1.0 - decay);
            assert!(
                (s[1] - rate).abs() < 1e-9 * (1.0 + rate.abs()),
                "w0 {w0}, torque {torque}, t {t}: rate {} vs {rate}",
                s[1]
            );
            assert!(
                (s[0] - heading).abs() < 1e-9 * (1.0 + heading.abs()),
                "w0 {w0}, torque {torque}, t {t}: heading {} vs {heading}",
                s[0]
            );
        }
    }
}

/// The state-space pair the spin LQR is designed on is the model itself: `A s + B tau` equals
/// `derivative(s, tau)` exactly (both linear), and the power balance
/// `d/dt (I_z w^2 / 2) = tau w - D_z w^2` holds.
#[test]
fn spin_state_space_is_the_model_and_its_power_balances() {
    for params in [
        SpinParams::<f64>::miapure_60kg(),
        SpinParams::miapure_unloaded(),
    ] {
        let spin = Spin::new(params).unwrap();
        let (a, b) = spin.state_space();
        for (s, torque) in [
            (Vector2::new(0.3, -2.0), 5.0),
            (Vector2::new(-4.0, 0.7), -12.0),
            (Vector2::new(0.0, 0.0), 1.0),
        ] {
            let d = spin.derivative(&s, torque);
            assert!((a * s + b * torque - d).amax() < 1e-12, "{s} {torque}");
            let power = params.inertia_kg_m2 * s[1] * d[1];
            let expected = torque * s[1] - params.damping_nm_s_per_rad * s[1] * s[1];
            assert!((power - expected).abs() < 1e-12 * (1.0 + expected.abs()));
        }
    }
}
