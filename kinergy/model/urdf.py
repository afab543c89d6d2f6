"""Import a serial arm of revolute joints from a URDF file (optional: needs ``yourdfpy``).

A URDF places each link frame with an arbitrary ``<origin xyz rpy>`` and turns it about an
arbitrary ``<axis>``; kinergy describes an arm by modified Denavit–Hartenberg parameters (Craig,
``mdh``). :func:`robot_from_urdf` converts one into the other without approximation:

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

URDF carries no drive data (and yourdfpy does not read ``<transmission>``): the drives are nominal (gear ratio 1, no rotor inertia, unit torque
and motor constants, no friction) and marked ``nominal`` in ``Robot.sources``; identify them from
logs before trusting energy predictions.
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
from kinergy.model.robot import (
    SOURCE_CATEGORIES,
    Drive,
    Friction,
    Joint,
    Limits,
    Link,
    Robot,
    Source,
)

__all__ = ["mdh_frames", "mdh_parameters", "mdh_transform", "robot_from_urdf"]


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
# MDH geometry: plain functions over arrays
# --------------------------------------------------------------------------------------------


def mdh_transform(a: float, alpha: float, offset: float, d: float) -> Array:
    """``Rx(alpha) · Tx(a) · Rz(offset) · Tz(d)``, shape (4, 4): frame i in frame i-1 at q_i = 0.

    Parameters
    ----------
    a, d : float
        a_{i-1} and d_i, m.
    alpha, offset : float
        alpha_{i-1} and offset_i, rad.
    """
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(offset), np.sin(offset)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [ca * st, ca * ct, -sa, -sa * d],
            [sa * st, sa * ct, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


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


def _check_xml(text: bytes, where: str) -> None:
    """Well-formed XML with the elements and attributes yourdfpy would otherwise trip on (or
    silently default: a missing ``ixx`` would become 1 kg m^2)."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
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


def _load_urdf(path: Path, where: str) -> Any:
    """The file parsed by yourdfpy (no scene graph, no meshes); every failure a KinergyError."""
    try:
        import yourdfpy
    except ImportError:
        raise KinergyError(
            "reading URDF files needs the 'yourdfpy' package (pip install kinergy[urdf])"
        ) from None
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise _fail(where, f"cannot read URDF file ({exc.strerror})") from None
    _check_xml(text, where)
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
    if joint.type == "continuous":
        position = np.array([-_TWO_PI, _TWO_PI])
    else:  # URDF: lower and upper default to 0
        position = np.array([limit.lower or 0.0, limit.upper or 0.0])
    try:
        return Limits(position=position, speed=limit.velocity, torque=limit.effort)
    except KinergyError as exc:
        raise exc.prefixed(jwhere) from None


def _nominal_drive() -> Drive:
    return Drive(
        gear_ratio=1.0,
        motor_inertia=0.0,
        reducer_inertia=0.0,
        torque_constant=1.0,
        motor_constant=1.0,
        kt_over_kb=1.0,
        friction=Friction("none", {}),
    )


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


def _joint(joint: Any, row: Array, parts: list[tuple[float, Array, Array]], where: str) -> Joint:
    """kinergy's joint for a URDF joint: MDH ``row`` = (a, alpha, offset, d), its body's rigid
    inertial, nominal drive, the URDF's limits."""
    lwhere = f"{where}: link {joint.child!r}"
    mass, com, inertia = _body_inertial(parts)
    if mass <= 0.0:
        raise _fail(
            lwhere,
            f"moved by joint {joint.name!r} but has no mass (nor do the links fixed to it); "
            "every moving body needs a positive mass",
        )
    try:
        link = Link(mass=mass, com=com, inertia=inertia)
    except KinergyError as exc:
        raise exc.prefixed(lwhere) from None
    a, alpha, offset, d = (float(x) for x in row)
    return Joint(
        name=joint.name,
        d=d,
        a=a,
        alpha=alpha,
        offset=offset,
        link=link,
        drive=_nominal_drive(),
        limits=_limits(joint, where),
    )


def _sources(file: str) -> dict[str, Source]:
    """Provenance: geometry, inertials and limits from the URDF; drives nominal."""
    published = Source("published", f"URDF {file}")
    nominal = Source("nominal", f"not in URDF {file}")
    drive = ("drive_inertia", "torque_constant", "friction", "motor_constant")
    return {c: nominal if c in drive else published for c in SOURCE_CATEGORIES}


# --------------------------------------------------------------------------------------------
# The public function
# --------------------------------------------------------------------------------------------


def robot_from_urdf(
    path: str | os.PathLike[str],
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> Robot:
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
    Robot
        Convention ``mdh``, one joint per ``revolute``/``continuous`` joint of the chain, named as
        in the URDF, with the same sign of q. Link inertials are the rigid sums of the links each
        joint moves (``fixed`` joints merged; a subtree hanging off the chain is lumped in at its
        q = 0 configuration). Limits from ``<limit>`` (continuous joints: +-2 pi rad); drives
        nominal (see the module docstring).

    Raises
    ------
    KinergyError
        ``PATH: ...`` naming the joint or link at fault: malformed XML, a ``prismatic``,
        ``planar`` or ``floating`` joint in the chain, a missing ``<limit>`` or its effort or
        velocity, a negative mass or a non-physical inertia, a moving body without mass,
        a branching tree without ``tip``; or when ``yourdfpy`` is not installed.

    Notes
    -----
    The conversion is exact (to rounding) except for consecutive axes within
    :data:`PARALLEL_TOLERANCE` of parallel, which are taken as parallel; the modelled axis then
    deviates from the URDF one by less than that angle.
    """
    path = Path(path)
    where = str(path)
    urdf = _load_urdf(path, where)
    tree = _tree(urdf, where)
    root = _root_link(tree, root, where)
    tip = _tip_link(tree, root, where) if tip is None else tip
    revolute = _revolute_chain(tree, root, tip, where)
    poses, body = _poses_and_bodies(tree, root, {j.name: i + 1 for i, j in enumerate(revolute)})
    params, frames = _mdh_chain(revolute, poses, where)
    parts = _body_parts(tree, body, poses, frames, len(revolute), where)
    joints = [
        _joint(joint, row, parts[i], where)
        for i, (joint, row) in enumerate(zip(revolute, params, strict=True))
    ]
    flange = np.linalg.solve(frames[-1], poses[tip])
    flange[np.abs(flange) < 1e-14] = 0.0
    try:
        return Robot(
            name=name or urdf.robot.name or path.stem,
            convention="mdh",
            joints=tuple(joints),
            base=frames[0],
            flange=flange,
            sources=_sources(path.name),
            description=f"imported from URDF {path.name} (links {root!r} to {tip!r}); "
            "drives are nominal",
        )
    except KinergyError as exc:
        raise exc.prefixed(where) from None
