"""Rigid-body dynamics checked against independent references.

- Pinocchio (built from our model by ``to_pinocchio``): RNEA, mass matrix, regressor·parameters,
  forward kinematics, on dh (ur5e, ur10e) and mdh (nursing-arm) robots, with and without payload.
- Identities: regressor @ parameters == RNEA, M q̈ + h == RNEA, forward ∘ inverse dynamics == id,
  J^T h == the wrench term of RNEA, base regressor full rank and reproducing RNEA.
- Finite differences: the Jacobian against forward kinematics.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_state

import kinergy
from kinergy.dynamics.kinematics import (
    axes_jacobian_rate,
    flange_pose,
    jacobian,
    link_poses,
    tool_axes,
)
from kinergy.dynamics.poses import tcp_jacobian, tcp_pose

pin = pytest.importorskip("pinocchio")
from kinergy.dynamics.pinocchio import to_pinocchio  # noqa: E402

ORACLE_ROBOTS = ["ur5e", "ur10e", "nursing-arm"]
PAYLOAD = kinergy.Payload(
    mass=2.3, com=[0.01, -0.02, 0.06], inertia=[0.012, 0.010, 0.008, 0.001, -0.0005, 0.0008]
)


def _robot(name: str, payload: bool) -> kinergy.Robot:
    if name not in kinergy.library_names():
        pytest.fail(f"built-in robot {name!r} is missing")
    robot = kinergy.load_robot(name)
    return robot.with_payload(PAYLOAD) if payload else robot


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize("payload", [False, True], ids=["bare", "payload"])
@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_rnea_and_regressor_match_pinocchio(name: str, payload: bool) -> None:
    robot = _robot(name, payload)
    model = to_pinocchio(robot)
    data = model.createData()
    q, qd, qdd = random_state(robot, 40, seed=1)
    ours = kinergy.rnea(robot, q, qd, qdd)
    via_regressor = kinergy.regressor(robot, q, qd, qdd) @ kinergy.inertial_parameters(robot)
    oracle = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])
    assert _rel(ours, oracle) < 1e-9
    assert _rel(via_regressor, oracle) < 1e-9


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_mass_matrix_matches_pinocchio_and_rnea_columns(name: str) -> None:
    robot = _robot(name, payload=True)
    model = to_pinocchio(robot)
    data = model.createData()
    q, _, _ = random_state(robot, 10, seed=2)
    m = kinergy.mass_matrix(robot, q)
    for k in range(len(q)):
        oracle = pin.crba(model, data, q[k])
        oracle = np.triu(oracle) + np.triu(oracle, 1).T
        assert _rel(m[k], oracle) < 1e-9
        # column j of M is RNEA with qdd = e_j, no speed, no gravity
        cols = kinergy.rnea(
            robot, np.tile(q[k], (robot.n, 1)), None, np.eye(robot.n), gravity=[0, 0, 0]
        )
        assert _rel(m[k], cols.T) < 1e-9
    np.testing.assert_allclose(m, np.swapaxes(m, 1, 2), atol=1e-12)
    assert np.all(np.linalg.eigvalsh(m) > 0)


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_forward_kinematics_matches_pinocchio(name: str) -> None:
    robot = _robot(name, payload=False)
    model = to_pinocchio(robot)
    data = model.createData()
    fid = model.getFrameId("flange")
    q, _, _ = random_state(robot, 10, seed=3)
    ours = flange_pose(robot, q)
    for k in range(len(q)):
        pin.framesForwardKinematics(model, data, q[k])
        assert np.allclose(ours[k], data.oMf[fid].homogeneous, atol=1e-12)


def test_ur5e_zero_pose_is_the_published_one(ur5e: kinergy.Robot) -> None:
    # UR5e at q = 0: flange at x = a2 + a3, y = -(d4 + d6), z = d1 - d5 (UR DH, Table I)
    pose = flange_pose(ur5e, np.zeros(6))
    np.testing.assert_allclose(
        pose[:3, 3], [-0.425 - 0.3922, -(0.1333 + 0.0996), 0.1625 - 0.0997], atol=1e-12
    )


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_jacobian_matches_finite_differences(name: str) -> None:
    robot = _robot(name, payload=False)
    q, qd, _ = random_state(robot, 5, seed=4)
    jac = jacobian(robot, q)
    h = 1e-6
    for k in range(len(q)):
        # linear part: d(position)/dt; angular part: from dR/dt R^T
        plus = flange_pose(robot, q[k] + h * qd[k])
        minus = flange_pose(robot, q[k] - h * qd[k])
        v = (plus[:3, 3] - minus[:3, 3]) / (2 * h)
        dr = (plus[:3, :3] - minus[:3, :3]) / (2 * h)
        skew = dr @ flange_pose(robot, q[k])[:3, :3].T
        w = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
        np.testing.assert_allclose(jac[k] @ qd[k], np.concatenate([v, w]), atol=1e-7)


@pytest.mark.parametrize("name", [*ORACLE_ROBOTS, "panda"])
def test_jacobian_rate_matches_differences_of_the_pose(name: str) -> None:
    """``Jdot qd`` in closed form against the TCP's acceleration on ``q(t) = q + t qd`` (where
    ``qdd = 0``): the second difference of its position, and the difference of its angular
    velocity."""
    robot = _robot(name, payload=False)
    q, qd, _ = random_state(robot, 6, seed=9)
    tcp = np.eye(4)
    tcp[:3, 3] = [0.02, -0.01, 0.12]
    rate = axes_jacobian_rate(*tool_axes(robot, q, tcp), qd)
    h = 1e-4
    position = [tcp_pose(robot, q + k * h * qd, tcp)[:, :3, 3] for k in (-1, 0, 1)]
    accel = (position[2] - 2.0 * position[1] + position[0]) / h**2
    omega = [
        np.einsum("sij,sj->si", tcp_jacobian(robot, q + k * h * qd, tcp)[:, 3:], qd)
        for k in (-1, 1)
    ]
    alpha = (omega[1] - omega[0]) / (2.0 * h)
    np.testing.assert_allclose(rate[:, :3], accel, atol=1e-5 * max(1.0, np.abs(accel).max()))
    np.testing.assert_allclose(rate[:, 3:], alpha, atol=1e-7)
    # the TCP Jacobian is the flange's with its linear rows moved by r: v_tcp = v + w x r
    flange_jac = jacobian(robot, q)
    r = flange_pose(robot, q)[:, :3, :3] @ tcp[:3, 3]  # (N, 3)
    moved = flange_jac.copy()
    moved[:, :3] += np.cross(flange_jac[:, 3:], r[:, :, None], axis=1)
    np.testing.assert_allclose(tcp_jacobian(robot, q, tcp), moved, atol=1e-12)


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_wrench_of_a_held_mass_equals_the_mass_as_payload(name: str) -> None:
    """Held still, a point mass on the flange is a wrench there: the flange pushes it up with
    ``-m g`` at its centre of mass. ``rnea(wrench=...)`` (``J^T h``) must give what the payload
    merged into the last link gives (the kernels' inertial path, independent of the Jacobian)."""
    robot = kinergy.load_robot(name)
    mass, com = 3.1, np.array([0.02, -0.04, 0.07])
    loaded = robot.with_payload(kinergy.Payload(mass=mass, com=com))
    q, _, _ = random_state(robot, 8, seed=5)
    zero = np.zeros_like(q)
    force = -mass * np.asarray(robot.gravity, dtype=float)
    pose = np.stack([flange_pose(robot, qk) for qk in q])
    lever = np.einsum("kij,j->ki", pose[:, :3, :3], com)
    wrench = np.concatenate([np.broadcast_to(force, lever.shape), np.cross(lever, force)], axis=1)
    held = kinergy.rnea(robot, q, zero, zero, wrench=wrench)
    np.testing.assert_allclose(held, kinergy.rnea(loaded, q, zero, zero), rtol=0, atol=1e-9)
    extra = held - kinergy.rnea(robot, q, zero, zero)
    assert np.max(np.abs(extra)) > 1.0  # the wrench mattered


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_forward_dynamics_inverts_inverse_dynamics(name: str) -> None:
    robot = _robot(name, payload=True)
    q, qd, qdd = random_state(robot, 20, seed=7)
    tau = kinergy.rnea(robot, q, qd, qdd)
    np.testing.assert_allclose(
        kinergy.forward_dynamics(robot, q, qd, tau), qdd, rtol=1e-8, atol=1e-8
    )


@pytest.mark.parametrize("name", ORACLE_ROBOTS)
def test_base_parameters_full_rank_and_reproduce_rnea(name: str) -> None:
    robot = _robot(name, payload=True)
    base = kinergy.base_parameters(robot)
    # fresh states, not the ones the base set was found on
    q, qd, qdd = random_state(robot, 200, seed=8)
    y = kinergy.regressor(robot, q, qd, qdd)
    yb = base.regressor(y).reshape(-1, base.size)
    assert np.linalg.matrix_rank(yb) == base.size
    assert base.size < 10 * robot.n
    # adding one dependent column makes the stack rank-deficient
    for d in base.dependent[:5]:
        widened = np.column_stack([yb, y.reshape(-1, 10 * robot.n)[:, d]])
        assert np.linalg.matrix_rank(widened) == base.size
    tau = kinergy.rnea(robot, q, qd, qdd)
    pib = base.project(kinergy.inertial_parameters(robot))
    assert _rel(base.regressor(y) @ pib, tau) < 1e-9


def test_ur5e_base_parameter_count(ur5e: kinergy.Robot) -> None:
    # a 6R arm with a vertical first axis and the UR's parallel joints 2-4: 36 base parameters
    assert kinergy.base_parameters(ur5e).size == 36


def test_single_sample_and_batch_agree(ur5e: kinergy.Robot) -> None:
    q, qd, qdd = random_state(ur5e, 3, seed=9)
    batch = kinergy.rnea(ur5e, q, qd, qdd)
    for k in range(3):
        single = kinergy.rnea(ur5e, q[k], qd[k], qdd[k])
        assert single.shape == (6,)
        np.testing.assert_allclose(single, batch[k], rtol=1e-14, atol=1e-12)
    assert kinergy.regressor(ur5e, q[0], qd[0], qdd[0]).shape == (6, 60)
    assert link_poses(ur5e, q).shape == (3, 6, 4, 4)
    assert jacobian(ur5e, q[0]).shape == (6, 6)


def test_payload_changes_torques_by_its_weight(ur5e: kinergy.Robot) -> None:
    # a point mass at the flange origin adds exactly J_v^T m g to the static torques
    q, _, _ = random_state(ur5e, 5, seed=10)
    loaded = ur5e.with_payload(kinergy.Payload(mass=3.0))
    extra = kinergy.rnea(loaded, q) - kinergy.rnea(ur5e, q)
    force = np.array([0.0, 0.0, 3.0 * 9.81])  # the flange pushes up on the mass
    expected = np.einsum("nji,j->ni", jacobian(ur5e, q)[:, :3], force)
    np.testing.assert_allclose(extra, expected, atol=1e-9)


def test_gravity_direction_is_configurable(ur5e: kinergy.Robot) -> None:
    q, _, _ = random_state(ur5e, 4, seed=11)
    import dataclasses

    wall = dataclasses.replace(ur5e, gravity=np.array([9.81, 0.0, 0.0]))
    model = to_pinocchio(wall)
    data = model.createData()
    for k in range(4):
        np.testing.assert_allclose(
            kinergy.rnea(wall, q[k]),
            pin.rnea(model, data, q[k], np.zeros(6), np.zeros(6)),
            atol=1e-10,
        )
