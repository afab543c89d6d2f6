"""Reading the user's logs for a command: each file read, its notes passed on, then prepared.

A motion can also be a URScript program (``*.script``): :func:`read_motion` then simulates it as
the UR controller runs it (:mod:`kinergy.trajectory.program_motion`, 500 Hz), which needs the
robot it runs on.
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Iterator, Sequence

from kinergy.arrays import Array
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.segments import segment_bounds
from kinergy.io.urscript_reader import read_program
from kinergy.logs.prepare import (
    SIGNALS,
    STATE,
    IdentData,
    PreparedSegment,
    prepare_segment,
    spill_log,
)
from kinergy.logs.reading import CheckedLog, InputLogs, LogReading
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion, MotionSource
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path

__all__ = ["MIN_SEGMENT", "InputLogs", "LogReading", "chunked_logs", "prepared_logs", "read_motion"]


MIN_SEGMENT = 1.0
"""Shortest segment of a log (s) :func:`prepared_logs` identifies from."""


def _segments(
    path: str | os.PathLike[str], t: Array, segment: Array | None, notes: list[str]
) -> list[tuple[str, tuple[int, int]]]:
    """The segments of the log at ``path`` identified from (time stamps ``t``, its ``segment``
    signal if any: :func:`~kinergy.io.segments.segment_bounds`), each with the name
    :func:`~kinergy.io.segments.split_segments` gives it: those shorter than :data:`MIN_SEGMENT`
    are left out. Where there are several segments, ``notes`` receives what was done with them."""
    name, bounds = os.fspath(path), segment_bounds(t, segment)
    if len(bounds) == 1:
        kept = [(name, bounds[0])]
    else:
        parts = [(f"{name}#{k}", ab) for k, ab in enumerate(bounds)]
        kept = [p for p in parts if t[p[1][1] - 1] - t[p[1][0]] >= MIN_SEGMENT] or [
            max(parts, key=lambda p: p[1][1] - p[1][0])
        ]
        gaps = [t[b[0]] - t[a[1] - 1] for a, b in itertools.pairwise(bounds)]
        notes.append(
            f"{path}: {len(parts)} segments (gaps up to {max(gaps):.3f} s), each prepared on "
            f"its own; {len(parts) - len(kept)} shorter than {MIN_SEGMENT:g} s left out"
        )
    return kept


#: the signals a spill keeps: what identification uses, and the state that decides segments
SPILLED = (*SIGNALS, *STATE)


def prepared_logs(
    paths: Sequence[str | os.PathLike[str] | Log], robot: Robot, reading: LogReading
) -> tuple[list[IdentData], InputLogs]:
    """:func:`chunked_logs` with each segment prepared whole (one chunk): the logs read through
    the checks, each segment of a log on its own (nothing is filtered or differentiated across a
    gap or a reconnection), as ``reading`` says.

    Segments shorter than :data:`MIN_SEGMENT` seconds are left out and counted in a note.
    """
    with chunked_logs(paths, robot, reading) as (segments, inputs):
        return [s.whole() for s in segments], inputs


@contextlib.contextmanager
def chunked_logs(
    paths: Sequence[str | os.PathLike[str] | Log],
    robot: Robot,
    reading: LogReading,
    *,
    rows: int = CHUNK_ROWS,
) -> Iterator[tuple[list[PreparedSegment], InputLogs]]:
    """Every log read once, through the checks (:class:`~kinergy.logs.reading.CheckedLog`, in
    chunks of ``rows``), into a temporary spill removed on leaving the context, and its segments
    prepared (:func:`kinergy.logs.prepare.prepare_segment`): each yields its samples in chunks of
    any size, equal to the whole segment's preparation."""
    inputs = InputLogs()
    with contextlib.ExitStack() as stack:
        segments: list[PreparedSegment] = []
        for path in paths:
            checked = CheckedLog(path, robot, reading, select=SPILLED, rows=rows)
            spill = spill_log(checked)
            stack.callback(spill.close)
            inputs.add(checked)
            t, segment = spill.state.t, spill.state.signals.get("segment")
            for name, ab in _segments(checked.path, t, segment, inputs.notes):
                prepared = prepare_segment(spill, ab, name, robot.n, reading.cutoff)
                if prepared.grid is not None:
                    rows = prepared.rows.stop - prepared.rows.start
                    inputs.notes.append(
                        f"{name}: irregular time stamps: its {rows} rows resampled to "
                        f"{prepared.grid[1]} samples {prepared.grid[0] * 1e3:.4g} ms apart (the "
                        "counts identify and validate give)"
                    )
                segments.append(prepared)
        yield segments, inputs


def read_motion(
    path: str | os.PathLike[str],
    robot: Robot,
    reading: LogReading | None = None,
    *,
    source: MotionSource | str = MotionSource.AUTO,
) -> tuple[Motion, InputLogs]:
    """The joint motion of a log or motion file (:func:`kinergy.io.motion.motion_from_log`,
    read through the checks), or of a URScript program (``*.script``) on ``robot`` as the
    controller runs it (one cycle, starting where it ends, at 500 Hz)."""
    inputs = InputLogs()
    if os.fspath(path).endswith(".script"):
        motion, _ = program_motion(robot, program_path(robot, read_program(path)))
        return motion, inputs
    checked = CheckedLog(path, robot, reading or LogReading())
    log = checked.read()
    inputs.add(checked)
    return motion_from_log(log, n_joints=robot.n, source=source), inputs
