//! The floor contact against solutions it does not share: a dropped ball's contact time and
//! rebound from the law's energy integral, the energy lost per load cycle from the loss
//! factor, a ball rolling and sliding down an incline from rigid-body mechanics, and the
//! terrain's geometry.

use super::*;
use crate::world::rubber::CoatingLaw;

const R: f64 = 0.1145;
const M: f64 = 3.6;
/// The ball's moment of inertia (kg m^2): MiaPURE's, 0.0472 (about 0.5 m R^2, a shell-heavy
/// bowling ball).
const I: f64 = 0.0472;
const G: f64 = 9.81;
const DT: f64 = 1.0 / 8000.0;

/// The loaded robot's weight on the floor (N): the damping's reference load.
const LOAD_N: f64 = 77.9 * G;

fn floor(params: &FloorParams, friction: f64) -> Floor {
    Floor::new(params, R, M, LOAD_N, friction)
}

/// A free ball (no body): semi-implicit Euler at 8 kHz under gravity and the floor.
struct Ball {
    state: BallState,
}

impl Ball {
    fn at(centre: DVec3) -> Self {
        Self {
            state: BallState {
                centre,
                velocity: DVec3::ZERO,
                angvel: DVec3::ZERO,
            },
        }
    }

    fn step(&mut self, floor: &mut Floor, gravity: DVec3) -> FloorOutput {
        let out = floor.step(&self.state, DT);
        let s = &mut self.state;
        s.velocity += (gravity + out.wrench.force / M) * DT;
        s.angvel += out.wrench.torque / I * DT;
        s.centre += s.velocity * DT;
        out
    }
}

/// Contact time and rebound speed of a ball dropped at `v0` onto the plane, from the law's
/// energy integral (gravity included, no damping): `t_c = 2 int_0^d_max d delta / v(delta)`
/// with `m v^2 / 2 = m v0^2 / 2 + m g delta - U(delta)`, computed here from the law's
/// coefficients (the code has no energy function of its own), with `delta = d_max (1 - u^2)` to remove the
/// turning point's singularity.
fn analytic_contact_time_secs(law: &CoatingLaw, v0: f64) -> f64 {
    let u_el = |d: f64| {
        law.hertz_n_per_m1_5 * d.powf(2.5) / 2.5 + law.thin_layer_n_per_m3 * d.powi(4) / 4.0
    };
    let excess = |d: f64| 0.5 * M * v0 * v0 + M * G * d - u_el(d);
    let (mut lo, mut hi) = (0.0, 0.05);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let d_max = 0.5 * (lo + hi);
    let n = 4000;
    let mut sum = 0.0;
    for k in 0..n {
        let u = (k as f64 + 0.5) / n as f64;
        let d = d_max * (1.0 - u * u);
        let v = (2.0 * excess(d) / M).max(1e-300).sqrt();
        sum += 2.0 * d_max * u / v / n as f64;
    }
    2.0 * sum
}

/// Drops the ball at `v0` from just above the plane; returns the contact time and the speed it
/// leaves with.
fn drop(params: &FloorParams, v0: f64) -> (f64, f64) {
    let mut f = floor(params, 0.9);
    let mut ball = Ball::at(DVec3::new(0.0, 0.0, R + 1e-9));
    ball.state.velocity = DVec3::new(0.0, 0.0, -v0);
    let mut touching = 0_u32;
    let mut started = false;
    for _ in 0..80_000 {
        let out = ball.step(&mut f, DVec3::new(0.0, 0.0, -G));
        if out.normal_n > 0.0 {
            started = true;
            touching += 1;
        } else if started {
            break;
        }
    }
    (f64::from(touching) * DT, ball.state.velocity.z)
}

#[test]
fn a_dropped_ball_stays_as_long_as_the_law_says_and_rebounds_by_its_loss_factor() {
    let elastic = FloorParams {
        coating_loss_factor: 0.0,
        ..FloorParams::miapure()
    };
    let law = floor(&elastic, 0.9).terrain.plane_law().to_owned();
    for v0 in [0.2, 0.5, 1.0] {
        let (t_c, v_out) = drop(&elastic, v0);
        let expected = analytic_contact_time_secs(&law, v0);
        println!(
            "v0 {v0}: contact {:.3} ms (analytic {:.3} ms), out {v_out:.4}",
            t_c * 1e3,
            expected * 1e3
        );
        assert!((t_c - expected).abs() < 2.0 * DT, "{t_c} {expected}");
        // No damping: the ball leaves as fast as it came (the gravity inside the contact
        // time changes nothing by symmetry).
        assert!((v_out - v0).abs() < 0.01 * v0, "{v_out}");
    }
    // With the loss factor: the rebound of the law's own equation of motion,
    // m delta'' = m g - max(0, F(delta) + c(delta) delta'), c = eta k(delta) / omega_0 with
    // omega_0 = sqrt(k(delta_0) / m) at the robot's load, solved here by RK4 at 1 us from the
    // law's coefficients.
    let params = FloorParams::miapure();
    let eta = params.coating_loss_factor;
    let k0 = 1.5 * law.hertz_n_per_m1_5 * law.deflection_m(LOAD_N).sqrt()
        + 3.0 * law.thin_layer_n_per_m3 * law.deflection_m(LOAD_N).powi(2);
    let omega_0 = (k0 / M).sqrt();
    let accel = |d: f64, v: f64| {
        let (e, k) = if d > 0.0 {
            (
                law.hertz_n_per_m1_5 * d.powf(1.5) + law.thin_layer_n_per_m3 * d.powi(3),
                1.5 * law.hertz_n_per_m1_5 * d.sqrt() + 3.0 * law.thin_layer_n_per_m3 * d * d,
            )
        } else {
            (0.0, 0.0)
        };
        G - (e + eta * k / omega_0 * v).max(0.0) / M
    };
    for v0 in [0.2, 0.5, 1.0] {
        let (_, v_out) = drop(&params, v0);
        let (mut d, mut v, h) = (0.0_f64, v0, 1e-6);
        loop {
            let (k1d, k1v) = (v, accel(d, v));
            let (k2d, k2v) = (
                v + 0.5 * h * k1v,
                accel(d + 0.5 * h * k1d, v + 0.5 * h * k1v),
            );
            let (k3d, k3v) = (
                v + 0.5 * h * k2v,
                accel(d + 0.5 * h * k2d, v + 0.5 * h * k2v),
            );
            let (k4d, k4v) = (v + h * k3v, accel(d + h * k3d, v + h * k3v));
            d += h / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            if d <= 0.0 && v < 0.0 {
                break;
            }
        }
        let (e, e_expected) = (v_out / v0, -v / v0);
        println!("v0 {v0}: restitution {e:.4} (the law's equation {e_expected:.4})");
        assert!((e - e_expected).abs() < 0.015, "{e} {e_expected}");
        assert!(e < 0.95, "{e}");
    }
}

#[test]
fn a_load_cycle_loses_pi_eta_k_amplitude_squared() {
    // Indent the plane harmonically about the static deflection at the ball's own frequency
    // on the contact under the robot's load; the normal force's work over one cycle is the
    // energy lost.
    let params = FloorParams::miapure();
    let mut f = floor(&params, 0.9);
    let law = *f.terrain.plane_law();
    let d0 = law.deflection_m(LOAD_N);
    let k = law.evaluate(d0).stiffness_n_per_m;
    let omega = (k / M).sqrt();
    let amp = 0.01 * d0;
    let period = std::f64::consts::TAU / omega;
    let n = 20_000;
    let h = period / f64::from(n);
    let mut work = 0.0;
    for i in 0..n {
        let t = (f64::from(i) + 0.5) * h;
        let delta = d0 + amp * (omega * t).sin();
        let rate = amp * omega * (omega * t).cos();
        let ball = BallState {
            centre: DVec3::new(0.0, 0.0, R - delta),
            velocity: DVec3::new(0.0, 0.0, -rate),
            angvel: DVec3::ZERO,
        };
        let out = f.step(&ball, h);
        work += out.normal_n * rate * h;
    }
    let expected = std::f64::consts::PI * params.coating_loss_factor * k * amp * amp;
    println!("lost {work:.4e} J per cycle, pi eta k A^2 = {expected:.4e} J");
    assert!(
        (work - expected).abs() < 0.01 * expected,
        "{work} {expected}"
    );
}

/// A ball released on an incline of `slope` (rad) with floor friction `mu`: its acceleration
/// along the slope after 0.5 s (m/s^2) and whether it slipped.
fn roll_down(slope: f64, mu: f64) -> (f64, f64) {
    let params = FloorParams {
        slope_rad: slope,
        slope_heading_deg: 0.0,
        ..FloorParams::miapure()
    };
    let mut f = floor(&params, mu);
    let n = params.plane_normal();
    let d0 = f.static_deflection_m(M * G * slope.cos());
    let mut ball = Ball::at(n * (R - d0));
    let down = DVec3::new(-slope.cos(), 0.0, -slope.sin());
    let gravity = DVec3::new(0.0, 0.0, -G);
    let steps = 4000;
    let mut v_half = 0.0;
    for k in 0..2 * steps {
        ball.step(&mut f, gravity);
        if k + 1 == steps {
            v_half = ball.state.velocity.dot(down);
        }
    }
    let v_end = ball.state.velocity.dot(down);
    let accel = (v_end - v_half) / (f64::from(steps) * DT);
    // Slip: the contact point's speed relative to the rolling speed.
    let slip = (ball.state.velocity + ball.state.angvel.cross(-n * R)).length();
    (accel, slip / v_end)
}

#[test]
fn a_ball_rolls_down_an_incline_at_g_sin_over_one_plus_i_over_mr2_and_slides_beyond_the_cone() {
    let slope = 0.2_f64;
    let rolling = G * slope.sin() / (1.0 + I / (M * R * R));
    let (a, slip) = roll_down(slope, 0.9);
    println!("rolling: {a:.4} m/s^2 (rigid-body {rolling:.4}), slip {slip:.2e}");
    assert!((a - rolling).abs() < 0.01 * rolling, "{a} {rolling}");
    assert!(slip < 1e-3, "{slip}");
    // It sticks while tan(slope) <= mu (1 + m R^2 / I); at mu = 0.05 it cannot (0.20 > 0.14)
    // and slides at g (sin - mu_k cos), spinning up at mu_k m g cos R / I.
    let mu = 0.05;
    let sliding = G * (slope.sin() - mu * slope.cos());
    let (a, slip) = roll_down(slope, mu);
    println!("sliding: {a:.4} m/s^2 (Coulomb {sliding:.4}), slip {slip:.2}");
    assert!((a - sliding).abs() < 0.01 * sliding, "{a} {sliding}");
    assert!(slip > 0.1, "{slip}");
}

#[test]
fn the_step_is_continuous_from_riser_over_the_edge_to_the_top() {
    let params = FloorParams::miapure();
    let mut f = floor(&params, 0.9);
    let step = FloorStep {
        edge_m: [1.0, 0.0],
        heading_deg: 0.0,
        height_m: 0.02,
        edge_radius_m: 0.005,
    };
    f.add_step(&step);
    // The ball's centre at the height that just touches the plateau, slid towards the edge:
    // the penetration of the step grows continuously.
    let z = R + 0.02 - 0.001;
    let mut last: Option<f64> = None;
    for i in 0..=400 {
        let x = 1.0 - 0.2 + 0.001 * f64::from(i);
        let p = f
            .terrain
            .patch(1, DVec3::new(x, 0.0, z), R)
            .map_or(0.0, |p| p.penetration_m);
        if let Some(l) = last {
            assert!((p - l).abs() < 1.2e-3, "jump at {x}: {l} -> {p}");
        }
        last = Some(p);
    }
    assert!((last.unwrap() - 0.001).abs() < 1e-12);
    assert!((f.height_m(1.1, 0.0) - 0.02).abs() < 1e-12);
    assert_eq!(f.height_m(0.9, 0.0), 0.0);
}

#[test]
fn a_bump_is_an_arc_of_its_chord_and_rise_standing_on_the_plane() {
    let params = FloorParams::miapure();
    let mut f = floor(&params, 0.9);
    let bump = FloorBump {
        centre_m: [0.5, 0.0],
        heading_deg: 0.0,
        height_m: 0.01,
        width_m: 0.04,
        length_m: 2.0,
    };
    f.add_bump(&bump);
    assert!((f.height_m(0.5, 0.3) - 0.01).abs() < 1e-12);
    assert!(f.height_m(0.5 + 0.0199, 0.0) > 0.0);
    assert!(f.height_m(0.5 + 0.0201, 0.0).abs() < 1e-12);
    // A ball resting on the crest: penetration R - (z - h).
    let p = f
        .terrain
        .patch(1, DVec3::new(0.5, 0.0, R + 0.01 - 0.001), R)
        .unwrap();
    assert!((p.penetration_m - 0.001).abs() < 1e-12);
    assert!((p.normal - DVec3::Z).length() < 1e-12);
    // Beyond its ends it is not there.
    assert!(f.terrain.patch(1, DVec3::new(0.5, 1.2, R), R).is_none());
}

#[test]
fn validation_names_the_field() {
    let ok = FloorParams::miapure();
    for (bad, field) in [
        (
            FloorParams {
                coating_shore_a_hardness: 95.0,
                ..ok
            },
            "floor.coating_shore_a_hardness",
        ),
        (
            FloorParams {
                coating_thickness_m: 0.0,
                ..ok
            },
            "floor.coating_thickness_m",
        ),
        (
            FloorParams {
                coating_loss_factor: f64::NAN,
                ..ok
            },
            "floor.coating_loss_factor",
        ),
        (
            FloorParams {
                kinetic_friction_ratio: 1.5,
                ..ok
            },
            "floor.kinetic_friction_ratio",
        ),
        (
            FloorParams {
                slope_rad: -0.1,
                ..ok
            },
            "floor.slope_rad",
        ),
        (
            FloorParams {
                slope_heading_deg: f64::INFINITY,
                ..ok
            },
            "floor.slope_heading_deg",
        ),
    ] {
        let err = bad.validate().unwrap_err().to_string();
        assert!(err.contains(field), "{err}");
    }
}
