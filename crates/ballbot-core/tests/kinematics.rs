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
    fn contact_forces_balance_f64(g in geometry(), support in vec3(2000.0), planar in vec3(300.0)) {
        contact_forces_balance::<f64>(&g, &support, &planar, 1e-9)?;
    }

    #[test]
    fn contact_forces_balance_f32(g in geometry(), support in vec3(2000.0), planar in vec3(300.0)) {
        contact_forces_balance::<f32>(&g, &support, &planar, 1e-4)?;
    }

    /// Saturation keeps direction, never exceeds the peak, and leaves feasible requests alone.
    #[test]
    fn saturation_respects_the_peak_f64(g in geometry(), planar in vec3(1000.0)) {
        saturation_respects_the_peak::<f64>(&g, &planar, 1e-9)?;
    }

    #[test]
    fn saturation_respects_the_peak_f32(g in geometry(), planar in vec3(1000.0)) {
        saturation_respects_the_peak::<f32>(&g, &planar, 1e-4)?;
    }
}

fn f64_of<T: RealField + Copy>(x: T) -> f64 {
    nalgebra::try_convert(x).unwrap_or(f64::NAN)
}

fn contact_forces_balance<T: RealField + Copy>(
    g: &Geometry,
    support: &Vector3<f64>,
    planar: &Vector3<f64>,
    tol: f64,
) -> Result<(), TestCaseError> {
    let kin = g.kinematics::<T>()?;
    let wheel = kin.wheel_torques_nm(&to::<T>(planar));
    let contacts = kin.contact_forces(&to::<T>(support), &wheel);
    let mut force = Vector3::<T>::zeros();
    for (w, c) in kin.wheels().iter().zip(contacts.wheels.iter()) {
        force += w.contact_normal * c.normal_force_n - w.rolling_direction * c.traction_n;
        prop_assert_eq!(c.lifted_off, c.normal_force_n <= T::zero());
        prop_assert_eq!(c.lifted_off, c.friction_utilisation == infinity::<T>());
    }
    let scale = norm(support) + wheel.map(f64_of).norm() / g.wheel_radius_m;
    prop_assert!(
        close(&force, &to::<T>(support), tol, scale),
        "{force} vs {support}"
    );
    Ok(())
}

fn infinity<T: RealField + Copy>() -> T {
    nalgebra::convert(f64::INFINITY)
}

fn saturation_respects_the_peak<T: RealField + Copy>(
    g: &Geometry,
    planar: &Vector3<f64>,
    tol: f64,
) -> Result<(), TestCaseError> {
    let kin = g.kinematics::<T>()?;
    let peak = f64_of(kin.drivetrain().actuator.peak_torque_nm);
    let out = kin.saturate_planar_torque(&to::<T>(planar));
    let scale = f64_of(out.scale);
    let applied = f64_of(out.wheel_torques_nm.amax());
    prop_assert!((0.0..=1.0).contains(&scale));
    prop_assert!(applied <= peak * (1.0 + tol));
    prop_assert!(close(
        &out.planar_torque_nm,
        &(to::<T>(planar) * out.scale),
        tol,
        norm(planar)
    ));
    let needed = f64_of(kin.wheel_torques_nm(&to::<T>(planar)).amax());
    if needed <= peak {
        prop_assert_eq!(scale, 1.0);
    } else {
        prop_assert!((applied - peak).abs() <= tol * peak, "{applied} vs {peak}");
    }
    Ok(())
}

// ---- planar WIP motion at a heading ---------------------------------------------------------

#[cfg(test)] // clippy: test helpers may unwrap
mod heading {
    use ballbot_core::kinematics::{
        decoupled_support_force_n, planar_support_force_n, planar_torque_at_heading,
        relative_rate_at_heading, support_force_in_body_n,
    };
    use ballbot_core::wip::{BALL_ANGLE, TILT};
    use ballbot_core::{BallbotParams, OmniKinematics, Wip, WipState};
    use nalgebra::{Vector3, Vector4};
    use proptest::prelude::*;

    fn miapure() -> (OmniKinematics<f64>, Wip<f64>) {
        let params = BallbotParams::<f64>::miapure_60kg();
        (
            OmniKinematics::from_ballbot(&params).unwrap(),
            Wip::new(params.sagittal).unwrap(),
        )
    }

    /// The torque that holds the lean constant (`theta_ddot = 0`) at tilt `tilt_rad`: the WIP
    /// accelerates steadily. `theta_ddot` is affine in the torque.
    fn steady_lean(wip: &Wip<f64>, tilt_rad: f64) -> (WipState<f64>, f64) {
        let s = Vector4::new(tilt_rad, 0.0, 0.0, 0.0);
        let at0 = wip.accelerations(&s, 0.0)[0];
        let slope = wip.accelerations(&s, 1.0)[0] - at0;
        (s, -at0 / slope)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// The motors' power at the wheels equals the WIP's input power for a motion at any
        /// heading.
        #[test]
        fn heading_power_matches_the_wip(
            heading in -7.0..7.0f64, tilt_rate in -3.0..3.0f64, ball_rate in -20.0..20.0f64,
            torque in -80.0..80.0f64,
        ) {
            let (kin, wip) = miapure();
            let s = Vector4::new(0.0, 0.0, tilt_rate, ball_rate);
            let power = kin.wheel_torques_nm(&planar_torque_at_heading(heading, torque))
                .dot(&kin.wheel_speeds_rad_per_s(&relative_rate_at_heading(heading, ball_rate, tilt_rate)));
            let expected = wip.input_power_w(&s, torque);
            prop_assert!((power - expected).abs() <= 1e-9 * expected.abs().max(1.0));
        }

        /// The contact forces of a WIP motion turn the upper body exactly as the WIP's own
        /// body equation says: their moment about the COM is `I_U theta_ddot` about the plane
        /// axis, nothing about the others (also with reflected wheel inertia and drivetrain
        /// friction).
        #[test]
        fn wip_contact_forces_turn_the_body_as_the_wip(
            heading in -7.0..7.0f64, tilt in -0.4..0.4f64, tilt_rate in -3.0..3.0f64,
            ball_rate in -20.0..20.0f64, torque in -80.0..80.0f64,
            wheel_inertia in 0.0..0.3f64, drive_damping in 0.0..2.0f64,
        ) {
            let mut params = BallbotParams::<f64>::miapure_60kg();
            params.sagittal.wheel_inertia_kg_m2 = wheel_inertia;
            params.sagittal.drive_damping_nm_s_per_rad = drive_damping;
            let kin = OmniKinematics::from_ballbot(&params).unwrap();
            let wip = Wip::new(params.sagittal).unwrap();
            let s = Vector4::new(tilt, 0.0, tilt_rate, ball_rate);
            let contacts = kin.wip_contact_forces(&wip, heading, &s, torque);
            let com = Vector3::z() * params.sagittal.com_height_m;
            let mut moment = Vector3::zeros();
            for (w, c) in kin.wheels().iter().zip(contacts.wheels.iter()) {
                let f = w.contact_normal * c.normal_force_n - w.rolling_direction * c.traction_n;
                moment += (w.contact_point_m - com).cross(&f);
            }
            let tilt_acc = wip.accelerations(&s, torque)[0];
            let axis = Vector3::new(-heading.sin(), heading.cos(), 0.0);
            let expected = axis * (params.sagittal.body_inertia_kg_m2 * tilt_acc);
            prop_assert!((moment - expected).amax() <= 1e-9 * (1.0 + expected.norm() + torque.abs()),
                "{moment} vs {expected}");
        }
    }

    /// The support force is Newton's law for the COM: compare with the COM acceleration
    /// differentiated numerically along an RK4 trajectory of the WIP.
    #[test]
    fn support_force_matches_com_acceleration_along_a_trajectory() {
        let (_, wip) = miapure();
        let p = *wip.params();
        let torque = 25.0;
        let dt = 1e-4;
        let mut s = Vector4::new(0.15, 0.0, -0.8, 4.0);
        let com = |s: &WipState<f64>| {
            Vector3::new(
                p.ball_radius_m * s[BALL_ANGLE] + p.com_height_m * s[TILT].sin(),
                0.0,
                p.com_height_m * s[TILT].cos(),
            )
        };
        for _ in 0..2000 {
            s = ballbot_core::rk4_step(|x| wip.derivative(x, torque), &s, dt);
        }
        let prev = ballbot_core::rk4_step(|x| wip.derivative(x, torque), &s, -dt);
        let next = ballbot_core::rk4_step(|x| wip.derivative(x, torque), &s, dt);
        let acc_world = (com(&next) - com(&s) * 2.0 + com(&prev)) / (dt * dt);
        let force_world = (acc_world + Vector3::z() * p.gravity_m_per_s2) * p.body_mass_kg;
        // Into the body frame, leaning by theta about +y.
        let (st, ct) = s[TILT].sin_cos();
        let force_body = Vector3::new(
            force_world[0] * ct - force_world[2] * st,
            0.0,
            force_world[0] * st + force_world[2] * ct,
        );
        let ours = planar_support_force_n(&p, 0.0, &s, &wip.accelerations(&s, torque));
        assert!(
            (ours - force_body).amax() < 1e-3 * force_body.norm(),
            "{ours} vs {force_body}"
        );
    }

    /// MODEL.md section 5 / the paper's section V: accelerating towards OW1 (heading 0)
    /// unloads OW2 and OW3, the two wheels that must drive, so they reach their friction cone
    /// first; accelerating away from OW1 (heading 180 deg) loads them.
    #[test]
    fn accelerating_towards_wheel_1_unloads_the_driving_wheels() {
        let (kin, wip) = miapure();
        let (s, torque) = steady_lean(&wip, 5f64.to_radians());
        assert!(torque > 0.0 && wip.accelerations(&s, torque)[1] > 0.0);
        let static_n = 74.3 * 9.81 / (3.0 * 45f64.to_radians().cos());
        let towards = kin.wip_contact_forces(&wip, 0.0, &s, torque);
        let away = kin.wip_contact_forces(&wip, core::f64::consts::PI, &s, torque);
        for i in [1, 2] {
            assert!(towards.wheels[i].normal_force_n < static_n - 10.0);
            assert!(away.wheels[i].normal_force_n > static_n + 10.0);
            assert!(towards.wheels[i].friction_utilisation > away.wheels[i].friction_utilisation);
        }
        // Wheel 1 only carries load (no traction: it is idle in sagittal travel).
        assert!(towards.wheels[0].traction_n.abs() < 1e-9);
        assert!(towards.max_friction_utilisation() > away.max_friction_utilisation());
    }

    /// The steady lean (and ball acceleration) at which the first contact fails (slip or
    /// lift-off), scanning in 0.05 deg steps up to 30 deg.
    fn first_contact_failure(
        kin: &OmniKinematics<f64>,
        wip: &Wip<f64>,
        heading_deg: f64,
    ) -> Option<(f64, f64)> {
        (0..600).find_map(|k| {
            let tilt_deg = f64::from(k) * 0.05;
            let (s, torque) = steady_lean(wip, tilt_deg.to_radians());
            let contacts = kin.wip_contact_forces(wip, heading_deg.to_radians(), &s, torque);
            let accel = wip.accelerations(&s, torque)[1] * wip.params().ball_radius_m;
            (!contacts.all_hold()).then_some((tilt_deg, accel))
        })
    }

    /// The paper's trend (Sec. V: slowest towards OW1, fastest away from it, 90 deg in
    /// between), seen through the friction cones: the steady acceleration at which the first
    /// omniwheel contact fails orders the headings 0 < 90 < 180 deg. MiaPURE 60 kg, mu = 0.6:
    /// 2.25 m/s^2 (16.2 deg lean; OW2 and OW3 slip) at 0 deg, 2.48 m/s^2 (17.7 deg; OW3
    /// slips) at 90 deg, 4.07 m/s^2 (28.1 deg; OW1 lifts off) at 180 deg.
    #[test]
    fn contact_failure_orders_headings_as_the_paper() {
        let (kin, wip) = miapure();
        let at_0 = first_contact_failure(&kin, &wip, 0.0).unwrap();
        let at_90 = first_contact_failure(&kin, &wip, 90.0).unwrap();
        let at_180 = first_contact_failure(&kin, &wip, 180.0).unwrap();
        assert!((at_0.1 - 2.25).abs() < 0.01, "{at_0:?}");
        assert!((at_90.1 - 2.48).abs() < 0.01, "{at_90:?}");
        assert!((at_180.1 - 4.07).abs() < 0.01, "{at_180:?}");
    }

    /// Whether every wheel torque is within the actuator's speed-dependent bounds.
    fn within_actuator_limits(
        kin: &OmniKinematics<f64>,
        heading: f64,
        s: &WipState<f64>,
        torque: f64,
    ) -> bool {
        let wheel = kin.wheel_torques_nm(&planar_torque_at_heading(heading, torque));
        let speeds = kin.wheel_speeds_rad_per_s(&relative_rate_at_heading(heading, s[3], s[2]));
        wheel.iter().zip(speeds.iter()).all(|(&t, &w)| {
            let (lo, hi) = kin.drivetrain().actuator.torque_bounds_nm(w);
            lo <= t && t <= hi
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Inside the contact interval every contact holds; just outside a finite end one
        /// fails.
        #[test]
        fn contact_interval_is_exact(
            heading in -7.0..7.0f64, tilt in -0.4..0.4f64, tilt_rate in -3.0..3.0f64,
            ball_rate in -20.0..20.0f64,
        ) {
            let (kin, wip) = miapure();
            let s = Vector4::new(tilt, 0.0, tilt_rate, ball_rate);
            let Some(range) = kin.wip_contact_torque_interval_nm(&wip, heading, &s) else {
                // Then no torque in a wide range works either.
                for k in -50..=50 {
                    let c = kin.wip_contact_forces(&wip, heading, &s, f64::from(k) * 10.0);
                    prop_assert!(!c.all_hold());
                }
                return Ok(());
            };
            prop_assert!(range.min_nm <= range.max_nm);
            let mid = range.clamp(0.5 * (range.min_nm.max(-1e4) + range.max_nm.min(1e4)));
            prop_assert!(kin.wip_contact_forces(&wip, heading, &s, mid).all_hold());
            for (end, outward) in [(range.max_nm, 1.0), (range.min_nm, -1.0)] {
                if end.is_finite() {
                    let eps = 1e-6 * (1.0 + end.abs());
                    let inside = kin.wip_contact_forces(&wip, heading, &s, end - outward * eps);
                    let outside = kin.wip_contact_forces(&wip, heading, &s, end + outward * eps);
                    prop_assert!(inside.all_hold(), "inside {end}: {inside:?}");
                    prop_assert!(!outside.all_hold(), "outside {end}: {outside:?}");
                }
            }
        }

        /// Inside the actuator interval every wheel is within its bounds; just outside one is
        /// not.
        #[test]
        fn actuator_interval_is_exact(
            heading in -7.0..7.0f64, tilt_rate in -3.0..3.0f64, ball_rate in -60.0..60.0f64,
        ) {
            let (kin, _) = miapure();
            let s = Vector4::new(0.0, 0.0, tilt_rate, ball_rate);
            let range = kin.wip_actuator_torque_interval_nm(heading, &s);
            prop_assert!(range.contains(0.0));
            for (end, outward) in [(range.max_nm, 1.0), (range.min_nm, -1.0)] {
                prop_assert!(end.is_finite());
                let eps = 1e-6 * (1.0 + end.abs());
                prop_assert!(within_actuator_limits(&kin, heading, &s, end - outward * eps));
                if end != 0.0 {
                    prop_assert!(!within_actuator_limits(&kin, heading, &s, end + outward * eps));
                }
            }
        }
    }

    /// At rest upright, the contacts allow less torque towards OW1 than away from it, and
    /// heading 180 deg mirrors heading 0. MiaPURE 60 kg, mu = 0.6: [-20.9, 17.1] N m at
    /// heading 0, against an actuator range of +-96.9 N m: friction, not the motors, limits
    /// the torque.
    #[test]
    fn contact_interval_at_rest_is_asymmetric_towards_wheel_1() {
        let (kin, wip) = miapure();
        let upright = Vector4::zeros();
        let towards = kin
            .wip_contact_torque_interval_nm(&wip, 0.0, &upright)
            .unwrap();
        let away = kin
            .wip_contact_torque_interval_nm(&wip, core::f64::consts::PI, &upright)
            .unwrap();
        assert!(
            towards.max_nm > 0.0 && towards.max_nm < -towards.min_nm,
            "{towards:?}"
        );
        assert!(
            (towards.max_nm + away.min_nm).abs() < 1e-9,
            "{towards:?} {away:?}"
        );
        assert!(
            (towards.min_nm + away.max_nm).abs() < 1e-9,
            "{towards:?} {away:?}"
        );
        let actuator = kin.wip_actuator_torque_interval_nm(0.0, &upright);
        assert!((actuator.max_nm - 96.9).abs() < 0.05, "{actuator:?}");
        assert!((towards.min_nm + 20.92).abs() < 0.01, "{towards:?}");
        assert!((towards.max_nm - 17.10).abs() < 0.01, "{towards:?}");
    }

    fn assert_same_contacts(
        a: &ballbot_core::ContactForces<f64>,
        b: &ballbot_core::ContactForces<f64>,
    ) -> Result<(), TestCaseError> {
        for (x, y) in a.wheels.iter().zip(b.wheels.iter()) {
            let scale = 1.0 + x.normal_force_n.abs() + x.traction_n.abs();
            prop_assert!(
                (x.normal_force_n - y.normal_force_n).abs() <= 1e-9 * scale,
                "{a:?} vs {b:?}"
            );
            prop_assert!(
                (x.traction_n - y.traction_n).abs() <= 1e-9 * scale,
                "{a:?} vs {b:?}"
            );
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// The decoupled 3D model with one plane upright and still reduces to the planar WIP
        /// at heading 0 (sagittal) or -90 deg (frontal).
        #[test]
        fn decoupled_model_reduces_to_one_plane(
            tilt in -0.4..0.4f64, tilt_rate in -3.0..3.0f64, ball_rate in -20.0..20.0f64,
            torque in -80.0..80.0f64, wheel_inertia in 0.0..0.3f64,
        ) {
            let mut params = BallbotParams::<f64>::miapure_60kg();
            params.sagittal.wheel_inertia_kg_m2 = wheel_inertia;
            params.frontal.wheel_inertia_kg_m2 = wheel_inertia;
            let kin = OmniKinematics::from_ballbot(&params).unwrap();
            let wip = Wip::new(params.sagittal).unwrap();
            let moving = Vector4::new(tilt, 0.3, tilt_rate, ball_rate);
            let still = Vector4::zeros();
            let sagittal_only = kin.decoupled_contact_forces(
                (&wip, &moving), (&wip, &still), &Vector3::new(0.0, torque, 0.0));
            assert_same_contacts(&sagittal_only, &kin.wip_contact_forces(&wip, 0.0, &moving, torque))?;
            let frontal_only = kin.decoupled_contact_forces(
                (&wip, &still), (&wip, &moving), &Vector3::new(torque, 0.0, 0.0));
            let heading = -core::f64::consts::FRAC_PI_2;
            assert_same_contacts(&frontal_only, &kin.wip_contact_forces(&wip, heading, &moving, torque))?;
        }

        /// With no motion the decoupled support force is the weight seen from the tilted
        /// body (ZYX attitude, roll = theta_x, pitch = theta_y).
        #[test]
        fn decoupled_support_force_is_the_weight_at_rest(
            roll in -0.5..0.5f64, pitch in -0.5..0.5f64,
        ) {
            let p = BallbotParams::<f64>::miapure_60kg().sagittal;
            let zero = nalgebra::Vector2::zeros();
            let ours = decoupled_support_force_n(
                (&p, &Vector4::new(pitch, 0.0, 0.0, 0.0), &zero),
                (&p, &Vector4::new(roll, 0.0, 0.0, 0.0), &zero),
            );
            let attitude = nalgebra::UnitQuaternion::from_euler_angles(roll, pitch, 0.0);
            let weight = support_force_in_body_n(p.body_mass_kg, p.gravity_m_per_s2, &attitude, &Vector3::zeros());
            prop_assert!((ours - weight).amax() <= 1e-9 * weight.norm(), "{ours} vs {weight}");
        }
    }

    /// A pure yaw torque at rest loads every wheel alike: normal forces stay at the static
    /// 344 N, tractions are equal.
    #[test]
    fn yaw_torque_leaves_normal_forces_static() {
        let (kin, wip) = miapure();
        let rest = Vector4::zeros();
        let c = kin.decoupled_contact_forces(
            (&wip, &rest),
            (&wip, &rest),
            &Vector3::new(0.0, 0.0, 30.0),
        );
        let static_n = 74.3 * 9.81 / (3.0 * 45f64.to_radians().cos());
        for w in &c.wheels {
            assert!((w.normal_force_n - static_n).abs() < 1e-9);
            assert!((w.traction_n - c.wheels[0].traction_n).abs() < 1e-9);
            assert!(w.traction_n.abs() > 1.0);
        }
    }
}
