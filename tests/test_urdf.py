"""URDF import checked against Pinocchio's own URDF parser.

- Oracle: small URDF files written here (a UR5e-like arm whose link frames are placed with
  arbitrary rpy/xyz, an arm with -y / x axes and parallel, intersecting and collinear consecutive
  axes, and random skew arms) are read by ``kinergy.load_robot`` and by
  ``pinocchio.buildModelFromUrdf``; joint torques (RNEA) and the pose of the tip link agree to
  1e-9 for random states. Both merge fixed joints, so this checks the lumping of inertials too.
- Errors: every problem is a one-line KinergyError naming the file and the joint or link; the CLI
  prints it as ``kinergy: error: ...`` without a traceback.
- Round trip: a URDF-imported robot saved as TOML and read back gives the same RNEA.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import random_state
from scipy.spatial.transform import Rotation

import kinergy
from kinergy.cli import main
from kinergy.model.urdf import robot_from_urdf

pin = pytest.importorskip("pinocchio")

TOL = 1e-9


# --------------------------------------------------------------------------------------------
# Writing URDF text
# --------------------------------------------------------------------------------------------


def _num(values: Sequence[float] | np.ndarray) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(values))


def _origin(pose: np.ndarray) -> str:
    rpy = Rotation.from_matrix(pose[:3, :3]).as_euler("xyz")  # URDF rpy: Rz(y) Ry(p) Rx(r)
    return f'<origin xyz="{_num(pose[:3, 3])}" rpy="{_num(rpy)}"/>'


def _pose(rot: np.ndarray, pos: Sequence[float] | np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = pos
    return out


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    return Rotation.random(random_state=rng).as_matrix()


def _inertial(rng: np.random.Generator, mass: float) -> str:
    """An ``<inertial>`` with an offset, rotated origin and a full, valid inertia tensor."""
    small = rng.uniform(0.005, 0.03, 2)
    low, high = abs(small[0] - small[1]), small.sum()  # the triangle inequality's range
    principal = np.array([*small, low + (high - low) * rng.uniform(0.05, 0.95)])
    rot = _random_rotation(rng)
    tensor = mass * rot @ np.diag(principal) @ rot.T
    values = {
        "ixx": tensor[0, 0],
        "iyy": tensor[1, 1],
        "izz": tensor[2, 2],
        "ixy": tensor[0, 1],
        "iyz": tensor[1, 2],
        "ixz": tensor[0, 2],
    }
    inertia = " ".join(f'{k}="{_num([v])}"' for k, v in values.items())
    origin = _pose(_random_rotation(rng), rng.uniform(-0.1, 0.1, 3))
    return (
        f'<inertial>{_origin(origin)}<mass value="{_num([mass])}"/><inertia {inertia}/></inertial>'
    )


@dataclass
class J:
    """A URDF joint: name, type, parent, child, pose of the child in the parent, axis."""

    name: str
    type: str
    parent: str
    child: str
    pose: np.ndarray
    axis: Sequence[float] | np.ndarray = (0.0, 0.0, 1.0)
    limit: str | None = '<limit lower="-3.0" upper="3.0" effort="150.0" velocity="3.14"/>'


def _urdf(name: str, links: dict[str, str], joints: Sequence[J]) -> str:
    """URDF text: ``links`` maps link names to their inner XML (``""`` for none)."""
    parts = [f'<?xml version="1.0"?>\n<robot name="{name}">']
    parts += [f'  <link name="{n}">{inner}</link>' for n, inner in links.items()]
    for j in joints:
        inner = [
            f'<parent link="{j.parent}"/>',
            f'<child link="{j.child}"/>',
            _origin(j.pose),
        ]
        if j.type != "fixed":
            inner.append(f'<axis xyz="{_num(j.axis)}"/>')
            if j.limit is not None:
                inner.append(j.limit)
        parts.append(f'  <joint name="{j.name}" type="{j.type}">{"".join(inner)}</joint>')
    parts.append("</robot>\n")
    return "\n".join(parts)


def _write(tmp_path: Path, file_name: str, text: str) -> Path:
    path = tmp_path / file_name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------
# Test arms
# --------------------------------------------------------------------------------------------


def ur5e_like(seed: int) -> str:
    """A UR5e-like arm (axes 2, 3, 4 parallel; 1-2, 4-5, 5-6 intersecting) whose link frames
    sit at random points of their axes with random orientations, so joint origins carry arbitrary
    rpy/xyz and axes are arbitrary unit vectors. Fixed joints: a massive base part, a massless
    forearm completed by a motor link through a fixed joint, a camera on a side branch, and a
    flange and tool after the last joint (the tool is the tip)."""
    rng = np.random.default_rng(seed)
    axes = np.array(
        [[0, 0, 1], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, 0, -1], [0, -1, 0]], dtype=float
    )
    points = np.array(
        [
            [0.0, 0.0, 0.1625],
            [0.0, 0.0, 0.1625],
            [-0.425, 0.0, 0.1625],
            [-0.8172, -0.1333, 0.1625],
            [-0.8172, -0.1333, 0.1625],
            [-0.8172, -0.1333, 0.0628],
        ]
    )
    names = ["shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"]
    joint_names = ["shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"]
    masses = [3.7, 8.4, 0.0, 1.2, 1.1, 0.25]
    links = {"base_link": "", "base_link_inertia": _inertial(rng, 4.0), "base_plate": ""}
    joints = [
        J(
            "base_fixed",
            "fixed",
            "base_link",
            "base_link_inertia",
            _pose(_random_rotation(rng), [0, 0, 0.01]),
        ),
        J("plate_fixed", "fixed", "base_link", "base_plate", np.eye(4)),
    ]
    frames = {"base_link": np.eye(4), "base_link_inertia": joints[0].pose}
    parent = "base_link_inertia"
    for i, name in enumerate(names):
        frame = _pose(_random_rotation(rng), points[i] + rng.uniform(-0.1, 0.1) * axes[i])
        frames[name] = frame
        links[name] = _inertial(rng, masses[i]) if masses[i] > 0 else ""
        joints.append(
            J(
                joint_names[i],
                "continuous" if name == "wrist_3" else "revolute",
                parent,
                name,
                np.linalg.solve(frames[parent], frame),
                frame[:3, :3].T @ axes[i],
                limit='<limit effort="28.0" velocity="3.14"/>' if name == "wrist_3" else J.limit,
            )
        )
        parent = name
        if name == "upper_arm":  # a side branch, merged by both parsers
            links["camera"] = _inertial(rng, 0.3)
            joints.append(
                J(
                    "camera_fixed",
                    "fixed",
                    name,
                    "camera",
                    _pose(_random_rotation(rng), [0.1, 0.05, 0.02]),
                )
            )
        if name == "forearm":  # the forearm's mass sits in a link fixed to it
            links["forearm_motor"] = _inertial(rng, 2.3)
            motor = frame @ _pose(_random_rotation(rng), [-0.2, 0.0, 0.03])
            frames["forearm_motor"] = motor
            joints.append(
                J("forearm_fixed", "fixed", name, "forearm_motor", np.linalg.solve(frame, motor))
            )
            parent = "forearm_motor"
    links["flange"] = ""
    links["tool"] = _inertial(rng, 0.8)
    joints.append(
        J("flange_fixed", "fixed", "wrist_3", "flange", _pose(_random_rotation(rng), [0, 0, 0.05]))
    )
    joints.append(
        J("tool_fixed", "fixed", "flange", "tool", _pose(_random_rotation(rng), [0.01, 0, 0.12]))
    )
    return _urdf("ur5e_like", links, joints)


def special_axes(seed: int) -> str:
    """Axes ``0 0 1``, ``0 -1 0`` (intersecting the first), ``0 -1 0`` (parallel), ``1 0 0``
    (intersecting), ``1 0 0`` (collinear, continuous), then a skew ``0 0 -1``; link frames without
    rotation except the last, so the URDF's own axes are the ones listed."""
    rng = np.random.default_rng(seed)
    spec = [
        ("j1", "revolute", [0.0, 0.0, 0.2], [0, 0, 0], [0, 0, 1]),
        ("j2", "revolute", [0.0, 0.0, 0.1], [0, 0, 0], [0, -1, 0]),
        ("j3", "revolute", [0.3, 0.05, 0.0], [0, 0, 0], [0, -1, 0]),
        ("j4", "revolute", [0.25, 0.0, 0.0], [0, 0, 0], [1, 0, 0]),
        ("j5", "continuous", [0.1, 0.0, 0.0], [0, 0, 0], [1, 0, 0]),
        ("j6", "revolute", [0.1, 0.02, 0.03], [0.3, -0.2, 0.5], [0, 0, -1]),
    ]
    links = {"root": ""}
    joints = []
    parent = "root"
    for k, (name, kind, xyz, rpy, axis) in enumerate(spec):
        child = f"link{k + 1}"
        links[child] = _inertial(rng, float(rng.uniform(0.5, 3.0)))
        pose = _pose(Rotation.from_euler("xyz", rpy).as_matrix(), xyz)
        limit = '<limit effort="50" velocity="2"/>' if kind == "continuous" else J.limit
        joints.append(J(name, kind, parent, child, pose, axis, limit))
        parent = child
    links["tip"] = ""
    joints.append(J("tip_fixed", "fixed", parent, "tip", _pose(np.eye(3), [0, 0, 0.07])))
    return _urdf("special_axes", links, joints)


def random_arm(seed: int) -> str:
    """Seven joints with random unit axes and random origins: skew axes everywhere."""
    rng = np.random.default_rng(seed)
    links = {"base": ""}
    joints = []
    parent = "base"
    for k in range(7):
        child = f"l{k}"
        links[child] = _inertial(rng, float(rng.uniform(0.2, 5.0)))
        axis = rng.normal(size=3)
        pose = _pose(_random_rotation(rng), rng.uniform(-0.3, 0.3, 3))
        joints.append(J(f"q{k}", "revolute", parent, child, pose, axis / np.linalg.norm(axis)))
        parent = child
    return _urdf(f"random_{seed}", links, joints)


ARMS = {
    "ur5e_like": (ur5e_like, "tool"),
    "special_axes": (special_axes, "tip"),
    "random": (random_arm, "l6"),
}


# --------------------------------------------------------------------------------------------
# Oracle
# --------------------------------------------------------------------------------------------


def _pin_q(model: object, q: np.ndarray) -> np.ndarray:
    """Pinocchio configuration: continuous joints (nq = 2) take ``(cos q, sin q)``."""
    out = []
    for joint, angle in zip(model.joints[1:], q, strict=True):  # type: ignore[attr-defined]
        out.extend([np.cos(angle), np.sin(angle)] if joint.nq == 2 else [angle])
    return np.array(out)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("arm", list(ARMS))
def test_rnea_and_tip_pose_match_pinocchio(tmp_path: Path, arm: str, seed: int) -> None:
    build, tip = ARMS[arm]
    path = _write(tmp_path, f"{arm}.urdf", build(seed))
    robot = kinergy.load_robot(path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert robot.convention == "mdh"
    assert list(model.names[1:]) == robot.joint_names
    np.testing.assert_array_equal(model.gravity.linear, robot.gravity)

    q, qd, qdd = random_state(robot, 20, seed=seed)
    ours = kinergy.rnea(robot, q, qd, qdd)
    poses = kinergy.flange_pose(robot, q)
    frame = model.getFrameId(tip)
    oracle = np.empty_like(ours)
    oracle_poses = np.empty_like(poses)
    for k in range(len(q)):
        qk = _pin_q(model, q[k])
        oracle[k] = pin.rnea(model, data, qk, qd[k], qdd[k])
        pin.framesForwardKinematics(model, data, qk)
        oracle_poses[k] = data.oMf[frame].homogeneous
    assert _rel(ours, oracle) < TOL
    assert np.max(np.abs(poses - oracle_poses)) < TOL


def test_ur5e_like_geometry_and_data(tmp_path: Path) -> None:
    """Parallel axes give alpha = 0 and d = 0 where free, whatever the URDF's link frames; the
    fixed base mass is in no body, the rest all is; continuous limits; provenance; drives."""
    path = _write(tmp_path, "arm.urdf", ur5e_like(0))
    robot = robot_from_urdf(path)
    assert robot.n == 6
    alpha = np.array([j.alpha for j in robot.joints])
    d = np.array([j.d for j in robot.joints])
    np.testing.assert_allclose(np.abs(alpha[[2, 3]]), 0.0, atol=1e-12)  # 2 ∥ 3 ∥ 4
    a = np.array([j.a for j in robot.joints])
    # d is free (0) where the next axis is parallel; as in the UR5e's MDH table otherwise
    np.testing.assert_allclose(d[:4], [0.0, 0.0, 0.0, 0.1333], atol=1e-12)
    np.testing.assert_allclose(a[[2, 3]], [0.425, 0.3922], atol=1e-12)
    # total moving mass: 3.7 + 8.4 + 0.3 camera + 2.3 motor + 1.2 + 1.1 + 0.25 + 0.8 tool
    np.testing.assert_allclose(sum(j.link.mass for j in robot.joints), 18.05, rtol=1e-12)
    assert robot.joints[-1].limits.position.tolist() == [-2 * np.pi, 2 * np.pi]
    assert robot.joints[0].limits.torque == 150.0
    assert robot.sources["inertia"].status == "published"
    assert robot.sources["inertia"].ref == "URDF arm.urdf"
    assert robot.sources["friction"].status == "nominal"
    assert all(j.drive.gear_ratio == 1.0 for j in robot.joints)


def test_root_tip_and_name_select_a_sub_chain(tmp_path: Path) -> None:
    """From the upper arm to the forearm motor: two joints, the flange at the motor link."""
    path = _write(tmp_path, "arm.urdf", ur5e_like(1))
    robot = robot_from_urdf(path, root="shoulder", tip="forearm_motor", name="sub")
    assert robot.name == "sub"
    assert robot.joint_names == ["shoulder_lift", "elbow"]
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q = np.zeros(model.nq)
    q[[0, 1, 2, 3, 4, 5, 6]] = [0.3, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]  # q1 = 0.3, wrist_3 = 0
    pin.framesForwardKinematics(model, data, q)
    shoulder = data.oMf[model.getFrameId("shoulder")].homogeneous
    motor = data.oMf[model.getFrameId("forearm_motor")].homogeneous
    pose = kinergy.flange_pose(robot, [0.0, 0.0])
    np.testing.assert_allclose(np.linalg.solve(shoulder, motor), pose, atol=1e-12)


def test_save_and_load_round_trip(tmp_path: Path) -> None:
    robot = kinergy.load_robot(_write(tmp_path, "arm.urdf", ur5e_like(2)))
    kinergy.save_robot(robot, tmp_path / "x.toml")
    again = kinergy.load_robot(tmp_path / "x.toml")
    q, qd, qdd = random_state(robot, 20, seed=7)
    assert _rel(kinergy.rnea(again, q, qd, qdd), kinergy.rnea(robot, q, qd, qdd)) < 1e-12
    np.testing.assert_allclose(
        kinergy.flange_pose(again, q), kinergy.flange_pose(robot, q), rtol=0, atol=1e-12
    )
    assert again.sources["kinematics"].ref == "URDF arm.urdf"


# --------------------------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------------------------

_MASS = '<inertial><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" iyz="0" ixz="0"/></inertial>'


def _two_joint(kind2: str = "revolute", mass2: str = _MASS, limit2: str | None = J.limit) -> str:
    links = {"base": "", "upper": _MASS, "lower": mass2}
    joints = [
        J("shoulder", "revolute", "base", "upper", _pose(np.eye(3), [0, 0, 0.1])),
        J("elbow", kind2, "upper", "lower", _pose(np.eye(3), [0.3, 0, 0]), (0, 1, 0), limit2),
    ]
    return _urdf("two", links, joints)


def _branching() -> str:
    links = {"base": "", "body": _MASS, "left": _MASS, "right": _MASS}
    joints = [
        J("waist", "revolute", "base", "body", np.eye(4)),
        J("left_arm", "revolute", "body", "left", _pose(np.eye(3), [0, 0.2, 0])),
        J("right_arm", "revolute", "body", "right", _pose(np.eye(3), [0, -0.2, 0])),
    ]
    return _urdf("branching", links, joints)


BAD_FILES = {
    "prismatic": (_two_joint(kind2="prismatic"), "joint 'elbow'"),
    "branching": (_branching(), "link 'body'"),
    "malformed": ('<robot name="x"><link name="a"></robot>\n', "not well-formed XML"),
    "negative_mass": (_two_joint(mass2=_MASS.replace('"1.0"', '"-2.0"')), "link 'lower'"),
    "no_limit": (_two_joint(limit2=None), "joint 'elbow'"),
    "no_effort": (_two_joint(limit2='<limit lower="-1" upper="1" velocity="1"/>'), "joint 'elbow'"),
    "massless": (_two_joint(mass2=""), "link 'lower'"),
    "bad_inertia": (
        _two_joint(mass2=_MASS.replace('izz="0.01"', 'izz="0.05"')),
        "link 'lower'",
    ),
    "no_ixx": (_two_joint(mass2=_MASS.replace('ixx="0.01" ', "")), "link 'lower'"),
    "not_urdf": ('<sdf version="1.6"/>\n', "not a URDF"),
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_errors_name_the_file_and_the_culprit(tmp_path: Path, case: str) -> None:
    text, culprit = BAD_FILES[case]
    path = _write(tmp_path, f"{case}.urdf", text)
    with pytest.raises(kinergy.KinergyError) as info:
        kinergy.load_robot(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    assert culprit in message
    assert "\n" not in message


def test_branching_tree_asks_for_tip_and_accepts_one(tmp_path: Path) -> None:
    path = _write(tmp_path, "tree.urdf", _branching())
    with pytest.raises(kinergy.KinergyError, match="tip"):
        robot_from_urdf(path)
    robot = robot_from_urdf(path, tip="right")
    assert robot.joint_names == ["waist", "right_arm"]
    # the left arm hangs off the chain: lumped into the body at its q = 0
    assert robot.joints[0].link.mass == pytest.approx(2.0)


def test_unknown_root_or_tip(tmp_path: Path) -> None:
    path = _write(tmp_path, "two.urdf", _two_joint())
    with pytest.raises(kinergy.KinergyError, match="'hand'"):
        robot_from_urdf(path, tip="hand")
    with pytest.raises(kinergy.KinergyError, match="not below"):
        robot_from_urdf(path, root="lower", tip="upper")


def test_urdf_needs_no_extra_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The standard library reads URDF: with yourdfpy (or any URDF parser) unimportable the
    import works the same."""
    monkeypatch.setitem(sys.modules, "yourdfpy", None)
    monkeypatch.setitem(sys.modules, "urdf_parser_py", None)
    robot = robot_from_urdf(_write(tmp_path, "two.urdf", _two_joint()))
    assert robot.joint_names == ["shoulder", "elbow"]


@pytest.mark.parametrize("case", ["malformed", "prismatic", "no_limit"])
def test_cli_prints_one_line_without_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    text, culprit = BAD_FILES[case]
    path = _write(tmp_path, "arm.urdf", text)
    status = main(["robot", "show", str(path)])
    err = capsys.readouterr().err
    assert status != 0
    assert err.startswith(f"kinergy: error: {path}: ")
    assert culprit in err
    assert err.count("\n") == 1
    assert "Traceback" not in err


def test_cli_shows_an_imported_robot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, "two.urdf", _two_joint())
    assert main(["robot", "show", str(path), "--json"]) == 0
    out = capsys.readouterr().out
    assert '"convention": "mdh"' in out
    assert '"elbow"' in out


def test_axes_rounded_to_parallel_stay_near(tmp_path: Path) -> None:
    """pi/2 written as 1.5708 leaves axes 2 and 3 3.7e-6 rad from parallel: they are taken as
    parallel (no common normal kilometres away), and the model stays within that angle of the
    URDF: tip position to 4 um, torques to 1e-6 relative (measured: 1.1 um, 6e-8)."""
    rot = Rotation.from_euler("xyz", [1.5708, 0.0, 0.0]).as_matrix()
    links = {"base": "", "l1": _MASS, "l2": _MASS, "l3": _MASS, "tip": ""}
    joints = [
        J("j1", "revolute", "base", "l1", _pose(np.eye(3), [0, 0, 0.1])),
        J("j2", "revolute", "l1", "l2", _pose(rot, [0, 0, 0.1])),
        J("j3", "revolute", "l2", "l3", _pose(rot.T, [0, 0.4, 0]), (0, -1, 0)),
        J("tip_fixed", "fixed", "l3", "tip", _pose(np.eye(3), [0.3, 0, 0])),
    ]
    path = _write(tmp_path, "rounded.urdf", _urdf("rounded", links, joints))
    robot = robot_from_urdf(path)
    assert max(abs(j.d) for j in robot.joints) < 1.0
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q, qd, qdd = random_state(robot, 20, seed=3)
    poses = kinergy.flange_pose(robot, q)
    frame = model.getFrameId("tip")
    oracle = np.empty((len(q), 3))
    torques = np.empty_like(q)
    for k in range(len(q)):
        pin.framesForwardKinematics(model, data, q[k])
        oracle[k] = data.oMf[frame].translation
        torques[k] = pin.rnea(model, data, q[k], qd[k], qdd[k])
    error = np.max(np.abs(poses[:, :3, 3] - oracle))
    assert 1e-8 < error < 4e-6  # within 3.7e-6 rad times the 0.7 m reach
    assert _rel(kinergy.rnea(robot, q, qd, qdd), torques) < 1e-6
