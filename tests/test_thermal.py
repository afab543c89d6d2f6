"""The joints' first-order thermal model: the exact step, heating by copper and friction losses,
and the twin warming up with its friction following."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinergy
from kinergy.drives.electrics import winding_resistances
from kinergy.drives.thermal import joint_losses, joint_temperatures
from kinergy.errors import KinergyError
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, realistic_truth, simulate


def test_constant_losses_approach_the_steady_state_exponentially(ur5e: kinergy.Robot) -> None:
    t = np.linspace(0.0, 3600.0, 3601)
    losses = np.tile(np.arange(1.0, 7.0), (t.size, 1))
    temps = joint_temperatures(ur5e, t, losses, ambient=20.0)
    for j, joint in enumerate(ur5e.joints):
        th = joint.drive.thermal
        assert th is not None
        want = 20.0 + th.resistance * losses[0, j] * (
            1 - np.exp(-t / (th.resistance * th.capacity))
        )
        np.testing.assert_allclose(temps[:, j], want, rtol=1e-9, atol=1e-9)
    # irregular time stamps take the same exact step
    ti = np.sort(np.concatenate([t[::7], [1.5, 2.7]]))
    irregular = joint_temperatures(ur5e, ti, losses[: ti.size], ambient=20.0)
    np.testing.assert_allclose(irregular[-1], temps[-1], rtol=1e-4)
    # a warm start cools to ambient without losses
    cool = joint_temperatures(ur5e, t, 0 * losses, ambient=20.0, initial=40.0)
    assert np.all(np.diff(cool, axis=0) <= 0) and np.all(cool[-1] < 40.0)


def test_losses_are_copper_and_friction_and_never_negative(ur5e: kinergy.Robot) -> None:
    current = np.array([[1.0, -2.0, 0, 0, 0, 0]])
    friction = np.array([[0.1, 0.2, -0.3, 0, 0, 0]])
    wm = np.array([[10.0, -5.0, -2.0, 0, 0, 0]])
    p = joint_losses(ur5e, current, friction, wm)
    r = winding_resistances(ur5e)
    assert p[0, 0] == pytest.approx(r[0] * 1.0 + 1.0)
    assert p[0, 1] == pytest.approx(r[1] * 4.0)  # friction driving the motion adds no heat
    assert p[0, 2] == pytest.approx(0.6)
    assert np.all(p >= 0)
    # the arm's standby power heats its joints in equal shares
    shared = joint_losses(ur5e, current, friction, wm, standby=30.0)
    np.testing.assert_allclose(shared - p, 5.0)


def test_a_still_twin_warms_by_its_standby_power(ur5e: kinergy.Robot) -> None:
    truth = realistic_truth(ur5e, 2)
    t = np.arange(0.0, 600.0, 0.5)
    still = kinergy.Motion(t, np.zeros((t.size, 6)), np.zeros((t.size, 6)), np.zeros((t.size, 6)))
    temps = simulate(truth, still, TwinSettings.exact())["joint_temperatures"]
    models = [j.drive.thermal for j in truth.joints]
    want = [
        25.0
        + m.resistance
        * truth.standby_power
        / 6
        * (1 - np.exp(-t[-1] / (m.resistance * m.capacity)))
        for m in models
        if m is not None
    ]
    # copper losses holding the arm against gravity add a little: at least the standby share
    assert np.all(temps[-1] >= np.array(want) - 1e-3)


def test_a_robot_without_thermal_models_is_named(ur5e: kinergy.Robot) -> None:
    joint = ur5e.joints[2]
    cold = ur5e.with_joints(
        [
            *ur5e.joints[:2],
            dataclasses.replace(joint, drive=dataclasses.replace(joint.drive, thermal=None)),
            *ur5e.joints[3:],
        ]
    )
    with pytest.raises(KinergyError, match="elbow"):
        joint_temperatures(cold, [0.0, 1.0], np.zeros((2, 6)))


def test_the_twin_warms_up_and_its_friction_follows(ur5e: kinergy.Robot) -> None:
    truth = realistic_truth(ur5e, 2)
    motion = paper_trajectory(ur5e, "test-a", dt=0.01)
    cold = simulate(truth, motion, TwinSettings.exact())
    warm = simulate(
        truth, motion, dataclasses.replace(TwinSettings.exact(), initial_temperature=45.0)
    )
    temps = cold["joint_temperatures"]
    assert np.all(temps[0] == 25.0) and np.all(temps[-1] > temps[0])
    assert np.all(warm["joint_temperatures"] > temps)
    # viscous friction falls as the joints warm: a warm arm draws less current at speed
    moving = np.abs(motion.qd) > 0.5
    assert np.mean(np.abs(warm["actual_current"][moving])) < np.mean(
        np.abs(cold["actual_current"][moving])
    )
