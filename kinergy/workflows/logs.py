"""Reading the user's logs for a command: each file read, its notes passed on, then prepared.

A motion can also be a URScript program (``*.script``): :func:`read_motion` then simulates it as
the UR controller runs it (:mod:`kinergy.trajectory.program_motion`, 500 Hz), which needs the
robot it runs on.
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Callable, Iterator, Sequence
from typing import TypedDict, Unpack

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.identify.log_chunks import prepare_segment, spill_log, streamable
from kinergy.identify.preprocess import IdentData, prepare
from kinergy.identify.streamed import Segment, WholeSegment
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.rosbag import BagOptions
from kinergy.io.rtde import read_log
from kinergy.io.segments import segment_bounds
from kinergy.io.urscript_reader import read_program
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path

__all__ = ["MIN_SEGMENT", "LogReading", "chunked_logs", "prepared_logs", "read_motion"]


MIN_SEGMENT = 1.0
"""Shortest segment of a log (s) :func:`prepared_logs` identifies from."""


class LogReading(TypedDict, total=False):
    """How :func:`prepared_logs` and :func:`chunked_logs` read and prepare each log (every key
    may be left out).

    Attributes
    ----------
    columns : str or None
        The layout of a headerless file (``--columns``, :mod:`kinergy.io.formats`); None: the
        file names its columns (UR's record.py layout).
    repair : bool
        Drop rows that cannot be read (each drop noted) instead of failing; default False.
    cutoff : float or None
        Low-pass cutoff for measured speeds, Hz (:func:`kinergy.identify.preprocess.prepare`);
        None: its default.
    note : callable or None
        Receives what reading changed (rows dropped by ``repair``, segments), one message each.
    joints : sequence of str or None
        The robot's joint names: a ROS 2 bag's joints are matched to them
        (:mod:`kinergy.io.rosbag`); the workflows that know the robot fill it in.
    bag : BagOptions or None
        A ROS 2 bag's topic and what its ``effort`` holds (``--topic``, ``--effort``).
    """

    columns: str | None
    repair: bool
    cutoff: float | None
    note: Callable[[str], None] | None
    joints: Sequence[str] | None
    bag: BagOptions | None


def _segments(
    path: str | os.PathLike[str],
    t: Array,
    segment: Array | None,
    notes: Sequence[str],
    note: Callable[[str], None] | None,
) -> list[tuple[str, tuple[int, int]]]:
    """The segments of the log at ``path`` identified from (time stamps ``t``, its ``segment``
    signal if any: :func:`~kinergy.io.segments.segment_bounds`), each with the name
    :func:`~kinergy.io.segments.split_segments` gives it: those shorter than :data:`MIN_SEGMENT`
    are left out. ``note`` receives the log's reading ``notes`` and, where there are several
    segments, what was done with them."""
    name, bounds = os.fspath(path), segment_bounds(t, segment)
    if len(bounds) == 1:
        kept = [(name, bounds[0])]
    else:
        parts = [(f"{name}#{k}", ab) for k, ab in enumerate(bounds)]
        kept = [p for p in parts if t[p[1][1] - 1] - t[p[1][0]] >= MIN_SEGMENT] or [
            max(parts, key=lambda p: p[1][1] - p[1][0])
        ]
        gaps = [t[b[0]] - t[a[1] - 1] for a, b in itertools.pairwise(bounds)]
        notes = [
            *notes,
            f"{path}: {len(parts)} segments (gaps up to {max(gaps):.3f} s), each prepared on "
            f"its own; {len(parts) - len(kept)} shorter than {MIN_SEGMENT:g} s left out",
        ]
    if note is not None:
        for text in notes:
            note(text)
    return kept


def prepared_logs(
    paths: Sequence[str | os.PathLike[str]], *, n_joints: int, **reading: Unpack[LogReading]
) -> list[IdentData]:
    """Read and prepare every log (:func:`kinergy.identify.preprocess.prepare`), each segment of
    a log on its own (:func:`kinergy.io.segments.segment_bounds`: nothing is filtered or
    differentiated across a gap or a reconnection), as ``reading`` says (:class:`LogReading`).

    Segments shorter than :data:`MIN_SEGMENT` seconds are left out and counted in a note.
    """
    datas: list[IdentData] = []
    for path in paths:
        log = read_log(
            path,
            columns=reading.get("columns"),
            repair=reading.get("repair", False),
            joints=reading.get("joints"),
            bag=reading.get("bag"),
        )
        segment = log.signals.get("segment")
        for name, (a, b) in _segments(path, log.t, segment, log.notes, reading.get("note")):
            part = Log(
                name, log.t[a:b], {k: v[a:b] for k, v in log.signals.items()}, list(log.notes)
            )
            datas.append(prepare(part, n_joints, cutoff=reading.get("cutoff")))
    return datas


@contextlib.contextmanager
def chunked_logs(
    paths: Sequence[str | os.PathLike[str]],
    *,
    n_joints: int,
    rows: int = CHUNK_ROWS,
    **reading: Unpack[LogReading],
) -> Iterator[list[Segment]]:
    """:func:`prepared_logs` as segments that yield their samples in chunks of ``rows``
    (:mod:`kinergy.identify.log_chunks`: each log read once into a temporary spill, removed on
    leaving the context). A log without the commanded motion is prepared whole
    (:class:`~kinergy.identify.streamed.WholeSegment`)."""
    cutoff = reading.get("cutoff")
    with contextlib.ExitStack() as stack:
        segments: list[Segment] = []
        for path in paths:
            spill = spill_log(
                path,
                columns=reading.get("columns"),
                repair=reading.get("repair", False),
                rows=rows,
                joints=reading.get("joints"),
                bag=reading.get("bag"),
            )
            stack.callback(spill.close)
            t, segment = spill.state.t, spill.state.signals.get("segment")
            for name, ab in _segments(path, t, segment, spill.notes, reading.get("note")):
                if streamable(spill):
                    segments.append(prepare_segment(spill, ab, name, n_joints, cutoff))
                else:
                    part = spill.read(*ab)
                    state = {k: v[ab[0] : ab[1]] for k, v in spill.state.signals.items()}
                    log = Log(name, part.t, {**part.signals, **state})
                    segments.append(WholeSegment(prepare(log, n_joints, cutoff=cutoff)))
        yield segments


def read_motion(
    path: str | os.PathLike[str],
    *,
    n_joints: int,
    columns: str | None = None,
    repair: bool = False,
    source: str = "auto",
    robot: Robot | None = None,
    bag: BagOptions | None = None,
) -> Motion:
    """The joint motion of a log or motion file (:func:`kinergy.io.motion.motion_from_log`), or
    of a URScript program (``*.script``) on ``robot`` as the controller runs it (one cycle,
    starting where it ends, at 500 Hz). A ROS 2 bag is read with ``robot``'s joint names and
    ``bag``'s options."""
    if os.fspath(path).endswith(".script"):
        if robot is None:
            raise KinergyError(f"{path}: a URScript program needs the robot it runs on")
        motion, _ = program_motion(robot, program_path(robot, read_program(path)))
        return motion
    joints = None if robot is None else robot.joint_names
    log = read_log(path, columns=columns, repair=repair, joints=joints, bag=bag)
    return motion_from_log(log, n_joints=n_joints, source=source)
