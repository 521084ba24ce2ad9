//! The rapier3d ballbot world: contact forces, conservation, kinematics, slip, determinism,
//! direction dependence.

use approx::assert_relative_eq;
use ballbot_core::BallbotParams;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::telemetry::FNV_OFFSET_BASIS;
use ballbot_sim::world::{BallbotWorld, WorldParams};
use nalgebra::Vector3;

/// The ideal world (stiff continuous-rim contacts, straight torque-speed line): the numbers
/// these tests and docs/world-reproduce.md quote are its.
fn miapure() -> WorldParams {
    WorldParams::ideal(BallbotParams::miapure_60kg())
}

/// Runs the world under the shipped controller for `duration_secs` with a body-frame velocity
/// command; calls `each` after every step. Returns false if a failure was detected. (The
/// planar balancer these tests once used, a torque-mode state feedback, rang up the ball's shear
/// mode on the compliant floor and falls: docs/world-contacts.md, "Floor".)
fn run_balanced(
    sim: &mut WorldRobot,
    duration_secs: f64,
    mut command: impl FnMut(f64) -> [f64; 2],
    mut each: impl FnMut(&BallbotWorld),
) -> bool {
    let steps = (duration_secs / sim.world().params().dt_secs).round() as usize;
    for _ in 0..steps {
        let [vx, vy] = command(sim.world().time_secs());
        sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: vx,
            vy_m_per_s: vy,
            yaw_rate_rad_per_s: 0.0,
        }));
        each(sim.world());
        if sim.world().failure().is_some() {
            return false;
        }
    }
    true
}

#[test]
fn resting_normal_forces_match_static_load() {
    let p = miapure();
    let m_u = p.robot.sagittal.body_mass_kg;
    let g = p.robot.sagittal.gravity_m_per_s2;
    let expected = m_u * g / (3.0 * p.robot.drivetrain.contact_angle_rad.cos());
    assert_relative_eq!(expected, 343.6, epsilon = 0.1);
    let mut world = BallbotWorld::new(p).unwrap();
    // 1 s: the ball first settles about 1.5 mm into rapier's soft floor (time constant about
    // 0.1 s), which loads the wheels dynamically while it sinks.
    for _ in 0..8000 {
        world.step([0.0; 3]);
    }
    for w in &world.telemetry().wheels {
        assert_relative_eq!(w.normal_force_n, expected, max_relative = 2e-3);
        assert!(
            w.traction_n.abs() < 1.0,
            "no traction at rest: {}",
            w.traction_n
        );
    }
    // The floor carries ball and body.
    let total = (p.robot.sagittal.ball_mass_kg + m_u) * g;
    assert_relative_eq!(world.telemetry().floor_force_n, total, max_relative = 1e-2);
}

#[test]
fn floor_contact_carries_the_robot_without_drift() {
    // Rapier's ball-floor contact (one solver substep per 8 kHz step): at rest with the motors
    // off the floor carries ball and body, the ball's sink into the soft floor converges, and
    // the ball does not creep sideways.
    let p = miapure();
    let g = p.robot.sagittal.gravity_m_per_s2;
    let weight_n = (p.robot.sagittal.ball_mass_kg + p.robot.sagittal.body_mass_kg) * g;
    let mut world = BallbotWorld::new(p).unwrap();
    let sink_at = |world: &mut BallbotWorld, steps: usize| {
        for _ in 0..steps {
            world.step([0.0; 3]);
        }
        let t = world.telemetry();
        assert_relative_eq!(t.floor_force_n, weight_n, max_relative = 1e-3);
        let c = t.ball_position_m;
        assert!(
            c.x.abs() < 1e-12 && c.y.abs() < 1e-12,
            "ball drifted to {c}"
        );
        p.robot.ball_radius_m() - c.z
    };
    let sink_1s = sink_at(&mut world, 8000);
    let sink_2s = sink_at(&mut world, 8000);
    assert!(sink_1s > 0.0 && sink_1s < 2e-3, "{sink_1s}");
    assert!((sink_2s - sink_1s).abs() < 1e-6, "{sink_1s} -> {sink_2s}");
    assert!(world.telemetry().ball_velocity_m_per_s.norm() < 1e-6);
}

#[test]
fn balanced_robot_keeps_static_load_and_lean_shifts_it() {
    // Balanced and at rest: the static load. Then a held lean towards OW1 (+x) must unload
    // OW2 and OW3 relative to OW1 (the paper's explanation of the direction dependence).
    let mut world = WorldRobot::new(miapure()).unwrap();
    let mut sum = [0.0; 3];
    let mut count = 0.0;
    assert!(run_balanced(
        &mut world,
        2.0,
        |_| [0.0, 0.0],
        |w| {
            if w.time_secs() > 1.0 {
                for (s, wheel) in sum.iter_mut().zip(&w.telemetry().wheels) {
                    *s += wheel.normal_force_n;
                }
                count += 1.0;
            }
        }
    ));
    for s in sum {
        assert_relative_eq!(s / count, 343.6, max_relative = 0.03);
    }
    let mut accel = WorldRobot::new(miapure()).unwrap();
    let mut leaning = [0.0; 3];
    let mut count = 0.0;
    assert!(run_balanced(
        &mut accel,
        1.5,
        |t| [(0.6 * t).min(0.6), 0.0],
        |w| {
            let t = w.telemetry();
            if t.tilt_rad[1] > 0.01 {
                for (s, wheel) in leaning.iter_mut().zip(&t.wheels) {
                    *s += wheel.normal_force_n;
                }
                count += 1.0;
            }
        }
    ));
    assert!(
        count > 100.0,
        "the body must lean forward while accelerating"
    );
    let mean = leaning.map(|s| s / count);
    assert!(
        mean[1] < mean[0] - 20.0 && mean[2] < mean[0] - 20.0,
        "{mean:?}"
    );
}

/// Free flight (no gravity, robot 1 m up), motors off, frictionless wheels, no contact
/// damping: ball and body interact only through the three normal springs. Returns the changes
/// of linear momentum, angular momentum (relative) and energy (relative) after 1 s, with
/// rapier stepping once every `rigid_step_ratio` world steps.
pub(crate) fn free_flight(dt_divisor: f64, rigid_step_ratio: u32) -> (f64, f64, f64) {
    let mut p = miapure();
    p.rigid_step_ratio = rigid_step_ratio;
    p.contact.normal_damping_n_s_per_m = 0.0;
    p.wheel_damping_nm_s_per_rad = 0.0;
    p.rolling_resistance = 0.0;
    p.spin_friction_m = 0.0;
    p.dt_secs /= dt_divisor;
    let mut world = BallbotWorld::new(p).unwrap();
    world.set_gravity_m_per_s2(0.0).unwrap();
    world.set_wheel_ball_friction(0.0).unwrap();
    world.translate_robot(Vector3::new(0.0, 0.0, 1.0));
    world.set_body_velocity(Vector3::new(0.3, -0.2, -0.05), Vector3::new(0.4, -0.3, 1.5));
    world.set_ball_velocity(Vector3::new(-0.2, 0.1, 0.4), Vector3::new(2.0, 1.0, -3.0));
    let p0 = world.linear_momentum_ns();
    let l0 = world.angular_momentum_nms();
    let e0 = world.kinetic_energy_j() + world.contact_energy_j();
    let mut touched = 0;
    for _ in 0..(8000.0 * dt_divisor) as usize {
        let t = world.step([0.0; 3]);
        touched += usize::from(t.wheels.iter().any(|w| w.normal_force_n > 0.0));
    }
    assert!(
        touched > 10,
        "the bodies must collide for the test to mean anything"
    );
    let p1 = world.linear_momentum_ns();
    let l1 = world.angular_momentum_nms();
    let e1 = world.kinetic_energy_j() + world.contact_energy_j();
    (
        (p1 - p0).norm(),
        (l1 - l0).norm() / l0.norm(),
        (e1 - e0).abs() / e0,
    )
}

#[test]
fn free_flight_conserves_momentum_and_energy() {
    // Linear and angular momentum: conserved to round-off and to the integrator's rotation
    // error, since every contact force acts equal and opposite at the same point. Energy:
    // the collision (springs engaging and releasing inside a step) costs an O(dt) error, so it
    // must be small at 8 kHz and halve with the step.
    let (dp, dl, de) = free_flight(1.0, 1);
    assert!(dp < 1e-9, "linear momentum changed by {dp}");
    assert!(dl < 1e-3, "angular momentum changed by {dl}");
    assert!(de < 0.015, "energy changed by {de}");
    let (_, _, de_half) = free_flight(2.0, 1);
    assert!(
        de_half < 0.6 * de && de_half > 0.4 * de,
        "first order: {de} -> {de_half}"
    );
}

#[test]
fn a_motor_spinning_its_wheel_gives_the_bodies_the_spin_momentum_at_the_gear_ratio() {
    // Free flight, no wheel-ball friction: one motor's torque accelerates its wheel and rotor,
    // whose inertia is I_w + n^2 I_r, and nothing else. The spins then carry (I_w + n I_r) w
    // (the rotor turns at n w), so the ball and body together must carry the opposite, the
    // total staying zero; the rigid bodies must not receive the full reflected impulse.
    let mut p = miapure();
    p.contact.normal_damping_n_s_per_m = 0.0;
    p.wheel_damping_nm_s_per_rad = 0.0;
    p.rolling_resistance = 0.0;
    p.spin_friction_m = 0.0;
    let (i_reflected, i_spin) = (
        p.reflected_wheel_inertia_kg_m2(),
        p.wheel_spin_momentum_inertia_kg_m2(),
    );
    let n = p.robot.drivetrain.actuator.gear_ratio;
    assert!(
        n > 2.0 && i_spin < 0.5 * i_reflected,
        "n {n}, {i_spin} vs {i_reflected}"
    );
    let ratio = p.rigid_step_ratio as usize;
    let (torque_nm, steps) = (1.0, 800 * ratio);
    let duration_secs = steps as f64 * p.dt_secs;
    let mut world = BallbotWorld::new(p).unwrap();
    world.set_gravity_m_per_s2(0.0).unwrap();
    world.set_wheel_ball_friction(0.0).unwrap();
    world.translate_robot(Vector3::new(0.0, 0.0, 1.0));
    for _ in 0..steps {
        world.step([torque_nm, 0.0, 0.0]);
    }
    let w = world.telemetry().wheels[0].speed_rad_per_s;
    let rigid = world.rigid_angular_momentum_nms().norm();
    let total = world.angular_momentum_nms().norm();
    println!(
        "wheel {w:.3} rad/s after {duration_secs} s; bodies {rigid:.5} N m s \
         (spin momentum {:.5}, reflected {:.5}); total {total:.2e}",
        i_spin * w,
        i_reflected * w
    );
    assert_relative_eq!(
        w,
        torque_nm * duration_secs / i_reflected,
        max_relative = 1e-3
    );
    assert_relative_eq!(rigid, i_spin * w, max_relative = 1e-3);
    assert!(total < 1e-3 * rigid, "total {total} vs bodies {rigid}");
}

#[test]
fn frictionless_floor_conserves_horizontal_momentum_and_energy_falls() {
    // Gravity on, frictionless floor and wheels, motors off: the body falls over. The floor
    // pushes only vertically, so the horizontal momentum stays zero; with contact damping the
    // total energy can only fall.
    let mut p = miapure();
    p.rolling_resistance = 0.0;
    p.spin_friction_m = 0.0;
    let mut world = BallbotWorld::new(p).unwrap();
    world.set_floor_friction(0.0).unwrap();
    world.set_wheel_ball_friction(0.0).unwrap();
    world.tilt_body([0.02, 0.05]);
    let energy =
        |w: &BallbotWorld| w.kinetic_energy_j() + w.potential_energy_j() + w.contact_energy_j();
    let e0 = energy(&world);
    let mut e_prev = e0;
    for k in 0..4000 {
        world.step([0.0; 3]);
        let e = energy(&world);
        if k % 40 == 0 {
            assert!(
                e <= e_prev + 1e-3 * e0.abs().max(1.0),
                "energy rose at step {k}: {e_prev} -> {e}"
            );
            e_prev = e;
        }
    }
    let p = world.linear_momentum_ns();
    assert!(p.x.abs() < 1e-6 && p.y.abs() < 1e-6, "{p}");
    assert!(world.telemetry().tilt_rad[1] > 0.2, "it did fall");
}

#[test]
fn wheel_speeds_match_kinematics_at_low_speed() {
    // High friction, slow diagonal drive. The kinematics psi_dot_i = (r / r_W) u_i . omega_rel
    // integrated over 1.5 s must give each wheel's turned angle: the compliant contact may
    // only store a bounded creep (the bristle), never accumulate slip.
    let mut p = miapure();
    p.robot.drivetrain.wheel_ball_friction = 2.0;
    let mut world = WorldRobot::new(p).unwrap();
    let (r, r_w) = (p.robot.ball_radius_m(), p.robot.drivetrain.wheel_radius_m);
    let a = p.robot.drivetrain.contact_angle_rad;
    let dt = p.dt_secs;
    let mut predicted = [0.0; 3];
    let mut start = None;
    assert!(run_balanced(
        &mut world,
        3.0,
        |t| [0.2 * t.min(1.0), 0.1 * t.min(1.0)],
        |w| {
            let t = w.telemetry();
            if w.time_secs() > 1.5 {
                let start = *start.get_or_insert(t.wheels.map(|w| w.angle_rad));
                let w_rel = t.body_orientation.inverse() * t.ball_angular_velocity_rad_per_s
                    - t.body_rate_rad_per_s;
                for (i, b) in p.robot.drivetrain.wheel_azimuths_rad.iter().enumerate() {
                    let u = Vector3::new(-a.cos() * b.cos(), -a.cos() * b.sin(), a.sin());
                    predicted[i] += dt * r / r_w * u.dot(&w_rel);
                    let _ = start;
                }
            }
        }
    ));
    let start = start.unwrap();
    for i in 0..3 {
        let turned = world.world().telemetry().wheels[i].angle_rad - start[i];
        assert!(
            predicted[i].abs() > 1.0,
            "wheel {i} must turn: {}",
            predicted[i]
        );
        assert_relative_eq!(turned, predicted[i], max_relative = 5e-3);
    }
}

#[test]
fn slip_starts_exactly_at_mu_times_normal_force() {
    // Rig: let the body settle on the ball, then clamp both. Ramp OW1's torque: the wheel
    // holds while tau / r_W < mu N and spins up from the step the demand crosses mu N.
    let p = miapure();
    let mu = p.robot.drivetrain.wheel_ball_friction;
    let r_w = p.robot.drivetrain.wheel_radius_m;
    let mut world = BallbotWorld::new(p).unwrap();
    for _ in 0..1600 {
        world.step([0.0; 3]);
    }
    world.set_ball_fixed(true);
    world.set_body_fixed(true);
    let n = world.step([0.0; 3]).wheels[0].normal_force_n;
    assert_relative_eq!(n, 343.6, max_relative = 0.03);
    let threshold_nm = mu * n * r_w;
    let ramp_nm_per_step = 0.001;
    let mut onset = None;
    for k in 0..30_000 {
        let tau = ramp_nm_per_step * k as f64;
        let t = world.step([tau, 0.0, 0.0]);
        let w = t.wheels[0];
        if w.slipping {
            onset = Some((tau, w));
            break;
        }
        assert!(
            w.speed_rad_per_s.abs() < 1e-2,
            "wheel turns while sticking at {tau} N m"
        );
    }
    let (tau, w) = onset.expect("must slip");
    // The wheel's inertia lags the ramp by a few steps: allow a few ramp increments.
    assert!(
        (tau - threshold_nm).abs() < 10.0 * ramp_nm_per_step + 1e-3 * threshold_nm,
        "slip at {tau} N m, mu N r_W = {threshold_nm}"
    );
    assert!(w.traction_demand_n.abs() > mu * w.normal_force_n);
    // Beyond the edge the wheel spins up and the traction is kinetic.
    for _ in 0..400 {
        world.step([threshold_nm * 1.2, 0.0, 0.0]);
    }
    let w = world.telemetry().wheels[0];
    assert!(w.slipping && w.speed_rad_per_s > 1.0, "{w:?}");
    let mu_k = mu * p.contact.kinetic_friction_ratio;
    assert_relative_eq!(
        w.traction_n.abs(),
        mu_k * w.normal_force_n,
        max_relative = 1e-9
    );
}

fn telemetry_hash(seed: u64) -> u64 {
    let mut p = miapure();
    p.sensors.seed = seed;
    let mut world = WorldRobot::new(p).unwrap();
    let mut hash = FNV_OFFSET_BASIS;
    run_balanced(
        &mut world,
        0.5,
        |t| [0.5 * t, 0.0],
        |w| {
            w.telemetry().hash_into(&mut hash);
        },
    );
    hash
}

#[test]
fn same_seed_gives_identical_telemetry() {
    assert_eq!(telemetry_hash(7), telemetry_hash(7));
    assert_ne!(telemetry_hash(7), telemetry_hash(8), "the seed must matter");
}

#[test]
fn core_controller_ramp_unloads_driving_wheels_more_towards_ow1() {
    // The core's cascaded LQR-PI in the loop, a 1 m/s^2 ramp to 1 m/s at 0 and 180 deg. The
    // paper's mechanism: towards OW1 (0 deg) the lean unloads the driving wheels OW2 and OW3,
    // away from it (180 deg) it loads them. So the smallest normal force during the run is
    // lower at 0 deg.
    use ballbot_sim::studies::ramp::{RampParams, max_speed_ramp};
    let ramp = RampParams {
        accel_m_per_s2: 1.0,
        max_command_m_per_s: 1.0,
        settle_secs: 0.2,
        sample_every_secs: 0.0025,
    };
    let run = |h| max_speed_ramp(miapure(), h, &ramp).unwrap();
    let (fwd, back) = (run(0.0), run(180.0));
    assert!(fwd.failure.is_none() && back.failure.is_none());
    assert!(fwd.max_speed_m_per_s > 0.9 && back.max_speed_m_per_s > 0.9);
    // The driving wheels OW2 and OW3 (OW1 idles along the sagittal plane).
    let min_n = |r: &ballbot_sim::studies::ramp::RampResult| {
        r.samples
            .iter()
            .map(|s| s.normal_force_n[1].min(s.normal_force_n[2]))
            .fold(f64::INFINITY, f64::min)
    };
    assert!(
        min_n(&fwd) < min_n(&back) - 5.0,
        "{} vs {}",
        min_n(&fwd),
        min_n(&back)
    );
}

#[test]
fn accelerating_towards_ow1_slips_at_a_lower_acceleration_than_away_from_it() {
    // The paper's failure happens while accelerating: the lean unloads the driving wheels
    // OW2/OW3 towards OW1 (0 deg) and loads them away from it (180 deg). The core's command
    // shaper caps speed at 2 m/s and acceleration at 1 m/s^2, below any traction limit, so the
    // caps are lifted here; its jerk limit (2 m/s^3) stays. Measured (docs/world-reproduce.md):
    // 0 deg survives 1.7 m/s^2 and slips from 1.8; 180 deg survives 1.9 with cone utilisation
    // 0.58.
    use ballbot_core::ballbot::BallbotControllerConfig;
    use ballbot_sim::studies::ramp::{RampParams, RampResult, max_speed_ramp_with_config};
    use ballbot_sim::world::FailureKind;
    let run = |heading_deg: f64, accel_m_per_s2: f64| -> RampResult {
        let params = miapure();
        let mut config = BallbotControllerConfig::paper(&params.robot).unwrap();
        config.shaping.translation.max_value = 5.0;
        config.shaping.translation.max_rate_per_s = 20.0;
        config.shaping.max_tilt_command_rad = 0.5;
        config.shaping.max_tilt_rate_command_rad_per_s = 5.0;
        let ramp = RampParams {
            accel_m_per_s2,
            max_command_m_per_s: 3.0,
            settle_secs: 0.5,
            sample_every_secs: 0.01,
        };
        max_speed_ramp_with_config(params, config, heading_deg, &ramp).unwrap()
    };
    let gentle = run(0.0, 1.6);
    assert!(gentle.failure.is_none(), "{:?}", gentle.failure);
    assert!(gentle.max_speed_m_per_s > 3.0);
    let (fwd, back) = (run(0.0, 1.9), run(180.0, 1.9));
    assert!(back.failure.is_none(), "{:?}", back.failure);
    assert!(back.max_speed_m_per_s > 3.0);
    let failure = fwd.failure.unwrap();
    assert!(
        matches!(failure.kind, FailureKind::SustainedSlip { wheel: 1 | 2 }),
        "{failure:?}"
    );
    assert!(fwd.max_speed_m_per_s < 1.5, "{}", fwd.max_speed_m_per_s);
    let peak_u = |r: &RampResult| {
        r.samples
            .iter()
            .map(|s| s.max_cone_utilisation)
            .fold(0.0, f64::max)
    };
    assert!(peak_u(&back) < 0.8, "{}", peak_u(&back));
}

#[test]
fn chassis_clearance_is_the_lowest_corner() {
    // The closed form (lowest of the four corners (+-h, +-h, 0) of the body frame) against the
    // corners transformed one by one, for tilts in every quadrant.
    let p = miapure();
    let h = p.chassis_half_width_m;
    for tilt in [
        [0.0, 0.0],
        [0.1, 0.3],
        [-0.4, 0.2],
        [0.25, -0.5],
        [-0.3, -0.1],
    ] {
        let mut world = BallbotWorld::new(p).unwrap();
        world.tilt_body(tilt);
        let t = world.telemetry();
        let lowest = [(h, h), (h, -h), (-h, h), (-h, -h)]
            .iter()
            .map(|&(x, y)| (t.body_position_m + t.body_orientation * Vector3::new(x, y, 0.0)).z)
            .fold(f64::INFINITY, f64::min);
        assert_relative_eq!(world.chassis_clearance_m(), lowest, epsilon = 1e-12);
    }
}

#[test]
fn falling_body_fails_on_tilt_when_it_crosses_the_limit() {
    // Motors off from a small lean: the body falls; the monitor must report a tilt failure at
    // the first step beyond max_tilt_rad (25 deg), with the tilt it saw.
    use ballbot_sim::world::FailureKind;
    use ballbot_sim::world::failure::tilt_from_vertical_rad;
    let p = miapure();
    let mut world = BallbotWorld::new(p).unwrap();
    world.tilt_body([0.0, 0.05]);
    let mut last_tilt = 0.0;
    for _ in 0..40_000 {
        let t = *world.step([0.0; 3]);
        if let Some(f) = world.failure() {
            let FailureKind::Tilt { tilt_rad } = f.kind else {
                panic!("expected a tilt failure, got {f:?}");
            };
            assert_eq!(tilt_rad, tilt_from_vertical_rad(&t));
            assert!(tilt_rad > p.failure.max_tilt_rad, "{tilt_rad}");
            assert!(last_tilt <= p.failure.max_tilt_rad, "{last_tilt}");
            return;
        }
        last_tilt = tilt_from_vertical_rad(&t);
    }
    panic!("the body never fell past the tilt limit (last tilt {last_tilt})");
}
