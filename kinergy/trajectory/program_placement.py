"""A robot program re-expressed for the robot standing elsewhere in its cell.

The cell (the pick and place points, the fixtures) stays where it is; the robot's base moves by
a :class:`BasePlacement`: a shift ``(x, y, z)`` (m) and a turn ``yaw`` (rad) about the vertical,
both in today's base frame, so gravity keeps its direction in the base frame. Every target of
the program is the same tool pose in the cell, expressed in the new base frame
``B = Trans(x, y, z) Rz(yaw)``:

- a pose target ``p[...]``: ``B^-1 X``;
- a joint target ``q``: its tool pose today (the TCP the program has set there), expressed in the
  new frame and solved again in the same inverse-kinematics branch, each joint at the ``2 pi``
  choice nearest today's angle within its limits (the configuration the programmer taught);
- the ``qnear`` of a pose target (``get_inverse_kin``): the solution in the branch today's
  program takes there, nearest today's joints.

``set_tcp`` and ``set_payload`` are in the flange frame and keep their values; every event keeps
its time. A target the arm cannot reach from the new base in its configuration is one line
naming the program line (:func:`moved_program`); straight lines and joint limits are then checked
when the moved program is resolved (:func:`kinergy.trajectory.program_path.program_path`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.dynamics.ik import ik_branches, joint_limits, wrap_near
from kinergy.dynamics.poses import pose_matrix, pose_vector, tcp_pose
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.robot_program import Move, RobotProgram

__all__ = ["BasePlacement", "moved_program"]


@dataclass(frozen=True)
class BasePlacement:
    """Where the robot's base stands relative to today's: a shift (m) and a turn about the
    vertical (rad), in today's base frame.

    Attributes
    ----------
    x, y, z : float
        m.
    yaw : float
        rad.
    """

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y", "z", "yaw"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise KinergyError(f"base placement: {name} must be finite, got {value}")
            object.__setattr__(self, name, value)

    @property
    def today(self) -> bool:
        """Whether this is today's placement (no shift, no turn)."""
        return self.x == 0.0 and self.y == 0.0 and self.z == 0.0 and self.yaw == 0.0

    @property
    def transform(self) -> Array:
        """The new base frame in today's, ``Trans(x, y, z) Rz(yaw)``, shape (4, 4)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array(
            [
                [c, -s, 0.0, self.x],
                [s, c, 0.0, self.y],
                [0.0, 0.0, 1.0, self.z],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )

    def label(self) -> str:
        """``x=+0.100 m, y=-0.200 m, z=+0.000 m, yaw=+15.0 deg``."""
        return (
            f"x={self.x:+.3f} m, y={self.y:+.3f} m, z={self.z:+.3f} m, "
            f"yaw={math.degrees(self.yaw):+.1f} deg"
        )


def _solve(robot: Robot, path: ProgramPath, flange: Array, branch: int, near: Array) -> Array:
    """Joints of a flange pose in one branch, nearest ``near`` within the limits (NaN where the
    branch cannot reach it)."""
    assert path.geometry is not None
    q = ik_branches(path.geometry, flange, hint6=near[5], branches=[branch])[0]
    lo, hi = joint_limits(robot)
    return np.asarray(wrap_near(q, near, lo, hi))


def _moved(robot: Robot, path: ProgramPath, k: int, move: Move, inverse: Array) -> Move:
    """Move ``k`` with its target in the new base frame (module docstring)."""
    tcp = path.tcp[k]
    if move.pose:
        target = inverse @ pose_matrix(move.target)
        qnear = None
        if move.qnear is not None:
            near = _solve(
                robot, path, target @ np.linalg.inv(tcp), int(path.branch[k]), path.q_end[k]
            )
            qnear = None if np.any(np.isnan(near)) else near
        return move.replaced(target=pose_vector(target), qnear=qnear)
    flange = inverse @ tcp_pose(robot, move.target, tcp) @ np.linalg.inv(tcp)
    q = _solve(robot, path, flange, int(path.branch[k]), move.target)
    if np.any(np.isnan(q)):
        raise KinergyError(
            f"{path.program.where(move.line)}: the joint target is out of reach of the moved "
            "arm in its configuration"
        )
    return move.replaced(target=q)


def moved_program(robot: Robot, program: RobotProgram, placement: BasePlacement) -> RobotProgram:
    """``program`` with every target the same tool pose in the cell, for the robot's base at
    ``placement`` (module docstring).

    Parameters
    ----------
    robot : Robot
        A UR-type arm (analytic inverse kinematics) with a vertical gravity.
    program : RobotProgram
    placement : BasePlacement

    Returns
    -------
    RobotProgram
        The same lines, events and moves, the targets re-expressed (resolve it with
        :func:`kinergy.trajectory.program_path.program_path` to check reach and limits).

    Raises
    ------
    KinergyError
        The robot has no analytic inverse kinematics or a tilted gravity; a joint target out of
        reach in its configuration (naming the program line).
    """
    g = np.asarray(robot.gravity, dtype=float)
    if abs(g[0]) > 1e-9 or abs(g[1]) > 1e-9:
        raise KinergyError(
            f"{robot.name}: a base placement needs a vertical gravity in the base frame "
            f"(the robot file gives {g.tolist()})"
        )
    path = program_path(robot, program)
    if path.geometry is None:
        raise KinergyError(f"{robot.name}: moving the base needs a UR-type arm (analytic IK)")
    if placement.today:
        return program
    inverse: Array = np.asarray(np.linalg.inv(placement.transform), dtype=float)
    moves = [_moved(robot, path, k, m, inverse) for k, m in enumerate(program.moves)]
    return program.with_moves(moves)
