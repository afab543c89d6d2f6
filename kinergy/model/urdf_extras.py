"""What a URDF file says beyond geometry and inertials: gear ratios (``<transmission>``), joint
friction (``<dynamics>``) and kinergy's own ``<kinergy:model>`` element.

:func:`read_standard` reads the standard elements of any URDF: a ROS
``transmission_interface/SimpleTransmission``'s ``mechanicalReduction`` (one joint, one actuator;
other transmission types are skipped) and each joint's ``<dynamics damping friction>`` (joint
side, N m s/rad and N m; absent values are 0). :func:`read_kinergy` reads the element of the
namespace :data:`~kinergy.model.urdf.NAMESPACE` that ``kinergy robot export --format urdf``
writes (:mod:`kinergy.model.urdf_export` gives its layout) into plain, checked values; turning them
into a robot, and checking them against the standard elements, is
:func:`kinergy.model.urdf.robot_from_urdf`'s.

Every problem is a one-line KinergyError naming the file, the element and the attribute.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import Any

from kinergy.errors import KinergyError
from kinergy.model.robot import SOURCE_CATEGORIES

__all__ = [
    "FORMAT_VERSION",
    "NAMESPACE",
    "KinergyJoint",
    "KinergyModel",
    "Standard",
    "read_kinergy",
    "read_standard",
]

#: the XML namespace of the ``<kinergy:model>`` element that carries what URDF cannot hold
#: (:mod:`kinergy.model.urdf_export`); other URDF parsers skip elements of a foreign namespace
NAMESPACE = "urn:kinergy:urdf"
#: the version of that element's layout this kinergy writes and reads
FORMAT_VERSION = "1"

_SIMPLE = "transmission_interface/SimpleTransmission"
_MODEL_KEYS = {
    "version",
    "convention",
    "gravity",
    "standby_power",
    "bus_voltage",
    "root",
    "flange",
    "payload",
    "base_xyz",
    "base_rpy",
    "flange_xyz",
    "flange_rpy",
}
_JOINT_KEYS = {"name", "d", "a", "alpha", "offset", "acceleration", "continuous"}
_DRIVE_KEYS = {
    "gear_ratio",
    "motor_inertia",
    "reducer_inertia",
    "torque_constant",
    "motor_constant",
    "kt_over_kb",
    "winding_resistance",
}
_LINE_KEYS = ("line_speed", "line_load")


def _tag(name: str) -> str:
    return f"{{{NAMESPACE}}}{name}"


@dataclass(frozen=True)
class Standard:
    """The standard drive elements of a URDF, by joint name.

    Attributes
    ----------
    reductions : mapping of str to float
        Gear ratio of each joint with a SimpleTransmission.
    dynamics : mapping of str to (float, float)
        ``(damping, friction)`` of each joint with a ``<dynamics>`` element, joint side.
    """

    reductions: Mapping[str, float]
    dynamics: Mapping[str, tuple[float, float]]


@dataclass(frozen=True)
class KinergyJoint:
    """One ``<kinergy:joint>``.

    Attributes
    ----------
    name : str
    kinematics : dict
        ``d, a, alpha, offset`` in the robot's convention (m, rad).
    acceleration : float or None
        rad/s^2.
    continuous : bool
        The joint turns without limit (``Limits.continuous``).
    drive : dict
        The drive's numbers (``gear_ratio`` only for a coupled robot).
    friction : dict or None
        ``model`` and its parameters (motor side); None when the element is absent.
    line : (float, float) or None
        The speed (rad/s) and load (N m) of the grid its ``<dynamics>`` line was fitted over.
    thermal : dict or None
        ``capacity``, ``resistance``.
    """

    name: str
    kinematics: dict[str, float]
    acceleration: float | None
    continuous: bool
    drive: dict[str, float]
    friction: dict[str, Any] | None
    line: tuple[float, float] | None
    thermal: dict[str, float] | None


@dataclass(frozen=True)
class KinergyModel:
    """The ``<kinergy:model>`` element: the robot-wide values and the joints, in file order."""

    convention: str
    gravity: list[float]
    standby_power: float
    bus_voltage: float
    root: str
    flange: str
    payload: str | None
    base: dict[str, list[float]]
    flange_pose: dict[str, list[float]]
    description: str
    sources: dict[str, dict[str, str]]
    coupling: list[list[float]] | None
    joints: tuple[KinergyJoint, ...]
    identified: dict[str, Any] | None = None


def _number(text: str | None, where: str) -> float:
    try:
        value = float(text)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise KinergyError(f"{where}: must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise KinergyError(f"{where}: must be finite, got {text!r}")
    return value


def _numbers(text: str | None, count: int | None, where: str) -> list[float]:
    parts = (text or "").split()
    if count is not None and len(parts) != count:
        raise KinergyError(f"{where}: must be {count} numbers, got {text!r}")
    return [_number(p, where) for p in parts]


def _known(element: ET.Element, allowed: Collection[str], where: str) -> None:
    unknown = sorted(set(element.attrib) - set(allowed))
    if unknown:
        raise KinergyError(
            f"{where}: unknown attribute(s) {', '.join(unknown)} "
            f"(allowed: {', '.join(sorted(allowed))})"
        )


def _required(element: ET.Element, key: str, where: str) -> str:
    value = element.get(key)
    if value is None:
        raise KinergyError(f"{where}: missing attribute {key!r}")
    return value


def read_standard(root: ET.Element, where: str) -> Standard:
    """The SimpleTransmissions and ``<dynamics>`` of a URDF's ``<robot>`` element ``root``."""
    reductions: dict[str, float] = {}
    for k, element in enumerate(root.findall("transmission")):
        if (element.findtext("type") or "").strip() != _SIMPLE:
            continue
        name = element.get("name") or f"number {k + 1}"
        twhere = f"{where}: <transmission name={name!r}>"
        joints, actuators = element.findall("joint"), element.findall("actuator")
        if len(joints) != 1 or len(actuators) != 1 or not joints[0].get("name"):
            raise KinergyError(
                f"{twhere}: a SimpleTransmission needs one named joint and one actuator"
            )
        joint_name = str(joints[0].get("name"))
        if joint_name in reductions:
            raise KinergyError(f"{twhere}: joint {joint_name!r} has two transmissions")
        text = actuators[0].findtext("mechanicalReduction")
        ratio = 1.0 if text is None else _number(text.strip(), f"{twhere} <mechanicalReduction>")
        if ratio == 0.0:
            raise KinergyError(f"{twhere} <mechanicalReduction>: must be non-zero")
        reductions[joint_name] = ratio
    dynamics: dict[str, tuple[float, float]] = {}
    for joint in root.findall("joint"):
        found = joint.find("dynamics")
        if found is None:
            continue
        jwhere = f"{where}: joint {joint.get('name')!r} <dynamics>"
        damping = _number(found.get("damping", "0"), f"{jwhere} damping")
        friction = _number(found.get("friction", "0"), f"{jwhere} friction")
        if damping < 0.0 or friction < 0.0:
            raise KinergyError(f"{jwhere}: damping and friction must be >= 0")
        dynamics[str(joint.get("name"))] = (damping, friction)
    return Standard(reductions, dynamics)


def _joint(element: ET.Element, index: int, where: str) -> KinergyJoint:
    name = element.get("name")
    jwhere = (
        f"{where}: <kinergy:joint name={name!r}>"
        if name
        else f"{where}: <kinergy:joint> {index + 1}"
    )
    _known(element, _JOINT_KEYS, jwhere)
    name = _required(element, "name", jwhere)
    kinematics = {
        key: _number(_required(element, key, jwhere), f"{jwhere} {key}")
        for key in ("d", "a", "alpha", "offset")
    }
    acceleration = element.get("acceleration")
    continuous = element.get("continuous", "false")
    if continuous not in ("true", "false"):
        raise KinergyError(f"{jwhere}: continuous must be true or false, got {continuous!r}")
    drives = element.findall(_tag("drive"))
    if len(drives) != 1:
        raise KinergyError(f"{jwhere}: needs one <kinergy:drive>, found {len(drives)}")
    _known(drives[0], _DRIVE_KEYS, f"{jwhere} <kinergy:drive>")
    drive = {
        key: _number(value, f"{jwhere} <kinergy:drive> {key}")
        for key, value in drives[0].attrib.items()
    }
    friction: dict[str, Any] | None = None
    line = None
    frictions = element.findall(_tag("friction"))
    if len(frictions) > 1:
        raise KinergyError(f"{jwhere}: more than one <kinergy:friction>")
    if frictions:
        fwhere = f"{jwhere} <kinergy:friction>"
        attrib = dict(frictions[0].attrib)
        model = attrib.pop("model", None)
        if model is None:
            raise KinergyError(f"{fwhere}: missing attribute 'model'")
        speed, load = (_number(attrib.pop(key, None), f"{fwhere} {key}") for key in _LINE_KEYS)
        if speed <= 0.0 or load <= 0.0:
            raise KinergyError(f"{fwhere}: line_speed and line_load must be > 0")
        friction = {"model": model}
        friction.update({key: _number(v, f"{fwhere} {key}") for key, v in attrib.items()})
        line = (speed, load)
    thermal = None
    thermals = element.findall(_tag("thermal"))
    if len(thermals) > 1:
        raise KinergyError(f"{jwhere}: more than one <kinergy:thermal>")
    if thermals:
        twhere = f"{jwhere} <kinergy:thermal>"
        _known(thermals[0], ("capacity", "resistance"), twhere)
        thermal = {
            key: _number(_required(thermals[0], key, twhere), f"{twhere} {key}")
            for key in ("capacity", "resistance")
        }
    return KinergyJoint(
        name=name,
        kinematics=kinematics,
        acceleration=None
        if acceleration is None
        else _number(acceleration, f"{jwhere} acceleration"),
        continuous=continuous == "true",
        drive=drive,
        friction=friction,
        line=line,
        thermal=thermal,
    )


def read_kinergy(root: ET.Element, where: str) -> KinergyModel | None:
    """The ``<kinergy:model>`` element of a URDF's ``<robot>`` element ``root``, checked; None
    when there is none."""
    found = root.findall(_tag("model"))
    if not found:
        return None
    if len(found) > 1:
        raise KinergyError(f"{where}: more than one <kinergy:model> element")
    model = found[0]
    mwhere = f"{where}: <kinergy:model>"
    _known(model, _MODEL_KEYS, mwhere)
    version = model.get("version")
    if version != FORMAT_VERSION:
        raise KinergyError(
            f"{mwhere}: layout version {version!r}; this kinergy reads version {FORMAT_VERSION!r}"
        )
    poses = {
        key: _numbers(_required(model, key, mwhere), 3, f"{mwhere} {key}")
        for key in ("gravity", "base_xyz", "base_rpy", "flange_xyz", "flange_rpy")
    }
    sources: dict[str, dict[str, str]] = {}
    for element in model.findall(_tag("source")):
        swhere = f"{mwhere} <kinergy:source>"
        _known(element, ("category", "status", "ref"), swhere)
        category = _required(element, "category", swhere)
        if category not in SOURCE_CATEGORIES or category in sources:
            raise KinergyError(f"{swhere}: category {category!r} unknown or repeated")
        sources[category] = {
            "status": _required(element, "status", swhere),
            "ref": element.get("ref", ""),
        }
    coupling = None
    couplings = model.findall(_tag("coupling"))
    if len(couplings) > 1:
        raise KinergyError(f"{mwhere}: more than one <kinergy:coupling>")
    if couplings:
        coupling = [
            _numbers(row.text, None, f"{mwhere} <kinergy:coupling> row {k + 1}")
            for k, row in enumerate(couplings[0].findall(_tag("row")))
        ]
    joints = tuple(_joint(e, k, mwhere) for k, e in enumerate(model.findall(_tag("joint"))))
    if not joints:
        raise KinergyError(f"{mwhere}: no <kinergy:joint>")
    if coupling is not None and (
        len(coupling) != len(joints) or any(len(row) != len(joints) for row in coupling)
    ):
        raise KinergyError(
            f"{mwhere} <kinergy:coupling>: must be {len(joints)} rows of {len(joints)} numbers "
            "(one per <kinergy:joint>)"
        )
    identified = None
    text = model.findtext(_tag("identified"))
    if text is not None:
        try:
            identified = json.loads(text)
        except ValueError:
            raise KinergyError(f"{mwhere} <kinergy:identified>: not valid JSON") from None
        if not isinstance(identified, dict):
            raise KinergyError(f"{mwhere} <kinergy:identified>: must be a JSON object")
    return KinergyModel(
        identified=identified,
        convention=_required(model, "convention", mwhere),
        gravity=poses["gravity"],
        standby_power=_number(model.get("standby_power", "0"), f"{mwhere} standby_power"),
        bus_voltage=_number(model.get("bus_voltage", "48"), f"{mwhere} bus_voltage"),
        root=_required(model, "root", mwhere),
        flange=_required(model, "flange", mwhere),
        payload=model.get("payload"),
        base={"xyz": poses["base_xyz"], "rpy": poses["base_rpy"]},
        flange_pose={"xyz": poses["flange_xyz"], "rpy": poses["flange_rpy"]},
        description=model.findtext(_tag("description")) or "",
        sources=sources,
        coupling=coupling,
        joints=joints,
    )
