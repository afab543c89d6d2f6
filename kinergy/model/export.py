"""What the URDF and MJCF exports share: the drives referred to the joints, the numbers as text,
and the comments every exported file carries.

The exports (:mod:`kinergy.model.urdf_export`, :mod:`kinergy.model.mjcf`) lay a robot out the
same way: body i is the frame joint i turns in, ``F_{i-1} · P_i``
(:func:`~kinergy.model.frames.joint_transforms`), placed in body i-1 by ``C_{i-1} · P_i`` (``C_0``
= the robot's base pose),
with joint i about its z axis; link i's frame is ``C_i`` in body i, so its inertial sits at
``C_i · com`` with the axes of ``C_i``. The flange is ``C_n · flange`` in body n, the payload a
body rigidly fixed there.

Drives referred to the joints (:class:`~kinergy.model.friction_line.JointSide`), with
``N = diag(gear_ratio) @ coupling``
(:func:`~kinergy.model.robot.transmission_matrix`; motor speeds ``wm = N qd``, joint torques
``tau = N^T tau_m``):

- reflected rotor and reducer inertia ``N^T diag(J_m + J_r) N`` (UR5e eq 2): its diagonal is a
  joint's ``armature``, ``n^2 (J_m + J_r)`` for a joint with its own motor of gear ratio ``n``;
- each motor's friction as its best Coulomb + viscous line ``c sign(wm) + b wm`` (motor side,
  :func:`~kinergy.model.friction_line.friction_line`), referred to the joints as
  ``N^T diag(b) N qd + N^T (c * sign(N qd))``: a joint's ``damping`` is the diagonal of
  ``N^T diag(b) N`` (``n^2 b``) and its Coulomb ``friction`` ``sum_k |N_kj| c_k`` (``|n| c``),
  the joint's friction when it moves alone.

For coupled joints the off-diagonal parts and the Coulomb torque of motors turned by several joints
are not a joint's own; :func:`coupling_comment` quantifies what a per-joint format leaves out.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.model.frames import joint_transforms, matrix_rpy
from kinergy.model.friction_line import LOADS, SPEED_FLOOR, SPEEDS, JointSide
from kinergy.model.robot import Robot

__all__ = [
    "COMPLETION_NOTE",
    "Export",
    "Layout",
    "comment",
    "completion_comment",
    "coupling_comment",
    "friction_comments",
    "layout",
    "line_note",
    "number",
    "numbers",
    "reflected_comment",
    "rpy",
]


@dataclass(frozen=True)
class Export:
    """An exported file's text and the notes for the user (what the format could not hold).

    Attributes
    ----------
    text : str
        The whole file (XML).
    notes : tuple of str
        One line each, for stderr.
    """

    text: str
    notes: tuple[str, ...]


@dataclass(frozen=True)
class Layout:
    """Where the bodies of an exported robot sit (see the module docstring).

    Attributes
    ----------
    joints : ndarray, shape (n, 4, 4)
        Pose of body i (joint i's frame at q_i = 0) in body i-1 (the base frame for i = 1).
    links : ndarray, shape (n, 4, 4)
        Pose of link frame i in body i (``C_i``).
    flange : ndarray, shape (4, 4)
        Pose of the flange in body n.
    """

    joints: Array
    links: Array
    flange: Array


def layout(robot: Robot) -> Layout:
    """The bodies of ``robot`` as the exports place them."""
    rows = np.array([(j.a, j.alpha, j.offset, j.d) for j in robot.joints])
    pre, post = joint_transforms(robot.convention, rows)
    before = np.concatenate([robot.base[None], post[:-1]])
    return Layout(joints=before @ pre, links=post, flange=post[-1] @ robot.flange)


def number(x: float) -> str:
    """``x`` as the shortest text that reads back as the same float."""
    return repr(float(x))


def numbers(values: Iterable[float]) -> str:
    """Space-separated :func:`number` s."""
    return " ".join(number(v) for v in np.asarray(list(values), dtype=float).ravel())


def rpy(rot: Array) -> Array:
    """URDF roll, pitch, yaw (rad, shape (3,)) of a rotation (3, 3), exact zeros kept."""
    out = matrix_rpy(rot)
    out[np.abs(out) < 1e-15] = 0.0
    return out


def comment(text: str) -> str:
    """``text`` made safe inside an XML comment (no ``--``, no trailing ``-``)."""
    safe = " ".join(text.split())
    while "--" in safe:
        safe = safe.replace("--", "- -")
    return f" {safe} "


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def friction_comments(robot: Robot, side: JointSide) -> list[tuple[int, str]]:
    """For each motor whose friction is not a line: ``(index, text)`` stating the line's error.

    The text names the family, the line (motor side and, for a joint with its own motor, joint
    side), its RMS and largest error over the grid and the grid itself.
    """
    out = []
    for k, (joint, line) in enumerate(zip(robot.joints, side.lines, strict=True)):
        if line.exact:
            continue
        gear = abs(joint.drive.gear_ratio)
        joint_part = (
            ""
            if side.coupled
            else f" (joint side: friction {_fmt(side.friction[k])} N m, damping "
            f"{_fmt(side.damping[k])} N m s/rad; RMS error {_fmt(gear * line.rms_error)} N m)"
        )
        out.append(
            (
                k,
                f"motor of joint {joint.name}: friction model {joint.drive.friction.name!r} is "
                f"not Coulomb + viscous; exported as its best line, Coulomb "
                f"{_fmt(line.coulomb)} N m and viscous {_fmt(line.viscous)} N m s/rad motor side"
                f"{joint_part}; RMS error {_fmt(line.rms_error)} N m motor side "
                f"({100 * line.relative_error:.1f} % of the model's RMS friction), largest "
                f"{_fmt(line.max_error)} N m, over motor speeds {_fmt(SPEED_FLOOR * line.speed)} "
                f"to {_fmt(line.speed)} rad/s both ways ({SPEEDS} each; the joints' speed limits, "
                "as the robot file does not record the speeds seen in identification) and "
                f"{LOADS} motor loads from {_fmt(-line.load)} to {_fmt(line.load)} N m (the "
                "torque limits), at the model's reference temperature",
            )
        )
    return out


def line_note(robot: Robot, side: JointSide) -> str | None:
    """The note of an export whose friction families are not all Coulomb + viscous: each fitted
    line's RMS error as a share of the model's RMS friction (None when every line is exact)."""
    fitted = [k for k, line in enumerate(side.lines) if not line.exact]
    if not fitted:
        return None
    return (
        "friction exported as the best Coulomb + viscous line (RMS error, % of the model's RMS "
        "friction): "
        + ", ".join(
            f"{robot.joints[k].name} {100 * side.lines[k].relative_error:.1f} %" for k in fitted
        )
        + "; the file's comments give each line and the speeds and loads it was fitted over"
    )


#: the note of an export whose link inertials were identified (base parameters)
COMPLETION_NOTE = (
    "the link inertials were identified as base parameters: the file holds the physically "
    "consistent completion kinergy wrote, which gives the identified joint torques but not "
    "unique link values (see its comment)"
)


def completion_comment(robot: Robot) -> str | None:
    """The comment of a robot whose link inertials were identified (from base parameters)."""
    groups = [g for g in ("mass", "com", "inertia") if robot.sources[g].status == "identified"]
    if not groups:
        return None
    return (
        f"Link {', '.join(groups)} identified by kinergy ({robot.sources[groups[0]].ref}). Joint "
        "torques determine only the base parameters (combinations of the links' inertial "
        "parameters); the masses, centres of mass and inertias here are the physically "
        "consistent completion kinergy wrote: they give the identified joint torques, but "
        "another completion would give the same torques with other link values."
    )


def coupling_comment(robot: Robot, side: JointSide, *, tendons: bool) -> str | None:
    """What a per-joint format leaves out of a coupled robot's drives (None when uncoupled).

    ``tendons``: the format holds the motors as MuJoCo fixed tendons (exact); else (URDF) only
    each joint's own share is there.
    """
    if not side.coupled:
        return None
    off = side.reflected - np.diag(side.armature)
    off_visc = side.viscous - np.diag(side.damping)
    ratio = _share(float(np.max(np.abs(off))), float(np.max(side.armature)))
    ratio_visc = _share(float(np.max(np.abs(off_visc))), float(np.max(side.damping)))
    if tendons:
        return (
            "Coupled joints: each motor is a fixed tendon whose length is the motor angle "
            "(coef = N_kj, N = diag(gear_ratio) @ coupling), with the motor's rotor and reducer "
            "inertia as its armature and its friction line (motor side) as its damping and "
            "frictionloss: MuJoCo adds N^T diag(J) N to the mass matrix, N^T diag(b) N qd and "
            "the motors' Coulomb friction N^T (c sign(N qd)) to the joint forces, exactly as "
            "kinergy refers them. The joints themselves carry no armature, damping or "
            "frictionloss."
        )
    return (
        "Coupled joints: URDF has no coupled transmission. The reflected rotor inertia "
        "N^T diag(J) N (N = diag(gear_ratio) @ coupling) is not in URDF at all (the kinergy "
        "element keeps the drives and the coupling); largest off-diagonal term over largest "
        f"diagonal term: {ratio}. <dynamics damping> is the diagonal of N^T diag(b) N (the "
        f"off-diagonal terms left out, largest over largest diagonal: {ratio_visc}); "
        "<dynamics friction> is sum_k |N_kj| c_k, the Coulomb friction of a "
        "joint moving alone: when several joints turn one motor, the motors' Coulomb torque "
        "N^T (c sign(N qd)) depends on all their speeds, and a joint's share is anywhere from "
        "minus to plus that value. The MJCF export holds the coupling exactly (tendons)."
    )


def _share(off: float, diagonal: float) -> str:
    """``off / diagonal`` in words: zero below rounding (the motors of a coupled joint alike)."""
    if diagonal <= 0.0 or off <= 1e-12 * diagonal:
        return "zero (to rounding)"
    return f"{off / diagonal:.3g}"


def reflected_comment(robot: Robot, side: JointSide) -> str:
    """URDF's missing rotor inertia, per joint (for tools that can add it, e.g. Pinocchio's
    ``model.armature``)."""
    values = ", ".join(
        f"{j.name} {_fmt(a)}" for j, a in zip(robot.joints, side.armature, strict=True)
    )
    return (
        "URDF holds no rotor inertia. Reflected rotor and reducer inertia per joint, the diagonal "
        f"of N^T diag(J_m + J_r) N (gear_ratio^2 (J_m + J_r) for a joint with its own motor), "
        f"kg m²: {values} (Pinocchio: model.armature; the MJCF export's armature)."
    )
