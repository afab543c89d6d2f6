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

What URDF cannot hold travels in one element of the namespace :data:`~kinergy.model.urdf_extras.NAMESPACE`,
``<kinergy:model>`` (:func:`kinergy.model.urdf.robot_from_urdf` reads it back; other parsers skip
it): the convention and the DH or MDH parameters the origins were made from, the base and flange
poses, gravity (URDF has none), the coupling, the acceleration limits, every drive's rotor and
reducer inertia, torque and motor constants, k_t/k_b, winding resistance, thermal model and its
friction family with all its parameters (and the grid its line was fitted over), the standby
power, bus voltage, description and the provenance of every parameter group. XML comments say
what a file leaves out: the rotor inertia (no URDF element), a friction family that is not a line
(the line's error), a coupled transmission.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

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
    number,
    numbers,
    reflected_comment,
    rpy,
)
from kinergy.model.friction_line import JointSide, joint_side
from kinergy.model.robot import SOURCE_CATEGORIES, Robot
from kinergy.model.toml import identified_to_dict
from kinergy.model.urdf_extras import FORMAT_VERSION, NAMESPACE

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


def _names(robot: Robot) -> tuple[list[str], str, str, str, str, str]:
    """Unique names: the links of the moving bodies, the base, flange and payload links, and the
    fixed joints of the flange and the payload."""
    taken: set[str] = set()
    links = [_unique(f"{j.name}_link", taken) for j in robot.joints]
    base, flange, payload = (_unique(name, taken) for name in (BASE, FLANGE, PAYLOAD))
    joints = set(robot.joint_names)
    return (
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


def _kinergy_element(robot: Robot, side: JointSide, names: tuple[str, str, str]) -> ET.Element:
    """``<kinergy:model>``: everything URDF has no element for."""
    base, flange, payload = names
    model = ET.Element(
        _tag("model"),
        version=FORMAT_VERSION,
        convention=robot.convention,
        gravity=numbers(robot.gravity),
        standby_power=number(robot.standby_power),
        bus_voltage=number(robot.bus_voltage),
        root=base,
        flange=flange,
        base_xyz=numbers(robot.base[:3, 3]),
        base_rpy=numbers(rpy(robot.base[:3, :3])),
        flange_xyz=numbers(robot.flange[:3, 3]),
        flange_rpy=numbers(rpy(robot.flange[:3, :3])),
    )
    if robot.payload is not None:
        model.set("payload", payload)
    ET.SubElement(model, _tag("description")).text = robot.description
    if robot.identified is not None:  # where the model came from, as the robot file says it
        record = identified_to_dict(robot.identified)
        ET.SubElement(model, _tag("identified")).text = json.dumps(record, sort_keys=True)
    for cat in SOURCE_CATEGORIES:
        source = robot.sources[cat]
        ET.SubElement(model, _tag("source"), category=cat, status=source.status, ref=source.ref)
    if side.coupled:
        coupling = ET.SubElement(model, _tag("coupling"))
        assert robot.coupling is not None
        for row in robot.coupling:
            ET.SubElement(coupling, _tag("row")).text = numbers(row)
    for joint, line in zip(robot.joints, side.lines, strict=True):
        element = ET.SubElement(
            model,
            _tag("joint"),
            name=joint.name,
            d=number(joint.d),
            a=number(joint.a),
            alpha=number(joint.alpha),
            offset=number(joint.offset),
        )
        if joint.limits.acceleration is not None:
            element.set("acceleration", number(joint.limits.acceleration))
        if joint.limits.continuous:  # URDF's <limit> keeps the planners' range
            element.set("continuous", "true")
        d = joint.drive
        drive = ET.SubElement(element, _tag("drive"))
        if side.coupled:  # else in the joint's <transmission>
            drive.set("gear_ratio", number(d.gear_ratio))
        for key in ("motor_inertia", "reducer_inertia", "torque_constant", "motor_constant"):
            drive.set(key, number(getattr(d, key)))
        drive.set("kt_over_kb", number(d.kt_over_kb))
        if d.winding_resistance is not None:
            drive.set("winding_resistance", number(d.winding_resistance))
        friction = ET.SubElement(element, _tag("friction"), model=d.friction.model)
        for key, value in d.friction.params.items():
            friction.set(key, number(value))
        friction.set("line_speed", number(line.speed))
        friction.set("line_load", number(line.load))
        if d.thermal is not None:
            ET.SubElement(
                element,
                _tag("thermal"),
                capacity=number(d.thermal.capacity),
                resistance=number(d.thermal.resistance),
            )
    return model


def _transmission(root: ET.Element, joint_name: str, gear_ratio: float) -> None:
    element = ET.SubElement(root, "transmission", name=f"{joint_name}_transmission")
    ET.SubElement(element, "type").text = "transmission_interface/SimpleTransmission"
    joint = ET.SubElement(element, "joint", name=joint_name)
    ET.SubElement(joint, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
    actuator = ET.SubElement(element, "actuator", name=f"{joint_name}_motor")
    ET.SubElement(actuator, "mechanicalReduction").text = number(gear_ratio)


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
    place = layout(robot)
    links, base, flange, payload, flange_joint, payload_joint = _names(robot)
    root = ET.Element("robot", name=robot.name)
    notes: list[str] = []
    root.append(
        ET.Comment(
            comment(
                f"{robot.name}, written by kinergy robot export"
                + (f" from {source}" if source else "")
                + ". Standard elements: kinematics (exact), link inertials, limits, joint-side "
                "Coulomb + viscous friction, gear ratios; <kinergy:model> (namespace "
                f"{NAMESPACE}, ignored by other tools) holds the drives, the friction model, "
                "gravity and what else URDF has no element for; kinergy robot import-urdf reads "
                "both back."
            )
        )
    )
    root.append(
        ET.Comment(
            comment(
                f"Gravity {numbers(robot.gravity)} m/s^2 in the base frame (URDF has no gravity; "
                "set your tool's)."
            )
        )
    )
    root.append(ET.Comment(comment(reflected_comment(robot, side))))
    completion = completion_comment(robot)
    coupling = coupling_comment(robot, side, tendons=False)
    for text in filter(None, [completion, coupling]):
        root.append(ET.Comment(comment(text)))
    if completion is not None:
        notes.append(COMPLETION_NOTE)
    if coupling is not None:
        notes.append(
            "coupled joints: URDF has no coupled transmission nor rotor inertia; <dynamics> holds "
            "each joint's own share of the motors' friction (the file's comment says what is "
            "left out; the kinergy element keeps the coupling, the MJCF export holds it exactly)"
        )
    line_comments = dict(friction_comments(robot, side))
    if line_comments:
        notes.append(
            "friction exported as the best Coulomb + viscous line (RMS error, % of the model's "
            "RMS friction): "
            + ", ".join(
                f"{robot.joints[k].name} {100 * side.lines[k].relative_error:.1f} %"
                for k in line_comments
            )
            + "; the file's comments give each line and the speeds and loads it was fitted over"
        )
    root.append(_kinergy_element(robot, side, (base, flange, payload)))

    ET.SubElement(root, "link", name=base)
    parent = base
    for i, joint in enumerate(robot.joints):
        link = ET.SubElement(root, "link", name=links[i])
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
        ET.SubElement(element, "child", link=links[i])
        ET.SubElement(element, "axis", xyz="0 0 1")
        lower, upper = joint.limits.position
        ET.SubElement(
            element,
            "limit",
            lower=number(lower),
            upper=number(upper),
            velocity=number(joint.limits.speed),
            effort=number(joint.limits.torque),
        )
        ET.SubElement(
            element,
            "dynamics",
            damping=number(side.damping[i]),
            friction=number(side.friction[i]),
        )
        parent = links[i]
    ET.SubElement(root, "link", name=flange)
    _fixed_joint(root, flange_joint, parent, flange, place.flange)
    if robot.payload is not None:
        p = robot.payload
        element = ET.SubElement(root, "link", name=payload)
        if p.mass > 0.0:
            pose = np.eye(4)
            pose[:3, 3] = p.com
            _inertial(element, p.mass, pose, p.inertia)
        _fixed_joint(root, payload_joint, flange, payload, np.eye(4))
    if not side.coupled:
        for joint in robot.joints:
            _transmission(root, joint.name, joint.drive.gear_ratio)
    ET.indent(root, space="  ")
    text = '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode")
    return Export(text=text + "\n", notes=tuple(notes))
