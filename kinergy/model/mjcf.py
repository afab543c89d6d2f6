"""A robot as a MuJoCo MJCF model (``kinergy robot export --format mjcf``).

The bodies sit as in the URDF export (:func:`kinergy.model.export.layout`): body i is the frame
joint i turns in, a ``hinge`` about its z axis with the robot's sign of q and ``range`` = the
position limits; its ``<inertial>`` holds link i's mass, centre of mass and inertia (diagonalised:
``quat`` gives the principal axes, ``diaginertia`` the principal moments). The world frame is the
robot's base frame, ``<option gravity>`` the robot's gravity. A site ``flange`` marks the flange; a
payload is a body ``payload`` fixed there.

The drives, referred to the joints (:class:`~kinergy.model.friction_line.JointSide`,
``N = diag(gear_ratio) @ coupling``):

- joints with their own motor: ``armature = n^2 (J_m + J_r)`` (the reflected rotor and reducer
  inertia, UR5e eq 2), ``damping = n^2 b`` and ``frictionloss = |n| c`` from the motor's friction
  line (:mod:`kinergy.model.friction_line`: a Coulomb + viscous family's own Coulomb level ``c``
  and viscous coefficient ``b``, exactly, its ``tanh`` smoothing left to MuJoCo's regularised
  friction; any other family's best line, with its error in a comment and a note);
- coupled joints: each motor is a ``<fixed>`` tendon whose length is the motor angle
  (``coef = N_kj``) with ``armature = J_m + J_r``, ``damping = b`` and ``frictionloss = c``, motor
  side, so that MuJoCo adds ``N^T diag(J) N`` to the mass matrix, ``N^T diag(b) N qd`` and the
  motors' Coulomb friction to the joint forces: the coupled transmission, exactly;
- one ``<motor>`` actuator per joint on its joint (gear 1: the control is the joint torque, N m)
  with ``ctrlrange`` = the joint's torque limit.

MuJoCo's ``frictionloss`` is a friction constraint solved with the rest (a soft, regularised Coulomb
friction that also holds a stopped joint); MJCF has no speed or acceleration limit and no motor
electrics: they stay in the robot file. Visual capsules (no collisions, no mass) join the joints.
"""

from __future__ import annotations

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
    line_note,
    number,
    numbers,
)
from kinergy.model.friction_line import JointSide, joint_side
from kinergy.model.robot import Robot, inertia_matrix

__all__ = ["robot_to_mjcf"]

#: radius of the visual capsules between joints, m
CAPSULE = 0.03


def _quat(rot: Array) -> Array:
    """MuJoCo's quaternion ``(w, x, y, z)`` of a rotation (3, 3)."""
    from scipy.spatial.transform import Rotation  # heavy (0.2 s): imported on first use

    x, y, z, w = Rotation.from_matrix(rot).as_quat()
    return np.array([w, x, y, z])


def _placed(element: ET.Element, pose: Array) -> None:
    element.set("pos", numbers(pose[:3, 3]))
    element.set("quat", numbers(_quat(pose[:3, :3])))


def principal(inertia: Array) -> tuple[Array, Array]:
    """Principal moments (3,) ascending and axes (3, 3, a proper rotation, columns the axes) of
    an inertia ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]``.

    A largest moment beyond MuJoCo's exact triangle inequality ``A + B >= C`` (kinergy accepts
    1e-9 of C: a flat plate's moments, or an identified link on the boundary, fall either side by
    rounding) is lowered to ``A + B``.
    """
    moments, axes = np.linalg.eigh(inertia_matrix(inertia))
    if np.linalg.det(axes) < 0.0:
        axes[:, 0] = -axes[:, 0]
    moments = np.maximum(moments, 0.0)
    moments[2] = min(moments[2], moments[0] + moments[1])
    return moments, axes


def _inertial(body: ET.Element, mass: float, com: Array, inertia: Array, rot: Array) -> None:
    """``<inertial>`` of ``mass`` at ``com`` (body frame) with ``inertia`` about it in the axes
    ``rot`` (3, 3) of the body frame."""
    moments, axes = principal(inertia)
    ET.SubElement(
        body,
        "inertial",
        pos=numbers(com),
        quat=numbers(_quat(rot @ axes)),
        mass=number(mass),
        diaginertia=numbers(moments),
    )


def _capsule(body: ET.Element, end: Array) -> None:
    if np.linalg.norm(end) > 1e-6:
        ET.SubElement(
            body, "geom", type="capsule", size=number(CAPSULE), fromto=numbers([0, 0, 0, *end])
        )


def _bodies(world: ET.Element, robot: Robot, side: JointSide) -> None:
    """The chain of bodies, each with its hinge (its drive's armature, damping and frictionloss
    unless the joints are coupled), the flange site and the payload."""
    place = layout(robot)
    line_comments = dict(friction_comments(robot, side))
    parent = world
    for i, joint in enumerate(robot.joints):
        if i in line_comments:
            parent.append(ET.Comment(comment(line_comments[i])))
        body = ET.SubElement(parent, "body", name=f"{joint.name}_link")
        _placed(body, place.joints[i])
        post = place.links[i]
        com = post[:3, :3] @ joint.link.com + post[:3, 3]
        _inertial(body, joint.link.mass, com, joint.link.inertia, post[:3, :3])
        hinge = ET.SubElement(
            body,
            "joint",
            name=joint.name,
            type="hinge",
            axis="0 0 1",
            range=numbers(joint.limits.position),
        )
        if not side.coupled:
            hinge.set("armature", number(side.armature[i]))
            hinge.set("damping", number(side.damping[i]))
            hinge.set("frictionloss", number(side.friction[i]))
        end = place.joints[i + 1] if i + 1 < robot.n else place.flange
        _capsule(body, end[:3, 3])
        parent = body
    flange = ET.SubElement(parent, "site", name="flange")
    _placed(flange, place.flange)
    if robot.payload is not None and robot.payload.mass > 0.0:
        p = robot.payload
        body = ET.SubElement(parent, "body", name="payload")
        _placed(body, place.flange)
        _inertial(body, p.mass, p.com, p.inertia, np.eye(3))


def _tendons(root: ET.Element, robot: Robot, side: JointSide) -> None:
    """Coupled joints: each motor a fixed tendon (module docstring)."""
    tendon = ET.SubElement(root, "tendon")
    for k, (joint, line) in enumerate(zip(robot.joints, side.lines, strict=True)):
        fixed = ET.SubElement(
            tendon,
            "fixed",
            name=f"{joint.name}_motor",
            armature=number(joint.drive.rotor_inertia),
            damping=number(line.viscous),
            frictionloss=number(line.coulomb),
        )
        for j, coef in enumerate(side.transmission[k]):
            if coef != 0.0:
                ET.SubElement(fixed, "joint", joint=robot.joints[j].name, coef=number(coef))


def robot_to_mjcf(robot: Robot, *, source: str = "") -> Export:
    """``robot`` as MJCF text (see the module docstring) and the notes for the user.

    Parameters
    ----------
    robot : Robot
    source : str
        What the robot was read from, for the file's first comment.

    Returns
    -------
    Export
        The MJCF and one note per thing it could not hold exactly (a friction line's error, link
        inertials completed from base parameters).
    """
    side = joint_side(robot)
    root = ET.Element("mujoco", model=robot.name)
    completion = completion_comment(robot)
    texts = [
        f"{robot.name}, written by kinergy robot export"
        + (f" from {source}" if source else "")
        + ". World = the robot's base frame. Joints: armature = reflected rotor and reducer "
        "inertia, damping and frictionloss = the drives' viscous coefficient and Coulomb level, "
        "joint side; actuators: joint torque (N m) within the torque limits. Not in MJCF: speed "
        "and acceleration limits, motor electrics (the robot file keeps them).",
        completion,
        coupling_comment(robot, side, tendons=True),
    ]
    for text in filter(None, texts):
        root.append(ET.Comment(comment(text)))
    notes = [COMPLETION_NOTE] if completion is not None else []
    line = line_note(robot, side)
    if line is not None:
        notes.append(line)
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    ET.SubElement(root, "option", gravity=numbers(robot.gravity), integrator="implicitfast")
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="0", conaffinity="0", rgba="0.7 0.7 0.75 1")
    _bodies(ET.SubElement(root, "worldbody"), robot, side)
    if side.coupled:
        _tendons(root, robot, side)
    actuator = ET.SubElement(root, "actuator")
    for joint in robot.joints:
        limit = joint.limits.torque
        ET.SubElement(
            actuator,
            "motor",
            name=joint.name,
            joint=joint.name,
            gear="1",
            ctrlrange=numbers([-limit, limit]),
        )
    ET.indent(root, space="  ")
    return Export(text=ET.tostring(root, encoding="unicode") + "\n", notes=tuple(notes))
