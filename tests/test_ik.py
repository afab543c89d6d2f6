"""Analytic UR inverse kinematics: every branch reproduces the pose, the controller's choice."""

from __future__ import annotations

import numpy as np
import pytest

from kinergy.dynamics.ik import (
    branch_of,
    ik_branches,
    joint_limits,
    nearest_solution,
    ur_geometry,
    wrap_choices,
)
from kinergy.dynamics.kinematics import flange_pose
from kinergy.errors import KinergyError
from kinergy.model.library import load_robot


@pytest.mark.parametrize("name", ["ur5e", "ur10e", "ur3e"])
def test_every_branch_reaches_the_pose(name: str) -> None:
    robot = load_robot(name)
    g = ur_geometry(robot)
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, size=(20, 6))
    poses = flange_pose(robot, q)
    sols = ik_branches(g, poses, hint6=q[:, 5])  # (20, 8, 6)
    found = 0
    for i in range(q.shape[0]):
        for b in range(8):
            if np.any(np.isnan(sols[i, b])):
                continue
            found += 1
            np.testing.assert_allclose(flange_pose(robot, sols[i, b]), poses[i], atol=1e-8)
        # the joints the pose came from are one of the branches (up to 2 pi)
        b = branch_of(g, q[i], poses[i])
        diff = np.angle(np.exp(1j * (sols[i, b] - q[i])))
        np.testing.assert_allclose(diff, 0.0, atol=1e-7)
    assert found >= 8 * q.shape[0] * 0.5


def test_chosen_branches_are_the_columns_of_all_eight() -> None:
    robot = load_robot("ur10e")
    g = ur_geometry(robot)
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, size=(30, 6))
    poses = flange_pose(robot, q)
    every = ik_branches(g, poses, hint6=q[:, 5])
    for pick in ([3], [7, 0, 5], list(range(8))):
        np.testing.assert_array_equal(
            ik_branches(g, poses, hint6=q[:, 5], branches=pick), every[:, pick]
        )
    with pytest.raises(KinergyError, match="branches are 0-7"):
        ik_branches(g, poses, branches=[8])


def test_nearest_solution_is_the_controllers_choice() -> None:
    robot = load_robot("ur5e")
    g = ur_geometry(robot)
    q = np.array([0.4, -1.5, 1.7, -1.8, -1.57, 4.0])  # wrist 3 beyond pi
    q_found, branch = nearest_solution(robot, g, flange_pose(robot, q), q + 0.05)
    np.testing.assert_allclose(q_found, q, atol=1e-8)
    assert branch == branch_of(g, q, flange_pose(robot, q))


def test_unreachable_pose_is_one_clear_line() -> None:
    robot = load_robot("ur5e")
    far = np.eye(4)
    far[:3, 3] = [3.0, 0.0, 0.5]
    with pytest.raises(KinergyError, match="out of reach"):
        nearest_solution(robot, ur_geometry(robot), far, np.zeros(6))


def test_wrap_choices_stay_within_the_limits() -> None:
    lo, hi = joint_limits(load_robot("ur5e"))
    choices = wrap_choices(np.full(6, 1.0), lo, hi)
    finite = choices[~np.isnan(choices)]
    assert np.all((finite >= -2 * np.pi) & (finite <= 2 * np.pi))
    assert np.sum(~np.isnan(choices[0])) == 2  # 1 and 1 - 2 pi


def test_other_arms_have_no_closed_form() -> None:
    with pytest.raises(KinergyError):
        ur_geometry(load_robot("panda"))
