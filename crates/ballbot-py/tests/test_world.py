"""The 3D world from Python, against the reference numbers of the Rust world tests
(crates/ballbot-sim/tests/world.rs): the static load per omniwheel, slip onset at mu N, free
flight conservation, wheel kinematics, determinism, the direction dependence of the ramp."""

import math
from pathlib import Path

import numpy as np
import pytest

import ballbot


def static_load_n(params: ballbot.WorldParams) -> float:
    """m_U g / (3 cos alpha): each omniwheel's share of the body weight along its normal."""
    robot = params.robot
    m_u, g = robot.sagittal.body_mass_kg, robot.sagittal.gravity_m_per_s2
    return m_u * g / (3.0 * math.cos(robot.drivetrain.contact_angle_rad))


def rotation_matrix(q_xyzw: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) in (x, y, z, w) order."""
    x, y, z, w = q_xyzw.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def test_resting_normal_forces_match_static_load() -> None:
    # The ideal world's stiff contacts: the rubber coating's sink turns the normals slightly
    # (349.0 N in the default world, whose whole-range coating law sinks the body 3.8 mm).
    params = ballbot.WorldParams.preset("ideal_miapure_60kg")
    expected = static_load_n(params)
    assert expected == pytest.approx(343.6, abs=0.1)
    world = ballbot.World(params)
    # 1 s, as in the Rust test.
    run = world.run(8000)
    assert run.steps == 8000 and run.time_secs.shape == (8000,)
    assert run.normal_force_n.shape == (8000, 3) and run.torque_nm.shape == (8000, 3)
    assert run.normal_force_n[-1] == pytest.approx([expected] * 3, rel=2e-3)
    assert np.all(np.abs(run.traction_n[-1]) < 1.0)
    # The floor carries ball and body.
    robot = params.robot
    total = (robot.sagittal.ball_mass_kg + robot.sagittal.body_mass_kg) * 9.81
    assert run.floor_force_n[-1] == pytest.approx(total, rel=1e-2)
    # One more step through `step` agrees with the run and with `telemetry`.
    t = world.step([0.0, 0.0, 0.0])
    assert [w.normal_force_n for w in t.wheels] == pytest.approx([expected] * 3, rel=2e-3)
    assert world.telemetry.time_secs == t.time_secs == pytest.approx(8001 * params.dt_secs)
    assert world.failure is None


def test_slip_starts_at_mu_times_normal_force() -> None:
    # The rig of the Rust test: settle, clamp ball and body, ramp OW1's torque per step. The
    # drivetrain is rigid: with the default one's backlash the motor side crosses the dead band
    # and knocks the wheel when the ramp starts, which is not what this test is about.
    params = ballbot.WorldParams.preset("miapure_60kg").replace(
        transmission=ballbot.TransmissionParams.preset("rigid")
    )
    mu = params.robot.drivetrain.wheel_ball_friction
    r_w = params.robot.drivetrain.wheel_radius_m
    world = ballbot.World(params)
    world.run(1600)
    world.set_ball_fixed(True)
    world.set_body_fixed(True)
    n = world.step(np.zeros(3)).wheels[0].normal_force_n
    assert n == pytest.approx(343.6, rel=0.03)
    ramp = np.zeros((30_000, 3))
    ramp[:, 0] = 0.001 * np.arange(30_000)
    run = world.run(30_000, ramp)
    slipping = run.slipping[:, 0]
    assert run.slipping.dtype == np.bool_ and slipping.any()
    onset = int(np.argmax(slipping))
    assert np.all(np.abs(run.wheel_speed_rad_per_s[:onset, 0]) < 1e-2)
    threshold_nm = mu * n * r_w
    assert abs(ramp[onset, 0] - threshold_nm) < 0.01 + 1e-3 * threshold_nm
    assert abs(run.traction_demand_n[onset, 0]) > mu * run.normal_force_n[onset, 0]


def test_free_flight_conserves_momentum() -> None:
    # No contact damping: the linear law's and the coating's (its loss factor, floor and wheels).
    params = ballbot.WorldParams(
        contact={"normal_damping_n_s_per_m": 0.0},
        floor={"coating_loss_factor": 0.0},
        wheel_damping_nm_s_per_rad=0.0,
        rolling_resistance=0.0,
        spin_friction_m=0.0,
    )
    world = ballbot.World(params)
    world.set_gravity_m_per_s2(0.0)
    world.set_wheel_ball_friction(0.0)
    world.translate_robot([0.0, 0.0, 1.0])
    world.set_body_velocity([0.3, -0.2, -0.05], [0.4, -0.3, 1.5])
    world.set_ball_velocity(np.array([-0.2, 0.1, 0.4]), (2.0, 1.0, -3.0))
    p0, l0 = world.linear_momentum_ns(), world.angular_momentum_nms()
    e0 = world.kinetic_energy_j() + world.contact_energy_j()
    run = world.run(8000)
    assert np.sum(np.any(run.normal_force_n > 0.0, axis=1)) > 10, "they must collide"
    assert np.linalg.norm(world.linear_momentum_ns() - p0) < 1e-9
    assert np.linalg.norm(world.angular_momentum_nms() - l0) < 1e-3 * np.linalg.norm(l0)
    e1 = world.kinetic_energy_j() + world.contact_energy_j()
    assert abs(e1 - e0) < 0.015 * e0
    # A push adds exactly its impulse to the linear momentum.
    before = world.linear_momentum_ns()
    world.push_body([5.0, -2.0, 1.0])
    assert world.linear_momentum_ns() - before == pytest.approx([5.0, -2.0, 1.0], abs=1e-9)
    assert world.chassis_clearance_m() > 0.5 and world.potential_energy_j() == 0.0


def test_wheel_speeds_match_kinematics_under_the_core_controller() -> None:
    # High friction, slow diagonal drive under the core's controller: each wheel's turned
    # angle must equal the integral of (r / r_W) u_i . omega_rel (no accumulated slip).
    # The ideal world's continuous rim: roller gaps change the rolling radius by up to 0.6 %.
    params = ballbot.WorldParams.preset("ideal_miapure_60kg").replace(
        robot={"drivetrain": {"wheel_ball_friction": 2.0}}
    )
    drive = params.robot.drivetrain
    r, r_w, a = params.robot.ball_radius_m, drive.wheel_radius_m, drive.contact_angle_rad
    sim = ballbot.WorldLoop(params)
    n = 24_000
    t = np.arange(n) * params.dt_secs
    command = np.zeros((n, 3))
    command[:, 0] = 0.2 * np.minimum(t, 1.0)
    command[:, 1] = 0.1 * np.minimum(t, 1.0)
    run = sim.run(n, command)
    assert run.failure is None and sim.mode is ballbot.Mode.BALANCING
    late = run.time_secs > 1.5
    rot = rotation_matrix(run.body_orientation[late])
    w_ball_body = np.einsum("nji,nj->ni", rot, run.ball_angular_velocity_rad_per_s[late])
    w_rel = w_ball_body - run.body_rate_rad_per_s[late]
    b = drive.wheel_azimuths_rad
    u = np.stack([-math.cos(a) * np.cos(b), -math.cos(a) * np.sin(b), np.full(3, math.sin(a))])
    predicted = params.dt_secs * r / r_w * np.sum(w_rel @ u, axis=0)
    angles = run.wheel_angle_rad[late]
    turned = angles[-1] - angles[0]
    # The first late sample's own increment is inside `predicted` but not in `turned`.
    first = params.dt_secs * r / r_w * (w_rel[0] @ u)
    assert np.all(np.abs(predicted) > 1.0)
    assert turned == pytest.approx(predicted - first, rel=5e-3)


def test_core_loop_cruises_at_the_commanded_speed() -> None:
    sim = ballbot.WorldLoop()
    assert sim.mode is ballbot.Mode.IDLE
    for _ in range(10):
        sim.step(0.3, 0.0, 0.0)
    run = sim.run(7990, [0.3, 0.0, 0.0], record_every=100)
    assert run.command.shape == (80, 3) and np.all(run.command[:, 0] == 0.3)
    assert run.time_secs[1] - run.time_secs[0] == pytest.approx(100 / 8000)
    assert sim.failure is None
    assert sim.telemetry.ball_velocity_m_per_s[0] == pytest.approx(0.3, abs=0.1)
    m = sim.measure()
    assert m.tilt_rad.shape == (2,) and m.wheel_speed_rad_per_s.shape == (3,)
    # Along x OW1 idles (it rolls along y); OW2 and OW3 turn equally in opposite directions.
    speeds = sim.encoder_speeds_rad_per_s()
    assert abs(speeds[0]) < 0.1 and abs(speeds[1]) > 1.0
    assert speeds[2] == pytest.approx(-speeds[1], rel=0.05)


def test_same_seed_gives_identical_arrays() -> None:
    def run(seed: int) -> ballbot.WorldLoopRun:
        params = ballbot.WorldParams(sensors={"seed": seed})
        ramp = np.zeros((4000, 3))
        ramp[:, 0] = 0.5 * np.arange(4000) / 8000
        return ballbot.WorldLoop(params).run(4000, ramp)

    a, b, c = run(7), run(7), run(8)
    b_fields = b.to_dict()
    for key, value in a.to_dict().items():
        if isinstance(value, np.ndarray):
            assert np.array_equal(value, b_fields[key]), key
    assert not np.array_equal(a.body_rate_rad_per_s, c.body_rate_rad_per_s), "seed"


def test_ramp_unloads_driving_wheels_more_towards_ow1() -> None:
    def min_driving_normal_n(heading_deg: float) -> float:
        settings = ballbot.RampSettings(
            accel_m_per_s2=1.0, max_command_m_per_s=1.0, settle_secs=0.2, sample_every_secs=0.0025
        )
        r = ballbot.max_speed_ramp(heading_deg=heading_deg, settings=settings)
        assert r.failure is None and r.max_speed_m_per_s > 0.9
        assert r.heading_deg == heading_deg
        n = r.time_secs.size
        assert r.normal_force_n.shape == (n, 3) and r.speed_m_per_s.shape == (n,)
        assert np.array_equal(r.max_cone_utilisation, r.cone_utilisation.max(axis=1))
        assert np.all(r.shaped_command_m_per_s <= r.command_m_per_s + 1e-12)
        return float(np.min(r.normal_force_n[:, 1:]))

    assert min_driving_normal_n(0.0) < min_driving_normal_n(180.0) - 5.0


def test_max_speed_ramp_is_not_capped_by_the_controllers_speed_limit() -> None:
    """By default the shaper's speed cap is the ramp's top, not the designed 2.0 m/s that ended
    every ramp at about 2.07 m/s whatever the heading."""
    ramp = {"accel_m_per_s2": 1.0, "max_command_m_per_s": 2.4, "settle_secs": 0.1}
    free = ballbot.max_speed_ramp(**ramp)
    capped = ballbot.max_speed_ramp(**ramp, max_speed_m_per_s=2.0)
    assert float(np.max(capped.shaped_command_m_per_s)) <= 2.0 + 1e-9
    assert float(np.max(free.shaped_command_m_per_s)) > 2.2, free.failure
    assert free.max_speed_m_per_s > capped.max_speed_m_per_s + 0.1


def test_falling_robot_fails_and_the_run_stops_there() -> None:
    world = ballbot.World()
    world.tilt_body((0.0, 0.05))
    run = world.run(40_000, stop_on_failure=True, record_every=1000)
    failure = world.failure
    assert failure is not None and run.failure == failure
    assert failure.kind in (
        ballbot.FailureKind.TILT,
        ballbot.FailureKind.BODY_TOUCHED_FLOOR,
        ballbot.FailureKind.LIFT_OFF,
    )
    assert run.steps < 40_000
    assert run.time_secs[-1] == pytest.approx(failure.time_secs)
    assert "Failure(kind=" in repr(failure)


def test_world_params_keywords_presets_and_files(tmp_path: Path) -> None:
    default = ballbot.WorldParams()
    assert default == ballbot.WorldParams.preset("miapure_60kg")
    assert set(ballbot.WorldParams.presets()) == {"miapure_60kg", "miapure_unloaded", "ideal_miapure_60kg"}
    unloaded = ballbot.WorldParams.preset("miapure_unloaded")
    assert unloaded.robot == ballbot.BallbotParams.preset("miapure_unloaded")
    assert ballbot.WorldParams.with_robot(unloaded.robot) == unloaded
    p = default.replace(
        dt_secs=1.0 / 16000,
        contact=ballbot.ContactParams(kinetic_friction_ratio=0.7),
        sensors={"seed": 3, "encoder_counts_per_rev": 4096},
    )
    assert p.dt_secs == 1.0 / 16000 and p.contact.kinetic_friction_ratio == 0.7
    assert p.sensors.seed == 3 and p.sensors.encoder_counts_per_rev == 4096
    assert p.failure == ballbot.FailureParams.preset("default")
    assert p.reflected_wheel_inertia_kg_m2() > p.wheel_inertia_kg_m2
    path = tmp_path / "world.toml"
    p.save(path)
    assert ballbot.WorldParams.load(path) == p
    assert ballbot.WorldParams.from_dict(p.to_dict()) == p
    assert "sensors=SensorParams(" in repr(p)


def test_bad_world_input_raises_documented_errors() -> None:
    with pytest.raises(ballbot.ParameterError, match="unknown preset `nope` for WorldParams"):
        ballbot.WorldParams.preset("nope")
    with pytest.raises(ValueError, match="contact.kinetic_friction_ratio"):
        ballbot.WorldParams(contact={"kinetic_friction_ratio": 1.5})
    with pytest.raises(ballbot.ParameterError, match="unknown parameter `contact.mu`"):
        ballbot.WorldParams(contact={"mu": 1.0})
    with pytest.raises(ballbot.ParameterError, match="dt_secs"):
        ballbot.WorldParams(dt_secs=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="sensors.seed"):
        ballbot.WorldParams(sensors={"seed": -1})
    with pytest.raises(ballbot.ParameterError, match="sensors.encoder_counts_per_rev"):
        ballbot.SensorParams(encoder_counts_per_rev=0)
    with pytest.raises(ballbot.ParameterError, match="seed"):
        ballbot.SensorParams(seed=True)
    world = ballbot.World()
    with pytest.raises(ballbot.ShapeError, match="`torque_nm` must be 3 numbers"):
        world.step([1.0, 2.0])
    with pytest.raises(ballbot.ParameterError, match="`torque_nm` must be finite"):
        world.step([0.0, float("nan"), 0.0])
    with pytest.raises(ballbot.ShapeError, match=r"\(n_steps, 3\) = \(10, 3\)"):
        world.run(10, np.zeros((5, 3)))
    bad = np.zeros((10, 3))
    bad[3, 1] = np.inf
    with pytest.raises(ballbot.ParameterError, match="row 3"):
        world.run(10, bad)
    with pytest.raises(ballbot.ParameterError, match="record_every"):
        world.run(10, record_every=0)
    # A negative count is a ValueError naming the argument (pyo3's OverflowError named none).
    with pytest.raises(ballbot.ParameterError, match=r"`n_steps`: must be >= 0, got -5"):
        world.run(-5)
    with pytest.raises(ballbot.ParameterError, match=r"`record_every`: must be >= 1, got -1"):
        world.run(10, record_every=-1)
    with pytest.raises(ValueError, match="`n_steps`"):
        ballbot.WorldLoop().run(-5)
    with pytest.raises(ballbot.ParameterError, match="impulse_ns"):
        world.push_body([float("nan"), 0.0, 0.0])
    with pytest.raises(ballbot.ParameterError, match="friction"):
        world.set_wheel_ball_friction(-0.1)
    assert world.time_secs == 0.0, "rejected input must not step the world"
    with pytest.raises(MemoryError):
        world.run(1 << 60)
    sim = ballbot.WorldLoop()
    with pytest.raises(ballbot.ParameterError, match="velocity command"):
        sim.step(float("nan"))
    with pytest.raises(ballbot.ParameterError, match="max_speed_m_per_s"):
        ballbot.WorldLoop(max_speed_m_per_s=-1.0)
    with pytest.raises(ballbot.ParameterError, match="accel_m_per_s2"):
        ballbot.max_speed_ramp(accel_m_per_s2=0.0)
    with pytest.raises(ballbot.ParameterError, match="outer_dt_secs"):
        ballbot.WorldLoop(ballbot.WorldParams(dt_secs=1.0 / 7000))


def test_the_default_drivetrain_has_stiction_a_coupling_and_backlash() -> None:
    default = ballbot.WorldParams.preset("miapure_60kg").transmission
    assert default == ballbot.TransmissionParams.preset("miapure")
    assert default.stiction_torque_nm == pytest.approx(0.37)
    assert default.coupling_stiffness_nm_per_rad > 0.0 and default.backlash_rad > 0.0
    rigid = ballbot.WorldParams.preset("ideal_miapure_60kg").transmission
    assert rigid == ballbot.TransmissionParams.preset("rigid")
    assert rigid.coupling_stiffness_nm_per_rad == 0.0
    with pytest.raises(ValueError, match="transmission.coulomb_torque_nm"):
        ballbot.TransmissionParams(stiction_torque_nm=0.1, coulomb_torque_nm=0.2)
    # A motor torque below the gearbox's breakaway does not turn the motor side: stiction holds
    # it with exactly that torque, and nothing reaches the wheel (ball and body clamped).
    world = ballbot.World(ballbot.WorldParams.preset("miapure_60kg"))
    world.run(1600)
    world.set_ball_fixed(True)
    world.set_body_fixed(True)
    tau = 0.3
    run = world.run(4000, np.tile([tau, 0.0, 0.0], (4000, 1)))
    w = world.telemetry.wheels[0]
    assert w.motor_torque_nm == pytest.approx(tau)
    assert w.gearbox_friction_nm == pytest.approx(w.motor_torque_nm)
    assert abs(w.motor_speed_rad_per_s) < 1e-9 and w.coupling_torque_nm == 0.0
    assert run.slipping[:, 0].sum() == 0


def test_miapures_sensors_read_a_filtered_delayed_imu() -> None:
    sensors = ballbot.SensorParams.preset("miapure")
    assert sensors.imu == ballbot.ImuParams.preset("vn100")
    assert sensors.imu.model == "attitude_filter" and sensors.link_latency_secs > 0.0
    # Not yet in the default world (docs/world-sensing.md); a world takes them as a part.
    default = ballbot.WorldParams.preset("miapure_60kg").sensors
    assert default.imu.model == "truth" and default.link_latency_secs == 0.0
    world = ballbot.WorldParams.preset("miapure_60kg").replace(sensors=sensors)
    assert world.sensors.imu.filter_time_constant_secs == pytest.approx(2.29, abs=0.01)
    with pytest.raises(ValueError, match="sensors.imu.sample_rate_hz"):
        ballbot.ImuParams(model="attitude_filter", sample_rate_hz=700.0)
    # The continuous filter's error starts at 0 and goes to the apparent vertical's lean.
    imu = sensors.imu
    lean = np.arctan2(1.0, 9.81)
    assert imu.tilt_error_under_acceleration_rad(1.0, 9.81, 0.0) == pytest.approx(0.0, abs=1e-15)
    late = imu.tilt_error_under_acceleration_rad(1.0, 9.81, 10.0 * imu.filter_time_constant_secs)
    assert late == pytest.approx(lean, rel=1e-3)


def test_correcting_the_imu_filters_lean_brings_the_robot_to_rest_after_a_stop() -> None:
    params = ballbot.WorldParams.preset("miapure_60kg").replace(
        sensors=ballbot.SensorParams.preset("miapure")
    )
    tau = params.sensors.imu.filter_time_constant_secs

    # A 0.5 m/s^2 ramp to 1.4 m/s from 0.5 s, a stop command at 5 s; the speed at 7 s.
    t = np.arange(7 * 8000) / 8000.0
    vx = np.where((t >= 0.5) & (t < 5.0), np.minimum((t - 0.5) * 0.5, 1.4), 0.0)
    command = np.stack([vx, np.zeros_like(vx), np.zeros_like(vx)], axis=1)

    def speed_after_stop(correction: bool) -> float:
        sim = ballbot.WorldLoop(params, imu_lean_time_constant_secs=tau if correction else None)
        sim.run(len(t), command, record_every=8000)
        assert sim.failure is None
        return float(np.linalg.norm(sim.telemetry.ball_velocity_m_per_s))

    assert speed_after_stop(False) > 0.1
    assert speed_after_stop(True) < 0.05
    with pytest.raises(ValueError, match="imu_lean.filter_time_constant_secs"):
        ballbot.WorldLoop(params, imu_lean_time_constant_secs=-1.0)


def test_the_floor_is_the_coatings_compliant_contact_and_can_be_inclined() -> None:
    floor = ballbot.WorldParams.preset("miapure_60kg").floor
    assert floor == ballbot.FloorParams.preset("miapure")
    assert floor == ballbot.WorldParams.preset("ideal_miapure_60kg").floor
    assert floor.coating_shore_a_hardness == 60.0 and floor.slope_rad == 0.0
    with pytest.raises(ValueError, match="floor.slope_rad"):
        ballbot.FloorParams(slope_rad=0.7)
    # At rest on the level floor the ball sits 1.20 mm deep in its coating, carrying the
    # robot's weight; on a 0.05 rad incline the floor's force is still the weight, now with
    # friction along the slope.
    params = ballbot.WorldParams.preset("miapure_60kg")
    world = ballbot.World(params)
    run = world.run(800)
    weight = (params.robot.sagittal.ball_mass_kg + params.robot.sagittal.body_mass_kg) * 9.81
    assert run.floor_force_n[-1] == pytest.approx(weight, rel=0.01)
    inclined = params.replace(floor=floor.replace(slope_rad=0.05))
    assert inclined.floor.slope_rad == 0.05
    ballbot.World(inclined).run(80)


def test_the_wheel_contacts_follow_the_coatings_law_in_the_default_world() -> None:
    default = ballbot.WorldParams.preset("miapure_60kg").contact
    assert default.normal_law == "coating" and default.roller_radius_m == 0.011
    assert ballbot.ContactParams().normal_law == "linear"
    assert ballbot.ContactParams.preset("coating").normal_law == "coating"
    assert ballbot.ContactParams(normal_law="coating").to_dict()["normal_law"] == "coating"
    with pytest.raises(ValueError, match="contact.roller_radius_m"):
        ballbot.ContactParams(roller_radius_m=0.0)
    with pytest.raises(ValueError):
        ballbot.ContactParams(normal_law="cubic")
    # At rest each wheel carries its share of the body's weight on its tilted normal, 2.7 mm
    # deep in the coating (the whole-range law; its linear fit would press 1.0 mm).
    params = ballbot.WorldParams.preset("ideal_miapure_60kg").replace(
        contact=ballbot.ContactParams.preset("coating")
    )
    world = ballbot.World(params)
    world.run(800)
    loads = [w.normal_force_n for w in world.telemetry.wheels]
    assert loads == pytest.approx([349.0] * 3, rel=0.005)
