"""Drives: friction models, transmissions (plain and coupled), motor electrics, energy.

Checked against independent references: the seed equations written out here sample by sample with
Pinocchio for the rigid-body part, closed-form cases, and identities (V I == eq 23 power, power
balance through the transmission, breakdown parts adding up to the electrical energy).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import random_state
from test_friction_models import NEW_MODELS

import kinergy
from kinergy.accounting.energy import energy
from kinergy.drives.coupled import coupled_joint_dynamics
from kinergy.drives.electrics import electrical_power
from kinergy.drives.transmission import (
    joint_torque,
    motor_speed,
    motor_torque,
    reflected_inertia,
)
from kinergy.errors import KinergyError
from kinergy.friction.registry import MODELS, get_model
from kinergy.model import Drive, Friction, Joint, Limits, Link, Robot
from kinergy.predict import drive_state
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import paper_trajectory

pin = pytest.importorskip("pinocchio")
from kinergy.dynamics.pinocchio import to_pinocchio  # noqa: E402

PARAMS = {
    "none": {},
    "viscous_coulomb": {"viscous": 2e-4, "coulomb": 0.05, "smoothing": 1e-3},
    "motor_reducer": {
        "motor_viscous": 6.6e-5,
        "motor_coulomb": 0.074,
        "reducer_coulomb": 0.069,
        "smoothing": 1e-3,
    },
    "power_flow": {
        "viscous": 4.75e-4,
        "coulomb_direct": 0.0938,
        "coulomb_reverse": 0.071,
        "smoothing": 1e-3,
    },
    "makkar": {
        "gamma1": 0.02,
        "gamma2": 50.0,
        "gamma3": 5.0,
        "gamma4": 0.05,
        "gamma5": 100.0,
        "gamma6": 3e-4,
    },
    "stribeck": {
        "coulomb": 0.05,
        "static": 0.08,
        "stribeck_speed": 2.0,
        "viscous": 2e-4,
        "smoothing": 1e-3,
    },
    **NEW_MODELS,
}


def test_every_model_has_test_parameters() -> None:
    assert set(PARAMS) == set(MODELS)


@pytest.mark.parametrize("model", sorted(MODELS))
def test_friction_opposes_motion(model: str) -> None:
    wm = np.random.default_rng(0).normal(0, 100, 500)
    load = np.random.default_rng(1).normal(0, 1, 500)
    tau = get_model(model).friction_torque(PARAMS[model], wm, load)
    if model == "none":
        assert np.all(tau == 0)
    else:
        assert np.all(tau * wm >= 0)  # dissipative: friction power tau * wm >= 0 always
        assert np.all(np.abs(tau[np.abs(wm) > 1.0]) > 0)


def test_power_flow_picks_the_coulomb_level_by_power_direction() -> None:
    # UR5e eqs 12-13 at speeds where tanh = 1
    p = PARAMS["power_flow"]
    wm = np.array([10.0, 10.0, -10.0, -10.0])
    load = np.array([1.0, -1.0, -1.0, 1.0])  # direct, reverse, direct, reverse
    expected = p["viscous"] * wm + np.array([1, 1, -1, -1]) * np.array(
        [p["coulomb_direct"], p["coulomb_reverse"], p["coulomb_direct"], p["coulomb_reverse"]]
    )
    np.testing.assert_allclose(
        get_model("power_flow").friction_torque(p, wm, load), expected, rtol=1e-12
    )
    with pytest.raises(KinergyError, match="load torque"):
        get_model("power_flow").friction_torque(p, wm)


def test_stribeck_and_makkar_closed_forms() -> None:
    s = PARAMS["stribeck"]
    # at zero-ish speed (tanh saturated) the level is the static friction, far out the Coulomb one
    assert get_model("stribeck").friction_torque(s, np.array([0.05]))[0] == pytest.approx(
        s["static"], rel=2e-3
    )
    far = get_model("stribeck").friction_torque(s, np.array([200.0]))[0]
    assert far == pytest.approx(s["coulomb"] + s["viscous"] * 200.0, rel=1e-9)
    g = PARAMS["makkar"]
    w = 0.3
    expected = (
        g["gamma1"] * (np.tanh(g["gamma2"] * w) - np.tanh(g["gamma3"] * w))
        + g["gamma4"] * np.tanh(g["gamma5"] * w)
        + g["gamma6"] * w
    )
    assert get_model("makkar").friction_torque(g, np.array([w]))[0] == pytest.approx(
        expected, rel=1e-14
    )


# --- transmissions -------------------------------------------------------------------------------


def test_transmission_power_balance_on_the_coupled_arm() -> None:
    robot = kinergy.load_robot("nursing-arm")
    rng = np.random.default_rng(2)
    qd = rng.normal(size=(50, 6))
    tau = rng.normal(size=(50, 6))
    tau_m = motor_torque(robot, tau)
    wm = motor_speed(robot, qd)
    np.testing.assert_allclose(np.sum(tau * qd, axis=1), np.sum(tau_m * wm, axis=1), rtol=1e-10)
    np.testing.assert_allclose(joint_torque(robot, tau_m), tau, atol=1e-9)


def test_nursing_coupling_is_eq_3() -> None:
    # phi1 = q_pitch + q_rot, phi2 = q_pitch - q_rot for each coupled joint (pitch first)
    robot = kinergy.load_robot("nursing-arm")
    block = np.array([[1.0, 1.0], [1.0, -1.0]])
    assert robot.coupling is not None
    for k in range(3):
        np.testing.assert_array_equal(robot.coupling[2 * k : 2 * k + 2, 2 * k : 2 * k + 2], block)


def test_reflected_inertia_is_ur5e_eq_2_and_nursing_eq_4() -> None:
    ur5e = kinergy.load_robot("ur5e")
    expected = np.diag([100.0**2 * j.drive.rotor_inertia for j in ur5e.joints])
    np.testing.assert_allclose(reflected_inertia(ur5e), expected, rtol=1e-14)
    # a differential joint: C^T diag(J1, J2) C (branch inertias at the bevel gears) gives
    # nursing eq 4's motor-branch terms J11 = J1 + J2, J12 = J1 - J2 (rotation q1 first there)
    j1, j2 = 0.0692, 0.0500
    c = np.array([[1.0, 1.0], [-1.0, 1.0]])  # eq 3: phi = C [q1 (rotation), q2 (pitch)]
    np.testing.assert_allclose(
        c.T @ np.diag([j1, j2]) @ c, [[j1 + j2, j1 - j2], [j1 - j2, j1 + j2]]
    )
    nursing = kinergy.load_robot("nursing-arm")
    block = reflected_inertia(nursing)[:2, :2]
    jm = [
        nursing.joints[k].drive.rotor_inertia * nursing.joints[k].drive.gear_ratio ** 2
        for k in (0, 1)
    ]
    np.testing.assert_allclose(
        block,
        [[jm[0] + jm[1], jm[0] - jm[1]], [jm[0] - jm[1], jm[0] + jm[1]]],
        rtol=1e-12,
        atol=1e-15,
    )


def test_coupled_joint_dynamics_table_2() -> None:
    # nursing eqs 10-11 with Table 2 (kg mm^2 -> kg m^2), against the Lagrangian by hand
    t2 = {
        "j1": 6.92e4 * 1e-6,
        "j2": 6.92e4 * 1e-6,
        "j3": 2.15e2 * 1e-6,
        "jh": 5.17e2 * 1e-6,
        "m3": 0.285,
        "r_h": 0.0523,
        "m_he": 0.608,
        "r_he": 0.04597,
    }
    q2 = np.array([0.3, -1.0])
    qdd = np.array([[1.0, 0.0], [0.5, -2.0]])
    out = coupled_joint_dynamics(q2, qdd, **t2)
    j11 = t2["j1"] + t2["j2"] + t2["j3"]
    j22 = t2["j1"] + t2["j2"] + t2["jh"] + t2["m3"] * t2["r_h"] ** 2
    expected = np.column_stack(
        [j11 * qdd[:, 0], j22 * qdd[:, 1] + t2["m_he"] * 9.81 * t2["r_he"] * np.sin(q2)]
    )
    np.testing.assert_allclose(out, expected, rtol=1e-12)


# --- electrics -----------------------------------------------------------------------------------


def _with_resistance(robot: Robot, ohms: float) -> Robot:
    joints = [
        dataclasses.replace(j, drive=dataclasses.replace(j.drive, winding_resistance=ohms))
        for j in robot.joints
    ]
    return robot.with_joints(joints)


@pytest.mark.parametrize("resistance", [None, 0.4])
def test_power_is_voltage_times_current(ur5e: Robot, resistance: float | None) -> None:
    robot = ur5e if resistance is None else _with_resistance(ur5e, resistance)
    q, qd, qdd = random_state(robot, 100, seed=3)
    s = drive_state(robot, q, qd, qdd)
    np.testing.assert_allclose(s.power, s.voltage * s.current, rtol=1e-10)  # eq 21 == eq 23
    if resistance is not None:
        kt = np.array([j.drive.torque_constant for j in robot.joints])
        np.testing.assert_allclose(s.voltage - resistance * s.current, s.wm * kt / 0.89, rtol=1e-10)


def _seed_equations(robot: Robot, motion: Motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """UR5e eqs 2, 11-17, 23, 25-26 written out sample by sample, Pinocchio for f_link."""
    model = to_pinocchio(robot)
    data = model.createData()
    n = robot.n
    p_mech = np.zeros((len(motion), n))
    p_elec = np.zeros((len(motion), n))
    current = np.zeros((len(motion), n))
    for k in range(len(motion)):
        f_link = pin.rnea(model, data, motion.q[k], motion.qd[k], motion.qdd[k])
        for j, joint in enumerate(robot.joints):
            d = joint.drive
            i = d.gear_ratio
            wm = i * motion.qd[k, j]
            dwm = i * motion.qdd[k, j]
            tau_sim = f_link[j] + i * (d.motor_inertia + d.reducer_inertia) * dwm  # eq 2
            p = d.friction.params
            wdir = wm if motion.qd[k, j] * tau_sim > 0 else 0.0  # eqs 15-16
            wrev = wm if motion.qd[k, j] * tau_sim < 0 else 0.0
            tau_m = (
                tau_sim / i
                + p["viscous"] * wm
                + np.tanh(wdir / p["smoothing"]) * p["coulomb_direct"]
                + np.tanh(wrev / p["smoothing"]) * p["coulomb_reverse"]
            )  # eq 17 times k_t
            current[k, j] = tau_m / d.torque_constant
            p_mech[k, j] = tau_m * wm  # eq 25 integrand
            p_elec[k, j] = tau_m**2 / d.motor_constant**2 + wm * tau_m / d.kt_over_kb  # eq 23
    return p_mech, p_elec, current


def test_energy_matches_the_seed_equations(ur5e: Robot) -> None:
    motion = paper_trajectory(ur5e, "test-a", dt=0.01)
    report = energy(ur5e, motion)
    p_mech, p_elec, current = _seed_equations(ur5e, motion)
    e_mech = np.trapezoid(p_mech, motion.t, axis=0)
    e_elec = np.trapezoid(p_elec, motion.t, axis=0)
    np.testing.assert_allclose(report.e_mech, e_mech, rtol=1e-2)  # the acceptance bar: 1 %
    np.testing.assert_allclose(report.e_elec, e_elec, rtol=1e-2)
    np.testing.assert_allclose(report.e_mech, e_mech, rtol=1e-9)  # and in fact to round-off
    np.testing.assert_allclose(report.e_elec, e_elec, rtol=1e-9)
    np.testing.assert_allclose(report.drive.current, current, rtol=1e-9, atol=1e-12)
    assert report.total_efficiency == pytest.approx(e_mech.sum() / e_elec.sum(), rel=1e-9)


def test_energy_breakdown_adds_up_and_recovery_clips(ur5e: Robot) -> None:
    motion = paper_trajectory(ur5e, "test-b", dt=0.01)
    signed = energy(ur5e, motion)
    parts = sum(signed.breakdown.values())
    np.testing.assert_allclose(parts, signed.e_elec, rtol=1e-9)
    # a rest-to-rest cycle back to the start: inertial and gravity energy net to about zero
    assert abs(signed.breakdown["gravity"].sum()) < 0.02 * signed.total_e_elec
    clipped = energy(ur5e, motion, recovery=False)
    assert np.all(clipped.e_elec >= signed.e_elec - 1e-9)
    assert clipped.total_e_elec >= signed.total_e_elec


def test_energy_of_a_constant_speed_turn_is_closed_form() -> None:
    # one vertical joint, no gravity torque, constant speed: every term integrates by hand
    friction = Friction("viscous_coulomb", {"viscous": 3e-4, "coulomb": 0.08, "smoothing": 1e-3})
    drive = Drive(
        gear_ratio=100.0,
        motor_inertia=5e-5,
        reducer_inertia=1e-4,
        torque_constant=0.1,
        motor_constant=0.25,
        kt_over_kb=0.89,
        friction=friction,
    )
    joint = Joint(
        "turn",
        d=0.1,
        a=0.3,
        alpha=0.0,
        offset=0.0,
        link=Link(mass=2.0, com=[-0.1, 0.0, 0.0], inertia=[0.01, 0.02, 0.02, 0, 0, 0]),
        drive=drive,
        limits=Limits(position=[-10, 10], speed=3.0, torque=100.0),
    )
    robot = Robot(name="turntable", convention="dh", joints=(joint,))
    w, duration = 1.5, 4.0
    t = np.linspace(0.0, duration, 401)
    motion = Motion(t, (w * t)[:, None], np.full((401, 1), w), np.zeros((401, 1)))
    report = energy(robot, motion)
    wm = 100.0 * w
    tau_m = 3e-4 * wm + 0.08 * np.tanh(wm / 1e-3)
    assert report.e_mech[0] == pytest.approx(tau_m * wm * duration, rel=1e-12)
    assert report.e_elec[0] == pytest.approx(
        (tau_m**2 / 0.25**2 + wm * tau_m / 0.89) * duration, rel=1e-12
    )
    assert report.breakdown["inertial"][0] == pytest.approx(0.0, abs=1e-9)


def test_standby_power_is_reported(ur5e: Robot) -> None:
    robot = dataclasses.replace(ur5e, standby_power=20.0)
    motion = paper_trajectory(robot, "test-a", dt=0.02)
    out = energy(robot, motion).to_dict()
    assert out["total"]["standby"] == pytest.approx(20.0 * motion.duration)
    assert out["total"]["e_elec_with_standby"] == pytest.approx(
        out["total"]["e_elec"] + 20.0 * motion.duration
    )


def test_test_a_efficiency_is_near_table_viii(ur5e: Robot) -> None:
    # UR5e doc Table VIII: eta 84.17 % on test A (their random points; ours differ)
    report = energy(ur5e, paper_trajectory(ur5e, "test-a"))
    assert 0.80 < report.total_efficiency < 0.88


def test_electrical_power_formula_directly(ur5e: Robot) -> None:
    tau_m = np.array([[0.5, -0.2, 0.1, 0.05, -0.03, 0.02]])
    wm = np.array([[100.0, -50.0, 20.0, 300.0, 10.0, -5.0]])
    km = np.array([0.27426] * 3 + [0.06632] * 3)
    np.testing.assert_allclose(
        electrical_power(ur5e, tau_m, wm), tau_m**2 / km**2 + wm * tau_m / 0.89, rtol=1e-12
    )


@pytest.mark.parametrize("model", sorted(MODELS))
def test_friction_columns_reproduce_the_model(model: str) -> None:

    rng = np.random.default_rng(12)
    wm = rng.normal(0, 50, 300)
    load = rng.normal(0, 1, 300)
    params = PARAMS[model]
    cols = get_model(model).friction_columns(params, wm, load)
    assert cols.shape == (300, len(get_model(model).linear))
    values = np.array([params.get(n, 0.0) for n in get_model(model).linear])
    if model == "motor_reducer":
        values[1] = params["motor_coulomb"] + params["reducer_coulomb"]
    np.testing.assert_allclose(
        cols @ values, get_model(model).friction_torque(params, wm, load), rtol=1e-12, atol=1e-15
    )
    # new linear values go back into a parameter set that evaluates to the new columns' torque
    new = values * 1.7 + 0.01
    updated = get_model(model).with_values(params, new)
    np.testing.assert_allclose(
        get_model(model).friction_torque(updated, wm, load), cols @ new, rtol=1e-12, atol=1e-15
    )
