"""Reading the user's logs for a command: each file read, its notes passed on, then prepared.

A motion can also be a URScript program (``*.script``): :func:`read_motion` then simulates it as
the UR controller runs it (:mod:`kinergy.trajectory.program_motion`, 500 Hz), which needs the
robot it runs on.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

from kinergy.errors import KinergyError
from kinergy.identify.preprocess import IdentData, prepare
from kinergy.io.motion import motion_from_log
from kinergy.io.rtde import read_log
from kinergy.io.urscript_reader import read_program
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path

__all__ = ["prepared_logs", "read_motion"]


def prepared_logs(
    paths: Sequence[str | os.PathLike[str]],
    *,
    n_joints: int,
    columns: str | None = None,
    repair: bool = False,
    cutoff: float | None = None,
    note: Callable[[str], None] | None = None,
) -> list[IdentData]:
    """Read and prepare every log (:func:`kinergy.identify.preprocess.prepare`).

    ``note`` receives what reading changed (rows dropped by ``repair``), one message each.
    """
    datas = []
    for path in paths:
        log = read_log(path, columns=columns, repair=repair)
        for message in log.notes:
            if note is not None:
                note(message)
        datas.append(prepare(log, n_joints, cutoff=cutoff))
    return datas


def read_motion(
    path: str | os.PathLike[str],
    *,
    n_joints: int,
    columns: str | None = None,
    repair: bool = False,
    source: str = "auto",
    robot: Robot | None = None,
) -> Motion:
    """The joint motion of a log or motion file (:func:`kinergy.io.motion.motion_from_log`), or
    of a URScript program (``*.script``) on ``robot`` as the controller runs it (one cycle,
    starting where it ends, at 500 Hz)."""
    if os.fspath(path).endswith(".script"):
        if robot is None:
            raise KinergyError(f"{path}: a URScript program needs the robot it runs on")
        motion, _ = program_motion(robot, program_path(robot, read_program(path)))
        return motion
    log = read_log(path, columns=columns, repair=repair)
    return motion_from_log(log, n_joints=n_joints, source=source)
