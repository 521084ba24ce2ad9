//! Load transfer between the omniwheels in the core's quasi-static contact model
//! (`OmniKinematics::contact_forces`): the slopes of the normal forces against the driving
//! wheels' traction, derived by hand in docs/drafts/load-transfer.md, and the pure lean.
//!
//! With `N = P F_s + Q tau` (body coordinates) and the symmetric layout, the force balance
//! `sum_i N_i n_i = F_s + sum_i F_i d_i` solves to
//! `N_i = F_s,z / (3 cos a) + 2 / (3 sin a) (h . e_i)`, `h` the horizontal part of
//! `F_s + sum_i F_i d_i` and `e_i = [cos b_i, sin b_i]`. Driving along x with OW2 and OW3
//! (`F_3 = -F_2`) gives `sum_i F_i d_i = -sqrt(3) F_2 x`, so at fixed `F_s`
//! `dN_1 / d|F_2| = +-2 / (sqrt(3) sin a)` and `dN_{2,3} / d|F_2| = -+1 / (sqrt(3) sin a)`
//! (upper sign towards OW1): `+-1.633` and `-+0.816 = sqrt(2/3)` at 45 deg.

use ballbot_core::kinematics::{planar_torque_at_heading, support_force_in_body_n};
use ballbot_core::{BallbotParams, OmniKinematics};
use nalgebra::{UnitQuaternion, Vector3};

/// `dN_i / d|F_2|` at fixed support force for driving at `heading_deg`, from the core's `Q`.
fn slopes_per_traction(kin: &OmniKinematics<f64>, heading_deg: f64, r_w: f64) -> Vector3<f64> {
    let (_, q) = kin.normal_force_matrices();
    let tau = kin.wheel_torques_nm(&planar_torque_at_heading(heading_deg.to_radians(), 10.0));
    let traction_2 = tau[1] / r_w;
    q * tau / traction_2.abs()
}

#[test]
fn driving_traction_unloads_ow2_and_ow3_towards_ow1_and_ow1_away_from_it() {
    let robot = BallbotParams::<f64>::miapure_60kg();
    let kin = OmniKinematics::from_ballbot(&robot).unwrap();
    let r_w = robot.drivetrain.wheel_radius_m;
    let sin_a = robot.drivetrain.contact_angle_rad.sin();
    let per_f = 1.0 / (3f64.sqrt() * sin_a);
    approx::assert_relative_eq!(per_f, (2.0f64 / 3.0).sqrt(), epsilon = 1e-12); // a = 45 deg
    let towards = slopes_per_traction(&kin, 0.0, r_w);
    approx::assert_relative_eq!(
        towards,
        Vector3::new(2.0 * per_f, -per_f, -per_f),
        epsilon = 1e-9
    );
    let away = slopes_per_traction(&kin, 180.0, r_w);
    approx::assert_relative_eq!(away, -towards, epsilon = 1e-9);
    // OW1 carries no traction at 0 and 180 deg; OW2 and OW3 equal and opposite.
    for heading in [0.0f64, 180.0] {
        let tau = kin.wheel_torques_nm(&planar_torque_at_heading(heading.to_radians(), 10.0));
        approx::assert_abs_diff_eq!(tau[0], 0.0, epsilon = 1e-12);
        approx::assert_relative_eq!(tau[1], -tau[2], epsilon = 1e-12);
    }
}

#[test]
fn a_pure_lean_towards_ow1_loads_ow2_and_ow3() {
    // Held still at a 2 deg lean towards OW1 (no traction): the support force m g, seen from
    // the leaning body, has the horizontal part -m g sin(2 deg) along x, which the normals of
    // OW2/OW3 (pointing to -x) carry: N_2 = m g (cos / (3 cos a) + sin / (3 sin a)).
    let robot = BallbotParams::<f64>::miapure_60kg();
    let kin = OmniKinematics::from_ballbot(&robot).unwrap();
    let (m, g) = (robot.sagittal.body_mass_kg, robot.sagittal.gravity_m_per_s2);
    let lean = UnitQuaternion::from_euler_angles(0.0, 2f64.to_radians(), 0.0);
    let f_s = support_force_in_body_n(m, g, &lean, &Vector3::zeros());
    assert!(f_s.x < 0.0, "{f_s}");
    let n = kin
        .contact_forces(&f_s, &Vector3::zeros())
        .normal_forces_n();
    let upright = kin
        .contact_forces(&Vector3::new(0.0, 0.0, m * g), &Vector3::zeros())
        .normal_forces_n();
    let (s2, c2) = 2f64.to_radians().sin_cos();
    let a = robot.drivetrain.contact_angle_rad;
    let expected_2 = m * g * (c2 / (3.0 * a.cos()) + s2 / (3.0 * a.sin()));
    approx::assert_relative_eq!(n[1], expected_2, epsilon = 1e-9);
    approx::assert_relative_eq!(n[2], expected_2, epsilon = 1e-9);
    approx::assert_relative_eq!(upright[1], 343.6, epsilon = 0.1);
    approx::assert_relative_eq!(n[1], 355.4, epsilon = 0.1);
    // OW1 carries what OW2 and OW3 gained, twice over.
    approx::assert_relative_eq!(
        n[0],
        m * g * (c2 / (3.0 * a.cos()) - 2.0 * s2 / (3.0 * a.sin())),
        epsilon = 1e-9
    );
}
