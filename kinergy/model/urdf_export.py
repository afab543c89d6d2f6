"""A robot as a URDF file: exact kinematics, link inertials, limits, joint-side friction, and the
drives in a kinergy element that other tools ignore (``kinergy robot export --format urdf``).

What the standard elements hold (read by Pinocchio, MuJoCo, ROS, ...):

- kinematics, exactly: body i is the frame joint i turns in (:func:`kinergy.model.export.layout`:
  DH or MDH to URDF ``<origin xyz rpy>``), every joint ``revolute`` about its z axis with the
  robot's sign of q; the root link ``base`` is the robot's base frame, the link ``flange`` its
  flange;
- each link's mass, centre of mass and inertia about it (``<inertial>``: origin at ``C_i · com``
  with link frame i's axes, so the six inertia numbers are the robot file's); they are physically
  consistent (kinergy checks every link on load);
- the payload as a link ``payload`` fixed at the flange (its frame is the flange frame);
- ``<limit lower upper velocity effort>`` from the joint's position, speed and torque limits;
- ``<dynamics damping friction>``: the drives' friction referred to the joint (N m s/rad, N m):
  each motor's friction as its best Coulomb + viscous line (motor side,
  :mod:`kinergy.model.friction_line`; exact for Coulomb + viscous families), referred through the
  gear: ``damping = n^2 b``, ``friction = |n| c`` for a joint with its own motor of gear ratio
  ``n`` (``wm = n qd``, ``tau = n tau_m``); for coupled joints the diagonal share of
  :class:`~kinergy.model.friction_line.JointSide`;
- ``<transmission>`` (ROS ``transmission_interface/SimpleTransmission``) with the gear ratio as
  ``mechanicalReduction``, for a joint with its own motor.

The robot itself travels whole in one element of the namespace
:data:`~kinergy.model.urdf_xml.NAMESPACE`, ``<kinergy:robot version="1">``, whose text is the
robot file's dictionary as JSON (:func:`kinergy.model.toml.robot_to_dict`, the ``robot show
--json`` shape; ``version`` is :data:`~kinergy.model.toml.ROBOT_SCHEMA`): one schema for TOML,
JSON and URDF. :func:`kinergy.model.urdf.import_urdf` reads it back with the code that reads robot
files and checks the standard elements against it; other parsers skip it. XML comments say what
the standard elements leave out: the rotor inertia (no URDF element), a friction family that is
not a line (the line's error), a coupled transmission.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.model.export import (
    COMPLETION_NOTE,
    Export,
    comment,
    completion_comment,
    coupling_comment,
    friction_comments,
    layout,
    line_note,
    number,
    numbers,
    reflected_comment,
    rpy,
)
from kinergy.model.friction_line import JointSide, joint_side
from kinergy.model.robot import Robot
from kinergy.model.toml import ROBOT_SCHEMA, robot_to_dict
from kinergy.model.urdf_xml import NAMESPACE

__all__ = ["robot_to_urdf"]

#: names of the fixed links (made unique against the robot's joint names)
BASE, FLANGE, PAYLOAD = "base", "flange", "payload"


def _tag(name: str) -> str:
    return f"{{{NAMESPACE}}}{name}"


def _origin(parent: ET.Element, pose: Array) -> None:
    ET.SubElement(parent, "origin", xyz=numbers(pose[:3, 3]), rpy=numbers(rpy(pose[:3, :3])))


def _inertial(parent: ET.Element, mass: float, pose: Array, inertia: Array) -> None:
    """``<inertial>`` of ``mass`` (kg) at ``pose`` (4, 4) with ``inertia`` ``[Ixx, Iyy, Izz, Ixy,
    Iyz, Ixz]`` (kg m^2) about the centre of mass in that pose's axes."""
    element = ET.SubElement(parent, "inertial")
    _origin(element, pose)
    ET.SubElement(element, "mass", value=number(mass))
    ixx, iyy, izz, ixy, iyz, ixz = (number(v) for v in inertia)
    ET.SubElement(element, "inertia", ixx=ixx, ixy=ixy, ixz=ixz, iyy=iyy, iyz=iyz, izz=izz)


def _unique(wanted: str, taken: set[str]) -> str:
    name = wanted
    while name in taken:
        name += "_"
    taken.add(name)
    return name


@dataclass(frozen=True)
class _Names:
    """Unique names: the links of the moving bodies, the base, flange and payload links, and the
    fixed joints of the flange and the payload."""

    links: list[str]
    base: str
    flange: str
    payload: str
    flange_joint: str
    payload_joint: str


def _names(robot: Robot) -> _Names:
    taken: set[str] = set()
    links = [_unique(f"{j.name}_link", taken) for j in robot.joints]
    base, flange, payload = (_unique(name, taken) for name in (BASE, FLANGE, PAYLOAD))
    joints = set(robot.joint_names)
    return _Names(
        links,
        base,
        flange,
        payload,
        _unique(f"{flange}_joint", joints),
        _unique(f"{payload}_joint", joints),
    )


def _fixed_joint(root: ET.Element, name: str, parent: str, child: str, pose: Array) -> None:
    joint = ET.SubElement(root, "joint", name=name, type="fixed")
    _origin(joint, pose)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)


def _embedded(robot: Robot) -> ET.Element:
    """``<kinergy:robot>``: the robot file's dictionary as JSON (module docstring)."""
    element = ET.Element(_tag("robot"), version=str(ROBOT_SCHEMA))
    element.text = "\n" + json.dumps(robot_to_dict(robot), indent=1) + "\n"
    return element


def _transmission(root: ET.Element, joint_name: str, gear_ratio: float) -> None:
    element = ET.SubElement(root, "transmission", name=f"{joint_name}_transmission")
    ET.SubElement(element, "type").text = "transmission_interface/SimpleTransmission"
    joint = ET.SubElement(element, "joint", name=joint_name)
    ET.SubElement(joint, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
    actuator = ET.SubElement(element, "actuator", name=f"{joint_name}_motor")
    ET.SubElement(actuator, "mechanicalReduction").text = number(gear_ratio)


def _comments(robot: Robot, side: JointSide, source: str) -> tuple[list[str], list[str]]:
    """The file's leading comments and the notes for the user."""
    texts = [
        f"{robot.name}, written by kinergy robot export"
        + (f" from {source}" if source else "")
        + ". Standard elements: kinematics (exact), link inertials, limits, joint-side Coulomb + "
        "viscous friction, gear ratios; <kinergy:robot> (namespace "
        f"{NAMESPACE}, ignored by other tools) holds the robot file itself, as JSON; kinergy "
        "robot import-urdf reads it back and checks the standard elements against it.",
        f"Gravity {numbers(robot.gravity)} m/s² in the base frame (URDF has no gravity; set "
        "your tool's).",
        reflected_comment(robot, side),
    ]
    notes = []
    completion = completion_comment(robot)
    coupling = coupling_comment(robot, side, tendons=False)
    texts += [text for text in (completion, coupling) if text is not None]
    if completion is not None:
        notes.append(COMPLETION_NOTE)
    if coupling is not None:
        notes.append(
            "coupled joints: URDF has no coupled transmission nor rotor inertia; <dynamics> holds "
            "each joint's own share of the motors' friction (the file's comment says what is "
            "left out; the embedded robot keeps the coupling, the MJCF export holds it exactly)"
        )
    line = line_note(robot, side)
    if line is not None:
        notes.append(line)
    return texts, notes


def _chain(root: ET.Element, robot: Robot, side: JointSide, names: _Names) -> None:
    """The links and joints of the arm, the flange and the payload."""
    place = layout(robot)
    line_comments = dict(friction_comments(robot, side))
    ET.SubElement(root, "link", name=names.base)
    parent = names.base
    for i, joint in enumerate(robot.joints):
        link = ET.SubElement(root, "link", name=names.links[i])
        post = place.links[i]
        com = np.eye(4)
        com[:3, :3] = post[:3, :3]
        com[:3, 3] = post[:3, :3] @ joint.link.com + post[:3, 3]
        _inertial(link, joint.link.mass, com, joint.link.inertia)
        if i in line_comments:
            root.append(ET.Comment(comment(line_comments[i])))
        element = ET.SubElement(root, "joint", name=joint.name, type="revolute")
        _origin(element, place.joints[i])
        ET.SubElement(element, "parent", link=parent)
        ET.SubElement(element, "child", link=names.links[i])
        ET.SubElement(element, "axis", xyz="0 0 1")
        lower, upper = joint.limits.position
        limits = (lower, upper, joint.limits.speed, joint.limits.torque)
        ET.SubElement(
            element,
            "limit",
            {
                k: number(v)
                for k, v in zip(("lower", "upper", "velocity", "effort"), limits, strict=True)
            },
        )
        ET.SubElement(
            element, "dynamics", damping=number(side.damping[i]), friction=number(side.friction[i])
        )
        parent = names.links[i]
    ET.SubElement(root, "link", name=names.flange)
    _fixed_joint(root, names.flange_joint, parent, names.flange, place.flange)
    if robot.payload is not None:
        p = robot.payload
        element = ET.SubElement(root, "link", name=names.payload)
        if p.mass > 0.0:
            pose = np.eye(4)
            pose[:3, 3] = p.com
            _inertial(element, p.mass, pose, p.inertia)
        _fixed_joint(root, names.payload_joint, names.flange, names.payload, np.eye(4))


def robot_to_urdf(robot: Robot, *, source: str = "") -> Export:
    """``robot`` as URDF text (see the module docstring) and the notes for the user.

    Parameters
    ----------
    robot : Robot
    source : str
        What the robot was read from, for the file's first comment.

    Returns
    -------
    Export
        The URDF and one note per thing the standard elements could not hold exactly (a friction
        line's error, a coupled transmission, link inertials completed from base parameters).
    """
    ET.register_namespace("kinergy", NAMESPACE)
    side = joint_side(robot)
    root = ET.Element("robot", name=robot.name)
    texts, notes = _comments(robot, side, source)
    for text in texts:
        root.append(ET.Comment(comment(text)))
    root.append(_embedded(robot))
    _chain(root, robot, side, _names(robot))
    if not side.coupled:
        for joint in robot.joints:
            _transmission(root, joint.name, joint.drive.gear_ratio)
    ET.indent(root, space="  ")
    text = '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode")
    return Export(text=text + "\n", notes=tuple(notes))
