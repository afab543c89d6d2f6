"""A URDF file read with the standard library's XML parser, into plain checked values.

What is read (everything else, meshes, materials, ``<gazebo>``, ``<ros2_control>`` hardware and
the like, is skipped):

- ``<link>``: its ``<inertial>`` (``<origin xyz rpy>``, ``<mass value>``, ``<inertia ixx ixy ixz
  iyy iyz izz>`` about the centre of mass in the origin's axes); ``<visual>`` and ``<collision>``
  (meshes) are not read: they hold no dynamics;
- ``<joint>``: type, ``<parent link>``, ``<child link>``, ``<origin xyz rpy>`` (default zero),
  ``<axis xyz>`` (default ``1 0 0``), ``<limit lower upper effort velocity>``, ``<dynamics damping
  friction>`` (other attributes, such as franka_description's ``D K mu_coulomb mu_viscous``, are
  not read);
- ``<transmission>`` anywhere in the file (ROS 1 at the top level, ros2_control inside
  ``<ros2_control>``) that drives one joint: a ``SimpleTransmission`` (``<type>``, ``<plugin>``
  or the older ``type`` attribute) or a transmission of no type naming one joint. Its gear ratio is the product of the
  ``mechanicalReduction`` / ``mechanical_reduction`` of its joint, its actuators and itself (each
  1 where absent), or Drake's ``<drake:gear_ratio>`` where given; a motor's rotor inertia is
  Drake's ``<drake:rotor_inertia>`` (kg m^2, motor side) where given. Transmissions of several
  joints (differential, four-bar) are not read; :attr:`UrdfFile.skipped` names them;
- ``<kinergy:robot>`` (namespace :data:`NAMESPACE`): the robot a ``kinergy robot export`` wrote,
  as the JSON text of the robot-file dictionary (:func:`kinergy.model.toml.robot_to_dict`),
  with the version of that dictionary's schema.

Every problem is one :class:`~kinergy.errors.KinergyError` line naming the file, the element and
the attribute.
"""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import Code, KinergyError
from kinergy.model.frames import rpy_matrix

__all__ = [
    "NAMESPACE",
    "Actuation",
    "Embedded",
    "Inertial",
    "Limit",
    "UrdfFile",
    "UrdfJoint",
    "UrdfLink",
    "parse_urdf",
    "read_urdf",
]

#: the XML namespace of kinergy's element in a URDF (other URDF parsers skip foreign elements)
NAMESPACE = "urn:kinergy:urdf"
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_REDUCTION = ("mechanicalReduction", "mechanical_reduction")


def _local(tag: Any) -> str:
    """An element's tag without its namespace (``{uri}name`` -> ``name``); comments give ""."""
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _fail(where: str, message: str, code: Code = Code.INVALID) -> KinergyError:
    return KinergyError(f"{where}: {message}", code)


def _numbers(text: str | None, count: int, where: str) -> Array:
    """``count`` finite numbers separated by spaces."""
    parts = (text or "").split()
    try:
        values = np.array([float(p) for p in parts])
    except ValueError:
        raise _fail(where, f"must be {count} numbers, got {text!r}", Code.NUMBER) from None
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise _fail(where, f"must be {count} finite numbers, got {text!r}", Code.NUMBER)
    return values


def _number(text: str | None, where: str, default: float | None = None) -> float:
    if text is None and default is not None:
        return default
    return float(_numbers(text, 1, where)[0])


@dataclass(frozen=True, eq=False)
class Inertial:
    """A link's ``<inertial>``.

    Attributes
    ----------
    mass : float
        kg (0 where absent).
    origin : ndarray, shape (4, 4)
        Pose of the centre-of-mass frame in the link frame.
    inertia : ndarray, shape (3, 3)
        About the centre of mass in the origin's axes, kg m^2 (zeros where absent).
    """

    mass: float
    origin: Array
    inertia: Array


@dataclass(frozen=True, eq=False)
class UrdfLink:
    """A ``<link>``: its name and inertial (None without one)."""

    name: str
    inertial: Inertial | None


@dataclass(frozen=True)
class Limit:
    """A joint's ``<limit>``: lower and upper (rad or m; 0 where absent), effort (N m) and
    velocity (rad/s), None where absent."""

    lower: float
    upper: float
    effort: float | None
    velocity: float | None


@dataclass(frozen=True, eq=False)
class UrdfJoint:
    """A ``<joint>``.

    Attributes
    ----------
    name, type, parent, child : str
    origin : ndarray, shape (4, 4)
        Pose of the child link frame in the parent link frame at q = 0.
    axis : ndarray, shape (3,)
        As written (not normalised).
    limit : Limit or None
    dynamics : (float, float) or None
        ``(damping, friction)``, joint side (N m s/rad, N m), >= 0.
    """

    name: str
    type: str
    parent: str
    child: str
    origin: Array
    axis: Array
    limit: Limit | None
    dynamics: tuple[float, float] | None


@dataclass(frozen=True)
class Actuation:
    """What a joint's transmission gives of its drive.

    Attributes
    ----------
    reduction : float
        Gear ratio: motor turns per joint turn, non-zero.
    rotor_inertia : float or None
        The motor's rotor inertia, kg m^2, motor side (Drake's ``drake:rotor_inertia``).
    source : str
        The transmission's name, for messages.
    """

    reduction: float
    rotor_inertia: float | None
    source: str


@dataclass(frozen=True)
class Embedded:
    """The ``<kinergy:robot>`` element: its schema version and the robot-file dictionary."""

    version: str
    data: Mapping[str, Any]


@dataclass(frozen=True, eq=False)
class UrdfFile:
    """A URDF file's content (module docstring), in file order.

    Attributes
    ----------
    path : str
        What errors name.
    name : str
        The ``<robot name>``.
    links : mapping of str to UrdfLink
    joints : tuple of UrdfJoint
    actuation : mapping of str to Actuation
        By joint name.
    embedded : Embedded or None
    skipped : tuple of str
        Transmissions not read, each in words.
    """

    path: str
    name: str
    links: Mapping[str, UrdfLink]
    joints: tuple[UrdfJoint, ...]
    actuation: Mapping[str, Actuation]
    embedded: Embedded | None
    skipped: tuple[str, ...]


def _origin(element: ET.Element | None, where: str) -> Array:
    """The pose of an ``<origin xyz rpy>`` (identity where absent), shape (4, 4)."""
    out = np.eye(4)
    if element is None:
        return out
    xyz = _numbers(element.get("xyz", "0 0 0"), 3, f"{where} <origin xyz>")
    rpy = _numbers(element.get("rpy", "0 0 0"), 3, f"{where} <origin rpy>")
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def _inertial(link: ET.Element, where: str) -> Inertial | None:
    element = link.find("inertial")
    if element is None:
        return None
    mass_element = element.find("mass")
    mass = 0.0
    if mass_element is not None:
        mass = _number(mass_element.get("value"), f"{where} <mass value>")
    inertia = np.zeros((3, 3))
    found = element.find("inertia")
    if found is not None:
        missing = [a for a in _INERTIA if found.get(a) is None]
        if missing:
            raise _fail(where, f"<inertia> lacks {', '.join(missing)}", Code.MISSING)
        ixx, ixy, ixz, iyy, iyz, izz = (
            _number(found.get(a), f"{where} <inertia {a}>") for a in _INERTIA
        )
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    return Inertial(mass, _origin(element.find("origin"), where), inertia)


def _limit(element: ET.Element | None, where: str) -> Limit | None:
    if element is None:
        return None
    where = f"{where} <limit>"

    def optional(key: str) -> float | None:
        text = element.get(key)
        return None if text is None else _number(text, f"{where} {key}")

    return Limit(
        lower=_number(element.get("lower"), f"{where} lower", 0.0),
        upper=_number(element.get("upper"), f"{where} upper", 0.0),
        effort=optional("effort"),
        velocity=optional("velocity"),
    )


def _dynamics(element: ET.Element | None, where: str) -> tuple[float, float] | None:
    if element is None:
        return None
    where = f"{where} <dynamics>"
    damping, friction = (
        checks.number(_number(element.get(key), f"{where} {key}", 0.0), f"{where} {key}", ge=0.0)
        for key in ("damping", "friction")
    )
    return damping, friction


def _joint(element: ET.Element, where: str) -> UrdfJoint:
    name = str(element.get("name"))
    jwhere = f"{where}: joint {name!r}"
    kind = element.get("type")
    if not kind:
        raise _fail(jwhere, "no 'type' attribute", Code.MISSING)
    ends = []
    for tag in ("parent", "child"):
        end = element.find(tag)
        if end is None or not end.get("link"):
            raise _fail(jwhere, f"missing <{tag} link=...>", Code.MISSING)
        ends.append(str(end.get("link")))
    axis_element = element.find("axis")
    axis = np.array([1.0, 0.0, 0.0])
    if axis_element is not None:
        axis = _numbers(axis_element.get("xyz", "1 0 0"), 3, f"{jwhere} <axis xyz>")
    return UrdfJoint(
        name=name,
        type=kind,
        parent=ends[0],
        child=ends[1],
        origin=_origin(element.find("origin"), jwhere),
        axis=axis,
        limit=_limit(element.find("limit"), jwhere),
        dynamics=_dynamics(element.find("dynamics"), jwhere),
    )


def _named(root: ET.Element, kind: str, where: str) -> list[ET.Element]:
    """The ``<link>`` or ``<joint>`` elements of ``<robot>``: each named, no name twice."""
    seen: set[str] = set()
    elements = root.findall(kind)
    for k, element in enumerate(elements):
        name = element.get("name")
        if not name:
            raise _fail(where, f"<{kind}> number {k + 1} has no 'name' attribute", Code.MISSING)
        if name in seen:
            raise _fail(where, f"{kind} {name!r} is defined twice")
        seen.add(name)
    return elements


def _value(element: ET.Element, where: str) -> float:
    """A Drake-style scalar element: ``<x value="..."/>`` or ``<x>...</x>``."""
    text = element.get("value", element.text)
    return _number(text.strip() if text else text, where)


def _reductions(element: ET.Element, where: str) -> list[float]:
    """The mechanical reductions written directly in ``element``."""
    return [
        _number((child.text or "").strip(), f"{where} <{_local(child.tag)}>")
        for child in element
        if _local(child.tag) in _REDUCTION
    ]


def _transmission(element: ET.Element, where: str) -> tuple[str, Actuation] | str:
    """A transmission of one joint as ``(joint, Actuation)``; any other in words (skipped)."""
    name = element.get("name") or "(unnamed)"
    twhere = f"{where}: <transmission name={name!r}>"
    kind = (
        element.findtext("type") or element.findtext("plugin") or element.get("type") or ""
    ).strip()
    joints = [j for j in element if _local(j.tag) == "joint" and j.get("name")]
    actuators = [a for a in element if _local(a.tag) == "actuator"]
    if len(joints) != 1 or (kind and not kind.endswith("SimpleTransmission")):
        shown = kind or "no type"
        return f"transmission {name!r} ({shown}, {len(joints)} joints)"
    reductions = _reductions(element, twhere) + _reductions(joints[0], twhere)
    rotor, gear = None, None
    for actuator in actuators:
        awhere = f"{twhere} <actuator>"
        reductions += _reductions(actuator, awhere)
        for child in actuator:
            if _local(child.tag) == "rotor_inertia":
                rotor = _value(child, f"{awhere} <drake:rotor_inertia>")
            elif _local(child.tag) == "gear_ratio":
                gear = _value(child, f"{awhere} <drake:gear_ratio>")
    ratio = gear if gear is not None else float(np.prod(reductions)) if reductions else 1.0
    if ratio == 0.0:
        raise _fail(twhere, "its mechanical reduction is 0 (it must be non-zero)", Code.NUMBER)
    if rotor is not None and rotor < 0.0:
        raise _fail(twhere, f"rotor inertia {rotor:g} kg m² is negative", Code.NUMBER)
    return str(joints[0].get("name")), Actuation(ratio, rotor, name)


def _actuation(root: ET.Element, where: str) -> tuple[dict[str, Actuation], tuple[str, ...]]:
    """Every transmission of the file, by joint; those not read, in words."""
    out: dict[str, Actuation] = {}
    skipped = []
    for element in root.iter():
        if _local(element.tag) != "transmission" or element.tag.startswith(f"{{{NAMESPACE}}}"):
            continue
        found = _transmission(element, where)
        if isinstance(found, str):
            skipped.append(found)
            continue
        joint, actuation = found
        before = out.get(joint)
        if before is not None and (
            before.reduction != actuation.reduction
            or before.rotor_inertia != actuation.rotor_inertia
        ):
            raise _fail(
                where,
                f"joint {joint!r} has two transmissions that disagree ({before.source!r}: "
                f"{before.reduction:g}, {actuation.source!r}: {actuation.reduction:g})",
            )
        out[joint] = actuation
    return out, tuple(skipped)


def _embedded(root: ET.Element, where: str) -> Embedded | None:
    """The ``<kinergy:robot>`` element, or None."""
    if root.find(f"{{{NAMESPACE}}}model") is not None:
        raise _fail(
            where,
            "its <kinergy:model> element is an earlier kinergy's export, which this kinergy no "
            "longer reads: export the robot file again (kinergy robot export), or remove the "
            "element to import the standard URDF elements alone",
            Code.UNSUPPORTED,
        )
    found = root.findall(f"{{{NAMESPACE}}}robot")
    if not found:
        return None
    ewhere = f"{where}: <kinergy:robot>"
    if len(found) > 1:
        raise _fail(where, "more than one <kinergy:robot> element")
    try:
        data = json.loads(found[0].text or "")
    except ValueError as exc:
        raise _fail(ewhere, f"not valid JSON ({exc})", Code.FILE) from None
    if not isinstance(data, dict):
        raise _fail(ewhere, "must hold a JSON object (the robot file's tables)", Code.FILE)
    return Embedded(found[0].get("version", ""), data)


def parse_urdf(text: bytes, where: str) -> UrdfFile:
    """A URDF's content from its bytes (module docstring); ``where`` names it in errors."""
    try:
        root = ET.fromstring(text)
    except (ET.ParseError, LookupError) as exc:  # LookupError: an unknown declared encoding
        raise _fail(where, f"not well-formed XML ({exc})", Code.FILE) from None
    if root.tag != "robot":
        raise _fail(
            where, f"not a URDF file: the root element is <{root.tag}>, not <robot>", Code.FILE
        )
    if not root.get("name"):
        raise _fail(where, "the <robot> element has no 'name' attribute", Code.MISSING)
    # huge numbers (an origin of 1e308 m) overflow in the poses; every value that reaches the
    # robot is checked finite and bounded there, in one line
    with np.errstate(over="ignore", invalid="ignore"):
        links = {
            str(e.get("name")): UrdfLink(
                str(e.get("name")), _inertial(e, f"{where}: link {e.get('name')!r}")
            )
            for e in _named(root, "link", where)
        }
        joints = tuple(_joint(e, where) for e in _named(root, "joint", where))
    actuation, skipped = _actuation(root, where)
    return UrdfFile(
        path=where,
        name=str(root.get("name")),
        links=links,
        joints=joints,
        actuation=actuation,
        embedded=_embedded(root, where),
        skipped=skipped,
    )


def read_urdf(path: str | os.PathLike[str]) -> UrdfFile:
    """:func:`parse_urdf` of a file.

    Raises
    ------
    KinergyError
        ``PATH: cannot read URDF file (...)``, or what :func:`parse_urdf` refuses.
    """
    where = str(path)
    try:
        text = Path(path).read_bytes()
    except OSError as exc:
        raise _fail(where, f"cannot read URDF file ({exc.strerror})", Code.FILE) from None
    return parse_urdf(text, where)
