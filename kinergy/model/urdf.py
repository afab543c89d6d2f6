"""Import a serial arm of revolute joints from a URDF file (optional: needs ``yourdfpy``).

A URDF places each link frame with an arbitrary ``<origin xyz rpy>`` and turns it about an
arbitrary ``<axis>``; kinergy describes an arm by modified Denavit–Hartenberg parameters (Craig,
``mdh``). :func:`import_urdf` converts one into the other without approximation:

1. Walk the tree from ``root`` to ``tip``. ``revolute`` and ``continuous`` joints become kinergy
   joints; ``fixed`` joints are merged (their child links are rigidly part of the body before them).
2. Put every link frame at q = 0 in the root frame, and with it each joint axis (a unit direction
   ``z_i`` through a point ``p_i``).
3. Choose the MDH frames (:func:`mdh_frames`): ``z_i`` along the URDF axis, so that ``q`` keeps its
   sign; ``x_i`` along the common normal from axis i to axis i+1. For intersecting axes ``x_i`` is
   ``z_i x z_{i+1}``; for parallel axes the common normal is not unique and the one through the
   previous frame's foot point is taken (``d = 0`` where it is free). Frame 0 coincides with frame 1
   at q = 0 (``a_0 = alpha_0 = d_1 = offset_1 = 0``); its pose in the root frame is ``Robot.base``.
4. Read the parameters ``(a_{i-1}, alpha_{i-1}, offset_i, d_i)`` off consecutive frames
   (:func:`mdh_parameters`), rebuild the frames from them, and express every link's inertial and
   the tip link (``Robot.flange``) in the rebuilt frames.

Each body's mass, centre of mass and inertia about the centre of mass are the rigid sums of its
links' ``<inertial>`` (the URDF inertia is about the centre of mass, in the axes of the inertial
``<origin>``; it is rotated into MDH link-frame axes and shifted by the parallel-axis theorem).

Drives (:mod:`kinergy.model.urdf_extras` reads the elements): URDF's standard elements give a
joint's gear ratio (a ROS SimpleTransmission's ``mechanicalReduction``) and its Coulomb + viscous
friction (``<dynamics friction damping>``, joint side, referred to the motor as ``coulomb =
friction / |n|``, ``viscous = damping / n^2``); the rest of the drives is nominal (no rotor
inertia, unit torque and motor constants) and marked ``nominal`` in ``Robot.sources``: identify
it from logs before trusting energy predictions.

A file ``kinergy robot export`` wrote (:mod:`kinergy.model.urdf_export`) has a
``<kinergy:model>`` element with what URDF cannot hold; :func:`import_urdf` then gives back the
robot it was written from instead: its convention and DH or MDH parameters (after checking that
they give the URDF's joint axes and flange), every link inertial in those frames, the drives,
friction family and parameters (after checking that they give the file's ``<dynamics>``), and
the rest of the robot file. A file edited since, so that the two no longer agree, is refused.
"""

from __future__ import annotations

import io
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction.model import SMOOTHING
from kinergy.model.frames import joint_transforms, mdh_transform
from kinergy.model.friction_line import joint_side, motor_ranges
from kinergy.model.robot import (
    CONVENTIONS,
    SOURCE_CATEGORIES,
    Drive,
    Friction,
    Joint,
    Limits,
    Link,
    Robot,
    Source,
)
from kinergy.model.toml import robot_from_dict, rpy_matrix
from kinergy.model.urdf_extras import (
    KinergyJoint,
    KinergyModel,
    Standard,
    read_kinergy,
    read_standard,
)

__all__ = [
    "UrdfImport",
    "import_urdf",
    "mdh_frames",
    "mdh_parameters",
    "robot_from_urdf",
]


#: Consecutive axes closer than this to parallel (|sin| of the angle between them) are treated as
#: parallel. URDF files often write pi/2 as 1.5708 (3.7e-6 rad off); taking such axes as skew would
#: put the common normal kilometres away and ruin the numerics of every algorithm.
PARALLEL_TOLERANCE = 1e-5

_REVOLUTE = ("revolute", "continuous")
_INERTIA_ATTRIBUTES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_TWO_PI = 2.0 * np.pi


def _fail(where: str, message: str) -> KinergyError:
    return KinergyError(f"{where}: {message}")


# --------------------------------------------------------------------------------------------
# MDH geometry: plain functions over arrays (the DH and MDH transforms: kinergy.model.frames)
# --------------------------------------------------------------------------------------------


def _closest_points(p1: Array, z1: Array, p2: Array, z2: Array) -> tuple[Array, Array]:
    """Feet of the common normal of two non-parallel lines ``p + t z`` (unit ``z``)."""
    w = p1 - p2
    b, d1, e = z1 @ z2, z1 @ w, z2 @ w
    denom = 1.0 - b * b
    return p1 + (b * e - d1) / denom * z1, p2 + (e - b * d1) / denom * z2


def _perpendicular(z: Array, guess: Array) -> Array:
    """A unit vector perpendicular to unit ``z``: ``guess`` made perpendicular, else a root axis."""
    for candidate in (guess, np.eye(3)[0], np.eye(3)[1]):
        v = candidate - z * (z @ candidate)
        norm = np.linalg.norm(v)
        if norm > 1e-6:
            return v / norm
    raise AssertionError("unreachable: x and y cannot both be parallel to z")


def mdh_frames(axes: Array, points: Array) -> Array:
    """Modified-DH frames for joint axes given in a common frame, at q = 0.

    Parameters
    ----------
    axes : ndarray, shape (n, 3)
        Unit direction of each joint axis; becomes the frame's z axis (positive q turns the
        same way as in the source description).
    points : ndarray, shape (n, 3)
        A point on each axis, m.

    Returns
    -------
    ndarray, shape (n, 4, 4)
        Pose of MDH frame i (i = 1..n) in the common frame: origin on axis i, x along the common
        normal to axis i+1 (pointing towards it, so a_i >= 0). Parallel axes: the normal through
        the previous foot point (the first axis: through ``points[0]``). Intersecting or collinear
        axes: x is ``z_i x z_{i+1}`` or carried over from the previous frame. The last frame's
        origin is the previous normal's foot on the last axis and its x that normal's direction.
    """
    n = len(axes)
    frames = np.tile(np.eye(4), (n, 1, 1))
    foot = np.asarray(points[0], dtype=float)  # where the previous common normal meets axis i
    x_prev = np.eye(3)[0]
    for i in range(n):
        z = axes[i]
        origin = foot
        if i + 1 < n:
            z_next, p_next = axes[i + 1], points[i + 1]
            normal = np.cross(z, z_next)
            sin = np.linalg.norm(normal)
            if sin > PARALLEL_TOLERANCE:
                origin, foot = _closest_points(points[i], z, p_next, z_next)
                x = normal / sin
                if x @ (foot - origin) < 0.0:
                    x = -x
            else:
                v = p_next - origin
                v = v - z * (z @ v)
                dist = np.linalg.norm(v)
                x = v / dist if dist > 1e-12 else _perpendicular(z, x_prev)
                foot = origin + v
        else:
            x = _perpendicular(z, x_prev)
        frames[i, :3, 0] = x
        frames[i, :3, 1] = np.cross(z, x)
        frames[i, :3, 2] = z
        frames[i, :3, 3] = origin
        x_prev = x
    return frames


def mdh_parameters(frames: Array) -> Array:
    """MDH parameters joining consecutive frames; frame 0 is taken equal to frame 1.

    Parameters
    ----------
    frames : ndarray, shape (n, 4, 4)
        MDH frames 1..n at q = 0 (from :func:`mdh_frames`), in any common frame.

    Returns
    -------
    ndarray, shape (n, 4)
        Rows ``(a_{i-1}, alpha_{i-1}, offset_i, d_i)`` (m, rad, rad, m) such that
        ``frames[i] = frames[i-1] · mdh_transform(*row_i)``; the first row is zeros.
    """
    n = len(frames)
    params = np.zeros((n, 4))
    for i in range(1, n):
        rel = np.linalg.solve(frames[i - 1], frames[i])
        alpha = np.arctan2(-rel[1, 2], rel[2, 2])
        offset = np.arctan2(-rel[0, 1], rel[0, 0])
        d = -np.sin(alpha) * rel[1, 3] + np.cos(alpha) * rel[2, 3]
        params[i] = (rel[0, 3], alpha, offset, d)
    params[np.abs(params) < 1e-14] = 0.0
    return params


# --------------------------------------------------------------------------------------------
# Reading the file
# --------------------------------------------------------------------------------------------


def _check_xml(text: bytes, where: str) -> ET.Element:
    """The ``<robot>`` element of well-formed XML with the elements and attributes yourdfpy would
    otherwise trip on (or silently default: a missing ``ixx`` would become 1 kg m^2)."""
    try:
        root = ET.fromstring(text)
    except (ET.ParseError, LookupError) as exc:  # LookupError: an unknown declared encoding
        raise _fail(where, f"not well-formed XML ({exc})") from None
    if root.tag != "robot":
        raise _fail(where, f"not a URDF file: the root element is <{root.tag}>, not <robot>")
    if not root.get("name"):
        raise _fail(where, "the <robot> element has no 'name' attribute")
    for kind in ("link", "joint"):
        seen: set[str] = set()
        for k, element in enumerate(root.findall(kind)):
            name = element.get("name")
            if not name:
                raise _fail(where, f"<{kind}> number {k + 1} has no 'name' attribute")
            if name in seen:
                raise _fail(where, f"{kind} {name!r} is defined twice")
            seen.add(name)
    for joint in root.findall("joint"):
        jwhere = f"{where}: joint {joint.get('name')!r}"
        if not joint.get("type"):
            raise _fail(jwhere, "no 'type' attribute")
        for tag in ("parent", "child"):
            end = joint.find(tag)
            if end is None or not end.get("link"):
                raise _fail(jwhere, f"missing <{tag} link=...>")
    for link in root.findall("link"):
        inertia = link.find("inertial/inertia")
        if inertia is None:
            continue
        missing = [a for a in _INERTIA_ATTRIBUTES if inertia.get(a) is None]
        if missing:
            raise _fail(
                f"{where}: link {link.get('name')!r}", f"<inertia> lacks {', '.join(missing)}"
            )
    return root


def _load_urdf(text: bytes, where: str) -> Any:
    """The file's text parsed by yourdfpy (no scene graph, no meshes); every failure a
    KinergyError."""
    try:
        import yourdfpy
    except ImportError:
        raise KinergyError(
            "reading URDF files needs the 'yourdfpy' package (pip install kinergy[urdf])"
        ) from None
    try:
        return yourdfpy.URDF.load(
            io.BytesIO(text),
            build_scene_graph=False,
            build_collision_scene_graph=False,
            load_meshes=False,
            load_collision_meshes=False,
        )
    except Exception as exc:  # yourdfpy raises anything from ValueError to KeyError
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise _fail(where, f"not a valid URDF file ({detail})") from None


# --------------------------------------------------------------------------------------------
# The tree and the chain
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Tree:
    """Links and joints of a URDF as plain maps."""

    links: Mapping[str, Any]  # name -> yourdfpy Link
    parent_joint: Mapping[str, Any]  # child link name -> yourdfpy Joint
    child_joints: Mapping[str, list[Any]]  # link name -> joints whose parent it is


def _tree(urdf: Any, where: str) -> _Tree:
    links = {link.name: link for link in urdf.robot.links}
    parent_joint: dict[str, Any] = {}
    child_joints: dict[str, list[Any]] = {name: [] for name in links}
    for joint in urdf.robot.joints:
        for end in (joint.parent, joint.child):
            if end not in links:
                raise _fail(
                    f"{where}: joint {joint.name!r}", f"refers to an undefined link {end!r}"
                )
        if joint.child in parent_joint:
            raise _fail(
                f"{where}: link {joint.child!r}",
                f"is the child of two joints ({parent_joint[joint.child].name!r} and "
                f"{joint.name!r}); a URDF must be a tree",
            )
        parent_joint[joint.child] = joint
        child_joints[joint.parent].append(joint)
    return _Tree(links, parent_joint, child_joints)


def _root_link(tree: _Tree, root: str | None, where: str) -> str:
    if root is not None:
        if root not in tree.links:
            raise _fail(where, f"no link named {root!r} (root)")
        return root
    roots = [name for name in tree.links if name not in tree.parent_joint]
    if len(roots) != 1:
        found = ", ".join(repr(r) for r in roots) or "none (the joints form a loop)"
        raise _fail(where, f"expected one root link, found {found}; give `root`")
    return roots[0]


def _has_moving_joint(tree: _Tree, link: str) -> bool:
    return any(
        j.type != "fixed" or _has_moving_joint(tree, j.child) for j in tree.child_joints[link]
    )


def _tip_link(tree: _Tree, root: str, where: str) -> str:
    """The end of the chain from ``root``: at a link with several child joints, follow the one
    subtree that still moves; anything else is ambiguous."""
    link = root
    while tree.child_joints[link]:
        children = tree.child_joints[link]
        if len(children) > 1:
            moving = [j for j in children if j.type != "fixed" or _has_moving_joint(tree, j.child)]
            if len(moving) != 1:
                names = ", ".join(repr(j.name) for j in children)
                raise _fail(
                    f"{where}: link {link!r}",
                    f"the tree branches here (joints {names}); give `tip`, the link at the end "
                    "of the arm",
                )
            children = moving
        link = children[0].child
    return link


def _chain_joints(tree: _Tree, root: str, tip: str, where: str) -> list[Any]:
    """The joints from ``root`` down to ``tip``, in order."""
    if tip not in tree.links:
        raise _fail(where, f"no link named {tip!r} (tip)")
    joints = []
    link = tip
    while link != root:
        if link not in tree.parent_joint:
            raise _fail(where, f"link {tip!r} (tip) is not below link {root!r} (root)")
        joint = tree.parent_joint[link]
        joints.append(joint)
        link = joint.parent
    return joints[::-1]


def _unit_axis(joint: Any, where: str) -> Array:
    axis = np.asarray(joint.axis if joint.axis is not None else [1.0, 0.0, 0.0], dtype=float)
    norm = np.linalg.norm(axis) if axis.shape == (3,) and np.all(np.isfinite(axis)) else 0.0
    if norm < 1e-9:
        raise _fail(
            f"{where}: joint {joint.name!r}", f"axis must be 3 numbers, not zero, got {axis}"
        )
    return axis / norm


def _origin(element: Any) -> Array:
    return np.eye(4) if element is None or element.origin is None else np.asarray(element.origin)


def _poses_and_bodies(
    tree: _Tree, root: str, moving: Mapping[str, int]
) -> tuple[dict[str, Array], dict[str, int]]:
    """Pose at q = 0 in the root frame of every link below ``root``, and the body it belongs to
    (0: fixed to the root; i: moved by the i-th revolute joint of the chain, ``moving``)."""
    poses = {root: np.eye(4)}
    body = {root: 0}
    stack = [root]
    while stack:
        link = stack.pop()
        for joint in tree.child_joints[link]:
            poses[joint.child] = poses[link] @ _origin(joint)
            body[joint.child] = moving.get(joint.name, body[link])
            stack.append(joint.child)
    return poses, body


# --------------------------------------------------------------------------------------------
# Inertials, limits, drives
# --------------------------------------------------------------------------------------------


def _link_inertial(link: Any, where: str) -> tuple[float, Array, Array]:
    """Mass (kg), pose of the inertial frame in the link frame (4, 4), inertia about the centre
    of mass in that frame (3, 3), checked; zeros when the link has no ``<inertial>``."""
    inertial = link.inertial
    if inertial is None:
        return 0.0, np.eye(4), np.zeros((3, 3))
    lwhere = f"{where}: link {link.name!r}"
    mass = 0.0 if inertial.mass is None else float(inertial.mass)
    inertia = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia)
    if not np.isfinite(mass) or mass < 0.0:
        raise _fail(lwhere, f"mass must be >= 0, got {mass:g}")
    if not np.all(np.isfinite(inertia)):
        raise _fail(lwhere, "inertia must be finite")
    eig = np.linalg.eigvalsh(inertia)
    scale = float(np.max(np.abs(eig)))
    if scale > 0.0:
        if mass == 0.0:
            raise _fail(lwhere, "has an inertia but no mass")
        if eig[0] < -1e-12 * scale:
            raise _fail(
                lwhere,
                f"inertia is not positive semi-definite (principal moments {eig.tolist()})",
            )
        if eig[0] + eig[1] < eig[2] * (1.0 - 1e-9):
            raise _fail(
                lwhere,
                f"inertia violates the triangle inequality (principal moments {eig.tolist()})",
            )
    return mass, _origin(inertial), inertia


def _body_inertial(parts: Sequence[tuple[float, Array, Array]]) -> tuple[float, Array, Array]:
    """Rigid sum of inertials.

    Parameters
    ----------
    parts : sequence of (mass, pose, inertia)
        kg; pose (4, 4) of each centre-of-mass frame in the body frame; inertia (3, 3) about the
        centre of mass in that frame's axes, kg m^2.

    Returns
    -------
    mass : float
    com : ndarray, shape (3,)
        m, body frame.
    inertia : ndarray, shape (6,)
        ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` about ``com``, body-frame axes, kg m^2.
    """
    mass = float(sum(m for m, _, _ in parts))
    if mass <= 0.0:
        return 0.0, np.zeros(3), np.zeros(6)
    com = np.sum([m * pose[:3, 3] for m, pose, _ in parts], axis=0) / mass
    total = np.zeros((3, 3))
    for m, pose, inertia in parts:
        rot, r = pose[:3, :3], pose[:3, 3] - com
        total += rot @ inertia @ rot.T + m * ((r @ r) * np.eye(3) - np.outer(r, r))
    six = np.array([total[0, 0], total[1, 1], total[2, 2], total[0, 1], total[1, 2], total[0, 2]])
    return mass, com, six


def _limits(joint: Any, where: str) -> Limits:
    jwhere = f"{where}: joint {joint.name!r}"
    limit = joint.limit
    if limit is None:
        raise _fail(
            jwhere,
            "missing <limit> (needs effort and velocity, and lower and upper for a revolute joint)",
        )
    for attr in ("effort", "velocity"):
        if getattr(limit, attr) is None:
            raise _fail(jwhere, f"<limit> lacks {attr!r}")
    continuous = joint.type == "continuous"
    if continuous:
        position = np.array([-_TWO_PI, _TWO_PI])
    else:  # URDF: lower and upper default to 0
        position = np.array([limit.lower or 0.0, limit.upper or 0.0])
    try:
        return Limits(
            position=position, speed=limit.velocity, torque=limit.effort, continuous=continuous
        )
    except KinergyError as exc:
        raise exc.prefixed(jwhere) from None


def _revolute_chain(tree: _Tree, root: str, tip: str, where: str) -> list[Any]:
    """The revolute and continuous joints from ``root`` to ``tip``; fixed joints are skipped,
    any other type is refused."""
    revolute = []
    for joint in _chain_joints(tree, root, tip, where):
        if joint.type in _REVOLUTE:
            revolute.append(joint)
        elif joint.type != "fixed":
            raise _fail(
                f"{where}: joint {joint.name!r}",
                f"type {joint.type!r} is not supported (kinergy models serial arms of revolute "
                "joints; fixed joints are merged)",
            )
    if not revolute:
        raise _fail(where, f"no revolute or continuous joint between links {root!r} and {tip!r}")
    return revolute


def _mdh_chain(
    revolute: Sequence[Any], poses: Mapping[str, Array], where: str
) -> tuple[Array, Array]:
    """MDH parameters (n, 4) of the joints and the frames (n + 1, 4, 4) they rebuild, frame 0
    the root-frame pose of joint 1's frame, exactly as :mod:`kinergy.dynamics.chain` does."""
    # joint frames at q = 0 in the root frame: the URDF child-link frames of the joints
    axes = np.array([poses[j.child][:3, :3] @ _unit_axis(j, where) for j in revolute])
    points = np.array([poses[j.child][:3, 3] for j in revolute])
    nominal_frames = mdh_frames(axes, points)
    params = mdh_parameters(nominal_frames)
    frames = np.empty((len(revolute) + 1, 4, 4))
    frames[0] = nominal_frames[0]
    frames[0][np.abs(frames[0]) < 1e-14] = 0.0  # rounding noise, for readable robot files
    for i, row in enumerate(params):
        frames[i + 1] = frames[i] @ mdh_transform(*row)
    return params, frames


def _body_parts(
    tree: _Tree,
    body: Mapping[str, int],
    poses: Mapping[str, Array],
    frames: Array,
    n: int,
    where: str,
) -> list[list[tuple[float, Array, Array]]]:
    """Per moving body, the inertials of the URDF links fixed to it, posed in its MDH frame."""
    parts: list[list[tuple[float, Array, Array]]] = [[] for _ in range(n)]
    for link_name, b in body.items():
        if b == 0:
            continue
        mass, origin, inertia = _link_inertial(tree.links[link_name], where)
        if mass > 0.0:
            pose = np.linalg.solve(frames[b], poses[link_name] @ origin)
            parts[b - 1].append((mass, pose, inertia))
    return parts


def _joint(
    joint: Any, row: Array, parts: list[tuple[float, Array, Array]], drive: Drive, where: str
) -> Joint:
    """kinergy's joint for a URDF joint: MDH ``row`` = (a, alpha, offset, d), its body's rigid
    inertial, ``drive``, the URDF's limits."""
    a, alpha, offset, d = (float(x) for x in row)
    return Joint(
        name=joint.name,
        d=d,
        a=a,
        alpha=alpha,
        offset=offset,
        link=_body_link(joint, parts, where),
        drive=drive,
        limits=_limits(joint, where),
    )


def _body_link(joint: Any, parts: list[tuple[float, Array, Array]], where: str) -> Link:
    """The rigid sum of the inertials moved by ``joint``, checked."""
    lwhere = f"{where}: link {joint.child!r}"
    mass, com, inertia = _body_inertial(parts)
    if mass <= 0.0:
        raise _fail(
            lwhere,
            f"moved by joint {joint.name!r} but has no mass (nor do the links fixed to it); "
            "every moving body needs a positive mass",
        )
    try:
        return Link(mass=mass, com=com, inertia=inertia)
    except KinergyError as exc:
        raise exc.prefixed(lwhere) from None


def _standard_drive(name: str, standard: Standard) -> Drive:
    """A drive from a URDF's standard elements: the gear ratio of its SimpleTransmission (else 1),
    Coulomb + viscous friction from its ``<dynamics>`` referred to the motor (``viscous =
    damping / n^2``, ``coulomb = friction / |n|``), the rest nominal."""
    gear = standard.reductions.get(name, 1.0)
    damping, coulomb = standard.dynamics.get(name, (0.0, 0.0))
    friction = (
        Friction(
            "viscous_coulomb",
            {"viscous": damping / gear**2, "coulomb": coulomb / abs(gear), "smoothing": SMOOTHING},
        )
        if damping > 0.0 or coulomb > 0.0
        else Friction("none", {})
    )
    return Drive(
        gear_ratio=gear,
        motor_inertia=0.0,
        reducer_inertia=0.0,
        torque_constant=1.0,
        motor_constant=1.0,
        kt_over_kb=1.0,
        friction=friction,
    )


def _sources(file: str, friction: bool) -> dict[str, Source]:
    """Provenance: geometry, inertials and limits from the URDF; the friction too when its
    ``<dynamics>`` give one; the rest of the drives nominal."""
    published = Source("published", f"URDF {file}")
    nominal = Source("nominal", f"not in URDF {file}")
    drive = ("drive_inertia", "torque_constant", "motor_constant", "thermal", "supply")
    out = {c: nominal if c in drive else published for c in SOURCE_CATEGORIES}
    if not friction:
        out["friction"] = nominal
    else:
        out["friction"] = Source("published", f"URDF {file} <dynamics>, as Coulomb + viscous")
    return out


# --------------------------------------------------------------------------------------------
# A file kinergy exported: <kinergy:model>
# --------------------------------------------------------------------------------------------


#: how far (m, or rad for directions) the URDF's axes and flange may be from those the
#: ``<kinergy:model>`` parameters give (rounding of the printed numbers is far below)
KINEMATICS_TOLERANCE = 1e-9


def _pose(xyz: Sequence[float], rpy: Sequence[float]) -> Array:
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def _check_kinematics(
    model: KinergyModel,
    revolute: Sequence[Any],
    poses: Mapping[str, Array],
    where: str,
) -> Array:
    """Link frames (n + 1, 4, 4) at q = 0 in the root frame that the recorded convention and
    parameters give, frame 0 the recorded base; a KinergyError when their joint axes or flange
    are not the URDF's (an edited file)."""
    if model.convention not in CONVENTIONS:
        raise _fail(
            f"{where}: <kinergy:model>",
            f"convention must be one of {', '.join(CONVENTIONS)}, got {model.convention!r}",
        )
    rows = np.array(
        [[k.kinematics[key] for key in ("a", "alpha", "offset", "d")] for k in model.joints]
    )
    pre, post = joint_transforms(model.convention, rows)
    frames = [_pose(model.base["xyz"], model.base["rpy"])]
    advice = (
        "the URDF was edited after kinergy wrote it; remove the <kinergy:model> element to "
        "import its geometry alone"
    )
    for i, joint in enumerate(revolute):
        turning = frames[-1] @ pre[i]
        axis = poses[joint.child][:3, :3] @ _unit_axis(joint, where)
        point = poses[joint.child][:3, 3]
        z = turning[:3, 2]
        scale = max(1.0, float(np.max(np.abs(point))))  # m: relative beyond a metre
        off = max(
            float(np.linalg.norm(axis - z)),
            float(np.linalg.norm(np.cross(point - turning[:3, 3], z))) / scale,
        )
        if not off <= KINEMATICS_TOLERANCE:  # NaN too
            raise _fail(
                f"{where}: joint {joint.name!r}",
                f"its axis is {off:.3g} from the one its <kinergy:joint> parameters give: {advice}",
            )
        frames.append(turning @ post[i])
    flange = frames[-1] @ _pose(model.flange_pose["xyz"], model.flange_pose["rpy"])
    scale = max(1.0, float(np.max(np.abs(poses[model.flange][:3, 3]))))
    off = max(
        float(np.max(np.abs(flange[:3, :3] - poses[model.flange][:3, :3]))),
        float(np.max(np.abs(flange[:3, 3] - poses[model.flange][:3, 3]))) / scale,
    )
    if not off <= KINEMATICS_TOLERANCE:  # NaN too
        raise _fail(
            f"{where}: link {model.flange!r}",
            f"the flange is {off:.3g} from where the <kinergy:model> kinematics put it: {advice}",
        )
    return np.array(frames)


def _snapped(com: Array, inertia: Array) -> dict[str, list[float]]:
    """``com`` (m) and ``inertia`` (kg m^2) with the rounding noise of the frame changes
    (components below 1e-14 m, or 1e-14 of the largest moment) made the zeros they were."""
    com = np.where(np.abs(com) < 1e-14, 0.0, com)
    scale = float(np.max(np.abs(inertia)))
    inertia = np.where(np.abs(inertia) < 1e-14 * scale, 0.0, inertia)
    return {"com": com.tolist(), "inertia": inertia.tolist()}


def _payload(tree: _Tree, model: KinergyModel, where: str) -> dict[str, Any] | None:
    """The payload link's inertial in the flange frame (a robot file's ``[payload]``); the link
    must hang from the flange link by fixed joints."""
    if model.payload is None:
        return None
    if model.payload not in tree.links:
        raise _fail(f"{where}: <kinergy:model>", f"no link named {model.payload!r} (payload)")
    pose = np.eye(4)
    link = model.payload
    while link != model.flange:
        joint = tree.parent_joint.get(link)
        if joint is None or joint.type != "fixed":
            raise _fail(
                f"{where}: link {model.payload!r}",
                f"the payload must be fixed to the flange link {model.flange!r}",
            )
        pose = _origin(joint) @ pose
        link = joint.parent
    mass, origin, inertia = _link_inertial(tree.links[model.payload], where)
    mass, com, six = _body_inertial([(mass, pose @ origin, inertia)])
    return {"mass": mass, **_snapped(com, six)}


def _restored_drive(
    kin: KinergyJoint, standard: Standard, coupled: bool, where: str
) -> dict[str, Any]:
    """A joint's ``drive`` table (robot file form) from its ``<kinergy:joint>`` and the URDF's
    standard elements."""
    jwhere = f"{where}: joint {kin.name!r}"
    drive: dict[str, Any] = dict(kin.drive)
    if coupled:
        if "gear_ratio" not in drive:
            raise _fail(jwhere, "a coupled robot's <kinergy:drive> needs its gear_ratio")
    else:
        if "gear_ratio" in drive:
            raise _fail(
                jwhere, "gear_ratio belongs in the joint's <transmission>, not in <kinergy:drive>"
            )
        if kin.name not in standard.reductions:
            raise _fail(jwhere, "no SimpleTransmission with its gear ratio (<mechanicalReduction>)")
        drive["gear_ratio"] = standard.reductions[kin.name]
    if kin.friction is not None:
        drive["friction"] = dict(kin.friction)
    elif coupled:
        raise _fail(
            jwhere,
            "a coupled robot needs every <kinergy:friction> (<dynamics> holds only each joint's "
            "share)",
        )
    else:
        damping, coulomb = standard.dynamics.get(kin.name, (0.0, 0.0))
        gear = float(drive["gear_ratio"])
        drive["friction"] = {
            "model": "viscous_coulomb",
            "viscous": damping / gear**2,
            "coulomb": coulomb / abs(gear),
            "smoothing": SMOOTHING,
        }
    if kin.thermal is not None:
        drive["thermal"] = dict(kin.thermal)
    return drive


def _check_dynamics(robot: Robot, model: KinergyModel, standard: Standard, where: str) -> None:
    """The URDF's ``<dynamics>`` must be what the restored friction exports (else the file was
    edited after kinergy wrote it)."""
    speed, load = motor_ranges(robot)
    for k, kin in enumerate(model.joints):
        if kin.line is not None:
            speed[k], load[k] = kin.line
    side = joint_side(robot, (speed, load))
    for k, joint in enumerate(robot.joints):
        file = standard.dynamics.get(joint.name, (0.0, 0.0))
        for label, value, computed in zip(
            ("damping", "friction"), file, (side.damping[k], side.friction[k]), strict=True
        ):
            if not abs(value - computed) <= 1e-9 * max(abs(value), abs(computed)):
                raise _fail(
                    f"{where}: joint {joint.name!r}",
                    f"<dynamics {label}={value!r}> is not the {float(computed)!r} its drive's "
                    "<kinergy:friction> gives (was the file edited?); remove that "
                    "<kinergy:friction> to import <dynamics> as Coulomb + viscous friction",
                )


def _restored(
    urdf: Any,
    model: KinergyModel,
    standard: Standard,
    path: Path,
    selection: tuple[str | None, str | None, str | None],
) -> Robot:
    """The robot a ``<kinergy:model>`` element and the URDF's standard elements describe."""
    where = str(path)
    root, tip, name = selection
    if (root is not None and root != model.root) or (tip is not None and tip != model.flange):
        raise _fail(
            where,
            f"the <kinergy:model> element describes the chain from link {model.root!r} to "
            f"{model.flange!r}; give no root and tip, or remove the element",
        )
    tree = _tree(urdf, where)
    _root_link(tree, model.root, where)
    revolute = _revolute_chain(tree, model.root, model.flange, where)
    names = [j.name for j in revolute]
    recorded = [k.name for k in model.joints]
    if names != recorded:
        raise _fail(
            f"{where}: <kinergy:model>",
            f"describes joints {', '.join(recorded)}, but the chain from {model.root!r} to "
            f"{model.flange!r} has {', '.join(names)}",
        )
    poses, body = _poses_and_bodies(
        tree, model.root, {j.name: i + 1 for i, j in enumerate(revolute)}
    )
    frames = _check_kinematics(model, revolute, poses, where)
    body = {link: b for link, b in body.items() if link != model.payload}
    parts = _body_parts(tree, body, poses, frames, len(revolute), where)
    coupled = model.coupling is not None
    joints = []
    for i, (joint, kin) in enumerate(zip(revolute, model.joints, strict=True)):
        link = _body_link(joint, parts[i], where)
        limits = _limits(joint, where)
        limit_table: dict[str, Any] = {
            "position": limits.position.tolist(),
            "speed": limits.speed,
            "torque": limits.torque,
        }
        if kin.acceleration is not None:
            limit_table["acceleration"] = kin.acceleration
        if kin.continuous or limits.continuous:
            limit_table["continuous"] = True
        joints.append(
            {
                "name": kin.name,
                **kin.kinematics,
                "mass": link.mass,
                **_snapped(link.com, link.inertia),
                "drive": _restored_drive(kin, standard, coupled, where),
                "limits": limit_table,
            }
        )
    sources: dict[str, Any] = dict(model.sources)
    if any(k.friction is None for k in model.joints):
        sources["friction"] = {"status": "published", "ref": f"URDF {path.name} <dynamics>"}
    data: dict[str, Any] = {
        "name": name or urdf.robot.name or path.stem,
        "description": model.description,
        "convention": model.convention,
        "gravity": model.gravity,
        "standby_power": model.standby_power,
        "bus_voltage": model.bus_voltage,
        "base": model.base,
        "flange": model.flange_pose,
        "sources": sources,
        "joints": joints,
    }
    if coupled:
        data["coupling"] = model.coupling
    if model.identified is not None:
        data["identified"] = model.identified
    payload = _payload(tree, model, where)
    if payload is not None:
        data["payload"] = payload
    try:
        robot = robot_from_dict(data)
    except KinergyError as exc:
        raise exc.prefixed(f"{where}: <kinergy:model>") from None
    _check_dynamics(robot, model, standard, where)
    return robot


# --------------------------------------------------------------------------------------------
# The public functions
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class UrdfImport:
    """A robot read from a URDF file.

    Attributes
    ----------
    robot : Robot
    restored : bool
        Whether the file's ``<kinergy:model>`` element gave the drives, the convention and the
        rest of what URDF cannot hold (a file ``kinergy robot export`` wrote); else the drives
        are nominal but for the gear ratios and friction the standard elements give.
    """

    robot: Robot
    restored: bool

    @property
    def drives(self) -> str:
        """Where the drives came from, in words."""
        if self.restored:
            return "drives, friction and coupling from its <kinergy:model> element"
        return _drives_found(self.robot.joints)


def _drives_found(robot_joints: Sequence[Joint]) -> str:
    """What a URDF without a ``<kinergy:model>`` element gave of its drives, in words."""
    given = [
        what
        for what, present in (
            (
                "gear ratios from <transmission>",
                any(j.drive.gear_ratio != 1.0 for j in robot_joints),
            ),
            (
                "friction from <dynamics>",
                any(j.drive.friction.model != "none" for j in robot_joints),
            ),
        )
        if present
    ]
    if not given:
        return "drives are nominal"
    return f"{' and '.join(given)}, the rest of the drives nominal"


def import_urdf(
    path: str | os.PathLike[str],
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> UrdfImport:
    """Read the serial chain of revolute joints from ``root`` to ``tip`` of a URDF file.

    Parameters
    ----------
    path : str or path
        The URDF file. Meshes are not loaded.
    root : str, optional
        Link the arm is mounted on (default: the URDF's root link). Its frame is the robot's base
        frame: gravity (``[0, 0, -9.81]`` m/s^2), ``Robot.base`` and forward kinematics are in it.
    tip : str, optional
        Link at the end of the arm; its frame is the flange (``Robot.flange``). Default: the leaf
        reached from ``root`` (at a branching link the one subtree with moving joints is followed;
        if that is ambiguous a KinergyError asks for ``tip``).
    name : str, optional
        Robot name (default: the URDF's robot name).

    Returns
    -------
    UrdfImport
        A file with a ``<kinergy:model>`` element (written by ``kinergy robot export``) gives back
        the robot it was written from: the recorded convention and DH or MDH parameters (checked
        against the URDF's axes and flange), base, flange, gravity, coupling, drives, friction
        family and parameters (checked against ``<dynamics>``), acceleration limits and
        provenance, with the link inertials, payload, position, speed and torque limits and gear
        ratios (``<transmission>``) read from the standard elements. Any other file gives
        convention ``mdh``, one joint per ``revolute``/``continuous`` joint of the chain, named as
        in the URDF, with the same sign of q; link inertials the rigid sums of the links each
        joint moves (``fixed`` joints merged; a subtree hanging off the chain is lumped in at its
        q = 0 configuration); limits from ``<limit>`` (continuous joints: +-2 pi rad for planners, and
        ``continuous``); gear
        ratios from ROS SimpleTransmissions, Coulomb + viscous friction from ``<dynamics>``, the
        rest of the drives nominal (see the module docstring).

    Raises
    ------
    KinergyError
        ``PATH: ...`` naming the joint, link or element at fault: malformed XML, a ``prismatic``,
        ``planar`` or ``floating`` joint in the chain, a missing ``<limit>`` or its effort or
        velocity, a negative mass or a non-physical inertia, a moving body without mass,
        a branching tree without ``tip``, a ``<kinergy:model>`` that disagrees with the URDF it is
        in; or when ``yourdfpy`` is not installed.

    Notes
    -----
    The conversion is exact (to rounding) except for consecutive axes within
    :data:`PARALLEL_TOLERANCE` of parallel, which are taken as parallel; the modelled axis then
    deviates from the URDF one by less than that angle.
    """
    path = Path(path)
    where = str(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise _fail(where, f"cannot read URDF file ({exc.strerror})") from None
    element = _check_xml(text, where)
    standard = read_standard(element, where)
    model = read_kinergy(element, where)
    # huge numbers (an origin of 1e308 m) overflow on the way; every value that reaches the robot
    # is checked finite and bounded, so the overflow is refused there, in one line
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        urdf = _load_urdf(text, where)
        if model is not None:
            return UrdfImport(_restored(urdf, model, standard, path, (root, tip, name)), True)
        return UrdfImport(_generic(urdf, standard, path, (root, tip, name)), False)


def _generic(
    urdf: Any, standard: Standard, path: Path, selection: tuple[str | None, str | None, str | None]
) -> Robot:
    """The robot a URDF without a ``<kinergy:model>`` element describes."""
    where = str(path)
    root, tip, name = selection
    tree = _tree(urdf, where)
    root = _root_link(tree, root, where)
    tip = _tip_link(tree, root, where) if tip is None else tip
    revolute = _revolute_chain(tree, root, tip, where)
    poses, body = _poses_and_bodies(tree, root, {j.name: i + 1 for i, j in enumerate(revolute)})
    params, frames = _mdh_chain(revolute, poses, where)
    parts = _body_parts(tree, body, poses, frames, len(revolute), where)
    joints = [
        _joint(joint, row, parts[i], _standard_drive(joint.name, standard), where)
        for i, (joint, row) in enumerate(zip(revolute, params, strict=True))
    ]
    flange = np.linalg.solve(frames[-1], poses[tip])
    flange[np.abs(flange) < 1e-14] = 0.0
    friction = any(j.drive.friction.model != "none" for j in joints)
    try:
        robot = Robot(
            name=name or urdf.robot.name or path.stem,
            convention="mdh",
            joints=tuple(joints),
            base=frames[0],
            flange=flange,
            sources=_sources(path.name, friction),
            description=f"imported from URDF {path.name} (links {root!r} to {tip!r}); "
            + _drives_found(joints),
        )
    except KinergyError as exc:
        raise exc.prefixed(where) from None
    return robot


def robot_from_urdf(
    path: str | os.PathLike[str],
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> Robot:
    """The robot of :func:`import_urdf` (same parameters)."""
    return import_urdf(path, root=root, tip=tip, name=name).robot
