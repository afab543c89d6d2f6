"""Reading the user's logs for a command: each file read, its notes passed on, then prepared.

A motion can also be a URScript program (``*.script``): :func:`read_motion` then simulates it as
the UR controller runs it (:mod:`kinergy.trajectory.program_motion`, 500 Hz), which needs the
robot it runs on.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Sequence

from kinergy.errors import KinergyError
from kinergy.identify.preprocess import IdentData, prepare
from kinergy.io.motion import motion_from_log
from kinergy.io.rtde import read_log
from kinergy.io.segments import split_segments
from kinergy.io.urscript_reader import read_program
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path

__all__ = ["MIN_SEGMENT", "prepared_logs", "read_motion"]


MIN_SEGMENT = 1.0
"""Shortest segment of a log (s) :func:`prepared_logs` identifies from."""


def prepared_logs(
    paths: Sequence[str | os.PathLike[str]],
    *,
    n_joints: int,
    columns: str | None = None,
    repair: bool = False,
    cutoff: float | None = None,
    note: Callable[[str], None] | None = None,
) -> list[IdentData]:
    """Read and prepare every log (:func:`kinergy.identify.preprocess.prepare`), each segment of
    a log on its own (:func:`kinergy.io.segments.split_segments`: nothing is filtered or
    differentiated across a gap or a reconnection).

    ``note`` receives what reading changed (rows dropped by ``repair``, segments), one message
    each. Segments shorter than :data:`MIN_SEGMENT` seconds are left out and counted.
    """
    datas: list[IdentData] = []
    for path in paths:
        log = read_log(path, columns=columns, repair=repair)
        messages = list(log.notes)
        parts = split_segments(log)
        if len(parts) > 1:
            kept = [p for p in parts if p.t[-1] - p.t[0] >= MIN_SEGMENT] or [
                max(parts, key=lambda p: p.t.size)
            ]
            gaps = [b.t[0] - a.t[-1] for a, b in itertools.pairwise(parts)]
            messages.append(
                f"{path}: {len(parts)} segments (gaps up to {max(gaps):.3f} s), each prepared on "
                f"its own; {len(parts) - len(kept)} shorter than {MIN_SEGMENT:g} s left out"
            )
            parts = kept
        for message in messages:
            if note is not None:
                note(message)
        datas.extend(prepare(part, n_joints, cutoff=cutoff) for part in parts)
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
