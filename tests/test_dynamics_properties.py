"""Property tests: the dynamics identities hold for any valid serial arm, not just the library's.

Hypothesis draws arms of 1-7 joints in either DH convention, with random geometry, masses, centres
of mass, physically valid inertia tensors, a random payload, flange and base pose, and checks
them against Pinocchio and against each other.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import kinergy
from kinergy.model import Drive, Friction, Joint, Limits, Link, Robot

pin = pytest.importorskip("pinocchio")
from kinergy.dynamics.pinocchio import to_pinocchio  # noqa: E402

DRIVE = Drive(
    gear_ratio=100.0,
    motor_inertia=1e-5,
    reducer_inertia=1e-5,
    torque_constant=0.1,
    motor_constant=0.1,
    kt_over_kb=0.9,
    friction=Friction("none", {}),
)
LIMITS = Limits(position=[-np.pi, np.pi], speed=3.0, torque=100.0)


def _valid_inertia(rng: np.random.Generator) -> list[float]:
    """Principal moments obeying the triangle inequality, rotated at random, as the 6-vector."""
    a, b = rng.uniform(0.001, 0.1, 2)
    c = rng.uniform(abs(a - b), a + b)
    rot = Rotation.random(random_state=rng).as_matrix()
    t = rot @ np.diag([a, b, c]) @ rot.T
    return [t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[1, 2], t[0, 2]]


def _pose(rng: np.random.Generator) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = Rotation.random(random_state=rng).as_matrix()
    out[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    return out


def _random_robot(seed: int, n: int, convention: str, payload: bool) -> Robot:
    rng = np.random.default_rng(seed)
    joints = [
        Joint(
            name=f"j{i}",
            d=float(rng.uniform(-0.4, 0.4)),
            a=float(rng.uniform(-0.4, 0.4)),
            alpha=float(rng.uniform(-np.pi, np.pi)),
            offset=float(rng.uniform(-np.pi, np.pi)),
            link=Link(
                mass=float(rng.uniform(0.2, 8.0)),
                com=rng.uniform(-0.2, 0.2, 3),
                inertia=np.array(_valid_inertia(rng)),
            ),
            drive=DRIVE,
            limits=LIMITS,
        )
        for i in range(n)
    ]
    load = None
    if payload:
        load = kinergy.Payload(
            mass=float(rng.uniform(0.1, 5.0)),
            com=rng.uniform(-0.1, 0.1, 3),
            inertia=np.array(_valid_inertia(rng)),
        )
    gravity = Rotation.random(random_state=rng).as_matrix() @ np.array([0.0, 0.0, -9.81])
    return Robot(
        name="random",
        convention=convention,
        joints=tuple(joints),
        gravity=gravity,
        payload=load,
        flange=_pose(rng),
        base=_pose(rng),
    )


robots = st.builds(
    _random_robot,
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 7),
    convention=st.sampled_from(["dh", "mdh"]),
    payload=st.booleans(),
)


@settings(max_examples=60, deadline=None)
@given(robot=robots, seed=st.integers(0, 2**32 - 1))
def test_random_arms_match_pinocchio(robot: Robot, seed: int) -> None:
    rng = np.random.default_rng(seed)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, 6, robot.n))
    tau = kinergy.rnea(robot, q, qd, qdd)
    model = to_pinocchio(robot)
    data = model.createData()
    oracle = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(6)])
    scale = max(np.max(np.abs(oracle)), 1.0)
    assert np.max(np.abs(tau - oracle)) < 1e-9 * scale
    via_regressor = kinergy.regressor(robot, q, qd, qdd) @ kinergy.inertial_parameters(robot)
    assert np.max(np.abs(via_regressor - oracle)) < 1e-9 * scale
    m = kinergy.mass_matrix(robot, q)
    for k in range(6):
        crba = pin.crba(model, data, q[k])
        crba = np.triu(crba) + np.triu(crba, 1).T
        assert np.max(np.abs(m[k] - crba)) < 1e-9 * max(np.max(np.abs(crba)), 1.0)
        fid = model.getFrameId("flange")
        pin.framesForwardKinematics(model, data, q[k])
        assert np.allclose(kinergy.flange_pose(robot, q[k]), data.oMf[fid].homogeneous, atol=1e-10)


@settings(max_examples=30, deadline=None)
@given(robot=robots, seed=st.integers(0, 2**32 - 1))
def test_random_arms_round_trip_through_toml(
    robot: Robot, seed: int, tmp_path_factory: pytest.TempPathFactory
) -> None:
    path = tmp_path_factory.mktemp("rt") / "random.toml"
    kinergy.save_robot(robot, path)
    again = kinergy.load_robot(path)
    rng = np.random.default_rng(seed)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, 4, robot.n))
    np.testing.assert_allclose(
        kinergy.rnea(again, q, qd, qdd), kinergy.rnea(robot, q, qd, qdd), rtol=1e-12, atol=1e-12
    )
