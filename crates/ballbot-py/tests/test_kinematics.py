"""Omniwheel kinematics from Python: the numbers of MODEL.md sections 4-6 and the Rust tests,
round trips both ways, vectorisation, and shape errors."""

import math

import numpy as np
import pytest

import ballbot


def test_capacity_matches_model_md(kin: ballbot.OmniKinematics) -> None:
    assert kin.planar_torque_capacity_nm() == pytest.approx([83.9, 96.9, 167.9], abs=0.05)


def test_sagittal_travel_leaves_wheel_one_idle(kin: ballbot.OmniKinematics) -> None:
    psi_dot = kin.wheel_speeds_rad_per_s([0.0, 5.0, 0.0])
    assert psi_dot.shape == (3,)
    assert psi_dot[0] == pytest.approx(0.0, abs=1e-12)
    assert psi_dot[1] == pytest.approx(-psi_dot[2], rel=1e-12)


def test_speeds_and_torques_round_trip_vectorised(kin: ballbot.OmniKinematics) -> None:
    rng = np.random.default_rng(3)
    omega = rng.normal(size=(200, 3))
    tau = rng.normal(scale=30.0, size=(200, 3))
    psi_dot = kin.wheel_speeds_rad_per_s(omega)
    assert psi_dot.shape == (200, 3)
    assert kin.relative_rate_rad_per_s(psi_dot) == pytest.approx(omega, rel=1e-10, abs=1e-12)
    motor = kin.motor_speeds_rad_per_s(omega)
    assert motor == pytest.approx(7.5 * psi_dot, rel=1e-12)
    assert kin.relative_rate_from_motor_speeds_rad_per_s(motor) == pytest.approx(omega, abs=1e-10)
    wheel_tau = kin.wheel_torques_nm(tau)
    assert kin.planar_torque_nm(wheel_tau) == pytest.approx(tau, abs=1e-10)
    assert kin.planar_torque_from_motor_torques_nm(kin.motor_torques_nm(tau)) == pytest.approx(
        tau, abs=1e-10
    )
    # Power balance: sum_i tau_i psi_dot_i = tau_x w_x + tau_y w_y - tau_z w_z.
    wheel_power = np.sum(wheel_tau * psi_dot, axis=1)
    planar_power = tau[:, 0] * omega[:, 0] + tau[:, 1] * omega[:, 1] - tau[:, 2] * omega[:, 2]
    assert wheel_power == pytest.approx(planar_power, rel=1e-9, abs=1e-9)
    # Row i of a batch equals the single-row call.
    assert kin.wheel_torques_nm(tau[17]) == pytest.approx(wheel_tau[17], rel=1e-15)
    # The matrices agree with the maps.
    assert kin.wheel_speed_matrix() @ omega[5] == pytest.approx(psi_dot[5], rel=1e-12)
    assert kin.wheel_torque_matrix() @ tau[5] == pytest.approx(wheel_tau[5], rel=1e-12)


def test_model_md_motor_torque_closed_form(kin: ballbot.OmniKinematics) -> None:
    tau = np.array([10.0, -20.0, 5.0])
    a, r_s, r_w = math.radians(45.0), 0.1145, 0.0625
    betas = np.radians([0.0, 120.0, 240.0])
    expected = (r_w / (3 * r_s)) * (
        (2 / math.cos(a)) * (-np.cos(betas) * tau[0] - np.sin(betas) * tau[1])
        - tau[2] / math.sin(a)
    )
    assert kin.wheel_torques_nm(tau) == pytest.approx(expected, rel=1e-12)


def test_static_load_and_contact_forces(kin: ballbot.OmniKinematics, wip: ballbot.Wip) -> None:
    weight = np.array([0.0, 0.0, 74.3 * 9.81])
    c = kin.contact_forces(weight, np.zeros(3))
    assert c.normal_force_n == pytest.approx([343.6] * 3, abs=0.1)
    assert float(c.all_hold) == 1.0 and len(c) == 1
    assert kin.normal_forces_n(weight, np.zeros(3)) == pytest.approx(c.normal_force_n)
    w = kin.wip_contact_forces(wip, 0.0, np.zeros(4), 0.0)
    assert w.normal_force_n == pytest.approx([343.6] * 3, abs=0.1)
    # A batch over headings: accelerating hard towards wheel 1 (0 deg) slips first.
    headings = np.radians([0.0, 90.0, 180.0])
    batch = kin.wip_contact_forces(wip, headings, np.zeros((3, 4)), 20.0)
    assert batch.normal_force_n.shape == (3, 3)
    use = batch.max_friction_utilisation
    assert use.shape == (3,)
    assert use[0] > use[2]


def test_torque_intervals(kin: ballbot.OmniKinematics, wip: ballbot.Wip) -> None:
    interval = kin.wip_actuator_torque_interval_nm(0.0, np.zeros(4))
    assert interval.shape == (2,)
    assert interval[0] < 0.0 < interval[1]
    # At rest the actuator range at heading 0 is the y capacity (96.9 N m).
    assert interval[1] == pytest.approx(96.9, abs=0.05)
    contact = kin.wip_contact_torque_interval_nm(wip, np.radians([0.0, 180.0]), np.zeros((2, 4)))
    assert contact.shape == (2, 2)
    assert np.all(contact[:, 0] < 0.0) and np.all(contact[:, 1] > 0.0)


def test_saturation_scales_uniformly(kin: ballbot.OmniKinematics) -> None:
    planar, wheel, scale = kin.saturate_planar_torque([0.0, 500.0, 0.0])
    assert float(scale) == pytest.approx(96.9 / 500.0, rel=1e-3)
    assert np.max(np.abs(wheel)) == pytest.approx(43.2)
    planar, wheel, scale = kin.saturate_planar_torque(np.zeros((4, 3)), np.zeros((4, 3)))
    assert scale == pytest.approx(np.ones(4))
    _, _, scale = kin.saturate_planar_torque([float("nan"), 0.0, 0.0])
    assert float(scale) == 0.0


def test_planar_helpers() -> None:
    omega = ballbot.relative_rate_from_planar([[1.0, 2.0]], [[0.5, 0.5]], 3.0)
    assert omega == pytest.approx(np.array([[0.5, 1.5, -3.0]]))
    assert ballbot.relative_rate_at_heading(0.0, 2.0, 0.5) == pytest.approx([0.0, 1.5, 0.0])
    t = ballbot.planar_torque_at_heading(np.radians([0.0, 90.0]), 10.0)
    assert t == pytest.approx(np.array([[0.0, 10.0, 0.0], [-10.0, 0.0, 0.0]]), abs=1e-12)


def test_shape_errors_name_the_expected_shape(kin: ballbot.OmniKinematics) -> None:
    with pytest.raises(ballbot.ShapeError, match=r"`planar_torque_nm` must have shape \(3,\)"):
        kin.wheel_torques_nm(np.zeros(4))
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        kin.wheel_speeds_rad_per_s(np.zeros((2, 2)))
    with pytest.raises(ballbot.ShapeError, match="same shape"):
        kin.contact_forces(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ballbot.ParameterError, match="ball_radius_m"):
        ballbot.OmniKinematics(ballbot.DrivetrainParams(), -1.0)
