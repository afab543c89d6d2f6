"""The serial chain of a URDF's tree, its frames at q = 0 and the rigid bodies its joints move.

A URDF (:mod:`kinergy.model.urdf_xml`) places each link frame with an ``<origin xyz rpy>`` and
turns it about an ``<axis>``. From ``root`` to ``tip``, ``revolute`` and ``continuous`` joints
become kinergy joints and ``fixed`` joints are merged: their child links are rigidly part of the
body before them (a subtree hanging off the chain is lumped in at its q = 0 configuration). Each
body's mass, centre of mass and inertia about it are the rigid sums of its links' inertials (a
URDF inertia is about the centre of mass in the axes of its ``<origin>``; it is rotated into the
body's axes and shifted by the parallel-axis theorem).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import Code, KinergyError
from kinergy.model.frames import mdh_frames, mdh_parameters, mdh_transform
from kinergy.model.robot import Limits, Link
from kinergy.model.urdf_xml import UrdfFile, UrdfJoint, UrdfLink

__all__ = [
    "Chain",
    "Part",
    "body_inertial",
    "body_link",
    "body_parts",
    "chain",
    "joint_limits",
    "mdh_chain",
    "unit_axis",
]

REVOLUTE = ("revolute", "continuous")
_TWO_PI = 2.0 * np.pi

#: a rigid part of a body: mass (kg), pose (4, 4) of its centre-of-mass frame in the body frame,
#: inertia (3, 3) about the centre of mass in that frame's axes (kg m^2)
Part = tuple[float, Array, Array]


def _fail(where: str, message: str, code: Code = Code.INVALID) -> KinergyError:
    return KinergyError(f"{where}: {message}", code)


@dataclass(frozen=True, eq=False)
class Chain:
    """The chain of a URDF from ``root`` to ``tip``.

    Attributes
    ----------
    root, tip : str
        The links the chain starts and ends at.
    joints : list of UrdfJoint
        Its revolute and continuous joints, in order.
    poses : mapping of str to ndarray (4, 4)
        Every link below ``root`` at q = 0, in the root frame.
    body : mapping of str to int
        The body each link belongs to: 0 fixed to the root, i moved by the i-th joint of the
        chain.
    """

    root: str
    tip: str
    joints: list[UrdfJoint]
    poses: Mapping[str, Array]
    body: Mapping[str, int]


def _children(urdf: UrdfFile) -> tuple[dict[str, UrdfJoint], dict[str, list[UrdfJoint]]]:
    """Each link's parent joint and child joints; a KinergyError unless the joints form a tree
    of the file's links."""
    parent: dict[str, UrdfJoint] = {}
    children: dict[str, list[UrdfJoint]] = {name: [] for name in urdf.links}
    for joint in urdf.joints:
        for end in (joint.parent, joint.child):
            if end not in urdf.links:
                raise _fail(
                    f"{urdf.path}: joint {joint.name!r}", f"refers to an undefined link {end!r}"
                )
        if joint.child in parent:
            raise _fail(
                f"{urdf.path}: link {joint.child!r}",
                f"is the child of two joints ({parent[joint.child].name!r} and {joint.name!r}); "
                "a URDF must be a tree",
            )
        parent[joint.child] = joint
        children[joint.parent].append(joint)
    return parent, children


def _root(urdf: UrdfFile, parent: Mapping[str, UrdfJoint], root: str | None) -> str:
    if root is not None:
        if root not in urdf.links:
            raise _fail(urdf.path, f"no link named {root!r} (root)", Code.MISSING)
        return root
    roots = [name for name in urdf.links if name not in parent]
    if len(roots) != 1:
        found = ", ".join(repr(r) for r in roots) or "none (the joints form a loop)"
        raise _fail(urdf.path, f"expected one root link, found {found}; give `root`")
    return roots[0]


def _moves(children: Mapping[str, list[UrdfJoint]], link: str) -> bool:
    """Whether a joint below ``link`` moves."""
    return any(j.type != "fixed" or _moves(children, j.child) for j in children[link])


def _tip(urdf: UrdfFile, children: Mapping[str, list[UrdfJoint]], root: str) -> str:
    """The end of the chain from ``root``: at a link with several child joints, the one subtree
    that still moves, or the link itself where none does (frames such as ``tool0`` and ``ee_link``
    fixed side by side: give ``tip`` for one of them); several moving subtrees are ambiguous."""
    link = root
    while children[link]:
        below = children[link]
        if len(below) > 1:
            moving = [j for j in below if j.type != "fixed" or _moves(children, j.child)]
            if not moving:
                return link
            if len(moving) != 1:
                names = ", ".join(repr(j.name) for j in below)
                raise _fail(
                    f"{urdf.path}: link {link!r}",
                    f"the tree branches here (joints {names}); give `tip`, the link at the end "
                    "of the arm",
                )
            below = moving
        link = below[0].child
    return link


def chain(urdf: UrdfFile, root: str | None = None, tip: str | None = None) -> Chain:
    """The chain of revolute and continuous joints from ``root`` (default: the root link) to
    ``tip`` (default: the leaf reached from ``root``, following the one subtree that moves).

    Raises
    ------
    KinergyError
        Naming the link or joint: a joint of an undefined link, a link with two parents, no or
        several root links, an unknown or unreachable ``root`` or ``tip``, a branching tree
        without ``tip``, a ``prismatic``, ``planar`` or ``floating`` joint in the chain, no
        revolute joint.
    """
    parent, children = _children(urdf)
    root = _root(urdf, parent, root)
    tip = _tip(urdf, children, root) if tip is None else tip
    if tip not in urdf.links:
        raise _fail(urdf.path, f"no link named {tip!r} (tip)", Code.MISSING)
    path = []
    link = tip
    while link != root:
        if link not in parent:
            raise _fail(urdf.path, f"link {tip!r} (tip) is not below link {root!r} (root)")
        path.append(parent[link])
        link = parent[link].parent
    revolute = []
    for joint in reversed(path):
        if joint.type in REVOLUTE:
            revolute.append(joint)
        elif joint.type != "fixed":
            raise _fail(
                f"{urdf.path}: joint {joint.name!r}",
                f"type {joint.type!r} is not supported (kinergy models serial arms of revolute "
                "joints; fixed joints are merged)",
                Code.UNSUPPORTED,
            )
    if not revolute:
        raise _fail(
            urdf.path, f"no revolute or continuous joint between links {root!r} and {tip!r}"
        )
    moving = {j.name: i + 1 for i, j in enumerate(revolute)}
    poses, body = {root: np.eye(4)}, {root: 0}
    stack = [root]
    while stack:
        link = stack.pop()
        for joint in children[link]:
            poses[joint.child] = poses[link] @ joint.origin
            body[joint.child] = moving.get(joint.name, body[link])
            stack.append(joint.child)
    return Chain(root, tip, revolute, poses, body)


def unit_axis(joint: UrdfJoint, where: str) -> Array:
    """The joint's axis as a unit vector; a KinergyError for a zero axis."""
    norm = float(np.linalg.norm(joint.axis))
    if not norm >= 1e-9:
        raise _fail(
            f"{where}: joint {joint.name!r}",
            f"axis must be 3 numbers, not zero, got {joint.axis.tolist()}",
        )
    return joint.axis / norm


def _link_part(link: UrdfLink, where: str) -> Part:
    """Mass, centre-of-mass pose and inertia of a link (zeros without ``<inertial>``), checked:
    a mass >= 0, no inertia without mass. Whether the inertia is physical is asked of each body's
    rigid sum (:func:`body_link`): a published file whose small part (a gripper's motor) has
    moments a little off the triangle inequality still gives a physical body."""
    inertial = link.inertial
    if inertial is None:
        return 0.0, np.eye(4), np.zeros((3, 3))
    lwhere = f"{where}: link {link.name!r}"
    mass, inertia = checks.number(inertial.mass, f"{lwhere} mass", ge=0.0), inertial.inertia
    if mass == 0.0 and np.any(inertia != 0.0):
        raise _fail(lwhere, "has an inertia but no mass")
    return mass, inertial.origin, inertia


def body_inertial(parts: Sequence[Part]) -> tuple[float, Array, Array]:
    """Rigid sum of inertials.

    Parameters
    ----------
    parts : sequence of Part
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


def joint_limits(joint: UrdfJoint, where: str) -> Limits:
    """kinergy's limits of a URDF joint (continuous: +-2 pi rad for planners, and
    ``Limits.continuous``)."""
    jwhere = f"{where}: joint {joint.name!r}"
    limit = joint.limit
    if limit is None:
        raise _fail(
            jwhere,
            "missing <limit> (needs effort and velocity, and lower and upper for a revolute joint)",
            Code.MISSING,
        )
    if limit.effort is None or limit.velocity is None:
        missing = "effort" if limit.effort is None else "velocity"
        raise _fail(jwhere, f"<limit> lacks {missing!r}", Code.MISSING)
    continuous = joint.type == "continuous"
    if continuous:  # the planners' range; the joint turns without limit
        position = np.array([-_TWO_PI, _TWO_PI])
    else:  # URDF: lower and upper default to 0
        position = np.array([limit.lower, limit.upper])
    try:
        return Limits(
            position=position, speed=limit.velocity, torque=limit.effort, continuous=continuous
        )
    except KinergyError as exc:
        raise exc.prefixed(jwhere) from None


def mdh_chain(found: Chain, where: str) -> tuple[Array, Array]:
    """MDH parameters (n, 4) of the chain's joints and the frames (n + 1, 4, 4) they rebuild,
    frame 0 the root-frame pose of joint 1's frame, exactly as :mod:`kinergy.dynamics.chain`
    does (:func:`~kinergy.model.frames.mdh_frames`)."""
    # joint frames at q = 0 in the root frame: the URDF child-link frames of the joints
    poses = found.poses
    axes = np.array([poses[j.child][:3, :3] @ unit_axis(j, where) for j in found.joints])
    points = np.array([poses[j.child][:3, 3] for j in found.joints])
    nominal = mdh_frames(axes, points)
    params = mdh_parameters(nominal)
    frames = np.empty((len(found.joints) + 1, 4, 4))
    frames[0] = nominal[0]
    frames[0][np.abs(frames[0]) < 1e-14] = 0.0  # rounding noise, for readable robot files
    for i, row in enumerate(params):
        frames[i + 1] = frames[i] @ mdh_transform(*row)
    return params, frames


def body_parts(urdf: UrdfFile, found: Chain, frames: Array) -> list[list[Part]]:
    """Per moving body, the inertials of the URDF links fixed to it, posed in its frame
    ``frames[i]`` (link frames (n + 1, 4, 4) at q = 0 in the root frame)."""
    parts: list[list[Part]] = [[] for _ in found.joints]
    for name, b in found.body.items():
        if b == 0:
            continue
        mass, origin, inertia = _link_part(urdf.links[name], urdf.path)
        if mass > 0.0:
            pose = np.linalg.solve(frames[b], found.poses[name] @ origin)
            parts[b - 1].append((mass, pose, inertia))
    return parts


def body_link(joint: UrdfJoint, parts: Sequence[Part], where: str) -> Link:
    """The rigid sum of the inertials moved by ``joint``, checked."""
    lwhere = f"{where}: link {joint.child!r}"
    mass, com, inertia = body_inertial(parts)
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
