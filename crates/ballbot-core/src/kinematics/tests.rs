//! Unit tests of the omniwheel kinematics against MODEL.md's closed forms and first
//! principles (torque of the tractions on the ball, force balance on the body).

use super::*;
use crate::check::lit;
use approx::{assert_abs_diff_eq, assert_relative_eq};
use nalgebra::UnitQuaternion;

fn miapure<T: RealField + Copy>() -> OmniKinematics<T> {
    OmniKinematics::from_ballbot(&BallbotParams::miapure_60kg()).unwrap()
}

fn deg<T: RealField + Copy>(d: f64) -> T {
    lit::<T>(d) * T::pi() / lit(180.0)
}

/// MODEL.md section 4, the inverse in closed form for wheels at 0, 120, 240 deg.
fn model_relative_rate(psi: [f64; 3], alpha: f64, rs: f64, rw: f64) -> [f64; 3] {
    let k = rw / rs;
    [
        k * 2.0 / (3.0 * alpha.cos()) * (-psi[0] + (psi[1] + psi[2]) / 2.0),
        k * (psi[2] - psi[1]) / (3f64.sqrt() * alpha.cos()),
        k * (psi[0] + psi[1] + psi[2]) / (3.0 * alpha.sin()),
    ]
}

/// MODEL.md section 4, the motor torques in closed form for wheels at 0, 120, 240 deg.
fn model_wheel_torques(tau: [f64; 3], alpha: f64, rs: f64, rw: f64) -> [f64; 3] {
    core::array::from_fn(|i| {
        let b = (120.0 * i as f64).to_radians();
        rw / (3.0 * rs)
            * (2.0 / alpha.cos() * (-b.cos() * tau[0] - b.sin() * tau[1]) - tau[2] / alpha.sin())
    })
}

#[test]
fn symmetric_layout_matches_model_closed_forms() {
    let kin = miapure::<f64>();
    let (alpha, rs, rw) = (45f64.to_radians(), 0.1145, 0.0625);
    for psi in [[1.0, 0.0, 0.0], [0.0, 2.0, -3.0], [4.0, -1.5, 0.25]] {
        let ours = kin.relative_rate_rad_per_s(&Vector3::from(psi));
        let model = model_relative_rate(psi, alpha, rs, rw);
        assert_relative_eq!(ours, Vector3::from(model), epsilon = 1e-12);
    }
    for tau in [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [30.0, -12.0, 7.0],
    ] {
        let ours = kin.wheel_torques_nm(&Vector3::from(tau));
        let model = model_wheel_torques(tau, alpha, rs, rw);
        assert_relative_eq!(ours, Vector3::from(model), epsilon = 1e-12);
    }
}

fn sagittal_travel_leaves_wheel_1_idle<T: RealField + Copy>(tol: f64) {
    let kin = miapure::<T>();
    // Ball rolling forward (+x) at 1 m/s under an upright body: phi_dot_y = v / r.
    let rate = relative_rate_from_planar([T::zero(), lit(1.0 / 0.1145)], [T::zero(); 2], T::zero());
    let psi = kin.wheel_speeds_rad_per_s(&rate);
    assert_abs_diff_eq!(psi[0], T::zero(), epsilon = lit(tol));
    assert_relative_eq!(psi[1], -psi[2], epsilon = lit(tol));
    // |psi_2| = (v / r_W) cos a sin 120 deg.
    let expected: T = lit(1.0 / 0.0625 * 45f64.to_radians().cos() * 120f64.to_radians().sin());
    assert_relative_eq!(psi[2], expected, max_relative = lit(tol));
    assert!(psi[1] < T::zero());
    // The same for the torques: a sagittal torque needs no torque from wheel 1.
    let tau = kin.wheel_torques_nm(&Vector3::new(T::zero(), lit(50.0), T::zero()));
    assert_abs_diff_eq!(tau[0], T::zero(), epsilon = lit(tol));
    assert_relative_eq!(tau[1], -tau[2], max_relative = lit(tol));
}

#[test]
fn sagittal_travel_leaves_wheel_1_idle_f64() {
    sagittal_travel_leaves_wheel_1_idle::<f64>(1e-12);
}

#[test]
fn sagittal_travel_leaves_wheel_1_idle_f32() {
    sagittal_travel_leaves_wheel_1_idle::<f32>(1e-5);
}

fn pure_spin_drives_all_wheels_equally<T: RealField + Copy>(tol: f64) {
    let kin = miapure::<T>();
    let rate = relative_rate_from_planar([T::zero(); 2], [T::zero(); 2], lit(2.0));
    let psi = kin.wheel_speeds_rad_per_s(&rate);
    // psi_i = (r_S / r_W) sin a (-theta_z_dot) for every wheel.
    let expected: T = lit(-0.1145 / 0.0625 * 45f64.to_radians().sin() * 2.0);
    for p in psi.iter() {
        assert_relative_eq!(*p, expected, max_relative = lit(tol));
    }
    let tau = kin.wheel_torques_nm(&Vector3::new(T::zero(), T::zero(), lit(10.0)));
    assert_relative_eq!(tau[0], tau[1], max_relative = lit(tol));
    assert_relative_eq!(tau[0], tau[2], max_relative = lit(tol));
}

#[test]
fn pure_spin_drives_all_wheels_equally_f64() {
    pure_spin_drives_all_wheels_equally::<f64>(1e-12);
}

#[test]
fn pure_spin_drives_all_wheels_equally_f32() {
    pure_spin_drives_all_wheels_equally::<f32>(1e-5);
}

/// First principles, independent of the matrices: wheel `i` pushes the ball with
/// `(tau_i / r_W) d_i` at `r_S n_i`; the total torque on the ball about its centre must be
/// `[tau_x, tau_y, -tau_z]` (body on ball in the planes, minus the yaw torque on the body).
#[test]
fn tractions_apply_the_planar_torque_to_the_ball() {
    let mut drivetrain = DrivetrainParams::<f64>::miapure();
    drivetrain.wheel_azimuths_rad = [0.3, 2.0, 4.4];
    drivetrain.contact_angle_rad = 0.9;
    let kin = OmniKinematics::new(drivetrain, 0.13).unwrap();
    let planar = Vector3::new(12.0, -30.0, 8.0);
    let wheel = kin.wheel_torques_nm(&planar);
    let mut on_ball = Vector3::zeros();
    for (w, tau) in kin.wheels().iter().zip(wheel.iter()) {
        let force = w.rolling_direction * (*tau / drivetrain.wheel_radius_m);
        on_ball += w.contact_point_m.cross(&force);
    }
    assert_relative_eq!(on_ball, Vector3::new(12.0, -30.0, -8.0), epsilon = 1e-12);
}

/// The sign conventions of the power balance: motors do positive work when the planar torque
/// drives the relative motion it acts on (sagittal torque with a forward-rolling ball, yaw
/// torque with a positive yaw rate).
#[test]
fn power_sign_conventions() {
    let kin = miapure::<f64>();
    let power = |planar: Vector3<f64>, rate: Vector3<f64>| {
        kin.wheel_torques_nm(&planar)
            .dot(&kin.wheel_speeds_rad_per_s(&rate))
    };
    let forward = relative_rate_from_planar([0.0, 10.0], [0.0; 2], 0.0);
    assert_relative_eq!(
        power(Vector3::new(0.0, 5.0, 0.0), forward),
        50.0,
        epsilon = 1e-12
    );
    let yaw = relative_rate_from_planar([0.0; 2], [0.0; 2], 3.0);
    assert_relative_eq!(
        power(Vector3::new(0.0, 0.0, 4.0), yaw),
        12.0,
        epsilon = 1e-12
    );
    // Motor rotor quantities carry the same power.
    let planar = Vector3::new(3.0, -2.0, 1.5);
    let rate = Vector3::new(-4.0, 6.0, 0.5);
    let rotor = kin
        .motor_torques_nm(&planar)
        .dot(&kin.motor_speeds_rad_per_s(&rate));
    assert_relative_eq!(rotor, power(planar, rate), epsilon = 1e-12);
}

#[test]
fn gear_ratio_scales_motor_quantities() {
    let kin = miapure::<f64>();
    let rate = Vector3::new(1.0, -2.0, 0.5);
    assert_relative_eq!(
        kin.motor_speeds_rad_per_s(&rate),
        kin.wheel_speeds_rad_per_s(&rate) * 7.5,
        epsilon = 1e-12
    );
    let planar = Vector3::new(10.0, 20.0, -5.0);
    assert_relative_eq!(
        kin.motor_torques_nm(&planar),
        kin.wheel_torques_nm(&planar) / 7.5,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        kin.relative_rate_from_motor_speeds_rad_per_s(&kin.motor_speeds_rad_per_s(&rate)),
        rate,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        kin.planar_torque_from_motor_torques_nm(&kin.motor_torques_nm(&planar)),
        planar,
        epsilon = 1e-12
    );
}

fn torque_capacity_matches_model<T: RealField + Copy>(tol: f64) {
    let kin = miapure::<T>();
    let cap = kin.planar_torque_capacity_nm();
    // MODEL.md section 6: 83.9 (x), 96.9 (y), 167.9 (z) N m from 43.2 N m per actuator.
    assert_relative_eq!(cap[0], lit(83.9), epsilon = lit(0.05));
    assert_relative_eq!(cap[1], lit(96.9), epsilon = lit(0.05));
    assert_relative_eq!(cap[2], lit(167.9), epsilon = lit(0.05));
    // At capacity the most loaded wheel is exactly at its peak torque.
    for j in 0..3 {
        let mut planar = Vector3::zeros();
        planar[j] = cap[j];
        let worst = kin.wheel_torques_nm(&planar).amax();
        assert_relative_eq!(worst, lit(43.2), max_relative = lit(tol));
    }
}

#[test]
fn torque_capacity_matches_model_f64() {
    torque_capacity_matches_model::<f64>(1e-12);
}

#[test]
fn torque_capacity_matches_model_f32() {
    torque_capacity_matches_model::<f32>(1e-5);
}

#[test]
fn saturation_scales_uniformly_to_the_peak() {
    let kin = miapure::<f64>();
    let feasible = Vector3::new(20.0, -30.0, 10.0);
    let out = kin.saturate_planar_torque(&feasible);
    assert_eq!(out.scale, 1.0);
    assert!(!out.is_saturated());
    assert_eq!(out.planar_torque_nm, feasible);

    let request = Vector3::new(150.0, 90.0, -200.0);
    let out = kin.saturate_planar_torque(&request);
    assert!(out.is_saturated() && out.scale > 0.0);
    assert_relative_eq!(out.wheel_torques_nm.amax(), 43.2, epsilon = 1e-12);
    assert_relative_eq!(out.planar_torque_nm, request * out.scale, epsilon = 1e-12);
    assert_relative_eq!(
        kin.wheel_torques_nm(&out.planar_torque_nm),
        out.wheel_torques_nm,
        epsilon = 1e-12
    );

    let nan = kin.saturate_planar_torque(&Vector3::new(f64::NAN, 0.0, 0.0));
    assert_eq!(nan.scale, 0.0);
    assert_eq!(nan.planar_torque_nm, Vector3::zeros());
}

#[test]
fn saturation_at_speed_follows_the_torque_speed_line() {
    let kin = miapure::<f64>();
    // Pure spin: all wheels turn at the same speed and need the same torque.
    let planar = Vector3::new(0.0, 0.0, 100.0);
    let wheel = kin.wheel_torques_nm(&planar);
    assert!(wheel[0] < 0.0); // a positive yaw torque drives the wheels negatively
    // Wheels at half the no-load speed in the direction they are driven: half the peak.
    let speeds = Vector3::repeat(-31.0);
    let out = kin.saturate_planar_torque_at_speed(&(planar * 3.0), &speeds);
    assert_relative_eq!(out.wheel_torques_nm.amax(), 21.6, epsilon = 1e-12);
    // Braking (speed against the torque): the full peak.
    let out = kin.saturate_planar_torque_at_speed(&(planar * 3.0), &(-speeds));
    assert_relative_eq!(out.wheel_torques_nm.amax(), 43.2, epsilon = 1e-12);
    // Beyond the no-load speed no motoring torque is left.
    let out = kin.saturate_planar_torque_at_speed(&planar, &Vector3::repeat(-70.0));
    assert_eq!(out.scale, 0.0);
    // A failed speed measurement gives no torque.
    let out = kin.saturate_planar_torque_at_speed(&planar, &Vector3::new(0.0, f64::NAN, 0.0));
    assert_eq!(out.scale, 0.0);
    assert_eq!(out.wheel_torques_nm, Vector3::zeros());
}

fn static_normal_force_is_344_n<T: RealField + Copy>(tol: f64) {
    let kin = miapure::<T>();
    let params = BallbotParams::<T>::miapure_60kg();
    let m = params.sagittal.body_mass_kg;
    let g = params.sagittal.gravity_m_per_s2;
    let support =
        contact::support_force_in_body_n(m, g, &UnitQuaternion::identity(), &Vector3::zeros());
    let contacts = kin.contact_forces(&support, &Vector3::zeros());
    // N_i = m_U g / (3 cos a) = 74.3 * 9.81 / (3 cos 45 deg) = 343.6 N.
    let expected: T = lit(74.3 * 9.81 / (3.0 * 45f64.to_radians().cos()));
    for w in &contacts.wheels {
        assert_relative_eq!(w.normal_force_n, expected, max_relative = lit(tol));
        assert_relative_eq!(w.normal_force_n, lit(344.0), epsilon = lit(0.5));
        assert_eq!(w.traction_n, T::zero());
        assert_eq!(w.friction_utilisation, T::zero());
        assert!(!w.lifted_off);
    }
    assert!(contacts.all_hold());
}

#[test]
fn static_normal_force_is_344_n_f64() {
    static_normal_force_is_344_n::<f64>(1e-12);
}

#[test]
fn static_normal_force_is_344_n_f32() {
    static_normal_force_is_344_n::<f32>(1e-5);
}

/// First principles: the contact forces on the body, `N_i n_i - F_i d_i`, add up to the
/// support force, and carry the planar torque (with the body's sign) about the ball centre.
#[test]
fn contact_forces_balance_the_body() {
    let mut drivetrain = DrivetrainParams::<f64>::miapure();
    drivetrain.wheel_azimuths_rad = [0.1, 2.3, 4.0];
    drivetrain.contact_angle_rad = 0.6;
    let kin = OmniKinematics::new(drivetrain, 0.12).unwrap();
    let support = Vector3::new(60.0, -25.0, 700.0);
    let planar = Vector3::new(-15.0, 40.0, 6.0);
    let wheel = kin.wheel_torques_nm(&planar);
    let contacts = kin.contact_forces(&support, &wheel);
    let mut force = Vector3::zeros();
    let mut torque = Vector3::zeros();
    for (g, c) in kin.wheels().iter().zip(contacts.wheels.iter()) {
        let f = g.contact_normal * c.normal_force_n - g.rolling_direction * c.traction_n;
        force += f;
        torque += g.contact_point_m.cross(&f);
    }
    assert_relative_eq!(force, support, epsilon = 1e-10);
    assert_relative_eq!(
        torque,
        -Vector3::new(planar[0], planar[1], -planar[2]),
        epsilon = 1e-10
    );
}

/// MODEL.md section 5: accelerating towards OW1 unloads OW2 and OW3.
#[test]
fn accelerating_towards_wheel_1_unloads_wheels_2_and_3() {
    let kin = miapure::<f64>();
    let rest = Vector3::new(0.0, 0.0, 74.3 * 9.81);
    let accel = support_force_in_body_n(
        74.3,
        9.81,
        &UnitQuaternion::identity(),
        &Vector3::new(3.0, 0.0, 0.0),
    );
    let n_rest = kin.normal_forces_n(&rest, &Vector3::zeros());
    let n_accel = kin.normal_forces_n(&accel, &Vector3::zeros());
    assert!(n_accel[0] > n_rest[0]);
    assert!(n_accel[1] < n_rest[1] && n_accel[2] < n_rest[2]);
    assert_relative_eq!(n_accel[1], n_accel[2], epsilon = 1e-9);
    // The sagittal torque that drives the ball forward unloads them further.
    let drive = kin.wheel_torques_nm(&Vector3::new(0.0, 60.0, 0.0));
    let n_drive = kin.normal_forces_n(&accel, &drive);
    assert!(n_drive[1] < n_accel[1] && n_drive[2] < n_accel[2]);
}

#[test]
fn lift_off_and_friction_utilisation() {
    let kin = miapure::<f64>();
    // Strong sideways pull: wheel 1 (at +x) must pull, i.e. lifts off.
    let contacts = kin.contact_forces(&Vector3::new(-900.0, 0.0, 100.0), &Vector3::zeros());
    assert!(contacts.wheels[0].lifted_off);
    assert!(contacts.any_lifted_off() && !contacts.all_hold());
    assert_eq!(contacts.max_friction_utilisation(), f64::INFINITY);
    // Utilisation |F| / (mu N) with mu = 0.6: traction 100 N at N = 344 N.
    let support = Vector3::new(0.0, 0.0, 74.3 * 9.81);
    let wheel = Vector3::new(0.0, 0.0625 * 100.0, -0.0625 * 100.0);
    let contacts = kin.contact_forces(&support, &wheel);
    let n = contacts.normal_forces_n();
    assert_relative_eq!(contacts.wheels[1].traction_n, 100.0, epsilon = 1e-12);
    assert_relative_eq!(
        contacts.wheels[1].friction_utilisation,
        100.0 / (0.6 * n[1]),
        epsilon = 1e-12
    );
    assert_eq!(contacts.wheels[0].friction_utilisation, 0.0);
}

#[test]
fn support_force_rotates_into_the_body() {
    // Body leaning forward by 10 deg (about +y): gravity's reaction tips towards -x in body.
    let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 10f64.to_radians());
    let f = support_force_in_body_n(10.0, 9.81, &q, &Vector3::zeros());
    assert_relative_eq!(f.norm(), 98.1, epsilon = 1e-12);
    assert_relative_eq!(f[0], -98.1 * 10f64.to_radians().sin(), epsilon = 1e-12);
    assert_abs_diff_eq!(f[1], 0.0, epsilon = 1e-12);
}

fn field_of(err: Error) -> &'static str {
    match err {
        Error::InvalidParameter { field, .. } => field,
        #[allow(unreachable_patterns)]
        _ => "",
    }
}

#[test]
fn rejects_invalid_contact_angles_naming_the_field() {
    for a in [0.0, -10.0, 90.0, 120.0, f64::NAN, f64::INFINITY] {
        let mut d = DrivetrainParams::<f64>::miapure();
        d.contact_angle_rad = deg(a);
        let err = OmniKinematics::new(d, 0.1145).unwrap_err();
        assert_eq!(field_of(err), "contact_angle_rad", "alpha = {a} deg");
    }
    let mut d = DrivetrainParams::<f32>::miapure();
    d.contact_angle_rad = deg(90.0);
    assert_eq!(
        field_of(OmniKinematics::new(d, 0.1145).unwrap_err()),
        "contact_angle_rad"
    );
}

#[test]
fn rejects_singular_layouts_naming_the_field() {
    let layouts: [[f64; 3]; 4] = [
        [0.0, 0.0, 120.0],
        [0.0, 120.0, 120.0],
        [0.0, 180.0, 360.0],
        [30.0, 210.0, 30.0],
    ];
    for az in layouts {
        let mut d = DrivetrainParams::<f64>::miapure();
        d.wheel_azimuths_rad = az.map(deg);
        let err = OmniKinematics::new(d, 0.1145).unwrap_err();
        assert_eq!(field_of(err), "wheel_azimuths_rad", "azimuths {az:?}");
    }
    let mut d = DrivetrainParams::<f32>::miapure();
    d.wheel_azimuths_rad = [0.0, 120.0, 120.0].map(deg);
    assert_eq!(
        field_of(OmniKinematics::new(d, 0.1145).unwrap_err()),
        "wheel_azimuths_rad"
    );
    // A valid but unusual layout is accepted.
    let mut d = DrivetrainParams::<f64>::miapure();
    d.wheel_azimuths_rad = [10.0, 100.0, 250.0].map(deg);
    assert!(OmniKinematics::new(d, 0.1145).is_ok());
}

#[test]
fn rejects_bad_radii_naming_the_field() {
    let d = DrivetrainParams::<f64>::miapure();
    for r in [0.0, -0.1, f64::NAN] {
        assert_eq!(
            field_of(OmniKinematics::new(d, r).unwrap_err()),
            "ball_radius_m"
        );
    }
    let mut d = DrivetrainParams::<f64>::miapure();
    d.wheel_radius_m = 0.0;
    assert_eq!(
        field_of(OmniKinematics::new(d, 0.1145).unwrap_err()),
        "wheel_radius_m"
    );
}

#[test]
fn headings_map_to_the_planes() {
    // Heading 0: the sagittal plane (rotation about y); 90 deg: frontal, travel +y = -x rotation.
    assert_relative_eq!(
        relative_rate_at_heading(0.0, 5.0, 1.0),
        relative_rate_from_planar([0.0, 5.0], [0.0, 1.0], 0.0)
    );
    assert_relative_eq!(
        relative_rate_at_heading(core::f64::consts::FRAC_PI_2, 5.0, 1.0),
        relative_rate_from_planar([-5.0, 0.0], [-1.0, 0.0], 0.0),
        epsilon = 1e-15
    );
    assert_relative_eq!(
        planar_torque_at_heading(core::f64::consts::PI, 3.0),
        Vector3::new(0.0, -3.0, 0.0),
        epsilon = 1e-15
    );
    // Travel at heading 180 deg turns the wheels backwards w.r.t. heading 0.
    let kin = miapure::<f64>();
    let ahead = kin.wheel_speeds_rad_per_s(&relative_rate_at_heading(0.0, 10.0, 0.0));
    let back =
        kin.wheel_speeds_rad_per_s(&relative_rate_at_heading(core::f64::consts::PI, 10.0, 0.0));
    assert_relative_eq!(ahead, -back, epsilon = 1e-12);
}

#[test]
fn ball_rate_inverts_relative_rate_from_planar() {
    let rel = relative_rate_from_planar([3.0, -2.0], [0.5, 0.25], 1.5);
    assert_eq!(ball_rate_from_relative_rate(&rel, [0.5, 0.25]), [3.0, -2.0]);
    assert_eq!(rel[2], -1.5);
}

/// The documented wheel rotation: wheel `i` spins at `psi_dot_i` about `-u_i` relative to the
/// body; its rim at the contact then moves with the ball surface along `d_i` (no slip in the
/// rolling direction; the rollers take the rest, along `u_i`, and there is none along `n_i`).
#[test]
fn wheel_rim_rolls_with_the_ball_surface() {
    let mut drivetrain = DrivetrainParams::<f64>::miapure();
    drivetrain.wheel_azimuths_rad = [0.2, 2.5, 4.1];
    drivetrain.contact_angle_rad = 0.7;
    let kin = OmniKinematics::new(drivetrain, 0.11).unwrap();
    let rel = Vector3::new(1.3, -0.7, 2.1);
    let psi = kin.wheel_speeds_rad_per_s(&rel);
    for (w, &psi_i) in kin.wheels().iter().zip(psi.iter()) {
        let ball_surface = rel.cross(&w.contact_point_m);
        let wheel_rate = -w.axle_direction * psi_i;
        let rim = wheel_rate.cross(&(-w.contact_normal * drivetrain.wheel_radius_m));
        let slip = ball_surface - rim;
        assert_abs_diff_eq!(slip.dot(&w.rolling_direction), 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(slip.dot(&w.contact_normal), 0.0, epsilon = 1e-12);
        assert_relative_eq!(w.axle_direction.norm(), 1.0, epsilon = 1e-12);
    }
}

/// The reflected inertia carries the wheels' and rotors' kinetic energy; for the symmetric
/// layout it is diagonal with MODEL.md's geometry factors.
#[test]
fn reflected_wheel_inertia_carries_the_wheel_energy() {
    let kin = miapure::<f64>();
    let (wheel, rotor) = (0.01, 2e-4);
    let inertia = kin.reflected_wheel_inertia_kg_m2(wheel, rotor);
    let rel = Vector3::new(0.7, -1.9, 2.6);
    let psi = kin.wheel_speeds_rad_per_s(&rel);
    let motor = kin.motor_speeds_rad_per_s(&rel);
    let energy = 0.5 * (wheel * psi.norm_squared() + rotor * motor.norm_squared());
    assert_relative_eq!(
        0.5 * rel.dot(&(inertia * rel)),
        energy,
        max_relative = 1e-12
    );
    let k2 = (0.1145f64 / 0.0625).powi(2) * (wheel + 7.5 * 7.5 * rotor);
    let (s, c) = 45f64.to_radians().sin_cos();
    let expected =
        Matrix3::from_diagonal(&Vector3::new(1.5 * c * c, 1.5 * c * c, 3.0 * s * s)) * k2;
    assert_relative_eq!(inertia, expected, epsilon = 1e-12);
}
