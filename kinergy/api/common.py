"""What the functions of :mod:`kinergy.api` share: how they take a robot, a path, progress."""

from __future__ import annotations

import os
from collections.abc import Callable

from kinergy.model.library import load_robot
from kinergy.model.robot import Robot

__all__ = ["PathLike", "Progress", "RobotLike", "robot_of"]

#: a file or folder
PathLike = str | os.PathLike[str]
#: a robot: a :class:`~kinergy.model.robot.Robot`, a built-in name (``"ur5e"``) or a robot file
RobotLike = Robot | PathLike
#: called with a message as each step of a long run starts
Progress = Callable[[str], None]


def robot_of(robot: RobotLike) -> Robot:
    """``robot`` as a :class:`Robot`: itself, or the built-in model or robot file it names."""
    return robot if isinstance(robot, Robot) else load_robot(robot)
