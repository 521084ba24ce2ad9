//! Property tests of the omniwheel kinematics over random states and random valid geometries
//! (contact angle, wheel azimuths, ball and wheel radii, gear ratio), in f64 and f32.

use ballbot_core::kinematics::relative_rate_from_planar;
use ballbot_core::{DrivetrainParams, OmniKinematics};
use nalgebra::{RealField, Vector3};
use proptest::prelude::*;

/// A random drivetrain geometry, as f64 (converted for the f32 runs).
#[derive(Clone, Copy, Debug)]
struct Geometry {
    contact_angle_deg: f64,
    azimuths_deg: [f64; 3],
    ball_radius_m: f64,
    wheel_radius_m: f64,
    gear_ratio: f64,
}

impl Geometry {
    /// How far the layout is from singular: `|sin(b2-b1) + sin(b3-b2) + sin(b1-b3)|`, 2.6 for
    /// the symmetric layout, 0 when two wheels share an azimuth.
    fn azimuthal_factor(&self) -> f64 {
        let [b1, b2, b3] = self.azimuths_deg.map(f64::to_radians);
        ((b2 - b1).sin() + (b3 - b2).sin() + (b1 - b3).sin()).abs()
    }

    fn kinematics<T: RealField + Copy>(&self) -> Result<OmniKinematics<T>, TestCaseError> {
        let c = |x: f64| -> T { nalgebra::convert(x) };
        let mut d = DrivetrainParams::<T>::miapure();
        d.contact_angle_rad = c(self.contact_angle_deg.to_radians());
        d.wheel_azimuths_rad = self.azimuths_deg.map(|b| c(b.to_radians()));
        d.wheel_radius_m = c(self.wheel_radius_m);
        d.actuator.gear_ratio = c(self.gear_ratio);
        OmniKinematics::new(d, c(self.ball_radius_m))
            .map_err(|e| TestCaseError::fail(format!("valid geometry {self:?} rejected: {e}")))
    }
}

fn geometry() -> impl Strategy<Value = Geometry> {
    (
        5.0..85.0f64,
        [0.0..360.0f64, 0.0..360.0f64, 0.0..360.0f64],
        0.05..0.5f64,
        0.02..0.2f64,
        1.0..50.0f64,
    )
        .prop_map(|(a, az, rs, rw, g)| Geometry {
            contact_angle_deg: a,
            azimuths_deg: az,
            ball_radius_m: rs,
            wheel_radius_m: rw,
            gear_ratio: g,
        })
        .prop_filter("layout too close to singular", |g| {
            g.azimuthal_factor() > 0.3
        })
}

fn vec3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    [-range..range, -range..range, -range..range].prop_map(Vector3::from)
}

fn to<T: RealField + Copy>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(nalgebra::convert)
}

/// `|a - b| <= tol * scale` component-wise, as f64.
fn close<T: RealField + Copy>(a: &Vector3<T>, b: &Vector3<T>, tol: f64, scale: f64) -> bool {
    let diff: Vector3<f64> = (a - b).map(|x| nalgebra::try_convert(x).unwrap_or(f64::NAN));
    diff.amax() <= tol * scale.max(1.0)
}

fn norm(v: &Vector3<f64>) -> f64 {
    v.norm()
}

/// inverse(forward(x)) = x for speeds, motor speeds, torques and motor torques, both ways.
fn round_trips<T: RealField + Copy>(
    g: &Geometry,
    rate: &Vector3<f64>,
    planar: &Vector3<f64>,
    tol: f64,
) -> Result<(), TestCaseError> {
    let kin = g.kinematics::<T>()?;
    let (rate_t, planar_t) = (to::<T>(rate), to::<T>(planar));

    let psi = kin.wheel_speeds_rad_per_s(&rate_t);
    let back = kin.relative_rate_rad_per_s(&psi);
    prop_assert!(close(&back, &rate_t, tol, norm(rate)), "{back} vs {rate}");
    let psi_back = kin.wheel_speeds_rad_per_s(&kin.relative_rate_rad_per_s(&psi));
    let psi_scale = psi.map(|x| nalgebra::try_convert(x).unwrap_or(0.0)).norm();
    prop_assert!(close(&psi_back, &psi, tol, psi_scale));

    let rotor = kin.motor_speeds_rad_per_s(&rate_t);
    let back = kin.relative_rate_from_motor_speeds_rad_per_s(&rotor);
    prop_assert!(close(&back, &rate_t, tol, norm(rate)));

    let wheel = kin.wheel_torques_nm(&planar_t);
    let back = kin.planar_torque_nm(&wheel);
    prop_assert!(
        close(&back, &planar_t, tol, norm(planar)),
        "{back} vs {planar}"
    );

    let motor = kin.motor_torques_nm(&planar_t);
    let back = kin.planar_torque_from_motor_torques_nm(&motor);
    prop_assert!(close(&back, &planar_t, tol, norm(planar)));
    Ok(())
}

/// sum_i tau_i psi_dot_i = tau_x omega_x + tau_y omega_y - tau_z omega_z, at the omniwheels
/// and at the rotors.
fn power_balance<T: RealField + Copy>(
    g: &Geometry,
    rate: &Vector3<f64>,
    planar: &Vector3<f64>,
    tol: f64,
) -> Result<(), TestCaseError> {
    let kin = g.kinematics::<T>()?;
    let (rate_t, planar_t) = (to::<T>(rate), to::<T>(planar));
    let expected = planar[0] * rate[0] + planar[1] * rate[1] - planar[2] * rate[2];
    let scale = norm(planar) * norm(rate);
    let as_f64 = |x: T| nalgebra::try_convert::<T, f64>(x).unwrap_or(f64::NAN);

    let wheel_power = as_f64(
        kin.wheel_torques_nm(&planar_t)
            .dot(&kin.wheel_speeds_rad_per_s(&rate_t)),
    );
    prop_assert!(
        (wheel_power - expected).abs() <= tol * scale.max(1.0),
        "wheel power {wheel_power} vs planar {expected}"
    );
    let rotor_power = as_f64(
        kin.motor_torques_nm(&planar_t)
            .dot(&kin.motor_speeds_rad_per_s(&rate_t)),
    );
    prop_assert!((rotor_power - expected).abs() <= tol * scale.max(1.0));
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn round_trips_f64(g in geometry(), rate in vec3(50.0), planar in vec3(300.0)) {
        round_trips::<f64>(&g, &rate, &planar, 1e-10)?;
    }

    #[test]
    fn round_trips_f32(g in geometry(), rate in vec3(50.0), planar in vec3(300.0)) {
        round_trips::<f32>(&g, &rate, &planar, 1e-3)?;
    }

    #[test]
    fn power_balance_f64(g in geometry(), rate in vec3(50.0), planar in vec3(300.0)) {
        power_balance::<f64>(&g, &rate, &planar, 1e-10)?;
    }

    #[test]
    fn power_balance_f32(g in geometry(), rate in vec3(50.0), planar in vec3(300.0)) {
        power_balance::<f32>(&g, &rate, &planar, 1e-3)?;
    }

    /// For every geometry: a rate with only a ball roll about the axis perpendicular to wheel
    /// `i`'s rolling plane leaves wheel `i` idle (generalises "sagittal travel leaves OW1 idle").
    #[test]
    fn roll_along_a_wheel_axle_plane_leaves_it_idle(g in geometry(), speed in -50.0..50.0f64) {
        let kin = g.kinematics::<f64>()?;
        for (i, w) in kin.wheels().iter().enumerate() {
            // Horizontal ball rate along the wheel's rolling direction d_i: u_i . d_i = 0.
            let d = w.rolling_direction;
            let rate = relative_rate_from_planar([d[0] * speed, d[1] * speed], [0.0; 2], 0.0);
            let psi = kin.wheel_speeds_rad_per_s(&rate);
            prop_assert!(psi[i].abs() <= 1e-10 * speed.abs().max(1.0), "wheel {i}: {psi}");
        }
    }

    /// Contact forces on the body add up to the support force for any geometry and load.
    #[test]
    fn contact_forces_balance(g in geometry(), support in vec3(2000.0), planar in vec3(300.0)) {
        let kin = g.kinematics::<f64>()?;
        let wheel = kin.wheel_torques_nm(&planar);
        let contacts = kin.contact_forces(&support, &wheel);
        let mut force = Vector3::zeros();
        for (w, c) in kin.wheels().iter().zip(contacts.wheels.iter()) {
            force += w.contact_normal * c.normal_force_n - w.rolling_direction * c.traction_n;
            prop_assert_eq!(c.lifted_off, c.normal_force_n <= 0.0);
        }
        let scale = norm(&support) + wheel.norm() / g.wheel_radius_m;
        prop_assert!((force - support).amax() <= 1e-9 * scale.max(1.0), "{force} vs {support}");
    }

    /// Saturation keeps direction, never exceeds the peak, and leaves feasible requests alone.
    #[test]
    fn saturation_respects_the_peak(g in geometry(), planar in vec3(1000.0)) {
        let kin = g.kinematics::<f64>()?;
        let peak = kin.drivetrain().actuator.peak_torque_nm;
        let out = kin.saturate_planar_torque(&planar);
        prop_assert!((0.0..=1.0).contains(&out.scale));
        prop_assert!(out.wheel_torques_nm.amax() <= peak * (1.0 + 1e-12));
        prop_assert!((out.planar_torque_nm - planar * out.scale).amax() <= 1e-9 * norm(&planar));
        let needed = kin.wheel_torques_nm(&planar).amax();
        if needed <= peak {
            prop_assert_eq!(out.scale, 1.0);
        } else {
            prop_assert!((out.wheel_torques_nm.amax() - peak).abs() <= 1e-9 * peak);
        }
    }
}
