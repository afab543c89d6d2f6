"""Import a serial arm of revolute joints from a URDF file (the standard library reads it).

Two kinds of file:

- **A file ``kinergy robot export`` wrote** holds the robot in its ``<kinergy:robot>`` element:
  the very dictionary a robot file holds (:func:`kinergy.model.toml.robot_to_dict`, as JSON, with
  the version of its schema, :data:`~kinergy.model.toml.ROBOT_SCHEMA`). It is read back with the
  code that reads robot files (:func:`~kinergy.model.toml.robot_from_dict`) and checked against
  the file's standard elements: they must be what that robot exports to (every joint's origin,
  axis, limits and ``<dynamics>``, every link's inertial, every transmission, to 1e-9 relative).
  A file edited since, so that the two disagree, is refused, naming the element and the value.
- **Any other URDF** (as published: meshes, ``<transmission>``, ``<ros2_control>``, ``<gazebo>``
  and all) is converted without approximation into modified Denavit–Hartenberg parameters
  (Craig, ``mdh``; :func:`kinergy.model.frames.mdh_frames`): one kinergy joint per
  ``revolute``/``continuous`` joint of the chain from ``root`` to ``tip``, the same sign of q,
  ``fixed`` joints merged, each body's inertial the rigid sum of its links'
  (:mod:`kinergy.model.urdf_chain`); frame 0's pose in the root frame is ``Robot.base``, the tip
  link's frame ``Robot.flange``. The drives take what the file gives
  (:mod:`kinergy.model.urdf_xml`): a transmission's gear ratio (else 1) and rotor inertia (as the
  motor inertia, motor side), the joint's ``<dynamics damping friction>`` as Coulomb + viscous
  friction referred to the motor (``coulomb = friction / |n|``, ``viscous = damping / n^2``,
  exactly what the MJCF export gives back); the rest is nominal (unit torque and motor
  constants) and marked ``nominal`` in ``Robot.sources``: identify it from logs before trusting
  energy predictions. Meshes are not read: they hold no dynamics.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import Code, KinergyError
from kinergy.friction.model import SMOOTHING
from kinergy.friction.none import MODEL as NO_FRICTION
from kinergy.friction.viscous_coulomb import MODEL as VISCOUS_COULOMB
from kinergy.model.frames import PARALLEL_TOLERANCE
from kinergy.model.robot import SOURCE_CATEGORIES, Convention, Drive, Friction, Joint, Robot, Source
from kinergy.model.toml import ROBOT_SCHEMA, robot_from_dict
from kinergy.model.urdf_chain import (
    body_link,
    body_parts,
    chain,
    joint_limits,
    mdh_chain,
)
from kinergy.model.urdf_export import robot_to_urdf
from kinergy.model.urdf_xml import Actuation, UrdfFile, UrdfJoint, parse_urdf, read_urdf

__all__ = ["PARALLEL_TOLERANCE", "UrdfImport", "import_urdf", "robot_from_urdf"]

#: how far (relative to the largest value of the element) a standard element may be from what
#: the embedded robot exports to: far above the rounding of the frame changes, far below an edit
AGREEMENT = 1e-9


@dataclass(frozen=True, eq=False)
class UrdfImport:
    """A robot read from a URDF file.

    Attributes
    ----------
    robot : Robot
    restored : bool
        Whether the file's ``<kinergy:robot>`` element gave the robot (a file ``kinergy robot
        export`` wrote); else the drives are what the standard elements give, the rest nominal.
    notes : tuple of str
        What the user should know: transmissions not read.
    """

    robot: Robot
    restored: bool
    notes: tuple[str, ...] = ()

    @property
    def drives(self) -> str:
        """Where the drives came from, in words."""
        if self.restored:
            return "the robot file its <kinergy:robot> element holds"
        return _drives_found(self.robot.joints)


def _drives_found(joints: Sequence[Joint]) -> str:
    """What a URDF without a ``<kinergy:robot>`` element gave of its drives, in words."""
    given = [
        what
        for what, present in (
            ("gear ratios from <transmission>", any(j.drive.gear_ratio != 1.0 for j in joints)),
            ("rotor inertias from <transmission>", any(j.drive.motor_inertia > 0 for j in joints)),
            (
                "friction from <dynamics>",
                any(j.drive.friction.model is not NO_FRICTION for j in joints),
            ),
        )
        if present
    ]
    if not given:
        return "drives are nominal"
    listed = " and ".join([", ".join(given[:-1]), given[-1]] if len(given) > 1 else given)
    return f"{listed}, the rest of the drives nominal"


# --------------------------------------------------------------------------------------------
# Any URDF: the standard elements
# --------------------------------------------------------------------------------------------


def _drive(joint: UrdfJoint, actuation: Actuation | None) -> Drive:
    """A drive from a URDF's standard elements: the transmission's gear ratio (else 1) and rotor
    inertia (else 0), Coulomb + viscous friction from ``<dynamics>`` referred to the motor
    (``viscous = damping / n^2``, ``coulomb = friction / |n|``), the rest nominal."""
    gear = actuation.reduction if actuation is not None else 1.0
    rotor = actuation.rotor_inertia if actuation is not None else None
    damping, coulomb = joint.dynamics or (0.0, 0.0)
    friction = (
        Friction(
            VISCOUS_COULOMB,
            {"viscous": damping / gear**2, "coulomb": coulomb / abs(gear), "smoothing": SMOOTHING},
        )
        if damping > 0.0 or coulomb > 0.0
        else Friction(NO_FRICTION, {})
    )
    return Drive(
        gear_ratio=gear,
        motor_inertia=rotor or 0.0,
        reducer_inertia=0.0,
        torque_constant=1.0,
        motor_constant=1.0,
        kt_over_kb=1.0,
        friction=friction,
    )


def _sources(file: str, joints: Sequence[Joint]) -> dict[str, Source]:
    """Provenance: geometry, inertials and limits from the URDF; the friction and the rotor
    inertias too where it gives them; the rest of the drives nominal."""
    published = Source("published", f"URDF {file}")
    nominal = Source("nominal", f"not in URDF {file}")
    drive = ("drive_inertia", "torque_constant", "motor_constant", "thermal", "supply")
    out = {c: nominal if c in drive else published for c in SOURCE_CATEGORIES}
    out["friction"] = nominal
    if any(j.drive.friction.model is not NO_FRICTION for j in joints):
        out["friction"] = Source("published", f"URDF {file} <dynamics>, as Coulomb + viscous")
    if any(j.drive.motor_inertia > 0.0 for j in joints):
        out["drive_inertia"] = Source("published", f"URDF {file} <transmission> rotor inertia")
    return out


def _generic(urdf: UrdfFile, selection: tuple[str | None, str | None, str | None]) -> Robot:
    """The robot a URDF's standard elements describe (module docstring)."""
    root, tip, name = selection
    found = chain(urdf, root, tip)
    params, frames = mdh_chain(found, urdf.path)
    parts = body_parts(urdf, found, frames)
    joints = []
    for i, (joint, row) in enumerate(zip(found.joints, params, strict=True)):
        a, alpha, offset, d = (float(x) for x in row)
        joints.append(
            Joint(
                name=joint.name,
                d=d,
                a=a,
                alpha=alpha,
                offset=offset,
                link=body_link(joint, parts[i], urdf.path),
                drive=_drive(joint, urdf.actuation.get(joint.name)),
                limits=joint_limits(joint, urdf.path),
            )
        )
    flange = np.linalg.solve(frames[-1], found.poses[found.tip])
    flange[np.abs(flange) < 1e-14] = 0.0
    file = Path(urdf.path).name
    try:
        return Robot(
            name=name or urdf.name or Path(urdf.path).stem,
            convention=Convention.MDH,
            joints=tuple(joints),
            base=frames[0],
            flange=flange,
            sources=_sources(file, joints),
            description=f"imported from URDF {file} (links {found.root!r} to {found.tip!r}); "
            + _drives_found(joints),
        )
    except KinergyError as exc:
        raise exc.prefixed(urdf.path) from None


# --------------------------------------------------------------------------------------------
# A file kinergy exported: <kinergy:robot>, checked against the standard elements
# --------------------------------------------------------------------------------------------


def _values(value: Any) -> Array | None:
    """Numbers to compare (None stays None, an absent number is NaN)."""
    if value is None:
        return None
    if isinstance(value, tuple):
        value = [np.nan if v is None else v for v in value]
    return np.asarray(value, dtype=float)


def _off(got: Array | None, want: Array | None) -> bool:
    """Whether ``got`` is farther than :data:`AGREEMENT` (relative to ``want``'s largest
    magnitude) from ``want``, or only one of them is there."""
    if got is None or want is None:
        return (got is None) != (want is None)
    if not np.array_equal(np.isnan(got), np.isnan(want)):
        return True
    got, want = np.nan_to_num(got), np.nan_to_num(want)
    scale = max(float(np.max(np.abs(want), initial=0.0)), 1e-300)
    return not float(np.max(np.abs(got - want), initial=0.0)) <= AGREEMENT * scale


def _shown(value: Array | None) -> str:
    if value is None:
        return "none"
    return f"{float(value):.6g}" if value.ndim == 0 else str(np.round(value, 6).tolist())


def _link_disagreement(file: UrdfFile, written: UrdfFile) -> str | None:
    for name, want in written.links.items():
        got = file.links.get(name)
        if got is None:
            return f"link {name!r} is missing"
        if (got.inertial is None) != (want.inertial is None):
            return f"link {name!r} <inertial> is {'absent' if got.inertial is None else 'extra'}"
        if got.inertial is None or want.inertial is None:
            continue
        for field, a, b in (
            ("mass", _values(got.inertial.mass), _values(want.inertial.mass)),
            ("origin", _values(got.inertial.origin), _values(want.inertial.origin)),
            ("inertia", _values(got.inertial.inertia), _values(want.inertial.inertia)),
        ):
            if _off(a, b):
                return f"link {name!r} <inertial> {field} is {_shown(a)}, not {_shown(b)}"
    extra = sorted(set(file.links) - set(written.links))
    return f"link {extra[0]!r} is not in it" if extra else None


def _joint_disagreement(file: UrdfFile, written: UrdfFile) -> str | None:
    joints = {j.name: j for j in file.joints}
    for want in written.joints:
        got = joints.get(want.name)
        if got is None:
            return f"joint {want.name!r} is missing"
        ends = (got.type, got.parent, got.child)
        if ends != (want.type, want.parent, want.child):
            return f"joint {want.name!r} is {ends}, not {(want.type, want.parent, want.child)}"
        limits = [
            None if x is None else _values((x.lower, x.upper, x.effort, x.velocity))
            for x in (got.limit, want.limit)
        ]
        for field, a, b in (
            ("<origin>", _values(got.origin), _values(want.origin)),
            ("<axis>", _values(got.axis), _values(want.axis)),
            ("<limit> (lower, upper, effort, velocity)", limits[0], limits[1]),
            ("<dynamics> (damping, friction)", _values(got.dynamics), _values(want.dynamics)),
        ):
            if _off(a, b):
                return f"joint {want.name!r} {field} is {_shown(a)}, not {_shown(b)}"
    extra = sorted(set(joints) - {j.name for j in written.joints})
    if extra:
        return f"joint {extra[0]!r} is not in it"
    for name, want_act in written.actuation.items():
        got_act = file.actuation.get(name)
        if got_act is None or _off(_values(got_act.reduction), _values(want_act.reduction)):
            shown = "missing" if got_act is None else f"{got_act.reduction:g}"
            return (
                f"joint {name!r} <transmission> mechanical reduction is {shown}, not "
                f"{want_act.reduction:g}"
            )
    return None


def _restored(urdf: UrdfFile, selection: tuple[str | None, str | None, str | None]) -> Robot:
    """The robot a ``<kinergy:robot>`` element holds, checked against the standard elements."""
    assert urdf.embedded is not None
    where = f"{urdf.path}: <kinergy:robot>"
    root, tip, name = selection
    if urdf.embedded.version != str(ROBOT_SCHEMA):
        raise KinergyError(
            f"{where}: schema version {urdf.embedded.version!r}; this kinergy reads version "
            f"{ROBOT_SCHEMA}",
            Code.UNSUPPORTED,
        )
    if root is not None or tip is not None:
        raise KinergyError(
            f"{where}: the element describes the whole arm; give no root and tip, or remove the "
            "element to import a part of the chain",
            Code.UNSUPPORTED,
        )
    try:
        robot = robot_from_dict(urdf.embedded.data)
    except KinergyError as exc:
        raise exc.prefixed(where) from None
    written = parse_urdf(robot_to_urdf(robot).text.encode(), "export")
    problem = _link_disagreement(urdf, written) or _joint_disagreement(urdf, written)
    if problem is not None:
        raise KinergyError(
            f"{urdf.path}: {problem} in the robot its <kinergy:robot> element holds: the file "
            "was edited after kinergy wrote it; restore it, or remove the <kinergy:robot> "
            "element to import the standard elements alone",
            Code.DISAGREES,
        )
    return robot if name is None else dataclasses.replace(robot, name=name)


# --------------------------------------------------------------------------------------------
# The public functions
# --------------------------------------------------------------------------------------------


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
        The URDF file (as published: meshes and the like are skipped).
    root : str, optional
        Link the arm is mounted on (default: the URDF's root link). Its frame is the robot's base
        frame: gravity (``[0, 0, -9.81]`` m/s^2), ``Robot.base`` and forward kinematics are in it.
    tip : str, optional
        Link at the end of the arm; its frame is the flange (``Robot.flange``). Default: the leaf
        reached from ``root`` (at a branching link the one subtree with moving joints is followed;
        if that is ambiguous a KinergyError asks for ``tip``).
    name : str, optional
        Robot name (default: the embedded robot's, else the URDF's).

    Returns
    -------
    UrdfImport
        A file with a ``<kinergy:robot>`` element (``kinergy robot export``) gives back the robot
        it was written from; any other file the robot its standard elements describe (module
        docstring).

    Raises
    ------
    KinergyError
        ``PATH: ...`` naming the joint, link or element at fault: malformed XML, a ``prismatic``,
        ``planar`` or ``floating`` joint in the chain, a missing ``<limit>`` or its effort or
        velocity, a negative mass or a non-physical inertia, a moving body without mass,
        a branching tree without ``tip``, a ``<kinergy:robot>`` element its standard elements
        disagree with (code ``DISAGREES``).

    Notes
    -----
    The conversion is exact (to rounding) except for consecutive axes within
    :data:`PARALLEL_TOLERANCE` of parallel, which are taken as parallel; the modelled axis then
    deviates from the URDF one by less than that angle.
    """
    urdf = read_urdf(path)
    notes = tuple(
        f"{urdf.path}: {skipped} not read (only transmissions of one joint are): the gear ratio "
        "of its joints is nominal"
        for skipped in urdf.skipped
    )
    # huge numbers overflow on the way; every value that reaches the robot is checked finite
    # and bounded, so the overflow is refused there, in one line
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if urdf.embedded is not None:
            return UrdfImport(_restored(urdf, (root, tip, name)), True, notes)
        return UrdfImport(_generic(urdf, (root, tip, name)), False, notes)


def robot_from_urdf(
    path: str | os.PathLike[str],
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> Robot:
    """The robot of :func:`import_urdf` (same parameters)."""
    return import_urdf(path, root=root, tip=tip, name=name).robot
